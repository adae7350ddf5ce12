//! One way to read a file that a scene or a model names: the model, an MTL
//! library, a texture, a glTF buffer or image, an environment map. Farms
//! and thumbnail services feed us files nobody checked, so every read:
//! - requires a regular file, checked on the open handle (a directory, a
//!   FIFO or a device such as `/dev/zero` is refused; the open never
//!   blocks on a FIFO);
//! - reads at most what the format declares (a glTF buffer's
//!   `byteLength`), or at most [`Input::read_cap`], plus one byte to see
//!   an overrun;
//! - in the sandbox (`--sandbox`, `render.sandbox`), stays inside the
//!   scene's folder: no `..`, no absolute path, no URI scheme, no symbolic
//!   link that leads out.
//!
//! [`Input`] also carries the memory budget that sizes are checked
//! against before anything is allocated: a decoded image with its RGBA
//! expansion and mip chain, an accessor's elements, an environment map.
//! With no `--max-memory` the budget is the smaller of the memory
//! available and the address-space limit, less headroom ([`default_budget`]).

use std::fs::File;
use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::Error;

/// The most bytes read from one file whose format declares no size.
pub const READ_CAP: u64 = 1 << 30;

/// How files named by a scene are read, and the memory they may take.
#[derive(Debug, Clone)]
pub struct Input {
    budget: u64,
    /// Bytes of decoded assets kept so far (textures with their chains,
    /// meshes), shared by the clones that load one scene.
    kept: Arc<AtomicU64>,
    /// The sandbox's folders, as given and canonical; None: any path.
    sandbox: Option<Arc<Vec<(PathBuf, PathBuf)>>>,
}

impl Default for Input {
    /// Any path, the default budget.
    fn default() -> Input {
        Input::new(default_budget())
    }
}

impl Input {
    /// Any path; sizes checked against `budget` bytes.
    pub fn new(budget: u64) -> Input {
        Input {
            budget,
            kept: Arc::default(),
            sandbox: None,
        }
    }

