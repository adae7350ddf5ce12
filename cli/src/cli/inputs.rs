//! What `softraster render INPUT...` renders: the inputs as given (scene
//! files, model files, folders read recursively, `--list` files), sorted,
//! named for their output folders, and split into shards.
//!
//! Every problem here is a bad argument (exit 2), found before anything
//! renders: a path that does not exist, a folder with nothing softraster
//! reads, a list line naming a missing file, a malformed `--shard`.

use std::collections::{BTreeMap, HashSet};
use std::io::BufRead;
use std::path::{Path, PathBuf};

use softraster::error::Error;

/// Whether a folder's file with extension `e` is an input: a scene or a
/// model of any format softraster reads (case-insensitive).
fn is_input_extension(e: &str) -> bool {
    e.eq_ignore_ascii_case("toml") || softraster::assets::is_model_extension(e)
}

/// One input to render.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Input {
    pub path: PathBuf,
    /// Its folder under the output root (`OUT/<name>/`); None for a lone
    /// file input, whose frames go where they go for one scene.
    pub name: Option<PathBuf>,
}

/// Where an input came from: named itself (on the command line or in a
/// list), or found in a folder (the folder).
#[derive(Debug, Clone)]
enum Origin {
    Named,
    Found(PathBuf),
}

/// The inputs `paths` and the list `list` (a file of one path a line, `-`
/// for stdin; empty lines and lines starting with `#` are skipped), sorted
/// by path and named for their output folders.
pub fn gather(paths: &[PathBuf], list: Option<&Path>) -> Result<Vec<Input>, Error> {
    let mut found: Vec<(PathBuf, Origin)> = Vec::new();
    for p in paths {
        add(p, None, &mut found)?;
    }
    if let Some(list) = list {
        for (line, p) in read_list(list)? {
            add(&p, Some((list, line)), &mut found)?;
        }
    }
    if found.is_empty() {
        return Err(Error::Argument(
            "render: no input (give a scene, a model, a folder or --list FILE)".into(),
        ));
    }
    found.sort_by(|a, b| a.0.cmp(&b.0));
    found.dedup_by(|a, b| a.0 == b.0);
    Ok(name(found))
}

/// Adds `p` (from line `from.1` of list `from.0`, if it came from one):
/// a file as itself, a folder as the files below it.
fn add(
    p: &Path,
    from: Option<(&Path, usize)>,
    found: &mut Vec<(PathBuf, Origin)>,
) -> Result<(), Error> {
    let whence = || match from {
        Some((list, line)) => format!("{}:{line}: ", shown(list)),
        None => String::new(),
    };
    let meta = std::fs::metadata(p)
        .map_err(|e| Error::Argument(format!("{}{}: {}", whence(), p.display(), reason(&e))))?;
    if !meta.is_dir() {
        found.push((p.to_path_buf(), Origin::Named));
        return Ok(());
    }
    let mut files = Vec::new();
    walk(p, &mut HashSet::new(), &mut files);
    if files.is_empty() {
        return Err(Error::Argument(format!(
            "{}{}: a folder with no file softraster reads below it (.toml, {})",
            whence(),
            p.display(),
            softraster::assets::model_extensions_listed()
        )));
    }
    found.extend(
        files
            .into_iter()
            .map(|f| (f, Origin::Found(p.to_path_buf()))),
    );
    Ok(())
}

