//! Skinned and morphed glTF meshes in their default pose, against
//! hand-computed vertex positions: glTF files written here, loaded, and
//! rendered (the bent bar covers the pixels its pose puts it on).

use crate::common;

use base64::Engine;
use glam::Vec3;

/// A glTF with one embedded buffer holding `parts` (each padded to 4
/// bytes); returns the buffer's base64 and each part's (offset, length).
fn buffer(parts: &[Vec<u8>]) -> (String, Vec<(usize, usize)>, usize) {
    let mut blob = Vec::new();
    let mut spans = Vec::new();
    for p in parts {
        while blob.len() % 4 != 0 {
            blob.push(0);
        }
        spans.push((blob.len(), p.len()));
        blob.extend_from_slice(p);
    }
    let len = blob.len();
    (
        base64::engine::general_purpose::STANDARD.encode(&blob),
        spans,
        len,
    )
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A bar from y = 0 to y = 2, width 0.2, three rows of two vertices; rows
/// at y = 0 and 1 follow joint 0, the row at y = 2 joint 1. Joint 1's
/// default transform bends it 90 degrees about Z at y = 1. The mesh node
/// has a far-away translation a skinned mesh must ignore.
fn bent_bar() -> String {
    let pos = f32s(&[
        -0.1, 0.0, 0.0, 0.1, 0.0, 0.0, //
        -0.1, 1.0, 0.0, 0.1, 1.0, 0.0, //
        -0.1, 2.0, 0.0, 0.1, 2.0, 0.0,
    ]);
    let idx: Vec<u8> = [0u16, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4]
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let joints: Vec<u8> = [
        0u8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0,
    ]
    .to_vec();
    let weights = f32s(&[
        1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, //
        1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, //
        1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0,
    ]);
    // Inverse bind: joint 0 at the origin, joint 1 at y = 1.
    let ibm = f32s(&[
        1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, //
        1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 1.0,
    ]);
    let (uri, s, len) = buffer(&[pos, idx, joints, weights, ibm]);
    let h = std::f32::consts::FRAC_1_SQRT_2;
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1]}}],
  "nodes": [
    {{"mesh": 0, "skin": 0, "translation": [100.0, 0.0, 0.0]}},
    {{"children": [2]}},
    {{"translation": [0.0, 1.0, 0.0], "rotation": [0.0, 0.0, {h}, {h}]}}
  ],
  "skins": [{{"joints": [1, 2], "inverseBindMatrices": 4}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "JOINTS_0": 2, "WEIGHTS_0": 3}}, "indices": 1}}]}}],
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{uri}"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3", "min": [-0.1, 0.0, 0.0], "max": [0.1, 2.0, 0.0]}},
    {{"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}},
    {{"bufferView": 2, "componentType": 5121, "count": 6, "type": "VEC4"}},
    {{"bufferView": 3, "componentType": 5126, "count": 6, "type": "VEC4"}},
    {{"bufferView": 4, "componentType": 5126, "count": 2, "type": "MAT4"}}
  ]
}}"#,
        s[0].0, s[0].1, s[1].0, s[1].1, s[2].0, s[2].1, s[3].0, s[3].1, s[4].0, s[4].1
    )
}

/// A unit quad in z = 0 with one morph target moving every vertex +1 in
/// x; default weights from the mesh, overridden by the node when given.
fn morphing_quad(node_weights: &str) -> String {
    let pos = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
    let delta = f32s(&[1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    let idx: Vec<u8> = [0u16, 1, 2, 0, 2, 3]
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let (uri, s, len) = buffer(&[pos, delta, idx]);
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0{node_weights}}}],
  "meshes": [{{"weights": [0.5], "primitives": [{{"attributes": {{"POSITION": 0}}, "targets": [{{"POSITION": 1}}], "indices": 2}}]}}],
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{uri}"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}},
    {{"buffer": 0, "byteOffset": {}, "byteLength": {}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3", "min": [1.0, 0.0, 0.0], "max": [1.0, 0.0, 0.0]}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        s[0].0, s[0].1, s[1].0, s[1].1, s[2].0, s[2].1
    )
}