    /// Every read confined to `folders` (the scene's folder).
    pub fn sandboxed(mut self, folders: &[&Path]) -> Input {
        let roots = folders
            .iter()
            .map(|f| {
                // A scene in the working directory has the folder "".
                let dir = if f.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    f
                };
                let canonical = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
                (f.to_path_buf(), canonical)
            })
            .collect();
        self.sandbox = Some(Arc::new(roots));
        self
    }

    /// The memory budget in bytes that assets are checked against.
    pub fn budget(&self) -> u64 {
        self.budget
    }

    /// Whether reads are kept inside the sandbox's folders.
    pub fn is_sandboxed(&self) -> bool {
        self.sandbox.is_some()
    }

    /// The most bytes read from one file of undeclared size: 1 GiB, or
    /// the budget when that is smaller.
    pub fn read_cap(&self) -> u64 {
        READ_CAP.min(self.budget)
    }

    /// Checks that `bytes` more (a decode's buffers, an accessor's
    /// elements) fit in what the budget has left; `what` names them.
    pub fn check(&self, what: &str, bytes: u64) -> Result<(), String> {
        let kept = self.kept.load(Ordering::Relaxed);
        if kept.saturating_add(bytes) > self.budget {
            return Err(format!(
                "{what} would take {}{}, more than the memory budget of {} (--max-memory sets it)",
                human(bytes),
                if kept > 0 {
                    format!(" beside the {} already loaded", human(kept))
                } else {
                    String::new()
                },
                human(self.budget)
            ));
        }
        Ok(())
    }

    /// [`Input::check`] for an asset at `path`: an [`Error::Memory`].
    pub fn check_file(&self, path: &Path, what: &str, bytes: u64) -> Result<(), Error> {
        self.check(what, bytes).map_err(|message| Error::Memory {
            path: path.to_path_buf(),
            message,
        })
    }

    /// Counts `bytes` kept for the render (a decoded texture and its
    /// chain) against the budget.
    pub fn keep(&self, bytes: u64) {
        self.kept.fetch_add(bytes, Ordering::Relaxed);
    }

    /// In the sandbox: that `path` stays inside its folders. `asked_by`
    /// is the file that named it (for the message).
    pub fn confine(&self, path: &Path, asked_by: Option<&Path>) -> Result<(), Error> {
        let Some(roots) = &self.sandbox else {
            return Ok(());
        };
        let refuse = |why: &str| Error::Sandbox {
            path: path.to_path_buf(),
            message: format!(
                "{}: {why}",
                asked_by
                    .map(|a| format!(" (named by {})", a.display()))
                    .unwrap_or_default(),
            ),
        };
        let Some(rest) = roots
            .iter()
            .find_map(|(given, _)| path.strip_prefix(given).ok())
        else {
            return Err(refuse("an absolute path or one outside the scene's folder"));
        };
        for (i, c) in rest.components().enumerate() {
            match c {
                Component::Normal(n) if i == 0 && looks_like_scheme(n) => {
                    return Err(refuse("a URI scheme"));
                }
                Component::Normal(_) | Component::CurDir => {}
                Component::ParentDir => return Err(refuse("a path with `..`")),
                Component::RootDir | Component::Prefix(_) => {
                    return Err(refuse("an absolute path"));
                }
            }
        }
        // A symbolic link inside the folder may lead out of it.
        if let Ok(real) = path.canonicalize()
            && !roots.iter().any(|(_, c)| real.starts_with(c))
        {
            return Err(refuse("a link that leads outside the scene's folder"));
        }
        Ok(())
    }

    /// Opens `path` for reading: confined (in the sandbox), never blocking,
    /// and only a regular file. Returns the file and its length.
    pub fn open(&self, path: &Path, asked_by: Option<&Path>) -> Result<(File, u64), Error> {
        self.confine(path, asked_by)?;
        let file = open_nonblocking(path).map_err(|e| {
            Error::asset(
                path,
                None,
                format!(
                    "cannot read: {e}{}",
                    asked_by
                        .map(|a| format!(" (named by {})", a.display()))
                        .unwrap_or_default()
                ),
            )
        })?;
        let meta = file
            .metadata()
            .map_err(|e| Error::asset(path, None, format!("cannot read: {e}")))?;
        if !meta.is_file() {
            return Err(Error::asset(
                path,
                None,
                format!("{}, not a regular file", crate::files::kind(&meta)),
            ));
        }
        Ok((file, meta.len()))
    }

    /// The whole of `path`: at most `declared` bytes when the format says
    /// how many (a longer file is read that far), else at most
    /// [`Input::read_cap`] (a longer file is an error).
    pub fn read(
        &self,
        path: &Path,
        asked_by: Option<&Path>,
        declared: Option<u64>,
    ) -> Result<Vec<u8>, Error> {
        let (file, len) = self.open(path, asked_by)?;
        let cap = self.read_cap();
        let limit = declared.unwrap_or(cap);
        if declared.is_none() && len > cap {
            return Err(too_long(path, len, cap));
        }
        if let Some(d) = declared {
            self.check_file(path, &format!("a file of {d} bytes"), d)?;
        }
        let mut bytes = Vec::with_capacity(len.min(limit) as usize);
        file.take(limit + 1)
            .read_to_end(&mut bytes)
            .map_err(|e| Error::asset(path, None, format!("cannot read: {e}")))?;
        if bytes.len() as u64 > limit {
            if declared.is_none() {
                // It grew while being read.
                return Err(too_long(path, bytes.len() as u64, cap));
            }
            bytes.truncate(limit as usize);
        }
        Ok(bytes)
    }

    /// [`Input::read`] as text (UTF-8, else Latin-1: `text::decode`).
    pub fn read_text(&self, path: &Path, asked_by: Option<&Path>) -> Result<String, Error> {
        Ok(super::text::decode(&self.read(path, asked_by, None)?))
    }
}

fn too_long(path: &Path, len: u64, cap: u64) -> Error {
    Error::asset(
        path,
        None,
        format!(
            "the file has {} bytes, more than the {} read from one file",
            len,
            human(cap)
        ),
    )
}

