//! Frame buffers to files: the resolve to display bytes, and the writers
//! (one format per file). Every file is written to a temporary name in its
//! directory and renamed into place, so an interrupted render never leaves a
//! half-written frame under the final name.

pub mod exr;
pub mod gif;
pub mod png;
pub mod video;

/// Tone mapping lives with shading (`shade::tonemap`); its old path stays.
pub use crate::shade::tonemap;

use std::io::Write;
use std::path::Path;

use crate::error::Error;
pub use crate::render::display::{Image8, resolve, resolve_into};

/// Writes `bytes` produced by `write` to `path` atomically.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), Error>,
) -> Result<(), Error> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let file = std::fs::File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush().map_err(|e| Error::io(&tmp, e))?;
        w.get_ref().sync_data().map_err(|e| Error::io(&tmp, e))?;
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
