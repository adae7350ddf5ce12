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

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Instant;

use crate::error::Error;
use crate::output::{self, Image8};
use crate::render::{AovPixel, Frame, FrameSequence, Renderer};
use crate::scene::{Scene, expand_pattern};

pub struct RenderJob {
    pub scene: Scene,
    /// Which frames of which cameras, and the files each writes.
    pub plan: FramePlan,
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

/// Which frames a run renders, of which cameras, and the files each
/// frame writes: `--frames` and `--camera` choose, and the writers,
/// `--skip-existing` and the GIF read their file names from here only.
#[derive(Debug, Clone)]
pub struct FramePlan {
    /// Frame numbers, in the order they are rendered.
    pub frames: Vec<u32>,
    /// Indices into `scene.cameras`.
    pub cameras: Vec<usize>,
    /// The animation's length: a run that covers it writes the GIF.
    pub total_frames: u32,
    naming: Naming,
}

/// What file names are made of.
#[derive(Debug, Clone)]
struct Naming {
    dir: PathBuf,
    pattern: String,
    stem: String,
    cameras: Vec<String>,
    color: bool,
    depth: bool,
    ao: bool,
    normal: bool,
    albedo: bool,
    position: bool,
    id: bool,
    gif: Option<String>,
    video: Option<String>,
}

/// The files of one frame of one camera (None: the scene does not ask).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameFiles {
    /// `<name>.png`.
    pub color: Option<PathBuf>,
    /// `<name>_depth.exr`, channel `Z`.
    pub depth: Option<PathBuf>,
    /// `<name>_ao.exr`, channel `AO`.
    pub ao: Option<PathBuf>,
    /// `<name>_normal.exr`, channels `N.X N.Y N.Z`.
    pub normal: Option<PathBuf>,
    /// `<name>_albedo.exr`, channels `albedo.R albedo.G albedo.B`.
    pub albedo: Option<PathBuf>,
    /// `<name>_position.exr`, channels `P.X P.Y P.Z`.
    pub position: Option<PathBuf>,
    /// `<name>_id.exr`, UINT channels `object_id` and `material_id`.
    pub id: Option<PathBuf>,
}

impl FrameFiles {
    /// The files, color first.
    pub fn all(&self) -> Vec<PathBuf> {
        [
            &self.color,
            &self.depth,
            &self.ao,
            &self.normal,
            &self.albedo,
            &self.position,
            &self.id,
        ]
        .into_iter()
        .flatten()
        .cloned()
        .collect()
    }
}

impl FramePlan {
    /// Every frame of every camera.
    pub fn all(scene: &Scene) -> FramePlan {
        FramePlan {
            frames: (0..scene.animation.frames).collect(),
            cameras: (0..scene.cameras.len()).collect(),
            total_frames: scene.animation.frames,
            naming: Naming {
                dir: scene.output.dir.clone(),
                pattern: scene.output.name.clone(),
                stem: scene.stem.clone(),
                cameras: scene.cameras.iter().map(|c| c.name.clone()).collect(),
                color: scene.output.color,
                depth: scene.output.depth,
                ao: scene.output.ao,
                normal: scene.output.normal,
                albedo: scene.output.albedo,
                position: scene.output.position,
                id: scene.output.id,
                gif: scene.output.gif.clone(),
                video: scene.output.video.clone(),
            },
        }
    }

    /// `--frames` (see `parse_frames`; None: all) and `--camera` (a name;
    /// None: all).
    pub fn select(
        scene: &Scene,
        frames: Option<&str>,
        camera: Option<&str>,
    ) -> Result<FramePlan, Error> {
        let mut plan = FramePlan::all(scene);
        if let Some(f) = frames {
            plan.frames = parse_frames(f, plan.total_frames)?;
        }
        if let Some(name) = camera {
            let names = &plan.naming.cameras;
            let i = names.iter().position(|c| c == name).ok_or_else(|| {
                Error::Argument(format!(
                    "--camera {name}: the scene has {}",
                    names.join(", ")
                ))
            })?;
            plan.cameras = vec![i];
        }
        Ok(plan)
    }

    /// Frames times cameras.
    pub fn total(&self) -> usize {
        self.frames.len() * self.cameras.len()
    }

    /// Whether the run renders every frame of the animation.
    pub fn covers_animation(&self) -> bool {
        self.frames.len() == self.total_frames as usize
    }

    pub fn camera_name(&self, cam: usize) -> &str {
        &self.naming.cameras[cam]
    }

