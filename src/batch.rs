//! A render job: every requested frame of every requested camera, rendered
//! in order and written by a writer thread, so PNG encoding of frame N
//! overlaps the rendering of frame N+1; then, when the job covers the whole
//! animation, each camera's GIF.
//!
//! Render farms split a scene by frames (`parse_frames`): every frame's
//! files depend on the scene and the frame number only, so shards run
//! anywhere produce the same bytes as one run, and `skip_existing` lets a
//! rerun finish what an interrupted one left (files land atomically, so an
//! existing file is a complete one).

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Instant;

use crate::error::Error;
use crate::output::{self, Image8};
use crate::render::{Frame, FrameSetup, render_into};
use crate::scene::Scene;

pub struct RenderJob {
    pub scene: Scene,
    /// Frame numbers, in the order they are rendered.
    pub frames: Vec<u32>,
    /// Indices into `scene.cameras`.
    pub cameras: Vec<usize>,
    /// Frames whose files all exist already are not rendered again.
    pub skip_existing: bool,
}

/// Reported once per finished (written, or skipped) frame and camera.
#[derive(Debug, Clone)]
pub struct FrameDone {
    pub frame: u32,
    pub camera: String,
    pub files: Vec<PathBuf>,
    /// Render time (without writing); 0 when skipped.
    pub render_seconds: f64,
    /// The files existed already (`skip_existing`).
    pub skipped: bool,
}

/// What a job wrote besides the frames.
#[derive(Debug, Clone, Default)]
pub struct JobSummary {
    /// GIFs written, one per camera.
    pub gifs: Vec<PathBuf>,
    /// Why the scene's GIF was not written, if it was not.
    pub gif_skipped: Option<String>,
}

/// A worker pool of `threads` threads (all cores when None).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, Error> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        if n == 0 {
            return Err(Error::Argument("--threads must be at least 1".into()));
        }
        builder = builder.num_threads(n);
    }
    builder
        .build()
        .map_err(|e| Error::Argument(format!("cannot start {threads:?} threads: {e}")))
}

