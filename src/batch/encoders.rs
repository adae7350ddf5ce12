//! The job's video encoders: one per camera, started at its first
//! frame, fed in frame order by the writer thread.

use std::path::PathBuf;

use crate::error::Error;
use crate::output::{self, Image8};

/// A camera's next video frame: rendered now, or read back from the PNG a
/// previous run wrote (`--skip-existing`).
pub(super) enum VideoFrame {
    Image(usize, Image8),
    File(usize, PathBuf),
}

/// The videos of a job, one per camera, started at their first frame.
pub(super) struct Videos {
    paths: Vec<Option<PathBuf>>,
    opts: output::video::VideoOptions,
    writers: Vec<Option<output::video::VideoWriter>>,
}

impl Videos {
    pub fn new(paths: Vec<Option<PathBuf>>, opts: output::video::VideoOptions) -> Videos {
        let writers = paths.iter().map(|_| None).collect();
        Videos {
            paths,
            opts,
            writers,
        }
    }

    pub fn push(&mut self, frame: VideoFrame) -> Result<(), Error> {
        let (cam, img) = match frame {
            VideoFrame::Image(cam, img) => (cam, img),
            VideoFrame::File(cam, png) => (cam, output::png::read(&png)?),
        };
        let Some(path) = self.paths.get(cam).cloned().flatten() else {
            return Ok(());
        };
        let w = match &mut self.writers[cam] {
            Some(w) => w,
            slot => slot.insert(output::video::VideoWriter::create(
                &path, img.width, img.height, self.opts,
            )?),
        };
        w.push(&img)
    }

    pub fn finish(self) -> Result<Vec<PathBuf>, Error> {
        let mut out = Vec::new();
        for w in self.writers.into_iter().flatten() {
            let path = w.path().to_path_buf();
            w.finish()?;
            out.push(path);
        }
        Ok(out)
    }
}