    /// The files frame `frame` of camera `cam` writes.
    pub fn files(&self, cam: usize, frame: u32) -> FrameFiles {
        let n = &self.naming;
        let stem = expand_pattern(&n.pattern, &n.stem, &n.cameras[cam], frame);
        let file = |on: bool, suffix: &str| on.then(|| n.dir.join(format!("{stem}{suffix}")));
        FrameFiles {
            color: file(n.color, ".png"),
            depth: file(n.depth, "_depth.exr"),
            ao: file(n.ao, "_ao.exr"),
            normal: file(n.normal, "_normal.exr"),
            albedo: file(n.albedo, "_albedo.exr"),
            position: file(n.position, "_position.exr"),
            id: file(n.id, "_id.exr"),
        }
    }

    /// The GIF of camera `cam`: `output.gif` in the output directory, per
    /// camera when the scene has several (`{camera}` in the name, or
    /// `_<camera>` before the extension).
    pub fn gif_path(&self, cam: usize) -> Option<PathBuf> {
        self.per_camera(self.naming.gif.as_ref()?, cam)
    }

    /// The video of camera `cam`: `output.video`, named per camera like
    /// the GIF.
    pub fn video_path(&self, cam: usize) -> Option<PathBuf> {
        self.per_camera(self.naming.video.as_ref()?, cam)
    }

    fn per_camera(&self, name: &str, cam: usize) -> Option<PathBuf> {
        let n = &self.naming;
        let cam_name = &n.cameras[cam];
        let name = if name.contains("{camera}") {
            name.replace("{camera}", cam_name)
        } else if n.cameras.len() > 1 {
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
            name.to_string()
        };
        Some(n.dir.join(name))
    }
}