/// The files below `dir` with a scene's or model's extension, following links to
/// folders but entering each folder once (`seen`: canonical paths), so a
/// link loop ends. Unreadable entries are passed over.
fn walk(dir: &Path, seen: &mut HashSet<PathBuf>, out: &mut Vec<PathBuf>) {
    let Ok(canonical) = std::fs::canonicalize(dir) else {
        return;
    };
    if !seen.insert(canonical) {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for e in entries {
        match std::fs::metadata(&e) {
            Ok(m) if m.is_dir() => walk(&e, seen, out),
            Ok(_) if readable(&e) => out.push(e),
            _ => {}
        }
    }
}

/// Whether `p` has a scene's or a model's extension.
fn readable(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(is_input_extension)
}

/// The paths of list `list` with their line numbers (from 1).
fn read_list(list: &Path) -> Result<Vec<(usize, PathBuf)>, Error> {
    let reader: Box<dyn BufRead> = if list == Path::new("-") {
        Box::new(std::io::stdin().lock())
    } else {
        let f = std::fs::File::open(list)
            .map_err(|e| Error::Argument(format!("--list {}: {}", list.display(), reason(&e))))?;
        Box::new(std::io::BufReader::new(f))
    };
    let mut out = Vec::new();
    for (i, line) in reader.lines().enumerate() {
        let line = line.map_err(|e| Error::Argument(format!("--list {}: {e}", shown(list))))?;
        let line = line.trim();
        if !line.is_empty() && !line.starts_with('#') {
            out.push((i + 1, PathBuf::from(line)));
        }
    }
    Ok(out)
}

fn shown(list: &Path) -> String {
    if list == Path::new("-") {
        "stdin".into()
    } else {
        list.display().to_string()
    }
}

fn reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file or folder".into(),
        _ => e.to_string(),
    }
}

/// Output folders: none for a lone named file; otherwise a named file's
/// stem, and a found file's path relative to its folder without the
/// extension. Where two inputs would share a folder, each keeps its
/// extension (`x.obj`, `x.glb`).
fn name(found: Vec<(PathBuf, Origin)>) -> Vec<Input> {
    if let [(path, Origin::Named)] = &found[..] {
        return vec![Input {
            path: path.clone(),
            name: None,
        }];
    }
    let plain = |(path, origin): &(PathBuf, Origin)| -> PathBuf {
        let rel = match origin {
            Origin::Found(root) => path.strip_prefix(root).unwrap_or(path),
            Origin::Named => Path::new(path.file_name().unwrap_or(path.as_os_str())),
        };
        rel.with_extension("")
    };
    let mut count: BTreeMap<PathBuf, usize> = BTreeMap::new();
    for f in &found {
        *count.entry(plain(f)).or_default() += 1;
    }
    found
        .iter()
        .map(|f| {
            let mut name = plain(f);
            if count[&name] > 1 {
                let ext = f.0.extension().unwrap_or_default().to_string_lossy();
                name = PathBuf::from(format!("{}.{ext}", name.display()));
            }
            Input {
                path: f.0.clone(),
                name: Some(name),
            }
        })
        .collect()
}

/// A split of the inputs: this process takes index i of every n.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// `I/N`, I from 0 to N - 1.
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("{s:?}: expected I/N with N >= 1 and I from 0 to N - 1, e.g. 0/4");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (i.trim().parse::<usize>(), n.trim().parse::<usize>());
        match (index, count) {
            (Ok(index), Ok(count)) if count >= 1 && index < count => Ok(Shard { index, count }),
            _ => Err(bad()),
        }
    }
}

impl Shard {
    /// The split of a Slurm job array, when this process is one of its
    /// tasks: I = `SLURM_ARRAY_TASK_ID` - `SLURM_ARRAY_TASK_MIN` (0 when
    /// unset), N = `SLURM_ARRAY_TASK_COUNT`.
    pub fn from_slurm(var: impl Fn(&str) -> Option<String>) -> Result<Option<Shard>, Error> {
        let (Some(id), Some(count)) = (var("SLURM_ARRAY_TASK_ID"), var("SLURM_ARRAY_TASK_COUNT"))
        else {
            return Ok(None);
        };
        let min = var("SLURM_ARRAY_TASK_MIN").unwrap_or_else(|| "0".into());
        let num = |name: &str, v: &str| {
            v.trim()
                .parse::<usize>()
                .map_err(|_| Error::Argument(format!("{name}={v:?}: expected a whole number")))
        };
        let (id, min, count) = (
            num("SLURM_ARRAY_TASK_ID", &id)?,
            num("SLURM_ARRAY_TASK_MIN", &min)?,
            num("SLURM_ARRAY_TASK_COUNT", &count)?,
        );
        match id.checked_sub(min) {
            Some(index) if index < count => Ok(Some(Shard { index, count })),
            _ => Err(Error::Argument(format!(
                "SLURM_ARRAY_TASK_ID={id} with SLURM_ARRAY_TASK_MIN={min} and \
                 SLURM_ARRAY_TASK_COUNT={count}: not a task of the array \
                 (give --shard I/N)"
            ))),
        }
    }

