//! glTF animation playback against hand-computed poses: files written
//! here (a skinned bar whose two joints move, a morphing cube, a light on
//! an animated node), played with `model.animation`, checked vertex by
//! vertex through the frame's draw list and pixel by pixel in renders.

use crate::common;
use softraster::render::Shot;

use base64::Engine;
use glam::Vec3;
use serde_json::{Value, json};
use softraster::render::DrawList;
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;
use softraster::scene::light::LightKind;

/// A glTF file being written: one embedded buffer, accessors appended.
struct Writer {
    blob: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Writer {
    fn new() -> Writer {
        Writer {
            blob: Vec::new(),
            views: Vec::new(),
            accessors: Vec::new(),
        }
    }

    /// An accessor of `kind` ("SCALAR", "VEC3"...) over `bytes`; returns its
    /// index.
    fn accessor(
        &mut self,
        bytes: Vec<u8>,
        component: u32,
        count: usize,
        kind: &str,
        extra: Value,
    ) -> usize {
        while !self.blob.len().is_multiple_of(4) {
            self.blob.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.blob.len(), "byteLength": bytes.len()}));
        self.blob.extend_from_slice(&bytes);
        let mut a = json!({"bufferView": self.views.len() - 1, "componentType": component, "count": count, "type": kind});
        if let (Value::Object(a), Value::Object(e)) = (&mut a, extra) {
            a.extend(e);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn floats(&mut self, v: &[f32], kind: &str) -> usize {
        let width = match kind {
            "SCALAR" => 1,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            _ => panic!("{kind}"),
        };
        let bytes = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let extra = if kind == "VEC3" {
            // POSITION needs min and max.
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in v.chunks(3) {
                for i in 0..3 {
                    lo[i] = lo[i].min(p[i]);
                    hi[i] = hi[i].max(p[i]);
                }
            }
            json!({"min": lo, "max": hi})
        } else if kind == "SCALAR" {
            let lo = v.iter().copied().fold(f32::INFINITY, f32::min);
            let hi = v.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            json!({"min": [lo], "max": [hi]})
        } else {
            json!({})
        };
        self.accessor(bytes, 5126, v.len() / width, kind, extra)
    }

    fn u16s(&mut self, v: &[u16]) -> usize {
        let bytes = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.accessor(bytes, 5123, v.len(), "SCALAR", json!({}))
    }

    fn joints(&mut self, v: &[u8]) -> usize {
        self.accessor(v.to_vec(), 5121, v.len() / 4, "VEC4", json!({}))
    }

    /// The whole file: `doc` plus buffers, views and accessors.
    fn finish(self, mut doc: Value) -> String {
        let uri = base64::engine::general_purpose::STANDARD.encode(&self.blob);
        doc["asset"] = json!({"version": "2.0"});
        doc["buffers"] = json!([{"byteLength": self.blob.len(), "uri": format!("data:application/octet-stream;base64,{uri}")}]);
        doc["bufferViews"] = Value::Array(self.views);
        doc["accessors"] = Value::Array(self.accessors);
        serde_json::to_string_pretty(&doc).unwrap()
    }
}

/// A bar along +Y, 0.2 wide, rows at y = 0, 1, 1.5 and 2. Rows 0 and 1
/// follow joint 0, row 2 joint 1; the row at 1.5 is half joint 0 (JOINTS_0)
/// and half joint 1 (JOINTS_1: an eight-influence vertex). Joint 0 is the
/// root at the origin, joint 1 its child at y = 1.
///
/// Clip "Bend" (2 s): joint 1 turns about +Z, LINEAR: 0 degrees at 0 s, 90
/// at 1 s and 2 s; joint 0 moves by STEP: (0, 0, 0) until 0.75 s, then (2,
/// 0, 0). Clip "Idle" has one key. A point light hangs under joint 1, 1
/// unit along its +X.
fn bar() -> String {
    let mut w = Writer::new();
    let rows = [0.0f32, 1.0, 1.5, 2.0];
    let mut pos = Vec::new();
    let mut nrm = Vec::new();
    for y in rows {
        pos.extend([-0.1, y, 0.0, 0.1, y, 0.0]);
        nrm.extend([0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    }
    let mut idx = Vec::new();
    for r in 0..3u16 {
        let (a, b, c, d) = (2 * r, 2 * r + 1, 2 * r + 3, 2 * r + 2);
        idx.extend([a, b, c, a, c, d]);
    }
    let p = w.floats(&pos, "VEC3");
    let n = w.floats(&nrm, "VEC3");
    let i = w.u16s(&idx);
    let j0 = w.joints(&[
        0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0,
        0, 0,
    ]);
    let w0 = w.floats(
        &[
            1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., //
            0.5, 0., 0., 0., 0.5, 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0.,
        ],
        "VEC4",
    );
    let j1 = w.joints(&[
        0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0,
        0, 0,
    ]);
    let w1 = w.floats(
        &[
            0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., //
            0.5, 0., 0., 0., 0.5, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.,
        ],
        "VEC4",
    );
    let mut ibm = glam::Mat4::IDENTITY.to_cols_array().to_vec();
    ibm.extend(glam::Mat4::from_translation(-Vec3::Y).to_cols_array());
    let ibm = w.floats(&ibm, "MAT4");
    let t_rot = w.floats(&[0.0, 1.0, 2.0], "SCALAR");
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let rot = w.floats(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, h, h, 0.0, 0.0, h, h],
        "VEC4",
    );
    let t_step = w.floats(&[0.0, 0.75, 2.0], "SCALAR");
    let tr = w.floats(&[0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 2.0, 0.0, 0.0], "VEC3");
    let t_one = w.floats(&[0.0], "SCALAR");
    let one = w.floats(&[0.0, 0.0, 0.0], "VEC3");
    let doc = json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 3.0}]}},
        "nodes": [
            {"mesh": 0, "skin": 0, "translation": [50.0, 0.0, 0.0]},
            {"name": "root", "children": [2]},
            {"name": "tip", "translation": [0.0, 1.0, 0.0], "children": [3]},
            {"translation": [1.0, 0.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}
        ],
        "skins": [{"joints": [1, 2], "inverseBindMatrices": ibm}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p, "NORMAL": n, "JOINTS_0": j0, "WEIGHTS_0": w0, "JOINTS_1": j1, "WEIGHTS_1": w1}, "indices": i}]}],
        "animations": [
            {"name": "Bend",
             "samplers": [
                {"input": t_rot, "output": rot, "interpolation": "LINEAR"},
                {"input": t_step, "output": tr, "interpolation": "STEP"}],
             "channels": [
                {"sampler": 0, "target": {"node": 2, "path": "rotation"}},
                {"sampler": 1, "target": {"node": 1, "path": "translation"}}]},
            {"name": "Idle",
             "samplers": [{"input": t_one, "output": one}],
             "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}
        ]
    });
    w.finish(doc)
}

