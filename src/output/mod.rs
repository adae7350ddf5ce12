//! Frame buffers to files: the resolve to display bytes, and the writers
//! (one format per file). Every file is written to a temporary name in its
//! directory and renamed into place, so an interrupted render never leaves a
//! half-written frame under the final name.

pub mod exr;
pub mod gif;
pub mod ids;
mod pack;
pub mod png;
pub mod video;

pub use pack::{FileToWrite, OutputFiles, pack};

/// The tone maps `resolve` applies (`render.tonemap`), for display values
/// of a linear colour.
pub use crate::shade::tonemap;

use std::io::Write;
use std::path::Path;

use crate::error::Error;
pub use crate::render::display::{Image8, resolve, resolve_into};

/// Writes `bytes` produced by `write` to `path` atomically: into a
/// temporary file created exclusively beside it (a planted file or link of
/// that name is never followed), then renamed over the target. The
/// temporary file is removed on error. A target that is a directory, a
/// FIFO or a device is refused, not replaced.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), Error>,
) -> Result<(), Error> {
    check_target(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let (file, tmp) = crate::files::temp_file(path)?;
    let result = (|| {
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush().map_err(|e| Error::io(&tmp, e))?;
        w.get_ref().sync_data().map_err(|e| Error::io(&tmp, e))?;
        drop(w);
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// [`write_atomic`] of bytes already made.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    write_atomic(path, |w| w.write_all(bytes).map_err(|e| Error::io(path, e)))
}

/// Refuses a target that exists and is not a regular file (or a link,
/// which the rename replaces without following).
pub fn check_target(path: &Path) -> Result<(), Error> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if !m.is_file() && !m.file_type().is_symlink() => Err(Error::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(format!(
                "the output file's place is taken by {}; not replaced",
                crate::files::kind(&m)
            )),
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_replace_files_but_not_folders_devices_or_planted_links() {
        let d = std::env::temp_dir().join(format!("softraster-atomic-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("taken")).unwrap();
        let f = d.join("a.png");
        write_bytes_atomic(&f, b"one").unwrap();
        write_bytes_atomic(&f, b"two").unwrap();
        assert_eq!(std::fs::read(&f).unwrap(), b"two");
        let e = write_bytes_atomic(&d.join("taken"), b"x").unwrap_err();
        assert!(e.to_string().contains("a directory"), "{e}");
        assert!(d.join("taken").is_dir());
        #[cfg(unix)]
        {
            let e = write_bytes_atomic(Path::new("/dev/null"), b"x").unwrap_err();
            assert!(e.to_string().contains("a device"), "{e}");
        }
        // Temporary names never repeat, and none is left behind.
        let (_, a) = crate::files::temp_file(&f).unwrap();
        let (_, b) = crate::files::temp_file(&f).unwrap();
        assert_ne!(a, b);
        let _ = std::fs::remove_file(&a);
        let _ = std::fs::remove_file(&b);
        let left: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(left.is_empty());
        let _ = std::fs::remove_dir_all(&d);
    }
}
