//! `--set key=value`: edits the scene text before it is parsed, so an override
//! is validated exactly like a key written in the file. Keys are dotted paths;
//! arrays of tables take an index (`light.0.intensity=5` or
//! `light[0].intensity=5`). Values are TOML (`render.msaa=4`,
//! `ambient.color=[0.1,0.1,0.1]`); a value that is not valid TOML is taken as a
//! string (`render.shading=flat`).

use std::path::Path;

use toml_edit::{DocumentMut, Item, Table, Value};

use super::desc::SceneDesc;
use crate::error::{Error, Location};

/// One parsed `--set`.
#[derive(Debug, Clone)]
pub struct SetOverride {
    /// The key's path (`light.0.shadows`: a key, an index, a key).
    pub path: Vec<PathPart>,
    /// The `key=value` text as given.
    pub raw: String,
    /// The value, parsed as TOML.
    pub value: Value,
}

/// One step of a `--set` key's path.
#[derive(Debug, Clone, PartialEq)]
pub enum PathPart {
    /// A table key.
    Key(String),
    /// An index into an array of tables (from 0).
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

/// Returns the scene text of `file` with every override applied, in
/// order. A scene that is not valid TOML is an error at its location.
pub fn apply(file: &Path, text: &str, sets: &[SetOverride]) -> Result<String, Error> {
    if sets.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| {
        let offset = e.span().map(|s| s.start).unwrap_or(0);
        Error::Scene {
            location: Location::from_offset(file, text, offset),
            message: e.message().trim_end().to_string(),
        }
    })?;
    for s in sets {
        set_one(doc.as_table_mut(), s)?;
    }
    Ok(doc.to_string())
}

/// For an error in the scene as edited by `sets`: when an override made
/// it (the file alone parses, and applying the overrides one by one, one
/// of them breaks it), the error names that `--set`; otherwise `error` as
/// it is.
pub fn blame(file: &Path, text: &str, sets: &[SetOverride], error: Error) -> Error {
    if sets.is_empty() || SceneDesc::parse(file, text).is_err() {
        return error;
    }
    for k in 1..=sets.len() {
        let Ok(edited) = apply(file, text, &sets[..k]) else {
            return error;
        };
        if let Err(Error::Scene { message, .. }) = SceneDesc::parse(file, &edited) {
            // Without the excerpt: it quotes the merged text, not what
            // the user typed.
            let message = message.split("\n  ").next().unwrap_or(&message);
            return Error::Argument(format!("--set {}: {message}", sets[k - 1].raw));
        }
    }
    error
}

/// `--set camera.0.azimuth=35` on a scene without `[[camera]]`: how to
/// add one instead.
fn no_array(k: &str, rest: &[PathPart], value: &Value) -> String {
    let mut v = value.clone();
    v.decor_mut().clear();
    match rest {
        [PathPart::Key(field)] => format!(
            "the scene has no [[{k}]] to change; add one with --set '{k}=[{{{field}={v}}}]'"
        ),
        _ => format!("the scene has no [[{k}]] array"),
    }
}

fn part_name(p: &PathPart) -> String {
    match p {
        PathPart::Key(k) => k.clone(),
        PathPart::Index(n) => n.to_string(),
    }
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
                .ok_or_else(|| bad(no_array(k, &s.path[i + 2..], &s.value)))?;
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
            let array = entry.is_array_of_tables();
            table = entry.as_table_mut().ok_or_else(|| {
                let rest: Vec<String> = s.path[i + 1..].iter().map(part_name).collect();
                bad(if array {
                    format!(
                        "`{k}` is a list ([[{k}]]): say which entry, e.g. `{k}.0.{}`",
                        rest.join(".")
                    )
                } else {
                    format!("`{k}` is not a table")
                })
            })?;
            i += 1;
        }
    }
    let Some(PathPart::Key(last)) = s.path.last() else {
        return Err(bad("the key must end with a name".into()));
    };
    table.insert(last, Item::Value(s.value.clone()));
    Ok(())
}

/// Where a loaded scene's text came from, to name in messages what the
/// user can fix: `text` is the scene file's own text (None: a model
/// file's generated one-line scene), `edited` the text after `sets`.
pub struct Origin<'a> {
    /// The scene or model file.
    pub file: &'a Path,
    /// The scene file's own text.
    pub text: Option<&'a str>,
    /// The text after the overrides.
    pub edited: &'a str,
    /// The `--set` overrides applied.
    pub sets: &'a [SetOverride],
}

