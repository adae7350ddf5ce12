//! The data passes (`output.normal`, `albedo`, `position`, `id`) against
//! known geometry: a sphere of radius 0.8 at the origin and an untextured
//! cube beside it, rendered through the binary and read back from the
//! EXR files.

use crate::common;

use std::path::{Path, PathBuf};

use glam::Vec3;
use softraster::output::exr::{read_channel, read_channel_u32};

fn scene(dir: &Path, extra: &str) -> PathBuf {
    let root = common::root();
    let text = format!(
        r#"
[output]
width = 120
height = 90
normal = true
albedo = true
position = true
id = true
depth = true
{extra}

[[model]]
name = "ball"
path = "{root}/assets/showcase/sphere.obj"

[[model]]
name = "box"
path = "{root}/assets/showcase/cube.obj"
translate = [1.6, 0.0, 0.0]

[[camera]]
eye = [0.6, 0.8, 4.5]
target = [0.6, 0.0, 0.0]
fov = 45.0
"#,
        root = root.display()
    );
    let p = dir.join("passes.toml");
    std::fs::write(&p, text).unwrap();
    p
}

struct Passes {
    n: Vec<Vec3>,
    albedo: Vec<Vec3>,
    p: Vec<Vec3>,
    depth: Vec<f32>,
    object: Vec<u32>,
    material: Vec<u32>,
    /// Material names by id, from `passes_ids.json`.
    material_names: std::collections::HashMap<u32, (u32, String)>,
}

fn read(out: &Path) -> Passes {
    let vec3 = |file: &str, names: [&str; 3]| -> Vec<Vec3> {
        let path = out.join(file);
        let [x, y, z] = names.map(|c| read_channel(&path, c).unwrap().2);
        (0..x.len()).map(|i| Vec3::new(x[i], y[i], z[i])).collect()
    };
    Passes {
        n: vec3("camera_0000_normal.exr", ["N.X", "N.Y", "N.Z"]),
        albedo: vec3(
            "camera_0000_albedo.exr",
            ["albedo.R", "albedo.G", "albedo.B"],
        ),
        p: vec3("camera_0000_position.exr", ["P.X", "P.Y", "P.Z"]),
        depth: read_channel(&out.join("camera_0000_depth.exr"), "Z")
            .unwrap()
            .2,
        object: read_channel_u32(&out.join("camera_0000_id.exr"), "object_id")
            .unwrap()
            .2,
        material: read_channel_u32(&out.join("camera_0000_id.exr"), "material_id")
            .unwrap()
            .2,
        material_names: {
            let text = std::fs::read_to_string(out.join("passes_ids.json")).unwrap();
            let ids: serde_json::Value = serde_json::from_str(&text).unwrap();
            ids["materials"]
                .as_array()
                .unwrap()
                .iter()
                .map(|m| {
                    (
                        m["id"].as_u64().unwrap() as u32,
                        (
                            m["object_id"].as_u64().unwrap() as u32,
                            m["name"].as_str().unwrap().to_string(),
                        ),
                    )
                })
                .collect()
        },
    }
}

fn render(scene: &Path, out: &Path, extra: &[&str]) {
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ];
    args.extend(extra);
    let (code, _, err) = crate::binary::run(&args);
    assert_eq!(code, 0, "{err}");
}

fn check(p: &Passes, label: &str) {
    let eye = Vec3::new(0.6, 0.8, 4.5);
    let forward = (Vec3::new(0.6, 0.0, 0.0) - eye).normalize();
    let (mut ball, mut cube, mut empty) = (0, 0, 0);
    for i in 0..p.n.len() {
        match p.object[i] {
            0 => {
                // Background (and the ground shadow catcher): no surface.
                empty += 1;
                assert_eq!(p.material[i], 0);
                assert_eq!(p.n[i], Vec3::ZERO, "{label}: pixel {i}");
                assert_eq!(p.albedo[i], Vec3::ZERO);
                assert!(p.depth[i].is_infinite());
            }
            obj => {
                // Unit normals, no blending across edges.
                assert!(
                    (p.n[i].length() - 1.0).abs() < 1e-3,
                    "{label}: |N| = {} at {i}",
                    p.n[i].length()
                );
                // Position lies at the depth along the view axis.
                let d = (p.p[i] - eye).dot(forward);
                assert!(
                    (d - p.depth[i]).abs() < 1e-3 * p.depth[i],
                    "{label}: position depth {d}, depth {} at {i}",
                    p.depth[i]
                );
                if obj == 1 {
                    ball += 1;
                    assert_eq!(p.material_names[&p.material[i]], (1, "sphere".to_string()));
                    // The sphere's normal is its radius direction (a
                    // tessellated sphere: within 2 degrees).
                    let radial = p.p[i].normalize();
                    assert!(
                        p.n[i].dot(radial) > 0.999,
                        "{label}: {} vs {radial}",
                        p.n[i]
                    );
                    assert!((p.p[i].length() - 0.8).abs() < 0.01);
                } else {
                    cube += 1;
                    assert_eq!(obj, 2);
                    assert_eq!(p.material_names[&p.material[i]], (2, "cube".to_string()));
                    // Untextured: the albedo is the material's Kd.
                    let kd = Vec3::new(0.2, 0.45, 0.8);
                    assert!((p.albedo[i] - kd).length() < 1e-5, "{}", p.albedo[i]);
                    // A cube's normals are its face axes.
                    let a = p.n[i].abs();
                    assert!(a.max_element() > 0.999, "{label}: cube normal {}", p.n[i]);
                }
            }
        }
    }
    println!("{label}: ball {ball}, cube {cube}, empty {empty} pixels");
    assert!(
        ball > 1000 && cube > 500 && empty > 1000,
        "{ball} {cube} {empty}"
    );
}

