//! Byte-identical frames at every lane width (see `widths`), for the
//! metallic-roughness models: pbr with packed maps and emission,
//! clearcoats, the KHR layers with and without maps of their own,
//! samplers and the nearest filter, bump maps, the sampled environment,
//! every shading mode, transmissive layers and materials with many slots.

use crate::common;
use crate::widths::{
    LIT_CUBES, QUAD_SCENE, SHADOWED_SPOT, layer_texture, same_at_every_width, turned_cube,
};

use common::{load_with, scene_in, scratch, shared_assets};
use std::path::Path;

#[test]
fn pbr_models_are_the_same_at_every_width() {
    // The walker: pbr factors without maps under the default look (studio
    // environment, its ground shadow), MSAA 4.
    let walker = common::root().join("scenes/walker.toml");
    let small = ["output.width=120", "output.height=120"];
    same_at_every_width(&load_with(&walker, &small), &[0, 30], "walker");
    // The showcase's OBJ materials shaded as pbr (map_Kd as the base
    // colour, its normal maps), with lights, shadows, SSAO and ambient.
    let showcase = common::root().join("scenes/showcase.toml");
    let mut sets = small.to_vec();
    sets.extend([
        "render.shading=\"pbr\"",
        "render.msaa=1",
        "render.shadows=\"pcf\"",
        "ambient.color=[0.2, 0.15, 0.1]",
    ]);
    same_at_every_width(&load_with(&showcase, &sets), &[2], "showcase as pbr");

    let Some(assets) = shared_assets() else {
        return;
    };
    let helmet = assets.join("gltf/FlightHelmet/FlightHelmet.gltf");
    let dir = scratch("lanes_helmet");
    let scene = format!(
        r#"
[output]
width = 160
height = 160
[render]
texture_filter = "trilinear"
[ambient]
color = [0.06, 0.06, 0.07]
[animation]
frames = 72
turntable = {{ axis = [0.0, 1.0, 0.0], degrees = 360 }}
[[model]]
path = "{helmet}"
[[light]]
kind = "directional"
direction = [0.5, -0.74, -0.45]
irradiance = 1
color = [0.9, 0.88, 0.85]
[[light]]
kind = "point"
position = [0.5, 0.6, 0.7]
intensity = 0.5
[[light]]
kind = "spot"
position = [-0.5, 0.8, 0.6]
direction = [0.5, -0.6, -0.5]
intensity = 2.0
inner_angle = 15
outer_angle = 30
"#,
        helmet = helmet.display()
    );
    let file = dir.join("helmet.toml");
    std::fs::write(&file, scene).unwrap();
    same_at_every_width(
        &load_with(&file, &[]),
        &[0, 25],
        "FlightHelmet, three lights",
    );
    same_at_every_width(
        &load_with(
            &file,
            &[
                "environment.preset=\"studio\"",
                "render.ao.method=\"ssao\"",
                "light.0.shadows=true",
                "render.texture_filter=\"anisotropic\"",
                "render.msaa=4",
            ],
        ),
        &[40],
        "FlightHelmet, environment, SSAO, shadow map, anisotropic, MSAA 4",
    );
}

