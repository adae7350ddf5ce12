//! Camera paths (`[[camera.keys]]`) and the turntable's `elevation`: frames
//! on keys render exactly as static cameras with the key's values, paths
//! move smoothly between keys, the turntable orbits on a cone, and bad keys
//! are refused with their location.

use crate::common;

use std::path::Path;

use glam::Vec3;
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;

/// The showcase's models and lights, small, with `cameras` and `animation`.
fn scene(dir: &Path, cameras: &str, animation: &str) -> Scene {
    let root = common::root();
    let text = std::fs::read_to_string(root.join("scenes/showcase.toml")).unwrap();
    // Everything up to the showcase's camera: output, render, models, lights.
    let head = &text[..text.find("[[camera]]").unwrap()];
    let head = head
        .replace("../assets/", &format!("{}/assets/", root.display()))
        .replace("width = 640", "width = 96")
        .replace("height = 480", "height = 72")
        .replace("video = \"showcase.mp4\"", "")
        .replace("gif = \"showcase.gif\"", "");
    let text = format!("{head}\n{cameras}\n{animation}\n");
    let path = dir.join("scene.toml");
    std::fs::write(&path, &text).unwrap();
    Scene::load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

const KEYS: &str = r#"
[[camera]]
name = "path"
[[camera.keys]]
frame = 0
eye = [0.0, 2.6, 5.2]
target = [0.0, 0.5, 0.0]
fov = 40.0
[[camera.keys]]
frame = 6
eye = [4.0, 1.5, 3.0]
target = [0.3, 0.6, 0.0]
fov = 30.0
[[camera.keys]]
frame = 11
eye = [-3.0, 4.0, 2.0]
target = [0.0, 0.4, 0.2]
up = [0.0, 1.0, 0.2]
"#;

#[test]
fn frames_on_keys_render_as_static_cameras() {
    let dir = common::scratch("camera_keys");
    let keyed = scene(&dir, KEYS, "[animation]\nframes = 12");
    let statics = [
        (
            0,
            "eye = [0.0, 2.6, 5.2]\ntarget = [0.0, 0.5, 0.0]\nfov = 40.0",
        ),
        (
            6,
            "eye = [4.0, 1.5, 3.0]\ntarget = [0.3, 0.6, 0.0]\nfov = 30.0",
        ),
        // The last key keeps the camera's fov (45) and gives its own up.
        (
            11,
            "eye = [-3.0, 4.0, 2.0]\ntarget = [0.0, 0.4, 0.2]\nup = [0.0, 1.0, 0.2]",
        ),
    ];
    for (frame, cam) in statics {
        let fixed = scene(
            &dir,
            &format!("[[camera]]\nname = \"path\"\n{cam}"),
            "[animation]\nframes = 12",
        );
        let a = common::render_frame(&keyed, 0, frame);
        let b = common::render_frame(&fixed, 0, frame);
        assert!(
            a.color == b.color,
            "frame {frame} differs from its static camera"
        );
        assert!(a.depth == b.depth, "frame {frame}: depth differs");
    }
    // Between keys the camera is elsewhere, and the frame differs.
    let mid = common::render_frame(&keyed, 0, 3);
    let on_key = common::render_frame(&keyed, 0, 0);
    assert!(mid.color != on_key.color);
    // Held after the last key.
    let cam = &keyed.cameras[0];
    assert_eq!(cam.at_frame(11).eye, cam.at_frame(500).eye);
}

#[test]
fn smooth_paths_move_without_jumps_and_linear_ones_go_straight() {
    let dir = common::scratch("camera_smooth");
    let keyed = scene(&dir, KEYS, "[animation]\nframes = 12");
    let cam = &keyed.cameras[0];
    // Per-frame steps vary gently: no step more than twice its neighbour
    // plus a margin (a kink or a jump would show as a spike).
    let eyes: Vec<Vec3> = (0..=11).map(|f| cam.at_frame(f).eye).collect();
    let steps: Vec<f32> = eyes.windows(2).map(|w| (w[1] - w[0]).length()).collect();
    for w in steps.windows(2) {
        assert!(
            w[1] < w[0] * 2.0 + 0.3 && w[0] < w[1] * 2.0 + 0.3,
            "{steps:?}"
        );
    }
    // Smooth is not linear: frame 3 is off the straight line between keys.
    let lin = scene(
        &dir,
        &KEYS.replace(
            "name = \"path\"\n",
            "name = \"path\"\ninterpolation = \"linear\"\n",
        ),
        "[animation]\nframes = 12",
    );
    let l = &lin.cameras[0];
    let straight = eyes[0].lerp(eyes[6], 0.5);
    assert!((l.at_frame(3).eye - straight).length() < 1e-5);
    assert!((cam.at_frame(3).eye - straight).length() > 0.05);
}

#[test]
fn turntable_elevation_orbits_on_a_cone() {
    let dir = common::scratch("camera_elevation");
    let spin = |rest: &str| {
        format!(
            "[animation]\nframes = 8\nturntable = {{ axis = [0.0, 1.0, 0.0], degrees = 360.0, rotate = \"camera\"{rest} }}"
        )
    };
    // A camera with an eye is raised about the pivot to 35 degrees.
    let s = scene(
        &dir,
        "[[camera]]\neye = [0.0, 0.5, 6.0]\ntarget = [0.0, 0.5, 0.0]",
        &spin(", elevation = 35.0"),
    );
    let pivot = s.animation.pivot;
    let flat = scene(
        &dir,
        "[[camera]]\neye = [0.0, 0.5, 6.0]\ntarget = [0.0, 0.5, 0.0]",
        &spin(""),
    );
    let d0 = flat.cameras[0].eye - pivot;
    for f in 0..8 {
        let eye = s.animation.turn(f).transform_point3(s.cameras[0].eye);
        let d = eye - pivot;
        let elev = (d.y / d.length()).asin().to_degrees();
        assert!((elev - 35.0).abs() < 1e-3, "frame {f}: {elev}");
        assert!((d.length() - d0.length()).abs() < 1e-4);
    }
    // A fitted camera looks from the turntable's elevation.
    let fitted = scene(&dir, "", &spin(", elevation = 50.0"));
    let c = &fitted.cameras[0];
    let back = (c.eye - c.target).normalize();
    assert!((back.y.asin().to_degrees() - 50.0).abs() < 0.5, "{back}");
    // The render from above sees more of the ground: a different frame.
    let a = common::render_frame(&s, 0, 0);
    let b = common::render_frame(&flat, 0, 0);
    assert!(a.color != b.color);
}

#[test]
fn bad_keys_are_refused_where_they_are() {
    let dir = common::scratch("camera_bad_keys");
    let root = common::root();
    let model = root.join("assets/showcase/cube.obj");
    for (cam, want, line) in [
        (
            "[[camera]]\n[[camera.keys]]\nframe = 5\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n[[camera.keys]]\nframe = 2\neye = [1.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n",
            "frame 2 comes after frame 5",
            10,
        ),
        (
            "[[camera]]\neye = [0.0, 0.0, 5.0]\n[[camera.keys]]\nframe = 0\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n",
            "takes its eye from the keys",
            5,
        ),
        (
            "[[camera]]\ninterpolation = \"linear\"\n",
            "camera.interpolation needs [[camera.keys]]",
            5,
        ),
        (
            "[[camera]]\n[[camera.keys]]\nframe = 0\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 5.0]\n",
            "must differ from its eye",
            8,
        ),
        (
            "[[camera]]\ninterpolation = \"cubic\"\n[[camera.keys]]\nframe = 0\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n",
            "unknown variant `cubic`",
            5,
        ),
    ] {
        let path = dir.join("bad.toml");
        let text = format!("[[model]]\npath = \"{}\"\n\n{cam}", model.display());
        std::fs::write(&path, &text).unwrap();
        let (code, _, err) = crate::binary::run(&["render", path.to_str().unwrap(), "--quiet"]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(want), "{err}");
        assert!(err.contains(&format!("bad.toml:{line}:")), "{err}");
    }
}
