//! Frames are byte-identical whatever the lane width: the shading code is
//! written once over the lane type (`shade::lanes`), and the renderer
//! gathers fragments into calls of 1, 4 or 8 lanes (every width this
//! build has: 1, 4 and 8 on x86-64-v3). Each test renders scenes that
//! reach the branches
//! (maps, normal maps, vertex colours, every light kind with ranges and
//! shadows, the environment, AO, MSAA, anisotropic and trilinear
//! filtering, address modes, orthographic cameras, illum 0 and 1; pbr
//! with packed occlusion-roughness-metallic maps, emission, the KHR layers
//! with and without maps of their own; samplers, bump maps, the sampled
//! environment, every shading mode, transmissive layers, materials with
//! many slots) at each width, and compares colour and depth bit for bit
//! with one lane at a time.

use crate::common;

use common::{load_with, same_frames, scene_in, scratch, shared_assets};
use softraster::render::Renderer;
use softraster::scene::Scene;

/// The lit scenes of the glTF-cube tests: 64x64, culling off, an ambient
/// light and a point light; their `[[model]]`s follow.
pub(crate) const LIT_CUBES: &str = "[output]\nwidth = 64\nheight = 64\n[render]\ncull = \"none\"\n\
    [ambient]\ncolor = [0.1, 0.1, 0.12]\n\
    [[light]]\nkind = \"point\"\nposition = [1.0, 1.5, 2.0]\nintensity = 4.0\n";

/// Frames `frames` of camera 0 at every lane width this build has, each
/// against one lane at a time; panics at the first pixel that differs in
/// any bit.
pub(crate) fn same_at_every_width(scene: &Scene, frames: &[u32], what: &str) {
    let single = Renderer::new(scene).with_lane_width(1);
    for &width in &softraster::render::lane_widths()[1..] {
        let lanes = Renderer::new(scene).with_lane_width(width);
        same_frames(&lanes, &single, frames, &format!("{what}, {width} lanes"));
    }
}

use std::path::Path;

#[test]
fn the_showcase_is_the_same_at_every_width() {
    // Studio environment, ray-traced shadows, SSAO, MSAA 4, MTL maps.
    let scene = common::root().join("scenes/showcase.toml");
    let small = ["output.width=160", "output.height=120"];
    same_at_every_width(&load_with(&scene, &small), &[0, 5], "showcase");
    let mut sets = small.to_vec();
    sets.extend([
        "render.msaa=1",
        "render.shadows=\"pcf\"",
        "render.ao.method=\"off\"",
    ]);
    same_at_every_width(&load_with(&scene, &sets), &[3], "showcase, pcf, one sample");
}

#[test]
fn textured_character_is_the_same_at_every_width() {
    let Some(assets) = shared_assets() else {
        return;
    };
    let dir = scratch("lanes_diablo3");
    let d = assets.join("tinyrenderer/diablo3_pose");
    let scene = format!(
        r#"
[output]
width = 200
height = 200
[render]
texture_filter = "{filter}"
msaa = {msaa}
cull = "back"
[ambient]
color = [0.06, 0.06, 0.07]
[animation]
frames = 72
turntable = {{ axis = [0.0, 1.0, 0.0], degrees = 360 }}
[[model]]
path = "{d}/diablo3_pose.obj"
[model.material]
illum = 2
kd = [1.0, 1.0, 1.0]
ks = [0.5, 0.5, 0.5]
ns = 32.0
map_kd = "{d}/diablo3_pose_diffuse.tga"
map_ks = "{d}/diablo3_pose_spec.tga"
norm = "{d}/diablo3_pose_nm_tangent.tga"
[[light]]
kind = "directional"
direction = [0.5, -0.74, -0.45]
irradiance = 1
color = [0.9, 0.88, 0.85]
shadows = {shadows}
[[light]]
kind = "point"
position = [1.8, 0.9, 2.4]
intensity = 5.8
color = [1, 0.95, 0.9]
[[light]]
kind = "spot"
position = [-1.5, 2.0, 1.5]
direction = [0.5, -0.6, -0.5]
intensity = 8.0
inner_angle = 15
outer_angle = 30
shadows = {shadows}
range = 4.0
[[light]]
kind = "point"
position = [-0.6, 0.2, 1.0]
intensity = 1.5
color = [0.4, 0.6, 1.0]
range = 1.2
[[camera]]
eye = [0, 0, 3.9]
target = [0, 0, 0]
fov = 45.0
"#,
        d = d.display(),
        filter = "trilinear",
        msaa = 1,
        shadows = false,
    );
    let scene_file = dir.join("d3.toml");
    std::fs::write(&scene_file, &scene).unwrap();
    same_at_every_width(
        &load_with(&scene_file, &[]),
        &[0, 9, 40],
        "diablo3, trilinear",
    );
    same_at_every_width(
        &load_with(
            &scene_file,
            &[
                "render.texture_filter=\"anisotropic\"",
                "render.msaa=4",
                "light.0.shadows=true",
                "light.2.shadows=true",
                "render.shadows=\"pcf\"",
            ],
        ),
        &[0, 20],
        "diablo3, anisotropic, MSAA 4, shadow maps",
    );
    same_at_every_width(
        &load_with(
            &scene_file,
            &[
                "light.0.shadows=true",
                "render.shadows=\"raytraced\"",
                "render.ao.method=\"ssao\"",
                "environment.preset=\"studio\"",
                "render.address=\"clamp\"",
            ],
        ),
        &[30],
        "diablo3, environment, ray-traced shadows, SSAO, clamp",
    );
    same_at_every_width(
        &load_with(
            &scene_file,
            &[
                "camera.0.projection=\"orthographic\"",
                "camera.0.height=2.5",
                "render.texture_filter=\"bilinear\"",
            ],
        ),
        &[5],
        "diablo3, orthographic, bilinear",
    );
}