/// `http:`, `file:`: a URI scheme where a relative path was expected.
fn looks_like_scheme(n: &std::ffi::OsStr) -> bool {
    let s = n.to_string_lossy();
    s.split_once(':').is_some_and(|(scheme, _)| {
        !scheme.is_empty()
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
    })
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    // O_NONBLOCK: opening a FIFO with no writer returns at once (and the
    // handle is then refused as not a regular file).
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    File::open(path)
}

/// Bytes as MiB or GiB with one decimal.
pub fn human(b: u64) -> String {
    let mib = b as f64 / (1u64 << 20) as f64;
    if mib >= 1024.0 {
        format!("{:.1} GiB", mib / 1024.0)
    } else {
        format!("{mib:.1} MiB")
    }
}

/// The budget when none is given: the smaller of the memory available
/// (`MemAvailable`) and the address-space limit (`RLIMIT_AS`), less
/// headroom for what no estimate counts (code, allocator arenas, stacks):
/// an eighth, at least 256 MiB. Where neither is known, 16 GiB.
pub fn default_budget() -> u64 {
    let known = [available_memory(), address_space_limit()]
        .into_iter()
        .flatten()
        .min();
    match known {
        Some(m) => m.saturating_sub((m / 8).max(256 << 20)).max(64 << 20),
        None => 16 << 30,
    }
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// The soft `RLIMIT_AS`, when there is one.
#[cfg(unix)]
fn address_space_limit() -> Option<u64> {
    let mut r = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given and nothing else.
    let ok = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut r) } == 0;
    (ok && r.rlim_cur != libc::RLIM_INFINITY).then_some(r.rlim_cur)
}

#[cfg(not(unix))]
fn address_space_limit() -> Option<u64> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("softraster-input-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn reads_what_is_declared_and_refuses_what_is_not_a_file() {
        let d = temp("read");
        let f = d.join("a.bin");
        std::fs::write(&f, [7u8; 100]).unwrap();
        let input = Input::new(1 << 30);
        assert_eq!(input.read(&f, None, Some(36)).unwrap().len(), 36);
        assert_eq!(input.read(&f, None, None).unwrap().len(), 100);
        let e = input.read(&d, None, None).unwrap_err().to_string();
        assert!(e.contains("a directory, not a regular file"), "{e}");
        #[cfg(unix)]
        {
            let e = input
                .read(Path::new("/dev/zero"), None, Some(36))
                .unwrap_err()
                .to_string();
            assert!(e.contains("a device"), "{e}");
        }
        // Undeclared and over the cap.
        let small = Input::new(64);
        let e = small.read(&f, None, None).unwrap_err().to_string();
        assert!(e.contains("more than"), "{e}");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn the_sandbox_keeps_reads_in_the_folder() {
        let d = temp("sandbox");
        std::fs::create_dir_all(d.join("sub")).unwrap();
        std::fs::write(d.join("sub/t.png"), b"x").unwrap();
        std::fs::write(d.join("secret"), b"x").unwrap();
        let scene = d.join("sub/scene.toml");
        let input = Input::new(1 << 30).sandboxed(&[&d.join("sub")]);
        assert!(input.confine(&d.join("sub/t.png"), Some(&scene)).is_ok());
        for bad in [
            d.join("sub/../secret"),
            d.join("secret"),
            PathBuf::from("/etc/passwd"),
            d.join("sub/file:/etc/passwd"),
        ] {
            let e = input.confine(&bad, Some(&scene)).unwrap_err().to_string();
            assert!(e.contains("--sandbox: refused to read it"), "{e}");
            assert!(e.contains("scene.toml"), "{e}");
        }
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(d.join("secret"), d.join("sub/link")).unwrap();
            let e = input.confine(&d.join("sub/link"), None).unwrap_err();
            assert!(e.to_string().contains("leads outside"), "{e}");
        }
        // Without the sandbox, any path.
        assert!(Input::new(1).confine(&d.join("secret"), None).is_ok());
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn the_budget_counts_what_is_kept() {
        let input = Input::new(1000);
        assert!(input.check("a texture", 900).is_ok());
        input.keep(600);
        let e = input.check("a texture", 500).unwrap_err();
        assert!(e.contains("beside"), "{e}");
        assert!(default_budget() >= 64 << 20);
    }
}