#[test]
fn passes_match_the_geometry_with_and_without_msaa() {
    let dir = common::scratch("aov");
    let s = scene(&dir, "");
    for (label, extra) in [
        ("1 sample", &[][..]),
        ("msaa 4", &["--set", "render.msaa=4"][..]),
        ("ssaa 2", &["--set", "render.ssaa=2"][..]),
    ] {
        let out = dir.join(label.replace(' ', "_"));
        render(&s, &out, extra);
        check(&read(&out), label);
    }
    // The ids are named.
    let ids: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("1_sample/passes_ids.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(ids["objects"][0]["name"], "ball");
    assert_eq!(ids["objects"][1]["id"], 2);
    let materials = ids["materials"].as_array().unwrap();
    assert!(
        materials
            .iter()
            .any(|m| m["name"] == "cube" && m["object_id"] == 2)
    );
}

#[test]
fn the_ground_shadow_catcher_is_not_an_object() {
    let dir = common::scratch("aov_ground");
    // No lights, no environment: the default look, with its ground shadow.
    let s = scene(&dir, "");
    let out = dir.join("out");
    render(&s, &out, &["--set", "ground.shadow=true"]);
    let p = read(&out);
    // Below the models the ground shows: id 0 there.
    let (w, h) = (120, 90);
    let bottom = (h - 2) * w + w / 2;
    assert_eq!(p.object[bottom], 0);
    assert_eq!(p.n[bottom], Vec3::ZERO);
    check(&p, "ground");
}

/// Object ids are named after the model's file (or `name`) and, in a glTF
/// file, after each node with a mesh: one id per node.
#[test]
fn object_ids_are_named_after_the_file_and_its_nodes() {
    use base64::Engine;
    let dir = common::scratch("aov_names");
    let mut bin = Vec::new();
    for v in [[-0.8f32, -0.8, 0.0], [0.8, -0.8, 0.0], [0.0, 0.8, 0.0]] {
        v.iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    let gltf = format!(
        r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"uri": "data:application/octet-stream;base64,{}", "byteLength": 36}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-0.8, -0.8, 0], "max": [0.8, 0.8, 0]}}],
  "meshes": [{{"name": "tri", "primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
  "nodes": [{{"mesh": 0, "name": "Left", "translation": [-1, 0, 0]}}, {{"mesh": 0, "translation": [1, 0, 0]}}],
  "scenes": [{{"nodes": [0, 1]}}]
}}"#,
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    std::fs::write(dir.join("pair.gltf"), gltf).unwrap();
    std::fs::write(
        dir.join("tri.obj"),
        "v -1 -1 -2\nv 1 -1 -2\nv 0 1 -2\nf 1 2 3\n",
    )
    .unwrap();
    let s = dir.join("s.toml");
    std::fs::write(
        &s,
        "[output]\nwidth = 64\nheight = 32\nid = true\n[[model]]\npath = \"pair.gltf\"\n\
         [[model]]\npath = \"tri.obj\"\n[[model]]\npath = \"tri.obj\"\ntranslate = [0.0, 0.0, -1.0]\n\
         [[camera]]\neye = [0.0, 0.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n",
    )
    .unwrap();
    let out = dir.join("out");
    render(&s, &out, &[]);
    let ids: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("s_ids.json")).unwrap()).unwrap();
    let names: Vec<(u64, &str)> = ids["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| (o["id"].as_u64().unwrap(), o["name"].as_str().unwrap()))
        .collect();
    assert_eq!(
        names,
        [(1, "pair/Left"), (2, "pair/tri"), (3, "tri"), (4, "tri_2")]
    );
    // The two nodes' triangles carry their own ids: left half 1, right 2.
    let (w, _, object) = read_channel_u32(&out.join("camera_0000_id.exr"), "object_id").unwrap();
    let w = w as usize;
    let at = |x: usize, y: usize| object[y * w + x];
    // The triangles sit about x = -1 and 1 (pixels 26 and 38 of 64).
    assert_eq!((at(26, 18), at(38, 18)), (1, 2));
}