/// A quad (`quad.obj`, turned) under a point and a directional light
/// with ambient, 96x80, both faces drawn.
pub(crate) const QUAD_SCENE: &str = r#"
[output]
width = 96
height = 80
[render]
cull = "none"
[ambient]
color = [0.1, 0.1, 0.1]
[[model]]
path = "quad.obj"
rotate = [-35.0, 20.0, 0.0]
[[light]]
kind = "point"
position = [0.5, 1.0, 2.0]
intensity = 3.0
[[light]]
kind = "directional"
direction = [0.3, -0.2, -1.0]
irradiance = 0.7
"#;

/// A spot light with a ray-traced shadow, to add to `QUAD_SCENE`.
pub(crate) const SHADOWED_SPOT: &str = r#"[[light]]
kind = "spot"
position = [-0.5, 0.8, 1.6]
direction = [0.3, -0.4, -1.0]
intensity = 2.0
inner_angle = 15
outer_angle = 30
shadows = true
"#;

#[test]
fn vertex_colours_illum_and_repeat_are_the_same_at_every_width() {
    let dir = scratch("lanes_small");
    // A tiled quad (coordinates up to 3: repeat), vertex colours, and a
    // second object of each illum model.
    let obj = "mtllib m.mtl\n\
        v -1 -1 0 1 0 0\nv 1 -1 0 0 1 0\nv 1 1 0 0 0 1\nv -1 1 0 1 1 0\n\
        vt 0 0\nvt 3 0\nvt 3 3\nvt 0 3\nvn 0 0 1\n\
        usemtl tiled\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n\
        v -1 -1 -0.5\nv 1 -1 -0.5\nv 0 1.5 -0.5\n\
        usemtl plain\nf 5//1 6//1 7//1\n";
    let checker = dir.join("checker.png");
    let img = image::RgbaImage::from_fn(16, 16, |x, y| {
        if (x / 4 + y / 4) % 2 == 0 {
            image::Rgba([230, 200, 40, 255])
        } else {
            image::Rgba([20, 60, 200, 255])
        }
    });
    img.save(&checker).unwrap();
    for illum in [0, 1, 2] {
        let mtl = format!(
            "newmtl tiled\nKd 1 1 1\nKa 0.2 0.2 0.2\nKs 0.4 0.4 0.4\nNs 20\nillum {illum}\nmap_Kd checker.png\nmap_Ks checker.png\n\
             newmtl plain\nKd 0.3 0.6 0.3\nKe 0.05 0 0\nillum {illum}\n"
        );
        let scene = scene_in(&dir, QUAD_SCENE, &[("quad.obj", obj), ("m.mtl", &mtl)]);
        same_at_every_width(&scene, &[0], &format!("quad, illum {illum}"));
    }
}