#[test]
fn clearcoats_are_the_same_at_every_width() {
    // The MTL PBR extension's clearcoat (Pc, Pcr: a constant layer) over
    // a quad and a triangle behind it, under every light kind (the spot
    // with a ray-traced shadow), ambient, the studio environment with and
    // without SSAO, MSAA 4; a coat of factor 0 is no coat. (Maps are left
    // out here; the coat's maps are in `khr_layers_with_maps`.)
    let dir = scratch("lanes_clearcoat");
    let obj = "mtllib m.mtl\n\
        v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
        usemtl coated\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n\
        v -1 -1 -0.5\nv 1 -1 -0.5\nv 0 1.5 -0.5\n\
        usemtl plain\nf 5//1 6//1 7//1\n";
    for (pc, pcr) in [(1.0, 0.05), (0.6, 0.4), (0.0, 0.3)] {
        let mtl = format!(
            "newmtl coated\nKd 0.8 0.1 0.1\nPr 0.6\nPm 0.2\nPc {pc}\nPcr {pcr}\n\
             newmtl plain\nKd 0.3 0.6 0.3\nKe 0.05 0 0\nPr 0.3\nPc {pc}\nPcr {pcr}\n"
        );
        scene_in(
            &dir,
            &format!("{QUAD_SCENE}{SHADOWED_SPOT}"),
            &[("quad.obj", obj), ("m.mtl", &mtl)],
        );
        let scene = load_with(&dir.join("scene.toml"), &["render.msaa=4"]);
        same_at_every_width(&scene, &[0], &format!("clearcoat {pc}, {pcr}"));
        let file = dir.join("lit.toml");
        std::fs::write(
            &file,
            "[output]\nwidth = 96\nheight = 80\n[render]\ncull = \"none\"\n\
             [[model]]\npath = \"quad.obj\"\nrotate = [-35.0, 20.0, 0.0]\n\
             [environment]\npreset = \"studio\"\n",
        )
        .unwrap();
        for sets in [vec![], vec!["render.ao={method=\"ssao\"}", "render.msaa=4"]] {
            same_at_every_width(
                &load_with(&file, &sets),
                &[0],
                &format!("clearcoat {pc}, {pcr}, studio {sets:?}"),
            );
        }
    }
}

#[test]
fn khr_layers_are_the_same_at_every_width() {
    // A turned glTF cube whose material has constant KHR layers (specular,
    // clearcoat, sheen, iridescence: each alone and all together), under
    // a point and a directional light, ambient, and the studio
    // environment with SSAO and MSAA 4.
    let dir = scratch("lanes_khr_layers");
    let base = r#""pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.1, 0.1, 1.0], "metallicFactor": 0.3, "roughnessFactor": 0.45}"#;
    let layers = [
        (
            "specular",
            r#""KHR_materials_specular": {"specularFactor": 0.7, "specularColorFactor": [1.0, 0.8, 0.6]}"#,
        ),
        (
            "clearcoat",
            r#""KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.15}"#,
        ),
        (
            "sheen",
            r#""KHR_materials_sheen": {"sheenColorFactor": [0.6, 0.6, 0.9], "sheenRoughnessFactor": 0.4}"#,
        ),
        (
            "iridescence",
            r#""KHR_materials_iridescence": {"iridescenceFactor": 0.9, "iridescenceIor": 1.35, "iridescenceThicknessMaximum": 380}"#,
        ),
    ];
    let all = layers.map(|(_, l)| l).join(", ");
    let mut cases: Vec<(&str, String)> = layers.iter().map(|(n, l)| (*n, l.to_string())).collect();
    cases.push(("all", all));
    let used = r#""KHR_materials_specular", "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_iridescence""#;
    for (name, ext) in cases {
        turned_cube(
            &dir,
            "c.gltf",
            &common::cube(),
            &format!(
                r#""extensionsUsed": [{used}], "materials": [{{{base}, "extensions": {{{ext}}}}}]"#
            ),
        );
        let scene = scene_in(
            &dir,
            r#"
[output]
width = 64
height = 64
[ambient]
color = [0.1, 0.1, 0.12]
[[model]]
path = "c.gltf"
[[light]]
kind = "point"
position = [1.0, 1.5, 2.0]
intensity = 4.0
[[light]]
kind = "directional"
direction = [-0.3, -0.5, -1.0]
irradiance = 0.8
"#,
            &[],
        );
        same_at_every_width(&scene, &[0], &format!("cube, {name}"));
        let file = dir.join("studio.toml");
        std::fs::write(
            &file,
            "[output]\nwidth = 64\nheight = 64\n[render]\nmsaa = 4\nao = { method = \"ssao\" }\n\
             [[model]]\npath = \"c.gltf\"\n[environment]\npreset = \"studio\"\n",
        )
        .unwrap();
        same_at_every_width(
            &load_with(&file, &[]),
            &[0],
            &format!("cube, {name}, studio"),
        );
    }
}

