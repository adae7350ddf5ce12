//! Which frames a run renders, of which cameras, and the files each
//! writes: `--frames` (`parse_frames`) and `--camera` choose; the
//! writers, `--skip-existing`, the GIF and the video read their file
//! names from the plan only.

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::output::OutputFiles;
use crate::scene::{Scene, expand_pattern};

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
pub struct RenderPlan {
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

impl RenderPlan {
    /// Every frame of every camera.
    pub fn all(scene: &Scene) -> RenderPlan {
        RenderPlan {
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
    ) -> Result<RenderPlan, Error> {
        let mut plan = RenderPlan::all(scene);
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

    /// The name camera `cam` gives its files.
    pub fn camera_name(&self, cam: usize) -> &str {
        &self.naming.cameras[cam]
    }

    /// The files frame `frame` of camera `cam` writes.
    pub fn files(&self, cam: usize, frame: u32) -> OutputFiles {
        let n = &self.naming;
        let stem = expand_pattern(&n.pattern, &n.stem, &n.cameras[cam], frame);
        let file = |on: bool, suffix: &str| on.then(|| n.dir.join(format!("{stem}{suffix}")));
        OutputFiles {
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
        let all = RenderPlan::all(&s);
        assert_eq!(
            (all.frames.len(), all.cameras.clone(), all.total()),
            (12, vec![0, 1], 24)
        );
        assert!(all.covers_animation());
        let p = RenderPlan::select(&s, Some("1-3,10.."), Some("side")).unwrap();
        assert_eq!(p.frames, vec![1, 2, 3, 10, 11]);
        assert_eq!((p.cameras.clone(), p.camera_name(1)), (vec![1], "side"));
        assert!(!p.covers_animation());
        let e = RenderPlan::select(&s, None, Some("top")).unwrap_err();
        assert_eq!(e.to_string(), "--camera top: the scene has front, side");
        assert!(RenderPlan::select(&s, Some("11..13"), None).is_err());
    }

    #[test]
    fn files_follow_the_output_settings() {
        let s = scene(
            "[output]\nname = \"{scene}-{camera}-{frame:03}\"\ndepth = true\ngif = \"t.gif\"\n",
        );
        let p = RenderPlan::all(&s);
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
        let p = RenderPlan::all(&s);
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