#[test]
fn blended_layers_are_the_same_at_every_width() {
    // Blended surfaces are layers the lanes shade (colour and opacity):
    // a constant d, a map_d without alpha (its red channel) and a map_Kd
    // with alpha, over a textured quad, as Blinn-Phong and as pbr, with
    // one sample and with MSAA 4 (coverage-weighted layers).
    let dir = scratch("lanes_blended");
    let obj = "mtllib m.mtl\n\
        v -1 -1 -0.5\nv 1 -1 -0.5\nv 1 1 -0.5\nv -1 1 -0.5\n\
        vt 0 0\nvt 2 0\nvt 2 2\nvt 0 2\nvn 0 0 1\n\
        usemtl back\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n\
        v -0.9 -0.9 0\nv 0.2 -0.9 0\nv 0.2 0.9 0\nv -0.9 0.9 0\n\
        usemtl constant\nf 5/1/1 6/2/1 7/3/1\nf 5/1/1 7/3/1 8/4/1\n\
        v -0.3 -0.8 0.2\nv 0.9 -0.8 0.2\nv 0.9 0.4 0.2\n\
        usemtl grey_map\nf 9/1/1 10/2/1 11/3/1\n\
        v -0.2 0.1 0.3\nv 0.95 0.1 0.3\nv 0.95 0.95 0.3\n\
        usemtl alpha_map\nf 12/1/1 13/2/1 14/3/1\n";
    let checker = |name: &str, alpha: bool| {
        let img = image::RgbaImage::from_fn(16, 16, |x, y| {
            let on = (x / 4 + y / 4) % 2 == 0;
            let a = if alpha && on { 60 } else { 255 };
            if on {
                image::Rgba([230, 200, 40, a])
            } else {
                image::Rgba([20, 60, 200, a])
            }
        });
        img.save(dir.join(name)).unwrap();
    };
    checker("checker.png", false);
    checker("holes.png", true);
    let grey = image::GrayImage::from_fn(8, 8, |x, _| image::Luma([(x * 30) as u8]));
    grey.save(dir.join("grey.png")).unwrap();
    let mtl = "newmtl back\nKd 1 1 1\nKs 0.3 0.3 0.3\nNs 30\nmap_Kd checker.png\n\
        newmtl constant\nKd 0.2 0.5 0.9\nKs 0.5 0.5 0.5\nNs 60\nd 0.4\n\
        newmtl grey_map\nKd 0.9 0.3 0.2\nd 0.9\nmap_d grey.png\n\
        newmtl alpha_map\nKd 1 1 1\nmap_Kd holes.png\nd 0.8\n";
    let scene = scene_in(&dir, QUAD_SCENE, &[("quad.obj", obj), ("m.mtl", mtl)]);
    let blended =
        |m: &softraster::scene::Material| m.alpha == softraster::scene::material::AlphaMode::Blend;
    assert_eq!(
        scene.models[0]
            .materials
            .iter()
            .filter(|m| blended(m))
            .count(),
        3
    );
    for sets in [
        vec![],
        vec!["render.msaa=4"],
        vec!["render.shading=\"pbr\"", "render.msaa=4"],
        vec![
            "render.shading=\"pbr\"",
            "render.texture_filter=\"anisotropic\"",
        ],
    ] {
        let file = dir.join("scene.toml");
        same_at_every_width(
            &load_with(&file, &sets),
            &[0],
            &format!("blended, {sets:?}"),
        );
    }
}

#[test]
fn texture_transforms_and_set_1_are_the_same_at_every_width() {
    // A turned glTF cube whose maps read both coordinate sets, with and
    // without KHR_texture_transform (offset, rotation, scale): base colour
    // and normal map through one transform of set 0, metallic-roughness
    // and emission from set 1, occlusion plain; opaque and blended, under
    // lights with trilinear and anisotropic filtering, and the studio look
    // with MSAA 4.
    let dir = scratch("lanes_transforms");
    layer_texture(&dir.join("t.png"));
    let mut cube = common::cube();
    cube.uv1 = cube
        .uv0
        .iter()
        .map(|t| [t[0] * 1.7 + 0.2, t[1] * 0.6])
        .collect();
    let moved = r#""extensions": {"KHR_texture_transform": {"offset": [0.3, -0.1], "rotation": 0.4, "scale": [2.0, 1.5]}}"#;
    let material = format!(
        r#""pbrMetallicRoughness": {{"baseColorFactor": [0.9, 0.6, 0.4, 0.7], "baseColorTexture": {{"index": 0, {moved}}},
            "metallicRoughnessTexture": {{"index": 0, "texCoord": 1}}, "metallicFactor": 0.6, "roughnessFactor": 0.8}},
            "normalTexture": {{"index": 0, {moved}}}, "occlusionTexture": {{"index": 0}},
            "emissiveTexture": {{"index": 0, "texCoord": 1}}, "emissiveFactor": [0.2, 0.1, 0.0]"#
    );
    // The opaque cube first, then the one drawn in front of it.
    for (alpha, file) in [
        ("OPAQUE", "o.gltf"),
        ("OPAQUE", "c.gltf"),
        ("BLEND", "c.gltf"),
    ] {
        turned_cube(
            &dir,
            file,
            &cube,
            &format!(
                r#""images": [{{"uri": "t.png"}}], "textures": [{{"source": 0}}],
                "extensionsUsed": ["KHR_texture_transform"], "materials": [{{{material}, "alphaMode": "{alpha}"}}]"#
            ),
        );
        if file == "o.gltf" {
            continue;
        }
        let models = "[[model]]\npath = \"o.gltf\"\ntranslate = [0.4, 0.3, -1.5]\n\
            [[model]]\npath = \"c.gltf\"\n";
        let scene = scene_in(&dir, &format!("{LIT_CUBES}{models}"), &[]);
        let file = dir.join("scene.toml");
        same_at_every_width(&scene, &[0], &format!("transforms, {alpha}"));
        let aniso = ["render.texture_filter=\"anisotropic\""];
        same_at_every_width(
            &load_with(&file, &aniso),
            &[0],
            &format!("transforms, {alpha}, anisotropic"),
        );
        let studio = dir.join("studio.toml");
        std::fs::write(
            &studio,
            format!(
                "[output]\nwidth = 64\nheight = 64\n[render]\nmsaa = 4\n\
                 [environment]\npreset = \"studio\"\n{models}"
            ),
        )
        .unwrap();
        same_at_every_width(
            &load_with(&studio, &[]),
            &[0],
            &format!("transforms, {alpha}, studio"),
        );
    }
}