#[test]
fn khr_layers_with_maps_are_the_same_at_every_width() {
    // The KHR layers with maps of their own (a clearcoat whose factor map
    // is 0 on half its texels, its roughness and normal maps; sheen colour
    // and roughness from alpha; specular weight from alpha and colour;
    // iridescence factor and thickness), each alone and all
    // together, on a textured cube under lights and the studio look.
    let dir = scratch("lanes_khr_maps");
    layer_texture(&dir.join("t.png"));
    let t = r#"{"index": 0}"#;
    let layers = [
        (
            "clearcoat",
            format!(
                r#""KHR_materials_clearcoat": {{"clearcoatFactor": 1.0, "clearcoatTexture": {t}, "clearcoatRoughnessFactor": 0.6, "clearcoatRoughnessTexture": {t}, "clearcoatNormalTexture": {t}}}"#
            ),
        ),
        (
            "sheen",
            format!(
                r#""KHR_materials_sheen": {{"sheenColorFactor": [0.8, 0.8, 1.0], "sheenColorTexture": {t}, "sheenRoughnessFactor": 0.7, "sheenRoughnessTexture": {t}}}"#
            ),
        ),
        (
            "specular",
            format!(
                r#""KHR_materials_specular": {{"specularFactor": 0.9, "specularTexture": {t}, "specularColorTexture": {t}}}"#
            ),
        ),
        (
            "iridescence",
            format!(
                r#""KHR_materials_iridescence": {{"iridescenceFactor": 1.0, "iridescenceTexture": {t}, "iridescenceThicknessTexture": {t}, "iridescenceThicknessMinimum": 100, "iridescenceThicknessMaximum": 500}}"#
            ),
        ),
    ];
    let all = layers
        .iter()
        .map(|(_, l)| l.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let mut cases: Vec<(&str, String)> = layers.iter().map(|(n, l)| (*n, l.clone())).collect();
    cases.push(("all", all));
    let used = r#""KHR_materials_specular", "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_iridescence""#;
    let base = r#""pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.3, 0.2, 1.0], "baseColorTexture": {"index": 0}, "metallicFactor": 0.2, "roughnessFactor": 0.5}"#;
    for (name, ext) in cases {
        turned_cube(
            &dir,
            "c.gltf",
            &common::cube(),
            &format!(
                r#""images": [{{"uri": "t.png"}}], "textures": [{{"source": 0}}],
                "extensionsUsed": [{used}], "materials": [{{{base}, "extensions": {{{ext}}}}}]"#
            ),
        );
        let lit = dir.join("lit.toml");
        std::fs::write(
            &lit,
            "[output]\nwidth = 64\nheight = 64\n[ambient]\ncolor = [0.1, 0.1, 0.12]\n\
             [[model]]\npath = \"c.gltf\"\n\
             [[light]]\nkind = \"point\"\nposition = [1.0, 1.5, 2.0]\nintensity = 4.0\n",
        )
        .unwrap();
        same_at_every_width(&load_with(&lit, &[]), &[0], &format!("maps, {name}"));
        let studio = dir.join("studio.toml");
        std::fs::write(
            &studio,
            "[output]\nwidth = 64\nheight = 64\n[render]\nmsaa = 4\n[[model]]\npath = \"c.gltf\"\n",
        )
        .unwrap();
        same_at_every_width(
            &load_with(&studio, &[]),
            &[0],
            &format!("maps, {name}, studio"),
        );
    }
}

/// The scene `file` under each texture filter with one sample and MSAA
/// 4, at every width (`same_at_every_width`).
fn every_filter_and_msaa(file: &Path, what: &str) {
    for filter in ["anisotropic", "trilinear", "bilinear", "nearest"] {
        for msaa in [1, 4] {
            let sets = [
                format!("render.texture_filter=\"{filter}\""),
                format!("render.msaa={msaa}"),
            ];
            let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
            same_at_every_width(&load_with(file, &sets), &[0], &format!("{what}, {sets:?}"));
        }
    }
}

#[test]
fn samplers_and_the_nearest_filter_are_the_same_at_every_width() {
    // glTF samplers with filters of their own: NEAREST magnification,
    // NEAREST and LINEAR minification without mip maps, on maps of one
    // material (base colour and occlusion, metallic-roughness, emission,
    // normal map); cubes magnified, near a texel a pixel and minified,
    // opaque and blended, with the scene's filters anisotropic,
    // trilinear, bilinear and nearest, and MSAA 4.
    let dir = scratch("lanes_samplers");
    layer_texture(&dir.join("t.png"));
    for (file, alpha) in [("o.gltf", "OPAQUE"), ("c.gltf", "BLEND")] {
        turned_cube(
            &dir,
            file,
            &common::cube(),
            &format!(
                r#""images": [{{"uri": "t.png"}}],
                "samplers": [{{"magFilter": 9728}}, {{"magFilter": 9729, "minFilter": 9728}}, {{"magFilter": 9728, "minFilter": 9729}}],
                "textures": [{{"source": 0, "sampler": 0}}, {{"source": 0, "sampler": 1}}, {{"source": 0, "sampler": 2}}],
                "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.9, 0.6, 0.4, 0.7], "baseColorTexture": {{"index": 0}},
                    "metallicRoughnessTexture": {{"index": 1}}, "metallicFactor": 0.6, "roughnessFactor": 0.8}},
                    "normalTexture": {{"index": 0}}, "occlusionTexture": {{"index": 0}},
                    "emissiveTexture": {{"index": 2}}, "emissiveFactor": [0.2, 0.1, 0.0], "alphaMode": "{alpha}"}}]"#
            ),
        );
    }
    let scene = &format!(
        "{LIT_CUBES}\
        [[model]]\npath = \"o.gltf\"\ntranslate = [0.4, 0.3, -1.5]\n\
        [[model]]\npath = \"o.gltf\"\ntranslate = [-1.5, -0.8, -9.0]\n\
        [[model]]\npath = \"o.gltf\"\ntranslate = [-0.9, 0.5, 0.5]\nscale = 1.6\n\
        [[model]]\npath = \"c.gltf\"\n"
    );
    let s = scene_in(&dir, scene, &[]);
    let base = s.models[0].materials[0].pbr.base_color_map.as_ref();
    assert!(base.is_some_and(|t| t.mag_nearest && t.min_limit.is_none()));
    every_filter_and_msaa(&dir.join("scene.toml"), "samplers");
    // The sampled environment reads the normal map at four points of
    // each pixel (`Fetch::normal_samples`).
    let sampled = [
        "environment.preset=\"studio\"",
        "environment.method=\"sampled\"",
        "environment.samples=4",
        "render.msaa=4",
    ];
    let scene = load_with(&dir.join("scene.toml"), &sampled);
    same_at_every_width(&scene, &[0], "samplers, sampled");
}