impl Origin<'_> {
    /// Where line `line` of the edited text came from: None when it is
    /// the scene file's own line; else the `--set` that wrote it, or ""
    /// for generated text no `--set` wrote.
    fn source(&self, line: usize) -> Option<String> {
        let l = self.edited.lines().nth(line.checked_sub(1)?)?.trim();
        if let Some(text) = self.text
            && text.lines().any(|t| t.trim() == l)
        {
            return None;
        }
        // The `--set` whose last key this line sets (the last such: the
        // one that wins).
        let set = self.sets.iter().rev().find(|s| {
            matches!(s.path.last(), Some(PathPart::Key(k))
                if l.strip_prefix(k.as_str()).is_some_and(|r| r.trim_start().starts_with('=')))
        });
        match set {
            Some(s) => Some(format!("--set {}", s.raw)),
            None if self.text.is_none() => Some(String::new()),
            None => None,
        }
    }

    /// A message naming `file:line:col` of text the user did not write
    /// (at its start, or inside, as "(from file:3:8)"): that place becomes
    /// the `--set` as typed, or the model file alone.
    pub fn warning(&self, w: String) -> String {
        let name = format!("{}:", self.file.display());
        let Some(at) = w.find(&name) else {
            return w;
        };
        let rest = &w[at + name.len()..];
        let digits = |s: &str| s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
        let n1 = digits(rest);
        let Some(after_line) = rest[n1..].strip_prefix(':') else {
            return w;
        };
        let n2 = digits(after_line);
        let (Ok(line), true) = (rest[..n1].parse::<usize>(), n2 > 0) else {
            return w;
        };
        let end = at + name.len() + n1 + 1 + n2;
        match self.source(line) {
            None => w,
            Some(s) if s.is_empty() => {
                format!("{}{}{}", &w[..at], self.file.display(), &w[end..])
            }
            Some(s) => format!("{}{s}{}", &w[..at], &w[end..]),
        }
    }

    /// `warning` for an error at a place in the edited text; the excerpt
    /// of a generated line is dropped.
    pub fn error(&self, e: Error) -> Error {
        let (location, message) = match e {
            Error::Scene { location, message } => (location, message),
            Error::Asset {
                path,
                line,
                message,
            } => {
                return Error::Asset {
                    path,
                    line,
                    message: self.warning(message),
                };
            }
            Error::SceneGlobal { file, message } => {
                return Error::SceneGlobal {
                    file,
                    message: self.warning(message),
                };
            }
            other => return other,
        };
        if location.file != self.file {
            return Error::Scene { location, message };
        }
        let short = || message.split("\n  ").next().unwrap_or(&message).to_string();
        match self.source(location.line) {
            None => Error::Scene { location, message },
            Some(s) if s.is_empty() => Error::SceneGlobal {
                file: self.file.to_path_buf(),
                message: short(),
            },
            Some(s) => Error::Argument(format!("{s}: {}", short())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(text: &str, s: &str) -> Result<String, Error> {
        apply(Path::new("s.toml"), text, &[s.parse()?])
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

    #[test]
    fn a_scene_that_is_not_toml_keeps_its_location() {
        let t = "[[model]]\npath = \"a.obj\"\n[render\nmsaa = 4\n";
        let e = set(t, "render.msaa=4").unwrap_err();
        assert!(matches!(e, Error::Scene { .. }), "{e:?}");
        assert!(e.to_string().starts_with("s.toml:3:"), "{e}");
    }

    #[test]
    fn an_error_made_by_an_override_names_it() {
        let file = Path::new("s.toml");
        let t = "[[model]]\npath = \"a.obj\"\n";
        let sets: Vec<SetOverride> = ["output.width=64", "render.msaa=3", "render.ssaa=2"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let edited = apply(file, t, &sets).unwrap();
        let e = SceneDesc::parse(file, &edited).unwrap_err();
        let e = blame(file, t, &sets, e);
        assert!(e.to_string().starts_with("--set render.msaa=3: "), "{e}");
        assert!(
            e.to_string().contains("expected one of 1, 2, 4, 8, 16"),
            "{e}"
        );
        // An error of the file itself stays the file's.
        let bad = "[[model]]\npath = \"\"\n";
        let e = SceneDesc::parse(file, bad).unwrap_err();
        let e = blame(file, bad, &sets, e);
        assert!(e.to_string().starts_with("s.toml:2:"), "{e}");
    }
}
