//! glTF end to end: the same mesh written as OBJ and as glTF (with a node
//! transform) renders to the same pixels; nested TRS nodes place a cube
//! where the composed matrix says; mirrored nodes keep their front faces;
//! samplers, texture coordinate sets and KHR_texture_transform pick the
//! texels they should; imported lights and cameras land where their nodes
//! put them.

use crate::common;

use common::render_frame;
use common::{Prim, cube, gltf_text};
use glam::{Mat4, Quat, Vec3};
use softraster::output::resolve;
use softraster::scene::Scene;
use softraster::scene::camera::Projection;
use softraster::scene::light::LightKind;

/// A 4x4 RGBA PNG: red, green / blue, yellow quadrants (top-left origin),
/// so that a flipped or rotated lookup shows.
fn quadrant_png() -> Vec<u8> {
    let mut img = image::RgbaImage::new(4, 4);
    for y in 0..4 {
        for x in 0..4 {
            let c = match (x < 2, y < 2) {
                (true, true) => [255, 0, 0, 255],
                (false, true) => [0, 255, 0, 255],
                (true, false) => [0, 0, 255, 255],
                (false, false) => [255, 255, 0, 255],
            };
            img.put_pixel(x, y, image::Rgba(c));
        }
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A pyramid over a square base, UVs across it (glTF convention), indexed.
fn pyramid() -> Prim {
    let apex = [0.0, 0.75, 0.0];
    let base = [
        [-0.5, 0.0, 0.5],
        [0.5, 0.0, 0.5],
        [0.5, 0.0, -0.5],
        [-0.5, 0.0, -0.5],
    ];
    let mut p = Prim::default();
    for k in 0..4 {
        let (a, b) = (base[k], base[(k + 1) % 4]);
        let n = (Vec3::from(b) - Vec3::from(a))
            .cross(Vec3::from(apex) - Vec3::from(a))
            .normalize()
            .to_array();
        let i = p.positions.len() as u32;
        p.positions.extend([a, b, apex]);
        p.normals.extend([n; 3]);
        p.uv0.extend(
            [[0.0, 1.0], [1.0, 1.0], [0.5, 0.0]]
                .map(|[u, v]| [u * 0.5 + 0.25 * (k % 2) as f32, v * 0.75]),
        );
        p.indices.extend([i, i + 1, i + 2]);
    }
    p
}

/// The node transform used by the OBJ-vs-glTF test: exact in binary
/// floating point (a quarter turn about Y, scale 2, dyadic translation).
fn node_matrix() -> Mat4 {
    Mat4::from_cols_array(&[
        0.0, 0.0, -2.0, 0.0, //
        0.0, 2.0, 0.0, 0.0, //
        2.0, 0.0, 0.0, 0.0, //
        0.25, -0.5, 0.125, 1.0,
    ])
}

fn obj_text(p: &Prim, m: Mat4) -> String {
    let mut s = String::from("mtllib m.mtl\nusemtl tex\n");
    let n3 = glam::Mat3::from_mat4(m).inverse().transpose();
    for q in &p.positions {
        let w = m.transform_point3(Vec3::from(*q));
        s += &format!("v {} {} {}\n", w.x, w.y, w.z);
    }
    for n in &p.normals {
        let w = (n3 * Vec3::from(*n)).normalize();
        s += &format!("vn {} {} {}\n", w.x, w.y, w.z);
    }
    for t in &p.uv0 {
        // OBJ's v runs up.
        s += &format!("vt {} {}\n", t[0], 1.0 - t[1]);
    }
    for t in p.indices.chunks(3) {
        let c = |i: u32| format!("{0}/{0}/{0}", i + 1);
        s += &format!("f {} {} {}\n", c(t[0]), c(t[1]), c(t[2]));
    }
    s
}

#[test]
fn the_same_mesh_as_obj_and_as_gltf_renders_the_same_pixels() {
    let dir = common::scratch("gltf_vs_obj");
    std::fs::write(dir.join("tex.png"), quadrant_png()).unwrap();
    let p = pyramid();
    let m = node_matrix();
    std::fs::write(dir.join("p.obj"), obj_text(&p, m)).unwrap();
    // Ns 1 and Ks 0.04 are what a rough (1) dielectric maps to.
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl tex\nKd 1 1 1\nKs 0.04 0.04 0.04\nNs 1\nmap_Kd tex.png\n",
    )
    .unwrap();
    let cols = m.to_cols_array();
    let (text, _) = gltf_text(
        &p,
        r#", "material": 0"#,
        &format!(
            r#""nodes": [{{"mesh": 0, "matrix": {cols:?}}}], "scenes": [{{"nodes": [0]}}], "scene": 0,
            "materials": [{{"name": "tex", "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}, "metallicFactor": 0, "roughnessFactor": 1}}}}],
            "textures": [{{"source": 0}}], "images": [{{"uri": "tex.png"}}]"#
        ),
        None,
    );
    std::fs::write(dir.join("p.gltf"), text).unwrap();
    let scene = |model: &str, shading: &str| {
        format!(
            "[output]\nwidth = 96\nheight = 80\n[render]\nshading = \"{shading}\"\ntexture_filter = \"nearest\"\n\
             [[model]]\npath = \"{model}\"\n\
             [[light]]\nkind = \"point\"\nposition = [2.0, 3.0, 2.5]\nintensity = 20.0\n\
             [[camera]]\neye = [2.0, 1.5, 3.0]\ntarget = [0.25, 0.2, 0.125]\n"
        )
    };
    for shading in ["unlit", "normals", "blinn-phong"] {
        let obj = common::scene_in(&dir, &scene("p.obj", shading), &[]);
        let gltf = common::scene_in(&dir, &scene("p.gltf", shading), &[]);
        let a = resolve(&render_frame(&obj, 0, 0), &obj.settings);
        let b = resolve(&render_frame(&gltf, 0, 0), &gltf.settings);
        let covered = a.data.chunks(3).filter(|c| c != &[0, 0, 0]).count();
        assert!(
            covered > 1500,
            "{shading}: the pyramid covers {covered} pixels"
        );
        let differing = a
            .data
            .chunks(3)
            .zip(b.data.chunks(3))
            .filter(|(x, y)| x != y)
            .count();
        assert_eq!(differing, 0, "{shading}: {differing} pixels differ");
    }
    // (OBJ's v is flipped on load, glTF's is not: equal pixels mean both
    // read the image the same way up.)
    let g = common::scene_in(&dir, &scene("p.gltf", "unlit"), &[]);
    assert!(g.warnings.is_empty(), "{:?}", g.warnings);
}

fn trs(t: [f32; 3], r: Quat, s: f32) -> Mat4 {
    Mat4::from_scale_rotation_translation(Vec3::splat(s), r, Vec3::from(t))
}

#[test]
fn nested_trs_nodes_place_a_cube_by_the_composed_matrix() {
    let dir = common::scratch("gltf_nested");
    let parent_r = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let child_r = Quat::from_rotation_x(0.6);
    let (text, _) = gltf_text(
        &cube(),
        "",
        &format!(
            r#""nodes": [
                {{"children": [1], "translation": [1.0, 2.0, 3.0], "rotation": {:?}, "scale": [2.0, 2.0, 2.0]}},
                {{"mesh": 0, "translation": [0.5, 0.0, 0.0], "rotation": {:?}, "scale": [0.5, 0.5, 0.5]}}
            ], "scenes": [{{"nodes": [0]}}], "scene": 0"#,
            parent_r.to_array(),
            child_r.to_array()
        ),
        None,
    );
    std::fs::write(dir.join("c.gltf"), text).unwrap();
    let scene = common::scene_in(&dir, "[[model]]\npath = \"c.gltf\"\n", &[]);
    let m = &scene.models[0];
    assert_eq!(m.world_from_object, Mat4::IDENTITY);
    let want = trs([1.0, 2.0, 3.0], parent_r, 2.0) * trs([0.5, 0.0, 0.0], child_r, 0.5);
    let c = cube();
    assert_eq!(m.mesh.positions.len(), c.positions.len());
    for (got, p) in m.mesh.positions.iter().zip(&c.positions) {
        let w = want.transform_point3(Vec3::from(*p));
        assert!((*got - w).length() < 1e-5, "{got} vs {w}");
    }
    // The composed center is (1, 3, 3): the parent's quarter turn about Z
    // takes the child's +x offset of 0.5 (times 2) to +y.
    let (lo, hi) = m.mesh.bounds();
    assert!(((lo + hi) * 0.5 - Vec3::new(1.0, 3.0, 3.0)).length() < 1e-5);
    for n in &m.mesh.normals {
        assert!((n.length() - 1.0).abs() < 1e-5);
    }
}

#[test]
fn a_mirroring_node_keeps_front_faces_outward() {
    let dir = common::scratch("gltf_mirror");
    let coverage = |scale: &str| {
        let (text, _) = gltf_text(
            &cube(),
            "",
            &format!(
                r#""nodes": [{{"mesh": 0, "scale": {scale}, "rotation": [0.2, 0.3, 0.1, 0.927]}}], "scenes": [{{"nodes": [0]}}]"#
            ),
            None,
        );
        std::fs::write(dir.join("m.gltf"), text).unwrap();
        let s = common::scene_in(
            &dir,
            "[output]\nwidth = 64\nheight = 64\n[render]\nshading = \"normals\"\n[[model]]\npath = \"m.gltf\"\n\
             [[camera]]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n",
            &[],
        );
        let f = render_frame(&s, 0, 0);
        let d: Vec<f32> = f.depth.iter().copied().filter(|d| d.is_finite()).collect();
        (d.len(), d.iter().sum::<f32>() / d.len().max(1) as f32)
    };
    let (plain, plain_depth) = coverage("[1.0, 1.0, 1.0]");
    let (mirrored, mirrored_depth) = coverage("[-1.0, 1.0, 1.0]");
    assert!(plain > 500, "{plain}");
    // The camera sits on the mirror plane, so the mirrored cube's image is
    // the plain one's mirror image: same coverage, same depths. Were the
    // winding not flipped, culling would keep the far faces (mean depth
    // beyond the center at 3) or nothing.
    assert!(
        (plain as i64 - mirrored as i64).abs() < 40,
        "{plain} vs {mirrored}"
    );
    assert!(plain_depth < 3.0, "{plain_depth}");
    assert!(
        (plain_depth - mirrored_depth).abs() < 0.01,
        "{plain_depth} vs {mirrored_depth}"
    );
}

#[test]
fn texcoord_sets_samplers_and_texture_transform_pick_the_right_texels() {
    let dir = common::scratch("gltf_sampler");
    std::fs::write(dir.join("tex.png"), quadrant_png()).unwrap();
    // A square facing +z; TEXCOORD_0 is all zeros, TEXCOORD_1 spans the
    // image; the transform shifts u by half the image, so the square's
    // right half reads past the edge, where CLAMP_TO_EDGE holds the last
    // column (REPEAT would show red and blue there).
    let p = Prim {
        positions: vec![
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
        ],
        normals: vec![[0.0, 0.0, 1.0]; 4],
        uv0: vec![[0.0, 0.0]; 4],
        uv1: vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    };
    let (text, _) = gltf_text(
        &p,
        r#", "material": 0"#,
        r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 0,
            "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.0], "texCoord": 1}}}}}],
        "extensionsUsed": ["KHR_texture_transform"],
        "textures": [{"source": 0, "sampler": 0}], "images": [{"uri": "tex.png"}],
        "samplers": [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]"#,
        None,
    );
    std::fs::write(dir.join("q.gltf"), text).unwrap();
    let s = common::scene_in(
        &dir,
        "[output]\nwidth = 40\nheight = 40\n[render]\nshading = \"unlit\"\ntexture_filter = \"anisotropic\"\n\
         [[model]]\npath = \"q.gltf\"\n\
         [[camera]]\nprojection = \"orthographic\"\nheight = 2.0\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n",
        &[],
    );
    let f = render_frame(&s, 0, 0);
    let at = |x: usize, y: usize| f.color[y * 40 + x].truncate();
    // Green on top, yellow below, everywhere; nearest (the sampler's
    // filters win over the scene's anisotropic): pure colors.
    let green = Vec3::new(0.0, 1.0, 0.0);
    let yellow = Vec3::new(1.0, 1.0, 0.0);
    for (x, y, want) in [
        (5, 5, green),
        (15, 5, green),
        (5, 35, yellow),
        (35, 5, green),
        (35, 35, yellow),
    ] {
        assert!(
            (at(x, y) - want).abs().max_element() < 1e-6,
            "({x},{y}): {} vs {want}",
            at(x, y)
        );
    }
}

#[test]
fn imported_lights_and_cameras_follow_their_nodes() {
    let dir = common::scratch("gltf_lights");
    let (text, _) = gltf_text(
        &cube(),
        "",
        r#""nodes": [
            {"mesh": 0},
            {"translation": [0.0, 0.0, 4.0], "children": [2, 3]},
            {"camera": 0, "name": "front"},
            {"translation": [1.0, 2.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"rotation": [-0.7071068, 0.0, 0.0, 0.7071068], "extensions": {"KHR_lights_punctual": {"light": 1}}}
        ], "scenes": [{"nodes": [0, 1, 4]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1, "zfar": 50.0}}],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 30.0, "range": 10.0, "color": [1.0, 0.5, 0.25]},
            {"type": "directional", "intensity": 2.0}
        ]}}"#,
        None,
    );
    std::fs::write(dir.join("l.gltf"), text).unwrap();
    let s = common::scene_in(
        &dir,
        "[[model]]\npath = \"l.gltf\"\nlights = true\ncameras = true\ntranslate = [0.0, 1.0, 0.0]\n",
        &[],
    );
    assert_eq!(s.lights.len(), 2);
    match s.lights[0].kind {
        LightKind::Point {
            position,
            intensity,
        } => {
            // Node chain (0, 0, 4) + (1, 2, 0), then the model's translate.
            assert!(
                (position - Vec3::new(1.0, 3.0, 4.0)).length() < 1e-5,
                "{position}"
            );
            assert_eq!(intensity, 30.0);
        }
        k => panic!("{k:?}"),
    }
    assert_eq!(s.lights[0].range, Some(10.0));
    assert_eq!(s.lights[0].color, Vec3::new(1.0, 0.5, 0.25));
    match s.lights[1].kind {
        // -Z turned a quarter about -X: pointing down.
        LightKind::Directional {
            direction,
            irradiance,
            ..
        } => {
            assert!((direction - Vec3::NEG_Y).length() < 1e-5, "{direction}");
            assert_eq!(irradiance, 2.0);
        }
        k => panic!("{k:?}"),
    }
    assert_eq!(
        s.cameras.len(),
        1,
        "the imported camera replaces the default"
    );
    let c = &s.cameras[0];
    assert_eq!(c.name, "front");
    assert!(
        (c.eye - Vec3::new(0.0, 1.0, 4.0)).length() < 1e-5,
        "{}",
        c.eye
    );
    assert!((c.forward() - Vec3::NEG_Z).length() < 1e-5);
    assert_eq!(
        c.projection,
        Projection::Perspective {
            fov_y: 0.5f32.to_degrees()
        }
    );
    assert_eq!((c.near, c.far), (0.1, 50.0));
    // It renders from there: the cube fills the middle of the frame.
    let f = render_frame(&s, 0, 0);
    let w = f.width as usize;
    let mid = f.depth[(f.height as usize / 2) * w + w / 2];
    assert!((mid - 3.5).abs() < 1e-3, "{mid}");
}