#[test]
fn bump_maps_are_the_same_at_every_width() {
    // MTL bump (height) maps, scaled by -bm, one plain and one moved by
    // -s and -o on a blended triangle, on a turned quad seen from both
    // sides (culling off), as Blinn-Phong and as pbr, with one sample
    // and MSAA 4, anisotropic, trilinear and bilinear filtering.
    let dir = scratch("lanes_bump");
    let img = image::GrayImage::from_fn(32, 32, |x, y| {
        let (x, y) = (x as f32 / 32.0, y as f32 / 32.0);
        let h = 0.5 + 0.25 * (x * 13.0).sin() + 0.2 * (y * 9.0 + x * 4.0).cos();
        image::Luma([(h * 255.0) as u8])
    });
    img.save(dir.join("h.png")).unwrap();
    let obj = "mtllib m.mtl\n\
        v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
        usemtl bumpy\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n\
        v -0.6 -0.6 0.4\nv 0.6 -0.6 0.4\nv 0 0.8 0.4\n\
        usemtl glass\nf 5/1/1 6/2/1 7/3/1\n";
    let mtl = "newmtl bumpy\nKd 0.8 0.6 0.4\nKs 0.5 0.5 0.5\nNs 30\nbump -bm 0.8 h.png\n\
        newmtl glass\nKd 0.3 0.5 0.9\nKs 0.5 0.5 0.5\nNs 60\nd 0.5\n\
        bump -s 2 1.5 1 -o 0.1 0.2 0 h.png\n";
    for (turn, what) in [("20.0", "front"), ("160.0", "back")] {
        let scene = QUAD_SCENE.replace(
            "rotate = [-35.0, 20.0, 0.0]",
            &format!("rotate = [-35.0, {turn}, 0.0]"),
        );
        let s = scene_in(&dir, &scene, &[("quad.obj", obj), ("m.mtl", mtl)]);
        let bumps = s.models[0].materials.iter().filter(|m| {
            matches!(
                m.normal_map,
                Some(softraster::scene::material::NormalMap::Height { .. })
            )
        });
        assert_eq!(bumps.count(), 2);
        let file = dir.join("scene.toml");
        for sets in [
            vec![],
            vec!["render.shading=\"pbr\"", "render.msaa=4"],
            vec!["render.texture_filter=\"trilinear\""],
            vec!["render.texture_filter=\"bilinear\"", "render.msaa=4"],
            vec!["render.shading=\"normals\""],
            vec!["render.shading=\"flat\""],
        ] {
            same_at_every_width(
                &load_with(&file, &sets),
                &[0],
                &format!("bump, {what}, {sets:?}"),
            );
        }
    }
}

