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

mod encoders;
mod plan;
mod writer;

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Instant;

use encoders::VideoFrame;
pub use plan::{RenderPlan, parse_frames};
use writer::ToWriter;

use crate::error::Error;
pub use crate::output::OutputFiles;
use crate::output::{self, Image8};
use crate::render::{FrameSequence, Renderer, Shot};
use crate::scene::Scene;

/// A scene's frames to render and write: the scene, its plan (frames,
/// cameras, file names) and whether existing files are kept. `run`
/// renders in order while a writer thread writes the previous frame.
pub struct RenderJob {
    scene: Scene,
    /// Every frame's exposure in stops (`Renderer::exposure`).
    exposure: f32,
    /// Which frames of which cameras, and the files each writes.
    pub plan: RenderPlan,
    /// Frames whose files all exist already are not rendered again.
    pub skip_existing: bool,
}

/// Reported once per finished (written, or skipped) frame and camera.
#[derive(Debug, Clone)]
pub struct ShotDone {
    /// The frame of the animation.
    pub frame: u32,
    /// The camera's name.
    pub camera: String,
    /// The files written (or found, when skipped).
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
    /// Videos written, one per camera.
    pub videos: Vec<PathBuf>,
    /// Why the scene's video was not written, if it was not.
    pub video_skipped: Option<String>,
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
        .map_err(|e| Error::Render(format!("cannot start {threads:?} threads: {e}")))
}

impl RenderJob {
    /// Every frame of every camera of `scene`. Its exposure is resolved
    /// here, once for the whole sequence (with `render.exposure = "auto"`,
    /// by rendering small frames), whichever frames the plan keeps.
    pub fn all(scene: Scene) -> RenderJob {
        let exposure = Renderer::new(&scene).exposure();
        RenderJob {
            plan: RenderPlan::all(&scene),
            scene,
            exposure,
            skip_existing: false,
        }
    }

    /// The job's scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The exposure of every frame, in stops (`render.exposure`, "auto"
    /// resolved).
    pub fn exposure(&self) -> f32 {
        self.exposure
    }

    /// Renders and writes everything; calls `on_done` as frames land. The
    /// videos are encoded as the frames land; then each camera's GIF is
    /// written. Both need the job to cover every frame of the animation.
    pub fn run(&self, on_done: impl FnMut(&ShotDone)) -> Result<JobSummary, Error> {
        let mut summary = JobSummary::default();
        let plan = &self.plan;
        let total = plan.total_frames;
        let partial = |what: &str, tool: &str| {
            format!(
                "{what} not written: this run has {} of the scene's {total} frames \
                 (run `softraster {tool}` on the frames, or render again with --skip-existing)",
                plan.frames.len()
            )
        };
        let videos = if self.scene.output.video.is_some() && !plan.covers_animation() {
            summary.video_skipped = Some(partial("output.video", "video"));
            false
        } else {
            self.scene.output.video.is_some()
        };
        if self.scene.output.id {
            output::ids::write(&self.scene)?;
        }
        summary.videos = self.render_frames(videos, on_done)?;
        if self.scene.output.gif.is_none() {
            return Ok(summary);
        }
        if !plan.covers_animation() {
            summary.gif_skipped = Some(partial("output.gif", "gif"));
            return Ok(summary);
        }
        let opts = output::gif::GifOptions {
            delay_ms: self.scene.output.gif_delay_ms,
            dither: self.scene.output.gif_dither,
        };
        for &cam in &plan.cameras {
            let Some(path) = plan.gif_path(cam) else {
                continue;
            };
            let frames: Vec<PathBuf> = (0..total)
                .filter_map(|f| plan.files(cam, f).color)
                .collect();
            output::gif::assemble(&frames, &path, opts)?;
            summary.gifs.push(path);
        }
        Ok(summary)
    }

    /// Renders the plan's frames and hands them to the writer thread; with
    /// `videos`, the writer also encodes each camera's colour frames, in
    /// order, into its video. Returns the videos written.
    fn render_frames(
        &self,
        videos: bool,
        mut on_done: impl FnMut(&ShotDone),
    ) -> Result<Vec<PathBuf>, Error> {
        let scene = &self.scene;
        let plan = &self.plan;
        let video_paths: Vec<Option<PathBuf>> = (0..scene.cameras.len())
            .map(|cam| if videos { plan.video_path(cam) } else { None })
            .collect();
        let video_opts = output::video::VideoOptions {
            fps: scene.output.video_fps,
            quality: scene.output.video_quality,
        };
        let (done_tx, done_rx) = mpsc::channel::<Result<ShotDone, Error>>();
        let (to_writer, writer) = writer::spawn(video_paths, video_opts, done_tx);
        let mut result = Ok(());
        let drain = |block: bool, on_done: &mut dyn FnMut(&ShotDone)| -> Result<(), Error> {
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
        let renderer = Renderer::new(scene);
        let mut buffer = FrameSequence::new();
        'frames: for &frame in &plan.frames {
            for &cam in &plan.cameras {
                let camera = plan.camera_name(cam).to_string();
                let files = plan.files(cam, frame);
                let in_video = videos && plan.video_path(cam).is_some();
                // A skipped frame's video frame is read back from its PNG.
                let can_skip = !in_video || files.color.is_some();
                if self.skip_existing && can_skip && files.all().iter().all(|f| f.is_file()) {
                    let done = ShotDone {
                        frame,
                        camera,
                        files: files.all(),
                        render_seconds: 0.0,
                        skipped: true,
                    };
                    if in_video {
                        let png = files.color.clone().unwrap_or_default();
                        let msg =
                            ToWriter::Frame(done, Vec::new(), Some(VideoFrame::File(cam, png)));
                        if to_writer.send(msg).is_err() {
                            break 'frames;
                        }
                    } else {
                        on_done(&done);
                    }
                    continue;
                }
                let t0 = Instant::now();
                // The display image is made as the frame renders.
                let mut image = (files.color.is_some() || in_video).then(Image8::empty);
                let shot = Shot::new(cam, frame).with_exposure(self.exposure);
                if let Err(e) = renderer.render_next(shot, &mut buffer, image.as_mut()) {
                    result = Err(e);
                    break 'frames;
                }
                let (outputs, color) = output::pack(buffer.frame(), image, files, in_video);
                let done = ShotDone {
                    frame,
                    camera,
                    files: outputs.iter().map(|o| o.path().to_path_buf()).collect(),
                    render_seconds: t0.elapsed().as_secs_f64(),
                    skipped: false,
                };
                let video_frame = color.map(|img| VideoFrame::Image(cam, img));
                if to_writer
                    .send(ToWriter::Frame(done, outputs, video_frame))
                    .is_err()
                {
                    break 'frames;
                }
                if let Err(e) = drain(false, &mut on_done) {
                    result = Err(e);
                    break 'frames;
                }
            }
        }
        if result.is_ok() {
            let _ = to_writer.send(ToWriter::Finish);
        }
        drop(to_writer);
        if result.is_ok() {
            result = drain(true, &mut on_done);
        }
        let written = writer
            .join()
            .map_err(|_| Error::Render("the file writer thread panicked".into()))?;
        result?;
        written
    }
}
