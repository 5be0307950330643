//! `--set KEY=VALUE`: override any scenario field by its dotted path before the file is typed.
//!
//! The value is read as JSON when it parses (`3`, `0.5`, `true`, `"walls"`, `{"min":1,"max":2}`),
//! else as a plain string (`--set domain.x_boundary=periodic`). Missing intermediate objects are
//! created, so a field the file left out can be switched on (`--set gravity=1`); whether the
//! field exists is then checked when the scenario is typed, with an error naming the path.

use crate::error::{Error, Result};
use crate::scenario::checks::MAX_FIELD_DEPTH;
use serde_json::Value;

/// Applies one `KEY=VALUE` override to the scenario's JSON value.
pub fn apply(root: &mut Value, set: &str) -> Result<()> {
    let (key, raw) = set.split_once('=').ok_or_else(|| {
        Error::input(
            "--set",
            format!("`{set}` is not KEY=VALUE (e.g. particles.count=1000)"),
        )
    })?;
    let key = key.trim();
    if key.is_empty() || key.split('.').any(str::is_empty) {
        return Err(Error::input(
            "--set",
            format!("`{key}` is not a dotted field path (e.g. domain.width)"),
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
    let value: Value = serde_json::from_str(raw).unwrap_or_else(|_| Value::String(raw.to_string()));
    let segments: Vec<&str> = key.split('.').collect();
    let mut node = root;
    for (depth, segment) in segments.iter().enumerate() {
        let here = || segments[..=depth].join(".");
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
                let parent = segments[..depth].join(".");
                return Err(Error::input(
                    format!("--set {key}"),
                    format!("`{parent}` is a value, not an object with fields"),
                ));
            }
        };
    }
    unreachable!("the loop returns at the last segment")
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
}