#[test]
fn the_sampled_environment_is_the_same_at_every_width() {
    // `method = "sampled"` (the Monte Carlo reference) on the showcase's
    // MTL materials (Blinn-Phong lobes) and the walker's pbr factors,
    // with MSAA 4 and one sample.
    let scenes = common::root().join("scenes");
    let sampled = [
        "output.width=96",
        "output.height=72",
        "environment.method=\"sampled\"",
        "environment.samples=4",
    ];
    for (file, frame) in [("showcase.toml", 4), ("walker.toml", 10)] {
        let scene = load_with(&scenes.join(file), &sampled);
        let env = scene.environment.as_ref().map(|e| e.method);
        let reference = softraster::scene::environment::EnvMethod::Sampled {
            samples: 4,
            bounces: 1,
        };
        assert_eq!(env, Some(reference));
        same_at_every_width(&scene, &[frame], &format!("{file} sampled"));
        let mut one = sampled.to_vec();
        one.push("render.msaa=1");
        same_at_every_width(
            &load_with(&scenes.join(file), &one),
            &[frame],
            &format!("{file} sampled, one sample"),
        );
    }
}

#[test]
fn shading_modes_are_the_same_at_every_width() {
    // The modes besides auto on the showcase's MTL materials (maps,
    // normal maps, lights, shadows, SSAO, the studio look) and the
    // walker's pbr factors: flat, unlit, the normals and depth views,
    // Blinn-Phong, Gouraud and wireframe, with MSAA 4 and one sample.
    let scenes = common::root().join("scenes");
    for mode in [
        "flat",
        "unlit",
        "normals",
        "depth",
        "blinn-phong",
        "gouraud",
        "wireframe",
    ] {
        for (file, frame) in [("showcase.toml", 6), ("walker.toml", 20)] {
            for msaa in [1, 4] {
                let sets = [
                    "output.width=96".to_string(),
                    "output.height=72".to_string(),
                    format!("render.shading=\"{mode}\""),
                    format!("render.msaa={msaa}"),
                ];
                let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
                same_at_every_width(
                    &load_with(&scenes.join(file), &sets),
                    &[frame],
                    &format!("{file}, {mode}, MSAA {msaa}"),
                );
            }
        }
    }
}