#[test]
fn an_obj_model_cannot_import_lights() {
    let dir = common::scratch("gltf_obj_lights");
    std::fs::write(dir.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(&path, "[[model]]\npath = \"t.obj\"\nlights = true\n").unwrap();
    let e = Scene::load(&path, &Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("scene.toml:3:10") && e.contains("only glTF"),
        "{e}"
    );
}

#[test]
fn strips_fans_and_unindexed_primitives_with_flat_normals_and_vertex_colors() {
    // One square four ways: indexed triangles, an unindexed strip, an
    // indexed fan, and an unindexed triangle list; no NORMAL (flat normals,
    // +z here), COLOR_0 red at the bottom, blue at the top.
    let dir = common::scratch("gltf_modes");
    let corners = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    let color = |p: &[f32; 3]| {
        let t = (p[1] + 1.0) * 0.5;
        [1.0 - t, 0.0, t, 1.0]
    };
    let prim = |order: &[usize], indices: Vec<u32>| {
        let positions: Vec<[f32; 3]> = order.iter().map(|&i| corners[i]).collect();
        Prim {
            colors: positions.iter().map(color).collect(),
            positions,
            indices,
            ..Default::default()
        }
    };
    let variants = [
        ("triangles", prim(&[0, 1, 2, 3], vec![0, 1, 2, 0, 2, 3]), 4),
        ("strip", prim(&[0, 1, 3, 2], vec![]), 5),
        ("fan", prim(&[0, 1, 2, 3], vec![0, 1, 2, 3]), 6),
        ("list", prim(&[0, 1, 2, 0, 2, 3], vec![]), 4),
    ];
    let mut frames = Vec::new();
    for (name, p, mode) in variants {
        let (text, _) = gltf_text(
            &p,
            &format!(r#", "mode": {mode}"#),
            r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]"#,
            None,
        );
        std::fs::write(dir.join(format!("{name}.gltf")), text).unwrap();
        let mut out = Vec::new();
        for shading in ["unlit", "normals"] {
            let s = common::scene_in(
                &dir,
                &format!(
                    "[output]\nwidth = 32\nheight = 32\n[render]\nshading = \"{shading}\"\n[[model]]\npath = \"{name}.gltf\"\n\
                     [[camera]]\nprojection = \"orthographic\"\nheight = 2.5\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n"
                ),
                &[],
            );
            out.push(render_frame(&s, 0, 0));
        }
        frames.push((name, out));
    }
    let (_, first) = &frames[0];
    let unlit = &first[0];
    let covered = unlit.depth.iter().filter(|d| d.is_finite()).count();
    assert!(covered > 500, "{covered}");
    // Vertex colors: red at the bottom row of the square, blue at the top,
    // blended between (the default material is white, metallic, rough).
    let at = |f: &softraster::render::Frame, x: usize, y: usize| f.color[y * 32 + x].truncate();
    assert!(
        at(unlit, 16, 27).x > 0.85 && at(unlit, 16, 27).z < 0.15,
        "{}",
        at(unlit, 16, 27)
    );
    assert!(
        at(unlit, 16, 5).z > 0.85 && at(unlit, 16, 5).x < 0.15,
        "{}",
        at(unlit, 16, 5)
    );
    // Flat normals: +z everywhere, shown as (0.5, 0.5, 1).
    let n = at(&first[1], 16, 16);
    assert!(
        (n - Vec3::new(0.5, 0.5, 1.0)).abs().max_element() < 1e-5,
        "{n}"
    );
    // The same square, split along either diagonal: equal up to rounding.
    for (name, f) in &frames[1..] {
        for k in 0..2 {
            let worst = f[k]
                .color
                .iter()
                .zip(&first[k].color)
                .map(|(a, b)| (*a - *b).abs().max_element())
                .fold(0.0f32, f32::max);
            assert!(
                worst < 1e-5,
                "{name}: differs from the indexed list by {worst}"
            );
        }
    }
}

fn textured_cube_files(dir: &std::path::Path) -> Prim {
    std::fs::write(dir.join("tex.png"), quadrant_png()).unwrap();
    let p = common::cube();
    let (plain, _) = gltf_text(
        &p,
        r#", "material": 0"#,
        r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0,
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
        "textures": [{"source": 0}], "images": [{"uri": "tex.png"}]"#,
        None,
    );
    std::fs::write(dir.join("plain.gltf"), plain).unwrap();
    p
}

/// An 80x80 scene of `model` under one light, textures nearest.
fn cube_scene(model: &str) -> String {
    format!(
        "[output]\nwidth = 80\nheight = 80\n[render]\ntexture_filter = \"nearest\"\n\
         [[model]]\npath = \"{model}\"\n\
         [[light]]\nkind = \"directional\"\ndirection = [-0.4, -0.7, -0.5]\n\
         [[camera]]\neye = [1.6, 1.2, 2.0]\ntarget = [0.0, 0.0, 0.0]\n"
    )
}

/// The cube with KHR_mesh_quantization (i16 positions dequantized by the
/// node's scale, i8 normalized normals, u16 normalized texture
/// coordinates) in EXT_meshopt_compression views over a fallback buffer.
fn compressed_cube_gltf(p: &Prim, filter_normals: bool) -> String {
    use base64::Engine;
    const Q: f32 = 16384.0;
    let n = p.positions.len();
    let pos: Vec<[i16; 4]> = p
        .positions
        .iter()
        .map(|v| [(v[0] * Q) as i16, (v[1] * Q) as i16, (v[2] * Q) as i16, 0])
        .collect();
    let mut nrm: Vec<[i8; 4]> = p
        .normals
        .iter()
        .map(|v| {
            [
                (v[0] * 127.0) as i8,
                (v[1] * 127.0) as i8,
                (v[2] * 127.0) as i8,
                0,
            ]
        })
        .collect();
    if filter_normals {
        // Octahedral encoding (what gltfpack writes for normals).
        let f: Vec<[f32; 4]> = p.normals.iter().map(|v| [v[0], v[1], v[2], 0.0]).collect();
        nrm = meshopt::encoding::encode_filter_oct::<i8>(&f, 8);
    }
    let uv: Vec<[u16; 2]> = p
        .uv0
        .iter()
        .map(|t| {
            [
                (t[0] * 65535.0).round() as u16,
                (t[1] * 65535.0).round() as u16,
            ]
        })
        .collect();
    let parts = [
        meshopt::encoding::encode_vertex_buffer(&pos).unwrap(),
        meshopt::encoding::encode_vertex_buffer(&nrm).unwrap(),
        meshopt::encoding::encode_vertex_buffer(&uv).unwrap(),
        meshopt::encoding::encode_index_buffer(&p.indices, n).unwrap(),
    ];
    let sizes = [n * 8, n * 4, n * 4, p.indices.len() * 4];
    let modes = [
        ("ATTRIBUTES", 8),
        ("ATTRIBUTES", 4),
        ("ATTRIBUTES", 4),
        ("TRIANGLES", 4),
    ];
    let mut blob = Vec::new();
    let (mut views, mut fallback_at) = (Vec::new(), 0);
    for (k, part) in parts.iter().enumerate() {
        let filter = if k == 1 && filter_normals {
            r#", "filter": "OCTAHEDRAL""#
        } else {
            ""
        };
        let stride = if k < 3 {
            format!(r#", "byteStride": {}"#, modes[k].1)
        } else {
            String::new()
        };
        let count = if k < 3 { n } else { p.indices.len() };
        views.push(format!(
            r#"{{"buffer": 1, "byteOffset": {fallback_at}, "byteLength": {}{stride}, "extensions": {{"EXT_meshopt_compression": {{"buffer": 0, "byteOffset": {}, "byteLength": {}, "byteStride": {}, "count": {count}, "mode": "{}"{filter}}}}}}}"#,
            sizes[k],
            blob.len(),
            part.len(),
            modes[k].1,
            modes[k].0
        ));
        blob.extend(part);
        while blob.len() % 4 != 0 {
            blob.push(0);
        }
        fallback_at += sizes[k];
    }
    let uri = base64::engine::general_purpose::STANDARD.encode(&blob);
    let s = 1.0 / Q;
    format!(
        r#"{{"asset": {{"version": "2.0"}},
        "extensionsUsed": ["EXT_meshopt_compression", "KHR_mesh_quantization"],
        "extensionsRequired": ["EXT_meshopt_compression", "KHR_mesh_quantization"],
        "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{uri}"}},
                    {{"byteLength": {fallback_at}, "extensions": {{"EXT_meshopt_compression": {{"fallback": true}}}}}}],
        "bufferViews": [{}],
        "accessors": [
          {{"bufferView": 0, "componentType": 5122, "count": {n}, "type": "VEC3", "min": [-8192, -8192, -8192], "max": [8192, 8192, 8192]}},
          {{"bufferView": 1, "componentType": 5120, "normalized": true, "count": {n}, "type": "VEC3"}},
          {{"bufferView": 2, "componentType": 5123, "normalized": true, "count": {n}, "type": "VEC2"}},
          {{"bufferView": 3, "componentType": 5125, "count": {}, "type": "SCALAR"}}],
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}, "indices": 3, "material": 0}}]}}],
        "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}, "metallicFactor": 0}}}}],
        "textures": [{{"source": 0}}], "images": [{{"uri": "tex.png"}}],
        "nodes": [{{"mesh": 0, "scale": [{s}, {s}, {s}]}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
        blob.len(),
        views.join(", "),
        p.indices.len()
    )
}

