//! `--set KEY=VALUE`: override any scenario field by its dotted path before the file is typed.
//!
//! The value is read as JSON when it parses (`3`, `0.5`, `true`, `"walls"`, `{"min":1,"max":2}`),
//! else as a plain string (`--set domain.x_boundary=periodic`); a value that opens a list or
//! an object (`[`, `{`) and does not parse is refused, not taken for a string. Missing intermediate objects are
//! created, so a field the file left out can be switched on (`--set gravity=1`); whether the
//! field exists is then checked when the scenario is typed, with an error naming the path.

use crate::error::{excerpt, Error, Result};
use crate::scenario::checks::MAX_FIELD_DEPTH;
use serde_json::Value;

/// Applies one `KEY=VALUE` override to the scenario's JSON value.
pub fn apply(root: &mut Value, set: &str) -> Result<()> {
    let (key, raw) = set.split_once('=').ok_or_else(|| {
        Error::input(
            "--set",
            format!(
                "`{}` is not KEY=VALUE (e.g. particles.count=1000)",
                excerpt(set)
            ),
        )
    })?;
    let key = key.trim();
    if key.is_empty() || key.split('.').any(str::is_empty) {
        return Err(Error::input(
            "--set",
            format!(
                "`{}` is not a dotted field path (e.g. domain.width)",
                excerpt(key)
            ),
        ));
    }
    let depth = key.split('.').count();
    if depth > MAX_FIELD_DEPTH {
        return Err(Error::input(
            "--set",
            format!(
                "a path of {depth} fields is deeper than any scenario field (at most \
                 {MAX_FIELD_DEPTH}, e.g. inlets.0.radius.species.0.mass)"
            ),
        ));
    }
    let value = value_of(key, raw)?;
    let segments: Vec<&str> = key.split('.').collect();
    let mut node = root;
    for (depth, segment) in segments.iter().enumerate() {
        let here = || excerpt(&segments[..=depth].join("."));
        let last = depth + 1 == segments.len();
        node = match node {
            Value::Object(map) => {
                if last {
                    map.insert((*segment).to_string(), value);
                    return Ok(());
                }
                map.entry((*segment).to_string())
                    .or_insert_with(|| Value::Object(Default::default()))
            }
            Value::Array(items) => {
                let index: usize = segment.parse().map_err(|_| {
                    Error::input(
                        format!("--set {}", here()),
                        "this field is a list: index it with a number",
                    )
                })?;
                let len = items.len();
                let slot = items.get_mut(index).ok_or_else(|| {
                    Error::input(
                        format!("--set {}", here()),
                        format!("index {index} is beyond the list's {len} entries"),
                    )
                })?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            _ => {
                let parent = excerpt(&segments[..depth].join("."));
                return Err(Error::input(
                    format!("--set {}", excerpt(key)),
                    format!("`{parent}` is a value, not an object with fields"),
                ));
            }
        };
    }
    unreachable!("the loop returns at the last segment")
}

/// The value of `--set KEY=RAW`: RAW as JSON when it parses, else RAW as a string; a RAW that
/// opens a list or an object but does not parse is a broken value, refused naming `KEY` and
/// quoting RAW's start.
fn value_of(key: &str, raw: &str) -> Result<Value> {
    match serde_json::from_str(raw) {
        Ok(value) => Ok(value),
        Err(e) if raw.trim_start().starts_with(['[', '{']) => Err(Error::input(
            format!("--set {}", excerpt(key)),
            format!("`{}` is not valid JSON ({e})", excerpt(raw)),
        )),
        Err(_) => Ok(Value::String(raw.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn sets_numbers_strings_and_creates_objects() {
        let mut v = json!({"particles": {"count": 10}, "domain": {"width": 5}});
        apply(&mut v, "particles.count=2500").unwrap();
        apply(&mut v, "domain.x_boundary=periodic").unwrap();
        apply(&mut v, "gravity=1").unwrap();
        apply(&mut v, "floor.amplitude=0.1").unwrap();
        assert_eq!(v["particles"]["count"], json!(2500));
        assert_eq!(v["domain"]["x_boundary"], json!("periodic"));
        assert_eq!(v["gravity"], json!(1));
        assert_eq!(v["floor"]["amplitude"], json!(0.1));
    }

    #[test]
    fn rejects_malformed_overrides_naming_them() {
        let mut v = json!({"particles": {"count": 10}});
        let e = apply(&mut v, "particles.count").unwrap_err();
        assert!(e.to_string().contains("KEY=VALUE"), "{e}");
        let e = apply(&mut v, "particles..count=3").unwrap_err();
        assert!(e.to_string().contains("dotted"), "{e}");
        let e = apply(&mut v, "particles.count.x=3").unwrap_err();
        assert!(e.to_string().contains("particles.count"), "{e}");
        assert_eq!(e.exit_code(), 2);
    }

    #[test]
    fn a_path_deeper_than_any_field_is_refused_at_once() {
        let mut v = json!({"particles": {"count": 10}});
        let key = vec!["a"; 60_000].join(".");
        let e = apply(&mut v, &format!("{key}=1")).unwrap_err();
        assert!(
            e.to_string().contains("deeper than any scenario field"),
            "{e}"
        );
        assert_eq!(v, json!({"particles": {"count": 10}}));
        apply(&mut v, "inlets=[{}]").unwrap();
        apply(&mut v, "inlets.0.radius.species=[{}]").unwrap();
        apply(&mut v, "inlets.0.radius.species.0.mass=2").unwrap();
        assert_eq!(v["inlets"][0]["radius"]["species"][0]["mass"], json!(2));
    }

    #[test]
    fn a_broken_json_value_is_refused_naming_the_key_and_quoting_its_start() {
        let mut v = json!({"particles": {"count": 10}});
        let raw = format!("[1,2,{}", "9".repeat(100_000));
        let e = apply(&mut v, &format!("particles.count={raw}")).unwrap_err();
        let message = e.to_string();
        assert!(
            message.starts_with("--set particles.count: `[1,2,9"),
            "{message}"
        );
        assert!(message.contains("not valid JSON"), "{message}");
        assert!(message.len() < 300, "{} characters", message.len());
        assert_eq!(e.exit_code(), 2);
        let e = apply(&mut v, &format!("{}.count", "p".repeat(100_000))).unwrap_err();
        assert!(e.to_string().len() < 300, "{e}");
        apply(&mut v, "output.rrd=run[1].rrd").unwrap();
        assert_eq!(v["output"]["rrd"], json!("run[1].rrd"));
    }
}