#[test]
fn transmissive_layers_are_the_same_at_every_width() {
    // KHR_materials_transmission (a factor and a map, with a clearcoat,
    // a normal map and vertex colours) on a cube in front of an opaque
    // one: its layers let the colour behind through, tinted; lit and
    // under the studio look, with one sample and MSAA 4 (over a
    // transparent background: the opacity counts), and as the
    // Blinn-Phong mode sees it (blended by its opacity).
    let dir = scratch("lanes_transmission");
    layer_texture(&dir.join("t.png"));
    let mut cube = common::cube();
    cube.colors = (0..cube.positions.len())
        .map(|k| [1.0, 0.8 + (k % 2) as f32 * 0.2, 0.7, 0.9])
        .collect();
    let images = r#""images": [{"uri": "t.png"}], "textures": [{"source": 0}]"#;
    turned_cube(
        &dir,
        "o.gltf",
        &common::cube(),
        &format!(
            r#"{images}, "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}}}]"#
        ),
    );
    turned_cube(
        &dir,
        "c.gltf",
        &cube,
        &format!(
            r#"{images}, "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_clearcoat"],
            "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.6, 0.9, 0.7, 1.0], "metallicFactor": 0.1, "roughnessFactor": 0.3}},
                "normalTexture": {{"index": 0}},
                "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 0.8, "transmissionTexture": {{"index": 0}}}},
                    "KHR_materials_clearcoat": {{"clearcoatFactor": 0.5}}}}}}]"#
        ),
    );
    let models = "[[model]]\npath = \"o.gltf\"\ntranslate = [0.4, 0.3, -1.5]\n\
        [[model]]\npath = \"c.gltf\"\n";
    let s = scene_in(&dir, &format!("{LIT_CUBES}{models}"), &[]);
    assert!(s.models[1].materials[0].pbr.transmission.is_some());
    let file = dir.join("scene.toml");
    let studio = dir.join("studio.toml");
    std::fs::write(
        &studio,
        format!("[output]\nwidth = 64\nheight = 64\n[environment]\npreset = \"studio\"\n{models}"),
    )
    .unwrap();
    for (scene, sets) in [
        (&file, vec![]),
        (
            &file,
            vec!["render.msaa=4", "output.background=\"transparent\""],
        ),
        (&file, vec!["render.shading=\"blinn-phong\""]),
        (&studio, vec!["render.msaa=4"]),
    ] {
        same_at_every_width(
            &load_with(scene, &sets),
            &[0],
            &format!("transmission, {scene:?}, {sets:?}"),
        );
    }
}

#[test]
fn materials_with_many_slots_are_the_same_at_every_width() {
    // A material whose maps fall in five slots (two texture sizes, two
    // transforms, both coordinate sets): past the three footprints a
    // fragment carries, the others are computed per lane call. Opaque
    // and blended, under trilinear, anisotropic, bilinear and nearest
    // filtering, with one sample and MSAA 4 (fragments along the edges
    // and whole quads).
    let dir = scratch("lanes_many_slots");
    layer_texture(&dir.join("t.png"));
    image::RgbaImage::from_fn(8, 8, |x, y| {
        image::Rgba([(x * 30) as u8, 90, (y * 30) as u8, 255])
    })
    .save(dir.join("s.png"))
    .unwrap();
    let mut cube = common::cube();
    cube.uv1 = cube
        .uv0
        .iter()
        .map(|t| [t[1] * 1.3, t[0] * 0.7 + 0.1])
        .collect();
    let a = r#", "extensions": {"KHR_texture_transform": {"offset": [0.3, -0.1], "rotation": 0.4, "scale": [2.0, 1.5]}}"#;
    let b = r#", "extensions": {"KHR_texture_transform": {"offset": [-0.2, 0.5], "scale": [0.5, 3.0]}}"#;
    for alpha in ["OPAQUE", "BLEND"] {
        let material = format!(
            r#""pbrMetallicRoughness": {{"baseColorFactor": [0.9, 0.7, 0.5, 0.6], "baseColorTexture": {{"index": 0{a}}},
                "metallicRoughnessTexture": {{"index": 1}}, "metallicFactor": 0.7, "roughnessFactor": 0.6}},
                "normalTexture": {{"index": 0{b}}}, "occlusionTexture": {{"index": 0}},
                "emissiveTexture": {{"index": 1, "texCoord": 1}}, "emissiveFactor": [0.3, 0.2, 0.1],
                "alphaMode": "{alpha}""#
        );
        turned_cube(
            &dir,
            "c.gltf",
            &cube,
            &format!(
                r#""images": [{{"uri": "t.png"}}, {{"uri": "s.png"}}], "textures": [{{"source": 0}}, {{"source": 1}}],
                "extensionsUsed": ["KHR_texture_transform"], "materials": [{{{material}}}]"#
            ),
        );
        if alpha == "OPAQUE" {
            // Behind the blended cube, the opaque one.
            std::fs::copy(dir.join("c.gltf"), dir.join("o.gltf")).unwrap();
        }
        let models = "[[model]]\npath = \"o.gltf\"\ntranslate = [0.4, 0.3, -1.5]\n\
            [[model]]\npath = \"c.gltf\"\n";
        scene_in(&dir, &format!("{LIT_CUBES}{models}"), &[]);
        every_filter_and_msaa(&dir.join("scene.toml"), &format!("five slots, {alpha}"));
    }
}