#[test]
fn unlit_materials_are_the_same_at_every_width() {
    // KHR_materials_unlit (the base colour and its map times the vertex
    // colours), opaque and blended, over a lit cube, in the auto and pbr
    // modes, with one sample and MSAA 4.
    let dir = scratch("lanes_unlit");
    layer_texture(&dir.join("t.png"));
    let mut cube = common::cube();
    cube.colors = (0..cube.positions.len())
        .map(|k| {
            [
                1.0 - (k % 3) as f32 * 0.3,
                0.8,
                0.5 + (k % 2) as f32 * 0.4,
                0.6,
            ]
        })
        .collect();
    for (file, extra) in [
        ("o.gltf", r#""alphaMode": "OPAQUE""#),
        (
            "c.gltf",
            r#""alphaMode": "BLEND", "extensions": {"KHR_materials_unlit": {}}"#,
        ),
        (
            "u.gltf",
            r#""alphaMode": "OPAQUE", "extensions": {"KHR_materials_unlit": {}}"#,
        ),
    ] {
        turned_cube(
            &dir,
            file,
            &cube,
            &format!(
                r#""images": [{{"uri": "t.png"}}], "textures": [{{"source": 0}}], "extensionsUsed": ["KHR_materials_unlit"],
                "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.9, 0.7, 0.5, 0.8], "baseColorTexture": {{"index": 0}}}}, {extra}}}]"#
            ),
        );
    }
    let scene = &format!(
        "{LIT_CUBES}\
        [[model]]\npath = \"o.gltf\"\ntranslate = [0.4, 0.3, -1.5]\n\
        [[model]]\npath = \"u.gltf\"\ntranslate = [-0.8, -0.5, -1.0]\nscale = 0.5\n\
        [[model]]\npath = \"c.gltf\"\n"
    );
    scene_in(&dir, scene, &[]);
    let file = dir.join("scene.toml");
    for sets in [
        vec![],
        vec!["render.msaa=4"],
        vec!["render.shading=\"pbr\"", "render.msaa=4"],
        vec!["render.shading=\"unlit\""],
        vec!["render.shading=\"flat\"", "render.msaa=4"],
        vec!["render.shading=\"normals\""],
        vec!["render.shading=\"depth\"", "render.msaa=4"],
    ] {
        same_at_every_width(&load_with(&file, &sets), &[0], &format!("unlit, {sets:?}"));
    }
}

#[test]
fn maps_without_coordinates_are_the_same_at_every_width() {
    // A glTF cube with coordinates of set 0 alone whose material reads
    // maps of set 1 too: those count as 1 (the metallic-roughness and
    // emissive maps) and leave the normal as it is (the normal map),
    // opaque and blended, with one sample and MSAA 4.
    let dir = scratch("lanes_no_uvs");
    layer_texture(&dir.join("t.png"));
    let set1 = r#"{"index": 0, "texCoord": 1}"#;
    for (file, alpha) in [("o.gltf", "OPAQUE"), ("c.gltf", "BLEND")] {
        turned_cube(
            &dir,
            file,
            &common::cube(),
            &format!(
                r#""images": [{{"uri": "t.png"}}], "textures": [{{"source": 0}}],
                "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.9, 0.6, 0.4, 0.7], "baseColorTexture": {{"index": 0}},
                    "metallicRoughnessTexture": {set1}, "metallicFactor": 0.7, "roughnessFactor": 0.3}},
                    "normalTexture": {set1}, "emissiveTexture": {set1}, "emissiveFactor": [0.3, 0.1, 0.0], "alphaMode": "{alpha}"}}]"#
            ),
        );
    }
    let scene = &format!(
        "{LIT_CUBES}\
        [[model]]\npath = \"o.gltf\"\ntranslate = [0.4, 0.3, -1.5]\n\
        [[model]]\npath = \"c.gltf\"\n"
    );
    let s = scene_in(&dir, scene, &[]);
    let (mesh, m) = (&s.models[0].mesh, &s.models[0].materials[0]);
    assert!(mesh.uvs1.is_empty() && m.pbr.metallic_roughness_map.is_some());
    let file = dir.join("scene.toml");
    for sets in [vec![], vec!["render.msaa=4"]] {
        same_at_every_width(
            &load_with(&file, &sets),
            &[0],
            &format!("set 1 missing, {sets:?}"),
        );
    }
}