/// A unit cube around the origin without normals (flat shaded), whose
/// morph target moves its +X face by +1 in x. Clip "Grow" animates the
/// weight by CUBICSPLINE from 0 at 0 s (out-tangent 1/s) to 1 at 1 s
/// (in-tangent 0).
fn cube() -> String {
    let mut w = Writer::new();
    let mut pos = Vec::new();
    let mut delta = Vec::new();
    for k in 0..8 {
        let c = [
            (k & 1) as f32 - 0.5,
            ((k >> 1) & 1) as f32 - 0.5,
            ((k >> 2) & 1) as f32 - 0.5,
        ];
        pos.extend(c);
        delta.extend([if c[0] > 0.0 { 1.0 } else { 0.0 }, 0.0, 0.0]);
    }
    // Each face's corners clockwise seen from outside (turned to
    // counter-clockwise triangles below).
    let faces: [[u16; 4]; 6] = [
        [0, 2, 6, 4], // -X
        [1, 5, 7, 3], // +X
        [0, 4, 5, 1], // -Y
        [2, 3, 7, 6], // +Y
        [0, 1, 3, 2], // -Z
        [4, 6, 7, 5], // +Z
    ];
    let idx: Vec<u16> = faces
        .iter()
        .flat_map(|[a, b, c, d]| [*a, *d, *c, *a, *c, *b])
        .collect();
    let p = w.floats(&pos, "VEC3");
    let d = w.floats(&delta, "VEC3");
    let i = w.u16s(&idx);
    let t = w.floats(&[0.0, 1.0], "SCALAR");
    // Per key: in-tangent, value, out-tangent.
    let v = w.floats(&[9.0, 0.0, 1.0, 0.0, 1.0, 9.0], "SCALAR");
    let doc = json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"weights": [0.0], "primitives": [{"attributes": {"POSITION": p}, "targets": [{"POSITION": d}], "indices": i}]}],
        "animations": [{"name": "Grow",
            "samplers": [{"input": t, "output": v, "interpolation": "CUBICSPLINE"}],
            "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}]
    });
    w.finish(doc)
}