    /// The inputs of this shard: those whose index is `index` modulo
    /// `count`.
    pub fn take(self, inputs: Vec<Input>) -> Vec<Input> {
        inputs
            .into_iter()
            .enumerate()
            .filter(|(k, _)| k % self.count == self.index)
            .map(|(_, i)| i)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree(files: &[&str]) -> PathBuf {
        let dir = std::env::temp_dir().join(format!(
            "softraster-inputs-{}-{}",
            std::process::id(),
            files.len()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        for f in files {
            let p = dir.join(f);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, "").unwrap();
        }
        dir
    }

    #[test]
    fn a_folder_gives_its_model_files_named_by_relative_path() {
        let dir = tree(&[
            "b/x.obj",
            "a.glb",
            "a.obj",
            "b/c/y.PLY",
            "notes.txt",
            "t.png",
        ]);
        let got = gather(std::slice::from_ref(&dir), None).unwrap();
        let names: Vec<String> = got
            .iter()
            .map(|i| i.name.as_ref().unwrap().display().to_string())
            .collect();
        // Sorted by path; a.glb and a.obj share a stem, so keep their
        // extensions.
        assert_eq!(names, ["a.glb", "a.obj", "b/c/y", "b/x"]);
        // A lone file keeps the one-scene output.
        let one = gather(&[dir.join("a.obj")], None).unwrap();
        assert_eq!(one[0].name, None);
        // Two named files: their stems.
        let two = gather(&[dir.join("b/x.obj"), dir.join("a.glb")], None).unwrap();
        assert_eq!(two[0].name, Some(PathBuf::from("a")));
        assert_eq!(two[1].name, Some(PathBuf::from("x")));
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn shards_split_by_index_and_bad_ones_are_refused() {
        let inputs: Vec<Input> = (0..7)
            .map(|k| Input {
                path: PathBuf::from(format!("{k}.obj")),
                name: None,
            })
            .collect();
        let s: Shard = "1/3".parse().unwrap();
        let got: Vec<_> = s.take(inputs).iter().map(|i| i.path.clone()).collect();
        assert_eq!(got, [PathBuf::from("1.obj"), "4.obj".into()]);
        for bad in ["3/2", "0/0", "2", "-1/2", "a/b", "1/2/3"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        let env = |vars: &'static [(&str, &str)]| {
            move |k: &str| vars.iter().find(|v| v.0 == k).map(|v| v.1.to_string())
        };
        let slurm = env(&[
            ("SLURM_ARRAY_TASK_ID", "12"),
            ("SLURM_ARRAY_TASK_MIN", "10"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ]);
        assert_eq!(
            Shard::from_slurm(slurm).unwrap(),
            Some(Shard { index: 2, count: 4 })
        );
        assert_eq!(Shard::from_slurm(env(&[])).unwrap(), None);
        let outside = env(&[
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ]);
        assert!(Shard::from_slurm(outside).is_err());
    }

    #[cfg(unix)]
    #[test]
    fn a_link_loop_ends() {
        let dir = tree(&["m/a.stl"]);
        std::os::unix::fs::symlink(&dir, dir.join("m/loop")).unwrap();
        let got = gather(std::slice::from_ref(&dir), None).unwrap();
        assert_eq!(got.len(), 1);
        std::fs::remove_dir_all(dir).unwrap();
    }
}
