//! Helpers shared by the integration tests of both packages (the command
//! line's tests include this file by path).
#![allow(dead_code)]

use softraster::render::Shot;
use std::path::{Path, PathBuf};
use std::sync::LazyLock;

use softraster::render::{Frame, Renderer};
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;

/// One frame of one camera, through the library's one entry for a frame.
pub fn render_frame(scene: &Scene, camera: usize, frame: u32) -> Frame {
    let mut out = Frame::new(0, 0);
    Renderer::new(scene)
        .render(Shot::new(camera, frame), &mut out)
        .unwrap();
    out
}

/// The repository root, whose `scenes/`, `assets/` and `tests/` folders
/// the tests of both packages read (the command line's tests run in `cli/`).
pub fn root() -> &'static Path {
    static ROOT: LazyLock<PathBuf> = LazyLock::new(|| {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
        match dir.parent() {
            Some(up) if !dir.join("scenes").is_dir() => up.to_path_buf(),
            _ => dir.to_path_buf(),
        }
    });
    &ROOT
}

/// A fresh directory under the target dir for one test's files.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `files` into `dir` and loads `scene` (TOML text) from there.
pub fn scene_in(dir: &Path, scene: &str, files: &[(&str, &str)]) -> Scene {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    Scene::load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Loads the scene file `path` with `--set` overrides `sets`.
pub fn load_with(path: &Path, sets: &[&str]) -> Scene {
    let opts = LoadOptions {
        sets: sets.iter().map(|s| s.parse().unwrap()).collect(),
        ..Default::default()
    };
    Scene::load(path, &opts).unwrap_or_else(|e| panic!("{e}"))
}

/// The shared model directory. When it is missing: under CI (`CI=true`)
/// the calling test fails with a message naming the path, so tests on real
/// models cannot pass by not running; elsewhere the test prints SKIPPED and
/// gets None.
pub fn shared_assets() -> Option<PathBuf> {
    let p = root().join("../shared/assets");
    if p.is_dir() {
        return Some(p);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!(
            "CI=true and the shared assets are missing: {} (tests on real models must run in CI)",
            p.display()
        );
    }
    eprintln!(
        "SKIPPED: {} not found; tests on real models did not run",
        p.display()
    );
    None
}

/// Direction through the center of pixel (px, py) in view space (z = -1)
/// for a perspective camera with vertical fov `fov` degrees.
pub fn view_ray(px: u32, py: u32, w: u32, h: u32, fov: f32) -> glam::Vec3 {
    let t = (fov.to_radians() * 0.5).tan();
    let aspect = w as f32 / h as f32;
    let x = ((px as f32 + 0.5) / w as f32 * 2.0 - 1.0) * t * aspect;
    let y = (1.0 - (py as f32 + 0.5) / h as f32 * 2.0) * t;
    glam::Vec3::new(x, y, -1.0)
}

/// One glTF primitive's data, written by `gltf_text` / `glb`.
#[derive(Default, Clone)]
pub struct Prim {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uv0: Vec<[f32; 2]>,
    pub uv1: Vec<[f32; 2]>,
    /// Linear RGBA (COLOR_0).
    pub colors: Vec<[f32; 4]>,
    pub indices: Vec<u32>,
}

/// A 2 x 2 square at z = 0 facing +Z, its texture coordinates 0..1 with
/// u along +x and v down the image (v = 0 at the top, y = 1).
pub fn plate() -> Prim {
    let corners = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    Prim {
        positions: corners.iter().map(|c| [c[0], c[1], 0.0]).collect(),
        normals: vec![[0.0, 0.0, 1.0]; 4],
        uv0: corners
            .iter()
            .map(|c| [(c[0] + 1.0) / 2.0, (1.0 - c[1]) / 2.0])
            .collect(),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    }
}

/// The binary buffer of `p` and its "accessors"/"bufferViews" JSON and
/// the primitive's "attributes"/"indices" JSON.
fn gltf_parts(p: &Prim) -> (Vec<u8>, String, String) {
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut attrs = Vec::new();
    let mut add = |name: &str, data: Vec<u8>, count: usize, ty: &str, comp: u32, minmax: String| {
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {}, "byteLength": {}}}"#,
            bin.len(),
            data.len()
        ));
        bin.extend(data);
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        accessors.push(format!(
            r#"{{"bufferView": {}, "componentType": {comp}, "count": {count}, "type": "{ty}"{minmax}}}"#,
            views.len() - 1
        ));
        attrs.push(format!(r#""{name}": {}"#, accessors.len() - 1));
    };
    let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for q in &p.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let mm = format!(r#", "min": {lo:?}, "max": {hi:?}"#);
    let n = p.positions.len();
    add("POSITION", f32s(&p.positions.concat()), n, "VEC3", 5126, mm);
    if !p.normals.is_empty() {
        add(
            "NORMAL",
            f32s(&p.normals.concat()),
            n,
            "VEC3",
            5126,
            String::new(),
        );
    }
    if !p.uv0.is_empty() {
        add(
            "TEXCOORD_0",
            f32s(&p.uv0.concat()),
            n,
            "VEC2",
            5126,
            String::new(),
        );
    }
    if !p.uv1.is_empty() {
        add(
            "TEXCOORD_1",
            f32s(&p.uv1.concat()),
            n,
            "VEC2",
            5126,
            String::new(),
        );
    }
    if !p.colors.is_empty() {
        add(
            "COLOR_0",
            f32s(&p.colors.concat()),
            n,
            "VEC4",
            5126,
            String::new(),
        );
    }
    if !p.indices.is_empty() {
        let data = p.indices.iter().flat_map(|x| x.to_le_bytes()).collect();
        add(
            "INDICES",
            data,
            p.indices.len(),
            "SCALAR",
            5125,
            String::new(),
        );
    }
    let mut prim_attrs: Vec<String> = attrs.clone();
    let indices = if !p.indices.is_empty() {
        let last = prim_attrs.pop().unwrap();
        format!(r#", "indices": {}"#, last.rsplit(' ').next().unwrap())
    } else {
        String::new()
    };
    let tables = format!(
        r#""accessors": [{}], "bufferViews": [{}]"#,
        accessors.join(", "),
        views.join(", ")
    );
    let prim = format!(r#""attributes": {{{}}}{indices}"#, prim_attrs.join(", "));
    (bin, tables, prim)
}

/// A .gltf document for one primitive (mesh 0; `prim_extra` is added to
/// the primitive, e.g. `, "material": 0`), `body` the remaining top-level
/// fields (nodes, scenes, materials...), and the buffer at `uri` (None: a
/// base64 data URI). Returns the text and the buffer's bytes.
pub fn gltf_text(p: &Prim, prim_extra: &str, body: &str, uri: Option<&str>) -> (String, Vec<u8>) {
    use base64::Engine;
    let (bin, tables, prim) = gltf_parts(p);
    let uri = match uri {
        Some(u) => u.to_string(),
        None => format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bin)
        ),
    };
    let text = format!(
        r#"{{"asset": {{"version": "2.0"}}, "buffers": [{{"uri": "{uri}", "byteLength": {}}}], {tables}, "meshes": [{{"primitives": [{{{prim}{prim_extra}}}]}}], {body}}}"#,
        bin.len()
    );
    (text, bin)
}

/// The same as a binary .glb (the buffer in the BIN chunk).
pub fn glb(p: &Prim, prim_extra: &str, body: &str) -> Vec<u8> {
    let (bin, tables, prim) = gltf_parts(p);
    let mut json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "buffers": [{{"byteLength": {}}}], {tables}, "meshes": [{{"primitives": [{{{prim}{prim_extra}}}]}}], {body}}}"#,
        bin.len()
    )
    .into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// A unit cube (side 1, centered), 24 vertices with face normals and UVs