#[test]
fn meshopt_compressed_quantized_files_render_like_plain_ones() {
    let dir = common::scratch("gltf_meshopt");
    let p = textured_cube_files(&dir);
    std::fs::write(dir.join("packed.gltf"), compressed_cube_gltf(&p, false)).unwrap();
    std::fs::write(dir.join("oct.gltf"), compressed_cube_gltf(&p, true)).unwrap();
    let plain = common::scene_in(&dir, &cube_scene("plain.gltf"), &[]);
    let a = resolve(&render_frame(&plain, 0, 0), &plain.settings);
    let covered = a.data.chunks(3).filter(|c| c != &[0, 0, 0]).count();
    assert!(covered > 1500, "the cube covers {covered} pixels");
    for (model, tolerance) in [("packed.gltf", 0), ("oct.gltf", 2)] {
        let s = common::scene_in(&dir, &cube_scene(model), &[]);
        assert!(s.warnings.is_empty(), "{model}: {:?}", s.warnings);
        let b = resolve(&render_frame(&s, 0, 0), &s.settings);
        let worst = a
            .data
            .iter()
            .zip(&b.data)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap();
        // Exact quantization gives the same pixels; octahedral normals
        // (8 bits) are within a level or two.
        assert!(worst <= tolerance, "{model}: a channel differs by {worst}");
    }
}