/// Frame selection for `--frames`: `a..b` (half-open), `a..` (to the end),
/// `a-b` (inclusive), `n`, or a comma-separated list of those, e.g.
/// `0..36` or `1-100,120`. The result is sorted and without repeats.
pub fn parse_frames(s: &str, total: u32) -> Result<Vec<u32>, Error> {
    let bad = |part: &str, why: &str| {
        Error::Argument(format!(
            "--frames {s}: `{part}` {why} (expected a..b half-open, a-b inclusive, n, or a list like 1-100,120)"
        ))
    };
    let num = |part: &str, v: &str| -> Result<u32, Error> {
        v.trim()
            .parse::<u32>()
            .map_err(|_| bad(part, "is not a frame number or range"))
    };
    let mut frames = std::collections::BTreeSet::new();
    for part in s.split(',') {
        let part = part.trim();
        let range = if let Some((a, b)) = part.split_once("..") {
            let a = if a.trim().is_empty() {
                0
            } else {
                num(part, a)?
            };
            let b = if b.trim().is_empty() {
                total
            } else {
                num(part, b)?
            };
            a..b
        } else if let Some((a, b)) = part.split_once('-') {
            let (a, b) = (num(part, a)?, num(part, b)?);
            a..b.saturating_add(1)
        } else {
            let n = num(part, part)?;
            n..n.saturating_add(1)
        };
        if range.start >= range.end {
            return Err(bad(part, "is empty"));
        }
        if range.end > total {
            return Err(bad(
                part,
                &format!("is past the end: the scene has frames 0..{total}"),
            ));
        }
        frames.extend(range);
    }
    Ok(frames.into_iter().collect())
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
    /// Every frame of every camera.
    pub fn all(scene: Scene) -> RenderJob {
        RenderJob {
            frames: (0..scene.animation.frames).collect(),
            cameras: (0..scene.cameras.len()).collect(),
            scene,
            skip_existing: false,
        }
    }

    pub fn total(&self) -> usize {
        self.frames.len() * self.cameras.len()
    }

    /// The files frame `frame` of camera `cam` writes.
    pub fn frame_files(&self, cam: usize, frame: u32) -> Vec<PathBuf> {
        let scene = &self.scene;
        let stem = scene.file_stem(&scene.cameras[cam].name, frame);
        let file = |suffix: &str| scene.output.dir.join(format!("{stem}{suffix}"));
        let mut files = Vec::new();
        if scene.output.color {
            files.push(file(".png"));
        }
        if scene.output.depth {
            files.push(file("_depth.exr"));
        }
        if scene.output.ao {
            files.push(file("_ao.exr"));
        }
        files
    }

    /// The GIF of camera `cam`: `output.gif` in the output directory, per
    /// camera when the scene has several.
    pub fn gif_path(&self, cam: usize) -> Option<PathBuf> {
        let scene = &self.scene;
        let name = scene.output.gif.as_ref()?;
        let cam_name = &scene.cameras[cam].name;
        let name = if name.contains("{camera}") {
            name.replace("{camera}", cam_name)
        } else if scene.cameras.len() > 1 {
            let p = Path::new(name);
            let stem = p
                .file_stem()
                .map(|s| s.to_string_lossy())
                .unwrap_or_default();
            let ext = p
                .extension()
                .map(|e| format!(".{}", e.to_string_lossy()))
                .unwrap_or_default();
            p.with_file_name(format!("{stem}_{cam_name}{ext}"))
                .to_string_lossy()
                .into_owned()
        } else {
            name.clone()
        };
        Some(scene.output.dir.join(name))
    }

    /// Renders and writes everything; calls `on_done` as frames land. Then
    /// writes each camera's GIF when the scene asks for one and the job
    /// covers every frame of the animation.
    pub fn run(&self, on_done: impl FnMut(&FrameDone)) -> Result<JobSummary, Error> {
        self.render_frames(on_done)?;
        let mut summary = JobSummary::default();
        if self.scene.output.gif.is_none() {
            return Ok(summary);
        }
        let total = self.scene.animation.frames;
        let covered = self.frames.len() == total as usize;
        if !covered {
            summary.gif_skipped = Some(format!(
                "output.gif not written: this run has {} of the scene's {total} frames \
                 (run `softraster gif` on the frames, or render again with --skip-existing)",
                self.frames.len()
            ));
            return Ok(summary);
        }
        let opts = output::gif::GifOptions {
            delay_ms: self.scene.output.gif_delay_ms,
            dither: self.scene.output.gif_dither,
        };
        for &cam in &self.cameras {
            let Some(path) = self.gif_path(cam) else {
                continue;
            };
            let frames: Vec<PathBuf> = (0..total)
                .map(|f| self.frame_files(cam, f).swap_remove(0))
                .collect();
            output::gif::assemble(&frames, &path, opts)?;
            summary.gifs.push(path);
        }
        Ok(summary)
    }

    fn render_frames(&self, mut on_done: impl FnMut(&FrameDone)) -> Result<(), Error> {
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
        'frames: for &frame in &self.frames {
            for &cam in &self.cameras {
                let name = &scene.cameras[cam].name;
                if self.skip_existing {
                    let files = self.frame_files(cam, frame);
                    if files.iter().all(|f| f.is_file()) {
                        on_done(&FrameDone {
                            frame,
                            camera: name.clone(),
                            files,
                            render_seconds: 0.0,
                            skipped: true,
                        });
                        continue;
                    }
                }
                let t0 = Instant::now();
                render_into(&FrameSetup::new(scene, cam, frame), &mut buffer);
                // The files in `frame_files` order: PNG, depth, AO.
                let mut files = self.frame_files(cam, frame).into_iter();
                let mut file = || files.next().unwrap_or_default();
                let (width, height) = (buffer.width, buffer.height);
                let mut outputs = Vec::new();
                if scene.output.color {
                    let img = output::resolve(&buffer, &scene.settings);
                    outputs.push(Output::Png(file(), img));
                }
                if scene.output.depth {
                    let z = buffer.depth.clone();
                    outputs.push(Output::Exr(file(), width, height, "Z", z));
                }
                if scene.output.ao {
                    let ao = if buffer.ao.is_empty() {
                        vec![1.0; buffer.depth.len()]
                    } else {
                        buffer.ao.clone()
                    };
                    outputs.push(Output::Exr(file(), width, height, "AO", ao));
                }
                let render_seconds = t0.elapsed().as_secs_f64();
                let done = FrameDone {
                    frame,
                    camera: name.clone(),
                    files: outputs.iter().map(|o| o.path().to_path_buf()).collect(),
                    render_seconds,
                    skipped: false,
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
