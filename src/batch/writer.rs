//! The job's writer thread: it writes each frame's files as the render
//! loop hands them over (so encoding frame N overlaps rendering frame
//! N+1), feeds the videos in order, and reports each frame written.

use std::path::PathBuf;
use std::sync::mpsc;
use std::thread::JoinHandle;

use super::ShotDone;
use super::encoders::{VideoFrame, Videos};
use crate::error::Error;
use crate::output::{FileToWrite, video::VideoOptions};

/// What the render loop sends the writer thread.
pub(super) enum ToWriter {
    /// A frame's files, and its colour for the camera's video.
    Frame(ShotDone, Vec<FileToWrite>, Option<VideoFrame>),
    /// Every frame was sent: finish the videos.
    Finish,
}

/// Starts the writer thread: it takes `ToWriter` messages (at most two
/// waiting), writes each frame's files, encodes the videos at `paths`
/// (per camera) and sends each frame's result to `done`; it stops at the
/// first failure. Its result: the videos written (none when it stopped
/// early: an unfinished video leaves no file).
pub(super) fn spawn(
    paths: Vec<Option<PathBuf>>,
    opts: VideoOptions,
    done: mpsc::Sender<Result<ShotDone, Error>>,
) -> (
    mpsc::SyncSender<ToWriter>,
    JoinHandle<Result<Vec<PathBuf>, Error>>,
) {
    let (to_writer, rx) = mpsc::sync_channel::<ToWriter>(2);
    let writer = std::thread::spawn(move || {
        let mut encoders = Videos::new(paths, opts);
        for msg in rx {
            let (frame_done, files, frame) = match msg {
                ToWriter::Frame(d, files, frame) => (d, files, frame),
                ToWriter::Finish => return encoders.finish(),
            };
            let r = files
                .into_iter()
                .try_for_each(FileToWrite::write)
                .and_then(|_| match frame {
                    Some(f) => encoders.push(f),
                    None => Ok(()),
                })
                .map(|_| frame_done);
            let failed = r.is_err();
            if done.send(r).is_err() || failed {
                break;
            }
        }
        Ok(Vec::new())
    });
    (to_writer, writer)
}