#[test]
fn object_space_normal_maps_are_the_same_at_every_width() {
    // Object-space normal maps (`normal_space = "object"`) on a turned
    // quad seen from both sides (culling off), lit, as Blinn-Phong and as
    // pbr, opaque and blended, with one sample and MSAA 4.
    let dir = scratch("lanes_object_space");
    let img = image::RgbaImage::from_fn(16, 16, |x, y| {
        image::Rgba([100 + (x * 8) as u8, 110 + (y * 6) as u8, 230, 255])
    });
    img.save(dir.join("n.png")).unwrap();
    let obj = "mtllib m.mtl\n\
        v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
        usemtl bumpy\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n\
        v -0.6 -0.6 0.4\nv 0.6 -0.6 0.4\nv 0 0.8 0.4\n\
        usemtl glass\nf 5/1/1 6/2/1 7/3/1\n";
    let mtl = "newmtl bumpy\nKd 0.8 0.6 0.4\nKs 0.5 0.5 0.5\nNs 30\nnorm n.png\n\
        newmtl glass\nKd 0.3 0.5 0.9\nKs 0.5 0.5 0.5\nNs 60\nd 0.5\nnorm n.png\n";
    let object = "[model.material]\nnormal_space = \"object\"\n";
    for (turn, what) in [("20.0", "front"), ("160.0", "back")] {
        let scene = QUAD_SCENE.replace(
            "rotate = [-35.0, 20.0, 0.0]",
            &format!("rotate = [-35.0, {turn}, 0.0]"),
        );
        let s = scene_in(
            &dir,
            &format!("{scene}{object}"),
            &[("quad.obj", obj), ("m.mtl", mtl)],
        );
        let object_maps = s.models[0].materials.iter().filter(|m| {
            matches!(
                m.normal_map,
                Some(softraster::scene::material::NormalMap::Normals {
                    space: softraster::scene::material::NormalSpace::Object,
                    ..
                })
            )
        });
        assert_eq!(object_maps.count(), 2);
        let file = dir.join("scene.toml");
        for sets in [vec![], vec!["render.shading=\"pbr\"", "render.msaa=4"]] {
            same_at_every_width(
                &load_with(&file, &sets),
                &[0],
                &format!("object space, {what}, {sets:?}"),
            );
        }
    }
}

/// A 16x16 checker of 4-texel squares: red 0 or 230, green and blue
/// ramps, alpha 40 or 255.
pub(crate) fn layer_texture(path: &Path) {
    let img = image::RgbaImage::from_fn(16, 16, |x, y| {
        let on = (x / 4 + y / 4) % 2 == 0;
        image::Rgba([
            if on { 230 } else { 0 },
            (x * 16) as u8,
            (y * 16) as u8,
            if on { 255 } else { 40 },
        ])
    });
    img.save(path).unwrap();
}

/// Writes `file` in `dir`: `cube` turned, its one primitive drawn with
/// material 0, and `body` (images, textures, samplers, materials,
/// extensions) beside the node.
pub(crate) fn turned_cube(dir: &Path, file: &str, cube: &common::Prim, body: &str) {
    let (text, _) = common::gltf_text(
        cube,
        r#", "material": 0"#,
        &format!(
            r#""nodes": [{{"mesh": 0, "rotation": [0.28, 0.36, 0.1, 0.88]}}], "scenes": [{{"nodes": [0]}}], "scene": 0, {body}"#
        ),
        None,
    );
    std::fs::write(dir.join(file), text).unwrap();
}
