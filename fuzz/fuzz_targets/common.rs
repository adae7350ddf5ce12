//! What the fuzz targets share: a scratch directory per process with small
//! synthetic assets the fuzzed files can name.

#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::OnceLock;

/// `$TMPDIR/softraster-fuzz-<pid>/`, holding `tri.obj`, `tex.png` (4x4),
/// `nm.png` (a flat normal map), `quad.gltf` and `lib.mtl`.
pub fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::temp_dir().join(format!("softraster-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("scratch dir");
        let tex = image::RgbImage::from_fn(4, 4, |x, y| image::Rgb([(x * 60) as u8, (y * 60) as u8, 128]));
        tex.save(d.join("tex.png")).expect("tex.png");
        image::RgbImage::from_pixel(4, 4, image::Rgb([128, 128, 255]))
            .save(d.join("nm.png"))
            .expect("nm.png");
        std::fs::write(
            d.join("tri.obj"),
            "mtllib lib.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n",
        )
        .expect("tri.obj");
        std::fs::write(d.join("lib.mtl"), "newmtl m\nKd 0.8 0.7 0.6\nmap_Kd tex.png\nnorm nm.png\n")
            .expect("lib.mtl");
        std::fs::write(d.join("quad.gltf"), QUAD_GLTF).expect("quad.gltf");
        d
    })
}

/// A quad as glTF with embedded buffers.
pub const QUAD_GLTF: &str = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":1},"indices":0}]}],"buffers":[{"byteLength":60,"uri":"data:application/octet-stream;base64,AAABAAIAAAACAAMAAACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAACAPwAAgD8AAAAAAACAvwAAgD8AAAAA"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":12},{"buffer":0,"byteOffset":12,"byteLength":48}],"accessors":[{"bufferView":0,"componentType":5123,"count":6,"type":"SCALAR"},{"bufferView":1,"componentType":5126,"count":4,"type":"VEC3","min":[-1,-1,0],"max":[1,1,0]}]}"#;

/// A float as TOML writes it (nan and inf included).
pub fn toml_f32(v: f32) -> String {
    if v.is_nan() {
        "nan".into()
    } else if v.is_infinite() {
        if v > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{v:?}")
    }
}

/// Loads and, when it loads, renders every camera's first frame of the
/// scene text (written to `name` in the scratch dir): the whole pipeline.
pub fn load_and_render(name: &str, text: &str, render: bool) {
    load_and_render_frames(name, text, render, &[0]);
}

/// As `load_and_render`, for the given frames.
pub fn load_and_render_frames(name: &str, text: &str, render: bool, frames: &[u32]) {
    use softraster::output::Image8;
    use softraster::render::{Frame, FrameSequence, Renderer, Shot};
    use softraster::scene::{LoadOptions, Scene};
    let path = dir().join(name);
    let Ok(scene) = Scene::from_text(&path, text, &LoadOptions::plain()) else {
        return;
    };
    if !render || scene.settings.width * scene.settings.height > 64 * 64 {
        return;
    }
    let renderer = Renderer::new(&scene);
    let mut frame = Frame::new(0, 0);
    // The sequence path (display bytes band by band, background kept
    // between frames) must give the one-frame path's bytes.
    let mut seq = FrameSequence::new();
    let mut image = Image8::empty();
    for cam in 0..scene.cameras.len().min(2) {
        for &f in frames {
            // The cameras are the scene's own: rendering them cannot fail.
            let shot = Shot::new(cam, f);
            renderer
                .render(shot, &mut frame)
                .expect("a camera of the scene");
            let want = softraster::output::resolve(&frame, &scene.settings);
            renderer
                .render_next(shot, &mut seq, Some(&mut image))
                .expect("a camera of the scene");
            assert!(image == want, "render_next's bytes differ from resolve's");
        }
    }
}