#[test]
fn a_skinned_bar_takes_its_joints_default_pose() {
    let dir = common::scratch("gltf_skin");
    let path = dir.join("bar.gltf");
    std::fs::write(&path, bent_bar()).unwrap();
    let m = loaded_model(&path);
    // Without normals each triangle corner is its own vertex: compare the
    // distinct positions.
    let mut got: Vec<Vec3> = m
        .mesh
        .positions
        .iter()
        .map(|p| (*p * 1e4).round() / 1e4)
        .collect();
    got.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
    got.dedup();
    // Rows 0 and 1 stay (joint 0 is the identity, the node's translation
    // is ignored); row 2 turns 90 degrees about Z around (0, 1): (x, 2) ->
    // (-1, 1 + x).
    let mut want = vec![
        Vec3::new(-0.1, 0.0, 0.0),
        Vec3::new(0.1, 0.0, 0.0),
        Vec3::new(-0.1, 1.0, 0.0),
        Vec3::new(0.1, 1.0, 0.0),
        Vec3::new(-1.0, 0.9, 0.0),
        Vec3::new(-1.0, 1.1, 0.0),
    ];
    want.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
    for (g, w) in got.iter().zip(&want) {
        assert!((*g - *w).length() < 1e-5, "{got:?}\nwant {want:?}");
    }
    // Rendered from the front: pixels on the bent part are covered, the
    // straight-up continuation (where a pose-less mesh would be) is not.
    let text = format!(
        "[output]\nwidth = 64\nheight = 64\n[render]\nshading = \"unlit\"\ncull = \"none\"\n[[model]]\npath = \"{}\"\n[[camera]]\nprojection = \"orthographic\"\nheight = 4.0\neye = [0.0, 1.0, 5.0]\ntarget = [0.0, 1.0, 0.0]\n",
        path.display()
    );
    std::fs::write(dir.join("s.toml"), text).unwrap();
    let scene = softraster::scene::Scene::load(
        &dir.join("s.toml"),
        &softraster::scene::assemble::LoadOptions::default(),
    )
    .unwrap();
    let f = common::render_frame(&scene, 0, 0);
    // World (x, y) to pixel: 16 pixels per unit, (0, 1) at the center.
    let covered = |x: f32, y: f32| {
        let px = (32.0 + x * 16.0) as usize;
        let py = (32.0 - (y - 1.0) * 16.0) as usize;
        f.depth[py * 64 + px].is_finite()
    };
    assert!(covered(-0.5, 1.0), "the bent half is missing");
    assert!(covered(0.0, 0.5));
    assert!(!covered(0.0, 1.6), "the bar still points up");
}

#[test]
fn morph_targets_blend_with_the_default_weights() {
    let dir = common::scratch("gltf_morph");
    for (node, shift) in [("", 0.5f32), (", \"weights\": [0.25]", 0.25)] {
        let path = dir.join("quad.gltf");
        std::fs::write(&path, morphing_quad(node)).unwrap();
        let m = loaded_model(&path);
        let xs: Vec<f32> = m.mesh.positions.iter().map(|p| p.x).collect();
        let (lo, hi) = xs
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), x| {
                (a.min(*x), b.max(*x))
            });
        assert!(
            (lo - shift).abs() < 1e-6 && (hi - 1.0 - shift).abs() < 1e-6,
            "{node}: {xs:?}"
        );
    }
}

/// The one model of the model file at `path`, loaded as a one-line scene.
fn loaded_model(path: &std::path::Path) -> softraster::scene::Model {
    let scene =
        softraster::scene::Scene::load(path, &Default::default()).unwrap_or_else(|e| panic!("{e}"));
    scene.models.into_iter().next().expect("one model")
}
