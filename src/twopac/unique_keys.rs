//! A JSON [`Value`] parsed like `serde_json::from_str`, except that a key twice in one
//! object is an error (serde_json keeps the last) that says where: the JSON path of the
//! duplicate (`phases[0].duration_s`) and, in the serde error, its line and column.
//!
//! The path is a list of steps on the stack, rendered only for the error.

use std::cell::RefCell;

use serde::de::{DeserializeSeed, Error as _, MapAccess, SeqAccess, Visitor};
use serde::Deserializer;
use serde_json::Value;

/// Parse `text`; on failure the serde error and, for a duplicate key, its JSON path.
pub(crate) fn from_str(text: &str) -> Result<Value, (Option<String>, serde_json::Error)> {
    let dup = RefCell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    let seed = UniqueKeys {
        at: None,
        dup: &dup,
    };
    seed.deserialize(&mut de)
        .and_then(|v| de.end().map(|()| v))
        .map_err(|e| (dup.take(), e))
}

/// One step of a JSON path: an object key or an array index.
enum Step<'a> {
    Key(&'a str),
    Index(usize),
}

/// A JSON path as a list on the stack, rendered only when an error needs it.
struct PathNode<'a> {
    parent: Option<&'a PathNode<'a>>,
    step: Step<'a>,
}

impl PathNode<'_> {
    /// `phases[3].contacts[1].normal`.
    fn render(&self) -> String {
        let head = self.parent.map(PathNode::render).unwrap_or_default();
        match self.step {
            Step::Key(k) if head.is_empty() => k.to_string(),
            Step::Key(k) => format!("{head}.{k}"),
            Step::Index(i) => format!("{head}[{i}]"),
        }
    }
}

/// Deserializes a [`Value`] like serde_json does, but refuses a duplicate object key and
/// records its path in `dup`.
struct UniqueKeys<'a> {
    at: Option<&'a PathNode<'a>>,
    dup: &'a RefCell<Option<String>>,
}

impl<'de> DeserializeSeed<'de> for UniqueKeys<'_> {
    type Value = Value;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for UniqueKeys<'_> {
    type Value = Value;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::Number(v.into()))
    }

    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::Number(v.into()))
    }

    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number))
    }

    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }

    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }

    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        self.deserialize(d)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::new();
        loop {
            let node = PathNode {
                parent: self.at,
                step: Step::Index(out.len()),
            };
            let seed = UniqueKeys {
                at: Some(&node),
                dup: self.dup,
            };
            match seq.next_element_seed(seed)? {
                Some(v) => out.push(v),
                None => return Ok(Value::Array(out)),
            }
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = serde_json::Map::new();
        while let Some(key) = map.next_key::<String>()? {
            let node = PathNode {
                parent: self.at,
                step: Step::Key(&key),
            };
            if out.contains_key(&key) {
                *self.dup.borrow_mut() = Some(node.render());
                return Err(A::Error::custom(format!(
                    "duplicate key \"{key}\" (each key once per object)"
                )));
            }
            let seed = UniqueKeys {
                at: Some(&node),
                dup: self.dup,
            };
            let v = map.next_value_seed(seed)?;
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
}