/// One file of a frame, ready to write.
enum Output {
    Png(PathBuf, Image8),
    /// Path, width, height, channel name, values.
    Exr(PathBuf, u32, u32, &'static str, Vec<f32>),
    /// Path, width, height, channels.
    ExrChannels(PathBuf, u32, u32, Vec<(&'static str, output::exr::Samples)>),
}

impl Output {
    fn path(&self) -> &std::path::Path {
        match self {
            Output::Png(p, _) | Output::Exr(p, ..) | Output::ExrChannels(p, ..) => p,
        }
    }

    fn write(&self) -> Result<(), Error> {
        match self {
            Output::Png(p, img) => output::png::write(p, img),
            Output::Exr(p, w, h, channel, values) => {
                output::exr::write_channel(p, *w, *h, channel, values)
            }
            Output::ExrChannels(p, w, h, channels) => {
                let channels = channels
                    .iter()
                    .map(|(name, s)| {
                        let s = match s {
                            output::exr::Samples::F32(v) => output::exr::Samples::F32(v.clone()),
                            output::exr::Samples::U32(v) => output::exr::Samples::U32(v.clone()),
                        };
                        (*name, s)
                    })
                    .collect();
                output::exr::write_channels(p, *w, *h, channels)
            }
        }
    }
}

/// A frame's files from its buffers and its display image (made where
/// the plan writes a colour file or `color` asks for it), as the plan
/// names them, and (with `color`) the display image for a video.
fn outputs(
    frame: &Frame,
    image: Option<Image8>,
    files: FrameFiles,
    color: bool,
) -> (Vec<Output>, Option<Image8>) {
    let (width, height) = (frame.width, frame.height);
    let mut out = Vec::new();
    let mut image = image;
    // (`image.take()` runs only where a colour file is written.)
    if let Some(p) = files.color
        && let Some(img) = image.take()
    {
        if color {
            image = Some(img.clone());
        }
        out.push(Output::Png(p, img));
    }
    if let Some(p) = files.depth {
        out.push(Output::Exr(p, width, height, "Z", frame.depth.clone()));
    }
    if let Some(p) = files.ao {
        let ao = if frame.ao.is_empty() {
            vec![1.0; frame.depth.len()]
        } else {
            frame.ao.clone()
        };
        out.push(Output::Exr(p, width, height, "AO", ao));
    }
    let aov = &frame.aov;
    let vec3 = |names: [&'static str; 3], get: fn(&AovPixel) -> glam::Vec3| {
        (0..3)
            .map(|k| {
                let v = aov.iter().map(|a| get(a)[k]).collect();
                (names[k], output::exr::Samples::F32(v))
            })
            .collect::<Vec<_>>()
    };
    if !aov.is_empty() {
        if let Some(p) = files.normal {
            let c = vec3(["N.X", "N.Y", "N.Z"], |a| a.normal);
            out.push(Output::ExrChannels(p, width, height, c));
        }
        if let Some(p) = files.albedo {
            let c = vec3(["albedo.R", "albedo.G", "albedo.B"], |a| a.albedo);
            out.push(Output::ExrChannels(p, width, height, c));
        }
        if let Some(p) = files.position {
            let c = vec3(["P.X", "P.Y", "P.Z"], |a| a.position);
            out.push(Output::ExrChannels(p, width, height, c));
        }
        if let Some(p) = files.id {
            let ids = |get: fn(&AovPixel) -> u32| {
                output::exr::Samples::U32(aov.iter().map(get).collect())
            };
            let c = vec![
                ("object_id", ids(|a| a.object)),
                ("material_id", ids(|a| a.material)),
            ];
            out.push(Output::ExrChannels(p, width, height, c));
        }
    }
    (out, image)
}

/// `scene` with `render.exposure = "auto"` resolved to stops.
pub fn with_auto_exposure(mut scene: Scene) -> Scene {
    if scene.settings.auto_exposure {
        scene.settings.exposure = crate::render::auto_exposure(&scene);
        scene.settings.auto_exposure = false;
    }
    scene
}

impl RenderJob {
    /// Every frame of every camera.
    pub fn all(scene: Scene) -> RenderJob {
        RenderJob {
            plan: FramePlan::all(&scene),
            scene,
            skip_existing: false,
        }
    }

    /// Renders and writes everything; calls `on_done` as frames land. The
    /// videos are encoded as the frames land; then each camera's GIF is
    /// written. Both need the job to cover every frame of the animation.
    pub fn run(&self, on_done: impl FnMut(&FrameDone)) -> Result<JobSummary, Error> {
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
            write_ids(&self.scene)?;
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
        mut on_done: impl FnMut(&FrameDone),
    ) -> Result<Vec<PathBuf>, Error> {
        let auto;
        let scene = if self.scene.settings.auto_exposure {
            auto = with_auto_exposure(self.scene.clone());
            &auto
        } else {
            &self.scene
        };
        let plan = &self.plan;
        let video_paths: Vec<Option<PathBuf>> = (0..scene.cameras.len())
            .map(|cam| if videos { plan.video_path(cam) } else { None })
            .collect();
        let video_opts = output::video::VideoOptions {
            fps: scene.output.video_fps,
            quality: scene.output.video_quality,
        };
        let (to_writer, writer_rx) = mpsc::sync_channel::<ToWriter>(2);
        let (done_tx, done_rx) = mpsc::channel::<Result<FrameDone, Error>>();
        let writer = std::thread::spawn(move || {
            let mut encoders = Videos::new(video_paths, video_opts);
            for msg in writer_rx {
                let (done, outputs, frame) = match msg {
                    ToWriter::Frame(done, outputs, frame) => (done, outputs, frame),
                    ToWriter::Finish => return encoders.finish(),
                };
                let r = outputs
                    .iter()
                    .try_for_each(Output::write)
                    .and_then(|_| match frame {
                        Some(f) => encoders.push(f),
                        None => Ok(()),
                    })
                    .map(|_| done);
                let failed = r.is_err();
                if done_tx.send(r).is_err() || failed {
                    break;
                }
            }
            // Stopped early: the unfinished videos leave no file.
            Ok(Vec::new())
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
                    let done = FrameDone {
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
                renderer.render_next(scene, cam, frame, &mut buffer, image.as_mut());
                let (outputs, color) = outputs(buffer.frame(), image, files, in_video);
                let done = FrameDone {
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

/// `{scene}_ids.json` in the output directory: what the id pass's numbers
/// stand for (`object_id`: 1 + the index of the model's part over the
/// models' parts in order, named `model` or `model/node`; `material_id`:
/// 1 + the material's index over the models' materials in order, with
/// the model's first object id; 0 = nothing).
fn write_ids(scene: &Scene) -> Result<(), Error> {
    let mut objects = Vec::new();
    let mut materials = Vec::new();
    for m in &scene.models {
        let first = objects.len() + 1;
        for name in m.object_names() {
            objects.push(serde_json::json!({ "id": objects.len() + 1, "name": name }));
        }
        for mat in &m.materials {
            materials.push(serde_json::json!({
                "id": materials.len() + 1,
                "name": mat.name,
                "object_id": first,
            }));
        }
    }
    let doc = serde_json::json!({
        "background": 0,
        "objects": objects,
        "materials": materials,
    });
    let path = scene.output.dir.join(format!("{}_ids.json", scene.stem));
    output::write_atomic(&path, |w| {
        serde_json::to_writer_pretty(&mut *w, &doc).map_err(|e| Error::Encode {
            path: path.clone(),
            message: e.to_string(),
        })?;
        w.write_all(b"\n").map_err(|e| Error::io(&path, e))
    })
}

/// What the render loop sends the writer thread.
enum ToWriter {
    /// A frame's files, and its colour for the camera's video.
    Frame(FrameDone, Vec<Output>, Option<VideoFrame>),
    /// Every frame was sent: finish the videos.
    Finish,
}

/// A camera's next video frame: rendered now, or read back from the PNG a
/// previous run wrote (`--skip-existing`).
enum VideoFrame {
    Image(usize, Image8),
    File(usize, PathBuf),
}

/// The videos of a job, one per camera, started at their first frame.
struct Videos {
    paths: Vec<Option<PathBuf>>,
    opts: output::video::VideoOptions,
    writers: Vec<Option<output::video::VideoWriter>>,
}

impl Videos {
    fn new(paths: Vec<Option<PathBuf>>, opts: output::video::VideoOptions) -> Videos {
        let writers = paths.iter().map(|_| None).collect();
        Videos {
            paths,
            opts,
            writers,
        }
    }

    fn push(&mut self, frame: VideoFrame) -> Result<(), Error> {
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

    fn finish(self) -> Result<Vec<PathBuf>, Error> {
        let mut out = Vec::new();
        for w in self.writers.into_iter().flatten() {
            let path = w.path().to_path_buf();
            w.finish()?;
            out.push(path);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene in a directory of its own: the tests run in parallel, and
    /// one writing `t.obj` while another reads it made the reader see an
    /// empty file (a CI failure of 2026-11-25).
    fn scene(extra: &str) -> Scene {
        static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("softraster-plan-{}-{n}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let text = format!("[[model]]\npath = \"t.obj\"\n[animation]\nframes = 12\n{extra}");
        let opts = crate::scene::assemble::LoadOptions::default();
        Scene::from_text(&dir.join("shot.toml"), &text, &opts).unwrap()
    }

    #[test]
    fn frames_and_cameras_are_chosen_by_the_flags() {
        let two =
            "[[camera]]\nname = \"front\"\n[[camera]]\nname = \"side\"\neye = [5.0, 0.0, 0.0]\n";
        let s = scene(two);
        let all = FramePlan::all(&s);
        assert_eq!(
            (all.frames.len(), all.cameras.clone(), all.total()),
            (12, vec![0, 1], 24)
        );
        assert!(all.covers_animation());
        let p = FramePlan::select(&s, Some("1-3,10.."), Some("side")).unwrap();
        assert_eq!(p.frames, vec![1, 2, 3, 10, 11]);
        assert_eq!((p.cameras.clone(), p.camera_name(1)), (vec![1], "side"));
        assert!(!p.covers_animation());
        let e = FramePlan::select(&s, None, Some("top")).unwrap_err();
        assert_eq!(e.to_string(), "--camera top: the scene has front, side");
        assert!(FramePlan::select(&s, Some("11..13"), None).is_err());
    }

    #[test]
    fn files_follow_the_output_settings() {
        let s = scene(
            "[output]\nname = \"{scene}-{camera}-{frame:03}\"\ndepth = true\ngif = \"t.gif\"\n",
        );
        let p = FramePlan::all(&s);
        let f = p.files(0, 7);
        let dir = &s.output.dir;
        assert_eq!(f.color, Some(dir.join("shot-camera-007.png")));
        assert_eq!(f.depth, Some(dir.join("shot-camera-007_depth.exr")));
        assert_eq!(f.ao, None);
        assert_eq!(
            f.all(),
            vec![
                dir.join("shot-camera-007.png"),
                dir.join("shot-camera-007_depth.exr")
            ]
        );
        assert_eq!(p.gif_path(0), Some(dir.join("t.gif")));
        // Several cameras: one GIF each.
        let s = scene(
            "[output]\ngif = \"t.gif\"\n[[camera]]\nname = \"a\"\n[[camera]]\nname = \"b\"\neye = [5.0, 0.0, 0.0]\n",
        );
        let p = FramePlan::all(&s);
        assert_eq!(p.gif_path(1), Some(s.output.dir.join("t_b.gif")));
        assert_eq!(p.files(1, 0).color, Some(s.output.dir.join("b_0000.png")));
    }

    #[test]
    fn frame_lists_parse_and_refuse() {
        assert_eq!(parse_frames("0..3", 5).unwrap(), vec![0, 1, 2]);
        assert_eq!(parse_frames("4,1-2,2", 5).unwrap(), vec![1, 2, 4]);
        assert_eq!(parse_frames("3..", 5).unwrap(), vec![3, 4]);
        assert!(parse_frames("3..3", 5).is_err());
        assert!(parse_frames("2-9", 5).is_err());
        assert!(parse_frames("x", 5).is_err());
    }
}