/// The cube as one Draco stream (positions 16 bits, normals 12, texture
/// coordinates 14), in a glTF whose accessors have no views.
fn draco_cube_gltf(p: &Prim) -> String {
    use base64::Engine;
    use draco_core::{DataType, FaceIndex, GeometryAttributeType, PointAttribute, PointIndex};
    let n = p.positions.len();
    let mut mesh = draco_core::Mesh::new();
    let mut add = |ty, comps: usize, values: Vec<f32>| {
        let mut a = PointAttribute::new();
        a.init(ty, comps as u8, DataType::Float32, false, n);
        for i in 0..n {
            let bytes: Vec<u8> = values[i * comps..(i + 1) * comps]
                .iter()
                .flat_map(|v| v.to_le_bytes())
                .collect();
            a.buffer_mut().write(i * comps * 4, &bytes);
        }
        mesh.add_attribute(a)
    };
    let pos = add(GeometryAttributeType::Position, 3, p.positions.concat());
    let nrm = add(GeometryAttributeType::Normal, 3, p.normals.concat());
    let uv = add(GeometryAttributeType::TexCoord, 2, p.uv0.concat());
    mesh.set_num_faces(p.indices.len() / 3);
    for (f, t) in p.indices.chunks_exact(3).enumerate() {
        mesh.set_face(
            FaceIndex(f as u32),
            [PointIndex(t[0]), PointIndex(t[1]), PointIndex(t[2])],
        );
    }
    let ids: Vec<u32> = [pos, nrm, uv]
        .iter()
        .map(|&a| mesh.attribute(a).unique_id())
        .collect();
    let mut options = draco_core::EncoderOptions::new();
    options.set_attribute_quantization(pos, 16);
    options.set_attribute_quantization(nrm, 12);
    options.set_attribute_quantization(uv, 14);
    let mut encoder = draco_core::MeshEncoder::new();
    encoder.set_mesh(mesh);
    let mut out = draco_core::EncoderBuffer::new();
    encoder.encode(&options, &mut out).unwrap();
    let bytes = out.data().to_vec();
    let uri = base64::engine::general_purpose::STANDARD.encode(&bytes);
    format!(
        r#"{{"asset": {{"version": "2.0"}},
        "extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],
        "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{uri}"}}],
        "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {len}}}],
        "accessors": [
          {{"componentType": 5126, "count": {n}, "type": "VEC3", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}},
          {{"componentType": 5126, "count": {n}, "type": "VEC3"}},
          {{"componentType": 5126, "count": {n}, "type": "VEC2"}},
          {{"componentType": 5125, "count": {}, "type": "SCALAR"}}],
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}, "indices": 3, "material": 0,
            "extensions": {{"KHR_draco_mesh_compression": {{"bufferView": 0, "attributes": {{"POSITION": {}, "NORMAL": {}, "TEXCOORD_0": {}}}}}}}}}]}}],
        "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}, "metallicFactor": 0}}}}],
        "textures": [{{"source": 0}}], "images": [{{"uri": "tex.png"}}],
        "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
        p.indices.len(),
        ids[0],
        ids[1],
        ids[2],
        len = bytes.len()
    )
}

#[test]
fn draco_compressed_files_render_like_plain_ones() {
    let dir = common::scratch("gltf_draco");
    let p = textured_cube_files(&dir);
    std::fs::write(dir.join("draco.gltf"), draco_cube_gltf(&p)).unwrap();
    let plain = common::scene_in(&dir, &cube_scene("plain.gltf"), &[]);
    let a = resolve(&render_frame(&plain, 0, 0), &plain.settings);
    let s = common::scene_in(&dir, &cube_scene("draco.gltf"), &[]);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.models[0].mesh.triangles.len(), 12);
    let b = resolve(&render_frame(&s, 0, 0), &s.settings);
    // 16-bit positions move edges by at most 1/65535 of the cube: a
    // handful of edge pixels may differ, the rest match within a level.
    let differing = a
        .data
        .chunks(3)
        .zip(b.data.chunks(3))
        .filter(|(x, y)| x.iter().zip(y.iter()).any(|(u, v)| u.abs_diff(*v) > 2))
        .count();
    let covered = a.data.chunks(3).filter(|c| c != &[0, 0, 0]).count();
    assert!(covered > 1500, "the cube covers {covered} pixels");
    assert!(differing <= 8, "{differing} pixels differ");
}
