//! A render job: every requested frame of every requested camera, rendered
//! in order and written by a writer thread, so PNG encoding of frame N
//! overlaps the rendering of frame N+1.

use std::ops::Range;
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Instant;

use crate::error::Error;
use crate::output::{self, Image8};
use crate::render::{Frame, FrameSetup, render_into};
use crate::scene::Scene;

pub struct RenderJob {
    pub scene: Scene,
    /// Half-open frame range.
    pub frames: Range<u32>,
    /// Indices into `scene.cameras`.
    pub cameras: Vec<usize>,
}

/// Reported once per finished (written) frame and camera.
#[derive(Debug, Clone)]
pub struct FrameDone {
    pub frame: u32,
    pub camera: String,
    pub files: Vec<PathBuf>,
    /// Render time (without writing).
    pub render_seconds: f64,
}

/// One file of a frame, ready to write.
enum Output {
    Png(PathBuf, Image8),
    /// Path, width, height, channel name, values.
    Exr(PathBuf, u32, u32, &'static str, Vec<f32>),
}

impl Output {
    fn path(&self) -> &std::path::Path {
        match self {
            Output::Png(p, _) | Output::Exr(p, ..) => p,
        }
    }

    fn write(&self) -> Result<(), Error> {
        match self {
            Output::Png(p, img) => output::png::write(p, img),
            Output::Exr(p, w, h, channel, values) => {
                output::exr::write_channel(p, *w, *h, channel, values)
            }
        }
    }
}

impl RenderJob {
    pub fn total(&self) -> usize {
        self.frames.len() * self.cameras.len()
    }

    /// Renders and writes everything; calls `on_done` as frames land.
    pub fn run(&self, mut on_done: impl FnMut(&FrameDone)) -> Result<(), Error> {
        let scene = &self.scene;
        let (to_writer, writer_rx) = mpsc::sync_channel::<(FrameDone, Vec<Output>)>(2);
        let (done_tx, done_rx) = mpsc::channel::<Result<FrameDone, Error>>();
        let writer = std::thread::spawn(move || {
            for (done, outputs) in writer_rx {
                let r = outputs.iter().try_for_each(Output::write).map(|_| done);
                let failed = r.is_err();
                if done_tx.send(r).is_err() || failed {
                    break;
                }
            }
        });
        let mut result = Ok(());
        let drain = |block: bool, on_done: &mut dyn FnMut(&FrameDone)| -> Result<(), Error> {
            loop {
                let msg = if block {
                    done_rx.recv().ok()
                } else {
                    done_rx.try_recv().ok()
                };
                match msg {
                    Some(Ok(d)) => on_done(&d),
                    Some(Err(e)) => return Err(e),
                    None => return Ok(()),
                }
            }
        };
        let mut buffer = Frame::new(0, 0);
        'frames: for frame in self.frames.clone() {
            for &cam in &self.cameras {
                let name = &scene.cameras[cam].name;
                let t0 = Instant::now();
                render_into(&FrameSetup::new(scene, cam, frame), &mut buffer);
                let stem = scene.file_stem(name, frame);
                let file = |suffix: &str| scene.output.dir.join(format!("{stem}{suffix}"));
                let (width, height) = (buffer.width, buffer.height);
                let mut outputs = Vec::new();
                if scene.output.color {
                    let img = output::resolve(&buffer, &scene.settings);
                    outputs.push(Output::Png(file(".png"), img));
                }
                if scene.output.depth {
                    let z = buffer.depth.clone();
                    outputs.push(Output::Exr(file("_depth.exr"), width, height, "Z", z));
                }
                if scene.output.ao {
                    let ao = if buffer.ao.is_empty() {
                        vec![1.0; buffer.depth.len()]
                    } else {
                        buffer.ao.clone()
                    };
                    outputs.push(Output::Exr(file("_ao.exr"), width, height, "AO", ao));
                }
                let render_seconds = t0.elapsed().as_secs_f64();
                let done = FrameDone {
                    frame,
                    camera: name.clone(),
                    files: outputs.iter().map(|o| o.path().to_path_buf()).collect(),
                    render_seconds,
                };
                if to_writer.send((done, outputs)).is_err() {
                    break 'frames;
                }
                if let Err(e) = drain(false, &mut on_done) {
                    result = Err(e);
                    break 'frames;
                }
            }
        }
        drop(to_writer);
        if result.is_ok() {
            result = drain(true, &mut on_done);
        }
        let _ = writer.join();
        result
    }
}