#[test]
fn lights_from_the_image_are_the_same_at_every_width() {
    // An image with a lamp (radiance 40, 10 degrees across, 45 degrees up)
    // gives a light with a disc: soft ray-traced shadows, widened pbr
    // lobes, Blinn-Phong lit as the image lit it, the blurred background
    // with the lamp added back.
    let dir = scratch("widths_env_lights");
    let lamp = glam::Vec3::new(1.0, 1.0, 0.0).normalize();
    exr::prelude::write_rgb_file(dir.join("env.exr"), 256, 128, |x, y| {
        let theta = (y as f32 + 0.5) / 128.0 * std::f32::consts::PI;
        let phi = ((x as f32 + 0.5) / 256.0 - 0.5) * std::f32::consts::TAU;
        let d = glam::Vec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        );
        let c = if d.dot(lamp) >= 5f32.to_radians().cos() {
            40.2
        } else {
            0.2
        };
        (c, c, c)
    })
    .unwrap();
    let env = format!(
        "environment.path={:?}",
        dir.join("env.exr").display().to_string()
    );
    let scenes = common::root().join("scenes");
    let walker = load_with(
        &scenes.join("walker.toml"),
        &["output.width=96", "output.height=72", &env],
    );
    assert_eq!(walker.lights.len(), 1, "the lamp is a light");
    same_at_every_width(&walker, &[10], "walker, lights from the image");
    let obj = softraster::procedural::sphere(1.0, 48, 24).to_obj("ball", "m.mtl", "m");
    let floor = "mtllib m.mtl\nusemtl m\nv -4 -1 -4\nv 4 -1 -4\nv 4 -1 4\nv -4 -1 4\nf 4 3 2 1\n";
    for background in ["\"environment\"", "\"blurred\""] {
        let text = format!(
            "[output]\nwidth = 64\nheight = 48\nbackground = {background}\n\
             [environment]\npath = \"env.exr\"\n\
             [[model]]\npath = \"ball.obj\"\n[[model]]\npath = \"floor.obj\"\n\
             [[camera]]\neye = [-1.0, 2.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 60.0\n"
        );
        let scene = scene_in(
            &dir,
            &text,
            &[
                ("ball.obj", obj.text.as_str()),
                ("floor.obj", floor),
                (
                    "m.mtl",
                    "newmtl m\nKd 0.6 0.5 0.4\nKs 0.5 0.5 0.5\nNs 200\nillum 2\n",
                ),
            ],
        );
        same_at_every_width(&scene, &[0], &format!("Blinn-Phong, {background}"));
    }
}
