//! The library's typed errors. Every error that comes from user input names
//! where it was found (file, and line and column where the format has them).
//! `exit_code` maps each kind to the CLI's exit status: 2 for a bad scene,
//! bad asset or bad arguments (permanent: rerunning will not help), 1 for a
//! render or I/O failure.

use std::fmt;
use std::path::{Path, PathBuf};

/// A place in a text file, 1-based.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file.
    pub file: PathBuf,
    /// The line, from 1.
    pub line: usize,
    /// The column in characters, from 1.
    pub column: usize,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file.display(), self.line, self.column)
    }
}

impl Location {
    /// The location of byte offset `offset` in `text`.
    pub fn from_offset(file: &Path, text: &str, offset: usize) -> Location {
        let offset = offset.min(text.len());
        let before = &text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
        let column = text[line_start..offset].chars().count() + 1;
        Location {
            file: file.to_path_buf(),
            line,
            column,
        }
    }
}

/// Everything the library can fail with. `Display` gives the message the
/// command line prints: the file (and line and column where known) first.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene file is malformed, has an unknown key, a wrong type or an
    /// out-of-range value.
    #[error("{location}: {message}")]
    Scene {
        /// Where in the scene file.
        location: Location,
        /// What is wrong and what was expected.
        message: String,
    },

    /// A scene-level problem that has no single place in the file (e.g. two
    /// cameras with the same name when both were defaulted).
    #[error("{file}: {message}")]
    SceneGlobal {
        /// The scene file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// A model, material library or texture that cannot be read or is
    /// malformed. `line` is set when the format is text and the line is known.
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Asset {
        /// The file.
        path: PathBuf,
        /// The line, for text formats where it is known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },

    /// `--sandbox`: a file names a path outside the scene's folder (with
    /// `..`, absolute, a URI scheme, or a link leading out). Never lenient.
    #[error("{}: --sandbox: refused to read it{message}", path.display())]
    Sandbox {
        /// The file that names the path.
        path: PathBuf,
        /// The path refused, and why.
        message: String,
    },

    /// An asset would take more memory than the budget (`--max-memory`,
    /// or the default: what the machine has), seen from its header
    /// before anything is allocated.
    #[error("{}: {message}", path.display())]
    Memory {
        /// The asset.
        path: PathBuf,
        /// The estimate and the budget.
        message: String,
    },

    /// `--strict` and the load gave warnings.
    #[error("{}: --strict: {} warning(s) treated as errors:\n  {}", file.display(), warnings.len(), warnings.join("\n  "))]
    Strict {
        /// The scene or model loaded.
        file: PathBuf,
        /// The warnings, each naming its file and line.
        warnings: Vec<String>,
    },

    /// A command-line argument (or its library counterpart: a frame
    /// list, a `--set`, a camera name) is invalid.
    #[error("{0}")]
    Argument(String),

    /// The render, or a tool measuring it, failed for a reason that is not
    /// the input's (the thread pool could not start, two frames that must
    /// match in size do not).
    #[error("{0}")]
    Render(String),

    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },

    /// Encoding an output image failed.
    #[error("{}: {message}", path.display())]
    Encode {
        /// The file being written.
        path: PathBuf,
        /// The encoder's message.
        message: String,
    },
}

impl Error {
    /// 2: the input is wrong and a rerun will fail the same way.
    /// 1: the render or the file system failed.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Scene { .. }
            | Error::SceneGlobal { .. }
            | Error::Asset { .. }
            | Error::Sandbox { .. }
            | Error::Memory { .. }
            | Error::Strict { .. }
            | Error::Argument(_) => 2,
            Error::Io { .. } | Error::Encode { .. } | Error::Render(_) => 1,
        }
    }

    /// An I/O failure on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Error {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// A bad asset at `path` (and `line`, where known).
    pub fn asset(
        path: impl Into<PathBuf>,
        line: Option<usize>,
        message: impl Into<String>,
    ) -> Error {
        Error::Asset {
            path: path.into(),
            line,
            message: message.into(),
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_map_to_lines_and_columns() {
        let text = "a = 1\nbb = 2\n";
        let l = Location::from_offset(Path::new("s.toml"), text, 6 + 5);
        assert_eq!((l.line, l.column), (2, 6));
        let l = Location::from_offset(Path::new("s.toml"), text, 0);
        assert_eq!((l.line, l.column), (1, 1));
        assert_eq!(l.to_string(), "s.toml:1:1");
    }
}