/// (the showcase's procedural cube, its v turned to glTF's top-left origin).
pub fn cube() -> Prim {
    let b = softraster::procedural::cube([0.0; 3], 0.5);
    Prim {
        positions: b.v,
        normals: b.vn,
        uv0: b.vt.iter().map(|t| [t[0], 1.0 - t[1]]).collect(),
        indices: b.f.iter().flatten().map(|&i| i as u32 - 1).collect(),
        ..Default::default()
    }
}

/// Frames `frames` of camera 0 of `scene` from two renderers that take
/// equivalent paths (`a` and `b`); panics at the first pixel whose colour
/// or depth differs in any bit, and where fewer than 100 pixels are
/// covered (a comparison of empty frames would prove nothing).
pub fn same_frames(a: &Renderer, b: &Renderer, frames: &[u32], what: &str) {
    for &f in frames {
        let (mut x, mut y) = (Frame::new(0, 0), Frame::new(0, 0));
        a.render(Shot::new(0, f), &mut x).unwrap();
        b.render(Shot::new(0, f), &mut y).unwrap();
        assert_eq!(x.color.len(), y.color.len());
        let mut covered = 0;
        for (i, (p, q)) in x.color.iter().zip(&y.color).enumerate() {
            let bits = |v: glam::Vec4| v.to_array().map(f32::to_bits);
            assert!(
                bits(*p) == bits(*q) && x.depth[i].to_bits() == y.depth[i].to_bits(),
                "{what}, frame {f}, pixel {} {}: {p} depth {} against {q} depth {}",
                i as u32 % x.width,
                i as u32 / x.width,
                x.depth[i],
                y.depth[i]
            );
            covered += x.depth[i].is_finite() as usize;
        }
        assert!(covered > 100, "{what}: only {covered} pixels covered");
    }
}