fn load(dir: &std::path::Path, scene: &str) -> Result<Scene, String> {
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    Scene::load(&path, &LoadOptions::default()).map_err(|e| e.to_string())
}

/// Positions of model 0 at `frame`, as the frame's draw list has them.
fn posed(scene: &Scene, frame: u32) -> Vec<Vec3> {
    let fs = DrawList::new(scene, 0, frame);
    let (p, _) = fs.posed[0].as_ref().expect("model 0 is posed");
    p.positions.clone()
}

fn near(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

const BAR_SCENE: &str = "[animation]\nfps = 4\n[output]\nwidth = 96\nheight = 64\n[render]\nshading = \"unlit\"\ncull = \"none\"\n\
    [[model]]\npath = \"bar.gltf\"\nanimation = \"Bend\"\nlights = true\n\
    [[camera]]\nprojection = \"orthographic\"\nheight = 4.0\neye = [1.0, 1.0, 5.0]\ntarget = [1.0, 1.0, 0.0]\n";

#[test]
fn a_skinned_bar_follows_its_joints_through_the_clip() {
    let dir = common::scratch("anim_bar");
    std::fs::write(dir.join("bar.gltf"), bar()).unwrap();
    let scene = load(&dir, BAR_SCENE).unwrap_or_else(|e| panic!("{e}"));
    // 2 s at 4 fps.
    assert_eq!(scene.animation.frames, 8);
    let (c, s) = (
        std::f32::consts::FRAC_PI_4.cos(),
        std::f32::consts::FRAC_PI_4.sin(),
    );
    // Frame 2 = 0.5 s: joint 1 at 45 degrees, joint 0 not moved yet (STEP).
    let turn = |x: f32, y: f32, c: f32, s: f32| {
        Vec3::new(x * c - (y - 1.0) * s, 1.0 + x * s + (y - 1.0) * c, 0.0)
    };
    let p = posed(&scene, 2);
    let want = [
        Vec3::new(-0.1, 0.0, 0.0),
        Vec3::new(0.1, 0.0, 0.0),
        Vec3::new(-0.1, 1.0, 0.0),
        Vec3::new(0.1, 1.0, 0.0),
        (Vec3::new(-0.1, 1.5, 0.0) + turn(-0.1, 1.5, c, s)) * 0.5,
        (Vec3::new(0.1, 1.5, 0.0) + turn(0.1, 1.5, c, s)) * 0.5,
        turn(-0.1, 2.0, c, s),
        turn(0.1, 2.0, c, s),
    ];
    for (g, w) in p.iter().zip(&want) {
        assert!(near(*g, *w), "frame 2: {p:?}\nwant {want:?}");
    }
    // Frame 4 = 1 s: 90 degrees, and the whole rig moved +2 in x.
    let p = posed(&scene, 4);
    let shift = Vec3::new(2.0, 0.0, 0.0);
    let want = [
        Vec3::new(1.9, 0.0, 0.0),
        Vec3::new(2.1, 0.0, 0.0),
        Vec3::new(1.9, 1.0, 0.0),
        Vec3::new(2.1, 1.0, 0.0),
        Vec3::new(-0.3, 1.2, 0.0) + shift,
        Vec3::new(-0.2, 1.3, 0.0) + shift,
        Vec3::new(-1.0, 0.9, 0.0) + shift,
        Vec3::new(-1.0, 1.1, 0.0) + shift,
    ];
    for (g, w) in p.iter().zip(&want) {
        assert!(near(*g, *w), "frame 4: {p:?}\nwant {want:?}");
    }
    // Normals stay +Z under turns about Z.
    let fs = DrawList::new(&scene, 0, 4);
    let (pz, _) = fs.posed[0].as_ref().unwrap();
    assert!(
        pz.normals.iter().all(|n| near(*n, Vec3::Z)),
        "{:?}",
        pz.normals
    );
    // The light follows joint 1: 1 unit along its +X, which at 90 degrees
    // points +Y; (0, 1) + (0, 1) + the shift.
    let light = fs.lights.iter().find_map(|l| match l.kind {
        LightKind::Point { position, .. } => Some(position),
        _ => None,
    });
    assert!(near(light.unwrap(), Vec3::new(2.0, 2.0, 0.0)), "{light:?}");
    let fs0 = DrawList::new(&scene, 0, 0);
    let light0 = fs0.lights.iter().find_map(|l| match l.kind {
        LightKind::Point { position, .. } => Some(position),
        _ => None,
    });
    assert!(
        near(light0.unwrap(), Vec3::new(1.0, 1.0, 0.0)),
        "{light0:?}"
    );

    // Rendered: 16 pixels per unit, (1, 1) at the center (48, 32).
    let covered = |f: &softraster::render::Frame, x: f32, y: f32| {
        let px = (48.0 + (x - 1.0) * 16.0) as usize;
        let py = (32.0 - (y - 1.0) * 16.0) as usize;
        f.depth[py * 96 + px].is_finite()
    };
    let f0 = common::render_frame(&scene, 0, 0);
    assert!(covered(&f0, 0.0, 1.8), "frame 0: the bar stands straight");
    assert!(!covered(&f0, 2.0, 0.5));
    let f4 = common::render_frame(&scene, 0, 4);
    assert!(covered(&f4, 2.0, 0.5), "frame 4: the bar moved to x = 2");
    assert!(covered(&f4, 1.3, 1.1), "frame 4: the tip points -X");
    assert!(!covered(&f4, 0.0, 0.5) && !covered(&f4, 2.0, 1.8));
}

#[test]
fn the_default_pose_of_the_rig_is_the_loaded_mesh() {
    let dir = common::scratch("anim_rest");
    std::fs::write(dir.join("bar.gltf"), bar()).unwrap();
    std::fs::write(
        dir.join("s.toml"),
        "[[model]]\npath = \"bar.gltf\"\nanimation = \"Bend\"\n",
    )
    .unwrap();
    let scene = softraster::scene::Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let m = &scene.models[0];
    let rig = &m.playback.as_ref().expect("the clip plays").rig;
    let posed = rig.place(
        &rig.node_pose(None),
        &m.mesh,
        &[],
        softraster::assets::rig::Parts::All,
    );
    assert_eq!(posed.positions.len(), m.mesh.positions.len());
    for (a, b) in posed.positions.iter().zip(&m.mesh.positions) {
        assert!(near(*a, *b), "{a} {b}");
    }
    for (a, b) in posed.normals.iter().zip(&m.mesh.normals) {
        assert!(near(*a, *b), "{a} {b}");
    }
    assert_eq!(rig.clip_names(), "0 \"Bend\", 1 \"Idle\"");
}

#[test]
fn a_morphing_cube_follows_its_cubic_spline_weights() {
    let dir = common::scratch("anim_cube");
    std::fs::write(dir.join("cube.gltf"), cube()).unwrap();
    let scene = load(
        &dir,
        "[animation]\nfps = 4\n[[model]]\npath = \"cube.gltf\"\nanimation = 0\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.animation.frames, 4);
    // Frame 1 = 0.25 s: Hermite with p0 = 0, m0 = 1, p1 = 1, m1 = 0.
    let s: f32 = 0.25;
    let weight = (-2.0 * s.powi(3) + 3.0 * s * s) + (s.powi(3) - 2.0 * s * s + s);
    for (frame, w) in [(0u32, 0.0f32), (1, weight)] {
        let p = posed(&scene, frame);
        let max_x = p.iter().map(|p| p.x).fold(f32::NEG_INFINITY, f32::max);
        let min_x = p.iter().map(|p| p.x).fold(f32::INFINITY, f32::min);
        assert!(
            (max_x - (0.5 + w)).abs() < 1e-5,
            "frame {frame}: {max_x} want {}",
            0.5 + w
        );
        assert!((min_x + 0.5).abs() < 1e-6);
    }
    // Flat normals are the posed faces': still axis-aligned, outward.
    let fs = DrawList::new(&scene, 0, 1);
    let (p, _) = fs.posed[0].as_ref().unwrap();
    for (v, n) in p.positions.iter().zip(&p.normals) {
        let axis = n.abs().max_element();
        assert!((axis - 1.0).abs() < 1e-5, "{n}");
        assert!(n.dot(*v) > 0.0, "{v} {n}");
    }
    // The bounds cover the clip: at 0.75 s the cube reaches x = 1.48.
    let right = scene.bounds_center.x + scene.bounds_radius;
    assert!(
        right > 1.4,
        "{} {}",
        scene.bounds_center,
        scene.bounds_radius
    );
}

#[test]
fn a_renderer_kept_across_frames_draws_what_fresh_ones_do() {
    // Shadow maps and BVHs are reused across frames only while nothing
    // moves: an animated model with a camera turntable (which would keep
    // the maps) must get new ones.
    let dir = common::scratch("anim_cache");
    std::fs::write(dir.join("bar.gltf"), bar()).unwrap();
    let text = "[animation]\nfps = 4\nturntable = { rotate = \"camera\", degrees = 40.0 }\n\
        [output]\nwidth = 48\nheight = 48\n[ground]\nshadow = true\n\
        [render]\nao = { method = \"raytraced\", samples = 4 }\n\
        [[light]]\nkind = \"directional\"\ndirection = [-0.3, -1.0, -0.4]\nshadows = true\n\
        [[model]]\npath = \"bar.gltf\"\nanimation = \"Bend\"\n";
    let scene = load(&dir, text).unwrap_or_else(|e| panic!("{e}"));
    let kept = softraster::render::Renderer::new(&scene);
    let mut out = softraster::render::Frame::new(0, 0);
    for frame in [0u32, 4, 5] {
        kept.render(Shot::new(0, frame), &mut out).unwrap();
        let fresh = common::render_frame(&scene, 0, frame);
        assert!(
            out.color == fresh.color,
            "frame {frame} differs from a fresh render"
        );
    }
    let f0 = common::render_frame(&scene, 0, 0);
    assert!(f0.color != out.color, "the bar did not move");
}

#[test]
fn bad_animation_keys_are_errors_naming_the_key() {
    let dir = common::scratch("anim_errors");
    std::fs::write(dir.join("bar.gltf"), bar()).unwrap();
    std::fs::write(dir.join("cube.gltf"), cube()).unwrap();
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    // An unknown channel path (which the gltf crate's own accessors would
    // unwrap: found by fuzzing) fails only the clip that has it.
    std::fs::write(
        dir.join("typo.gltf"),
        bar().replacen("\"path\": \"translation\"", "\"path\": \"trcnslation\"", 1),
    )
    .unwrap();
    let still = r#"{"asset": {"version": "2.0"}, "scenes": [{"nodes": []}]}"#;
    std::fs::write(dir.join("still.gltf"), still).unwrap();
    for (model, anim, want) in [
        (
            "bar.gltf",
            "\"Walk\"",
            "no animation named \"Walk\"; it has: 0 \"Bend\", 1 \"Idle\"",
        ),
        (
            "bar.gltf",
            "7",
            "no animation 7; it has: 0 \"Bend\", 1 \"Idle\"",
        ),
        ("bar.gltf", "-1", "an animation's name"),
        (
            "tri.obj",
            "\"Walk\"",
            "only glTF and FBX models' animations are read; this one is OBJ",
        ),
        ("still.gltf", "0", "has no animations"),
        (
            "typo.gltf",
            "\"Bend\"",
            "animation 0 of typo.gltf cannot be played: channel 1: its target path is not translation, rotation, scale or weights",
        ),
    ] {
        let text = format!("[[model]]\npath = \"{model}\"\nanimation = {anim}\n");
        let e = load(&dir, &text)
            .err()
            .unwrap_or_else(|| panic!("{model} {anim} loaded"));
        assert!(e.contains(want), "{e}");
        assert!(e.contains("scene.toml:3:"), "no line: {e}");
    }
    // The file's other clip still plays, and without a clip it renders.
    for anim in ["animation = \"Idle\"\n", ""] {
        let text = format!("[[model]]\npath = \"typo.gltf\"\n{anim}");
        let scene = load(&dir, &text).unwrap_or_else(|e| panic!("{e}"));
        common::render_frame(&scene, 0, 0);
    }
}

#[test]
fn frames_given_override_the_clip_length_and_the_clip_loops() {
    let dir = common::scratch("anim_loop");
    std::fs::write(dir.join("bar.gltf"), bar()).unwrap();
    let text = BAR_SCENE.replace("fps = 4\n", "fps = 4\nframes = 12\n");
    let scene = load(&dir, &text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.animation.frames, 12);
    // Frame 10 = 2.5 s = 0.5 s of the 2 s clip.
    assert_eq!(posed(&scene, 10), posed(&scene, 2));
}

#[test]
fn the_walker_steps_with_alternate_feet() {
    // The committed walking figure (`softraster generate-assets`): its
    // clip gives 24 frames at 24 fps, and its ankles swing forward (+Z)
    // and back in turn, half a cycle apart.
    let root = common::root();
    let scene = Scene::load(&root.join("scenes/walker.toml"), &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.animation.frames, 96);
    let p = scene.models[0].playback.as_ref().unwrap();
    assert_eq!(p.clip.name, "Walk");
    assert!((p.clip.duration - 1.0).abs() < 1e-6);
    let ankle = |t: f64, shin: usize| {
        p.nodes_at(t).worlds[shin].transform_point3(Vec3::new(0.0, -0.44, 0.0))
    };
    // Shins are joints 4 (left) and 6 (right).
    let (l1, r1) = (ankle(0.25, 4), ankle(0.25, 6));
    let (l3, r3) = (ankle(0.75, 4), ankle(0.75, 6));
    assert!(l1.z > 0.15 && r1.z < -0.15, "{l1} {r1}");
    assert!(l3.z < -0.15 && r3.z > 0.15, "{l3} {r3}");
    // Posed, the figure stays about 1.8 tall and on its feet.
    let fs = DrawList::new(&scene, 0, 6);
    let (posed, _) = fs.posed[0].as_ref().unwrap();
    let lo = posed
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min);
    let hi = posed
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f32::NEG_INFINITY, f32::max);
    assert!(
        lo > -0.05 && lo < 0.1 && (hi - 1.8).abs() < 0.1,
        "{lo} {hi}"
    );
    assert!(
        posed
            .normals
            .iter()
            .all(|n| (n.length() - 1.0).abs() < 1e-4)
    );
    // The default frame count without `frames` is the clip's.
    let dir = common::scratch("anim_walker");
    let glb = root.join("assets/showcase/walker.glb");
    let s = load(
        &dir,
        &format!(
            "[[model]]\npath = \"{}\"\nanimation = \"Walk\"\n",
            glb.display()
        ),
    )
    .unwrap();
    assert_eq!(s.animation.frames, 24);
}
