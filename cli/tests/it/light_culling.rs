//! Per-tile light culling (`render::light_tiles`) gives the frames of
//! shading every fragment with every light, bit for bit: colour and depth
//! of every pixel, over scenes with many lights that have a range or a
//! cone (point and spot lights with and without shadows, more than 63
//! lights, directional and unlimited ones among them), with and without
//! MSAA, Blinn-Phong and pbr.
//! Whether tiles do drop lights is the unit tests' part
//! (`light_tiles::tests`, `shade::light::tests`).

use crate::common;

use std::fmt::Write;

use common::{load_with, same_frames, scratch, shared_assets};
use softraster::render::Renderer;
use softraster::scene::Scene;

/// Frames `frames` of camera 0 with and without light culling.
fn same_both_ways(scene: &Scene, frames: &[u32], what: &str) {
    let all = Renderer::new(scene).with_light_culling(false);
    same_frames(&Renderer::new(scene), &all, frames, what);
}

/// 60 point lights with ranges in a grid over the showcase's ground, 8
/// spots from above (two casting shadows, two with a range), a
/// directional light and an unlimited point light: 70 in all.
fn many_lights() -> String {
    let mut s = String::new();
    for i in 0..60 {
        let (gx, gz) = ((i % 10) as f32, (i / 10) as f32);
        let (x, z) = (-2.7 + gx * 0.6, -1.5 + gz * 0.6);
        let y = 0.15 + 0.25 * ((i * 7) % 5) as f32;
        let range = 0.5 + 0.1 * (i % 6) as f32;
        let c = [
            (i % 3) as f32 * 0.4 + 0.2,
            ((i + 1) % 3) as f32 * 0.4 + 0.2,
            0.6,
        ];
        let shadows = i % 17 == 0;
        writeln!(
            s,
            "[[light]]\nkind = \"point\"\nposition = [{x}, {y}, {z}]\nintensity = 0.4\n\
             color = [{}, {}, {}]\nrange = {range}\nshadows = {shadows}\n",
            c[0], c[1], c[2]
        )
        .unwrap();
    }
    for k in 0..8 {
        let a = k as f32 * std::f32::consts::TAU / 8.0;
        let (x, z) = (1.4 * a.cos(), 1.4 * a.sin());
        let outer = 8 + 3 * k;
        let range = if k % 4 == 1 { "range = 3.2\n" } else { "" };
        writeln!(
            s,
            "[[light]]\nkind = \"spot\"\nposition = [{x}, 3.0, {z}]\ndirection = [{}, -1.0, {}]\n\
             intensity = 6.0\ninner_angle = {}\nouter_angle = {outer}\nshadows = {}\n{range}",
            -0.3 * a.cos(),
            -0.3 * a.sin(),
            outer / 2,
            k % 3 == 0
        )
        .unwrap();
    }
    s.push_str(
        "[[light]]\nkind = \"directional\"\ndirection = [-0.4, -1.0, -0.6]\nirradiance = 0.3\n\n\
         [[light]]\nkind = \"point\"\nposition = [0.0, 4.0, 3.0]\nintensity = 2.0\n",
    );
    s
}

#[test]
fn many_local_lights_give_the_same_frames_with_and_without_culling() {
    let dir = scratch("light_culling_showcase");
    let assets = common::root().join("assets/showcase");
    let a = assets.display().to_string().replace('\\', "/");
    let mut text = format!(
        "[output]\nwidth = 160\nheight = 120\n[render]\nmsaa = 4\nshadows = \"pcf\"\n\
         [ambient]\ncolor = [0.03, 0.03, 0.03]\n\
         [animation]\nframes = 24\nturntable = {{ axis = [0.0, 1.0, 0.0], degrees = 360 }}\n\
         [[model]]\npath = \"{a}/ground.obj\"\n\
         [[model]]\npath = \"{a}/sphere.obj\"\ntranslate = [-1.1, 0.8, 0.2]\n\
         [[model]]\npath = \"{a}/torus.obj\"\ntranslate = [1.1, 0.75, -0.2]\nrotate = [60.0, 0.0, 20.0]\n\
         [[model]]\npath = \"{a}/cube.obj\"\ntranslate = [0.1, 0.45, 1.3]\nrotate = [0.0, 30.0, 0.0]\n\
         [[camera]]\neye = [0.0, 2.2, 4.5]\ntarget = [0.0, 0.4, 0.0]\nfov = 45.0\n"
    );
    text.push_str(&many_lights());
    let path = dir.join("lights.toml");
    std::fs::write(&path, &text).unwrap();
    same_both_ways(&load_with(&path, &[]), &[0, 7], "70 lights, MSAA 4, PCF");
    same_both_ways(
        &load_with(
            &path,
            &[
                "render.msaa=1",
                "render.shading=\"pbr\"",
                "render.shadows=\"raytraced\"",
                "render.ao.method=\"ssao\"",
            ],
        ),
        &[3],
        "70 lights, pbr, one sample, ray-traced shadows, SSAO",
    );
    same_both_ways(
        &load_with(
            &path,
            &[
                "environment.preset=\"studio\"",
                "output.background=\"blurred\"",
                "ground.shadow=true",
                "camera.0.projection=\"orthographic\"",
                "camera.0.height=4.0",
            ],
        ),
        &[11],
        "70 lights, environment, ground shadow, orthographic",
    );
}

#[test]
fn a_textured_character_under_local_lights_is_the_same_with_and_without_culling() {
    // The benchmark's diablo3-lights scene (diffuse, specular and normal
    // maps: the lanes), written out by `bench --write-scene`.
    let Some(assets) = shared_assets() else {
        return;
    };
    let dir = scratch("light_culling_diablo3");
    let path = dir.join("d3.toml");
    let (code, _, err) = crate::binary::run(&[
        "bench",
        "--case",
        "diablo3-lights",
        "--assets",
        assets.to_str().unwrap(),
        "--write-scene",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.matches("range = ").count(), 24, "{text}");
    assert_eq!(text.matches("kind = \"spot\"").count(), 4, "{text}");
    let small = ["output.width=200", "output.height=200"];
    same_both_ways(
        &load_with(&path, &small),
        &[0, 20],
        "diablo3 under 29 lights",
    );
    let mut msaa = small.to_vec();
    msaa.extend(["render.msaa=4", "render.texture_filter=\"anisotropic\""]);
    same_both_ways(
        &load_with(&path, &msaa),
        &[9],
        "diablo3 under 29 lights, MSAA 4",
    );
}
