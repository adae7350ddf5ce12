//! `--set key=value`: edits the scene text before it is parsed, so an override
//! is validated exactly like a key written in the file. Keys are dotted paths;
//! arrays of tables take an index (`light.0.intensity=5` or
//! `light[0].intensity=5`). Values are TOML (`render.msaa=4`,
//! `ambient.color=[0.1,0.1,0.1]`); a value that is not valid TOML is taken as a
//! string (`render.shading=flat`).

use toml_edit::{DocumentMut, Item, Table, Value};

use crate::error::Error;

/// One parsed `--set`.
#[derive(Debug, Clone)]
pub struct SetOverride {
    pub path: Vec<PathPart>,
    pub raw: String,
    pub value: Value,
}

#[derive(Debug, Clone, PartialEq)]
pub enum PathPart {
    Key(String),
    Index(usize),
}

impl std::str::FromStr for SetOverride {
    type Err = Error;
    fn from_str(s: &str) -> Result<SetOverride, Error> {
        let bad = |why: &str| Error::Argument(format!("--set {s}: {why}"));
        let (key, val) = s
            .split_once('=')
            .ok_or_else(|| bad("expected key=value, e.g. render.msaa=4"))?;
        let mut path = Vec::new();
        for part in key.trim().split('.') {
            let (name, idx) = match part.split_once('[') {
                Some((n, rest)) => {
                    let i = rest
                        .strip_suffix(']')
                        .and_then(|i| i.parse::<usize>().ok())
                        .ok_or_else(|| bad("expected an index like light[0]"))?;
                    (n, Some(i))
                }
                None => (part, None),
            };
            if let Ok(i) = name.parse::<usize>() {
                path.push(PathPart::Index(i));
            } else if name.is_empty() {
                return Err(bad("empty key component"));
            } else {
                path.push(PathPart::Key(name.to_string()));
            }
            if let Some(i) = idx {
                path.push(PathPart::Index(i));
            }
        }
        if !matches!(path.last(), Some(PathPart::Key(_))) {
            return Err(bad("the key must end with a name"));
        }
        let val = val.trim();
        let value = val
            .parse::<Value>()
            .unwrap_or_else(|_| Value::from(val.to_string()));
        Ok(SetOverride {
            path,
            raw: s.to_string(),
            value,
        })
    }
}

/// Returns the scene text with every override applied, in order.
pub fn apply(text: &str, sets: &[SetOverride]) -> Result<String, Error> {
    if sets.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc: DocumentMut = text
        .parse()
        // A syntax error is reported by the real parser with its location.
        .map_err(|_| Error::Argument("--set: the scene file is not valid TOML".into()))?;
    for s in sets {
        set_one(doc.as_table_mut(), s)?;
    }
    Ok(doc.to_string())
}

fn set_one(root: &mut Table, s: &SetOverride) -> Result<(), Error> {
    let bad = |why: String| Error::Argument(format!("--set {}: {why}", s.raw));
    let mut table: &mut Table = root;
    let mut i = 0;
    while i < s.path.len() - 1 {
        let PathPart::Key(k) = &s.path[i] else {
            return Err(bad("an index must follow a key".into()));
        };
        if let Some(PathPart::Index(n)) = s.path.get(i + 1) {
            let arr = table
                .get_mut(k)
                .and_then(Item::as_array_of_tables_mut)
                .ok_or_else(|| bad(format!("the scene has no [[{k}]] array")))?;
            let len = arr.len();
            table = arr
                .get_mut(*n)
                .ok_or_else(|| bad(format!("[[{k}]] has {len} entries, no index {n}")))?;
            i += 2;
        } else {
            let entry = table.entry(k).or_insert_with(|| {
                let mut t = Table::new();
                t.set_implicit(true);
                Item::Table(t)
            });
            // Inline tables (`ao = { .. }`) become normal tables for editing.
            if let Item::Value(Value::InlineTable(it)) = entry {
                let t = std::mem::take(it).into_table();
                *entry = Item::Table(t);
            }
            table = entry
                .as_table_mut()
                .ok_or_else(|| bad(format!("`{k}` is not a table")))?;
            i += 1;
        }
    }
    let Some(PathPart::Key(last)) = s.path.last() else {
        return Err(bad("the key must end with a name".into()));
    };
    table.insert(last, Item::Value(s.value.clone()));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(text: &str, s: &str) -> Result<String, Error> {
        apply(text, &[s.parse()?])
    }

    #[test]
    fn sets_nested_keys_and_array_entries() {
        let t = "[[model]]\npath = \"a.obj\"\n[[light]]\nintensity = 1.0\n";
        let out = set(t, "render.msaa=4").unwrap();
        assert!(
            out.contains("[render]") && out.contains("msaa = 4"),
            "{out}"
        );
        let out = set(t, "light.0.intensity=5").unwrap();
        assert!(out.contains("intensity = 5"), "{out}");
        let out = set(t, "light[0].kind=spot").unwrap();
        assert!(out.contains("kind = \"spot\""), "{out}");
        assert!(set(t, "light.3.kind=spot").is_err());
        assert!(set(t, "nonsense").is_err());
    }

    #[test]
    fn edits_inline_tables() {
        let t = "[[model]]\npath = \"a.obj\"\n[render]\nao = { method = \"ssao\" }\n";
        let out = set(t, "render.ao.samples=8").unwrap();
        let v: toml::Table = toml::from_str(&out).unwrap();
        assert_eq!(v["render"]["ao"]["samples"].as_integer(), Some(8));
        assert_eq!(v["render"]["ao"]["method"].as_str(), Some("ssao"));
    }
}
