//! The scenario file as JSON text, read strictly: a UTF-8 byte-order mark is skipped, a key
//! repeated within one object is refused (plain JSON parsing silently keeps the last), and a
//! list is accepted only where the scenario holds a list (the typed reading would otherwise
//! accept a list of values in field order for any group of fields, e.g. `"output": []`).

use crate::error::{excerpt, Error, Result};
use serde::de::{DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::Value;
use std::cell::RefCell;

/// The fields that hold lists (dotted paths).
const LIST_FIELDS: [&str; 5] = [
    "inlets",
    "output.field_bins",
    "particles.placement.positions",
    "particles.placement.velocities",
    "particles.radius.species",
];

/// Parses scenario text into a JSON value, refusing malformed JSON and repeated keys.
pub fn parse(text: &str) -> Result<Value> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let malformed = |e: serde_json::Error| {
        Error::input(
            "",
            format!(
                "malformed JSON at line {} column {}: {e}",
                e.line(),
                e.column()
            ),
        )
    };
    let value: Value = serde_json::from_str(text).map_err(malformed)?;
    if let Some(key) = first_repeated_key(text).map_err(malformed)? {
        return Err(Error::input(
            excerpt(&key),
            "is given twice in one object: keep one (JSON readers disagree on which wins)",
        ));
    }
    Ok(value)
}

/// A reader's message with each "quoted" or `quoted` value in it cut to its [`excerpt`]: the
/// typed reading quotes the value it refuses (a string of megabytes, a long key) whole.
pub fn quotes_cut(message: &str) -> String {
    let mut out = String::with_capacity(message.len().min(1024));
    let mut chars = message.chars();
    while let Some(c) = chars.next() {
        out.push(c);
        if c != '"' && c != '`' {
            continue;
        }
        let mut quoted = String::new();
        let mut escaped = false;
        let mut closed = false;
        for q in chars.by_ref() {
            if q == c && !escaped {
                closed = true;
                break;
            }
            escaped = c == '"' && q == '\\' && !escaped;
            quoted.push(q);
        }
        out.push_str(&excerpt(&quoted));
        if closed {
            out.push(c);
        }
    }
    out
}

/// `true` for an inlet's species list, `inlets.k.radius.species`.
fn inlet_species(path: &str) -> bool {
    path.strip_prefix("inlets.")
        .and_then(|rest| rest.strip_suffix(".radius.species"))
        .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
}

/// Refuses a list anywhere but in `LIST_FIELDS` and inlets' species lists (and looks inside
/// species entries and inlets).
pub fn lists_only_where_lists_belong(value: &Value) -> Result<()> {
    fn walk(v: &Value, path: &str) -> Result<()> {
        match v {
            Value::Object(map) => map.iter().try_for_each(|(k, x)| {
                if path.is_empty() {
                    walk(x, k)
                } else {
                    walk(x, &format!("{path}.{k}"))
                }
            }),
            Value::Array(items) if LIST_FIELDS.contains(&path) || inlet_species(path) => {
                if path == "particles.radius.species" || path == "inlets" || inlet_species(path) {
                    for (k, item) in items.iter().enumerate() {
                        walk(item, &format!("{path}.{k}"))?;
                    }
                }
                Ok(())
            }
            Value::Array(_) => Err(Error::input(
                if path.is_empty() { "SCENARIO" } else { path },
                "a list is not accepted here: give a value or an object with fields",
            )),
            _ => Ok(()),
        }
    }
    walk(value, "")
}

/// The dotted path of the first key given twice in one object, if any.
fn first_repeated_key(text: &str) -> serde_json::Result<Option<String>> {
    let found = RefCell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    Walk {
        path: String::new(),
        found: &found,
    }
    .deserialize(&mut de)?;
    Ok(found.into_inner())
}

/// Visits every value of a JSON document, noting the first repeated key.
struct Walk<'a> {
    path: String,
    found: &'a RefCell<Option<String>>,
}

impl<'de> DeserializeSeed<'de> for Walk<'_> {
    type Value = ();
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> std::result::Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Walk<'_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E>(self, _: bool) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> std::result::Result<(), E> {
        Ok(())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<(), A::Error> {
        let mut k = 0usize;
        loop {
            let item = Walk {
                path: format!("{}.{k}", self.path),
                found: self.found,
            };
            if seq.next_element_seed(item)?.is_none() {
                return Ok(());
            }
            k += 1;
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<(), A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            let path = if self.path.is_empty() {
                key.clone()
            } else {
                format!("{}.{key}", self.path)
            };
            if !seen.insert(key) && self.found.borrow().is_none() {
                *self.found.borrow_mut() = Some(path.clone());
            }
            map.next_value_seed(Walk {
                path,
                found: self.found,
            })?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_byte_order_mark_is_skipped() {
        assert!(parse("\u{feff}{\"a\": 1}").is_ok());
    }

    #[test]
    fn a_repeated_key_is_named_with_its_path() {
        let e = parse(r#"{"a": {"b": 1, "c": [{"d": 1, "d": 2}]}}"#).unwrap_err();
        assert!(e.to_string().contains("a.c.0.d"), "{e}");
        let e = parse(r#"{"gravity": 1, "gravity": 2}"#).unwrap_err();
        assert!(e.to_string().contains("gravity"), "{e}");
        assert!(parse(r#"{"a": {"b": 1}, "c": {"b": 2}}"#).is_ok());
    }

    #[test]
    fn lists_are_refused_where_fields_belong() {
        let v: Value = serde_json::from_str(r#"{"output": []}"#).unwrap();
        let e = lists_only_where_lists_belong(&v).unwrap_err();
        assert!(e.to_string().contains("output"), "{e}");
        let v: Value = serde_json::from_str(
            r#"{"particles": {"placement": {"positions": [[1, 2]]},
                "radius": {"species": [{"radius": [1]}]}}}"#,
        )
        .unwrap();
        let e = lists_only_where_lists_belong(&v).unwrap_err();
        assert!(
            e.to_string().contains("particles.radius.species.0.radius"),
            "{e}"
        );
    }

    #[test]
    fn quoted_values_in_messages_are_cut() {
        let long = "x".repeat(10_000);
        let m = quotes_cut(&format!("invalid type: string \"{long}\", expected usize"));
        assert!(m.starts_with("invalid type: string \"xxx"), "{m}");
        assert!(m.ends_with("(10000 characters)\", expected usize"), "{m}");
        let m = quotes_cut(&format!("unknown field `{long}`, expected one of `a`, `b`"));
        assert!(m.ends_with("characters)`, expected one of `a`, `b`"), "{m}");
        let short = r#"invalid type: string "a\"b", expected f64"#;
        assert_eq!(quotes_cut(short), short);
    }
}
