//! Emissive surfaces light the scene as a path tracer's do: under
//! `method = "sampled"` by points drawn on them, under the prefiltered
//! default as area lights (`environment.emitters`). The radiance of a
//! Lambertian plane under an emissive square against the closed form.

use std::f32::consts::PI;

use softraster::scene::Scene;

use crate::common::{self, render_frame};

/// Radiance leaving a Lambertian floor (albedo 0.5) at the point below
/// the centre of an emissive square (side `side`, radiance 10, facing
/// down) at height 1, seen from the side: its environment is black.
fn floor_under_lamp(name: &str, side: f32, method: &str) -> f32 {
    let more = if method == "sampled" {
        "samples = 256\n"
    } else {
        ""
    };
    floor_under_lamp_with(name, side, method, more)
}

/// `floor_under_lamp` with more `[environment]` keys.
fn floor_under_lamp_with(name: &str, side: f32, method: &str, more: &str) -> f32 {
    let dir = common::scratch(name);
    let h = side / 2.0;
    let obj = format!(
        "mtllib m.mtl\n\
         v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\n\
         v {n} 1 {n}\nv {h} 1 {n}\nv {h} 1 {h}\nv {n} 1 {h}\n\
         usemtl floor\nf 4 3 2 1\n\
         usemtl lamp\nf 5 6 7 8\n",
        n = -h
    );
    std::fs::write(dir.join("m.obj"), obj).unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl floor\nKd 0.5 0.5 0.5\nKs 0 0 0\nillum 1\n\
         newmtl lamp\nKd 0 0 0\nKs 0 0 0\nKe 10 10 10\nillum 1\n",
    )
    .unwrap();
    let scene = format!(
        "[output]\nwidth = 16\nheight = 16\n[render]\ntonemap = \"clamp\"\nexposure = 0.0\n\
         [environment]\npreset = \"neutral\"\nintensity = 0.0\nmethod = \"{method}\"\n{more}\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [3.0, 0.6, 0.0]\ntarget = [0.0, 0.0, 0.0]\n\
         projection = \"orthographic\"\nheight = 0.05\n"
    );
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let c = render_frame(&s, 0, 0).color[8 * 16 + 8];
    (c.x + c.y + c.z) / 3.0
}

/// Irradiance at a point at distance `h` below the centre of a parallel
/// square of side `side` and radiance `l`: four rectangles with a corner
/// above the point, each of form factor
/// (X atan(Y / sqrt(1 + X^2)) / sqrt(1 + X^2) + the same with X, Y
/// swapped) / (2 pi), X = Y = side / (2 h); E = pi l F.
fn square_irradiance(l: f32, side: f32, h: f32) -> f32 {
    let x = side / (2.0 * h);
    let s = (1.0 + x * x).sqrt();
    let f = 2.0 * x / s * (x / s).atan() / (2.0 * PI);
    PI * l * 4.0 * f
}

#[test]
fn a_lamp_lights_a_lambertian_floor_as_the_closed_form_says() {
    for side in [0.2f32, 1.0] {
        let expect = 0.5 / PI * square_irradiance(10.0, side, 1.0);
        let got = floor_under_lamp(&format!("emitter_floor_{side}"), side, "sampled");
        assert!(
            (got - expect).abs() < 0.02 * expect,
            "side {side}: {got} vs {expect}"
        );
    }
}

#[test]
fn under_the_prefiltered_default_a_lamp_is_an_area_light() {
    // One light at the square's centre, from a disc of its area: on the
    // axis E = l A / (h^2 + A / pi), the disc's own law, within 1% of the
    // square's at side 1 and closer for a smaller lamp.
    for side in [0.2f32, 1.0] {
        let expect = 0.5 / PI * square_irradiance(10.0, side, 1.0);
        let got = floor_under_lamp(&format!("emitter_area_{side}"), side, "prefiltered");
        assert!(
            (got - expect).abs() < 0.02 * expect,
            "side {side}: {got} vs {expect}"
        );
    }
    // `emitters = 0`: the lamp is shown and lights nothing, as the GPU
    // viewers show it.
    let dark = floor_under_lamp_with("emitter_area_off", 1.0, "prefiltered", "emitters = 0\n");
    assert!(dark < 1e-6, "{dark}");
}

/// A box under a lamp in a dim sky: the floor lit by the lamp around the
/// box's soft shadow, the box's top and sides lit, the lamp itself shown.
fn box_under_lamp(name: &str, shading: &str) -> Scene {
    let dir = common::scratch(name);
    let obj = "mtllib m.mtl\n\
         v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\n\
         v -0.3 2 -0.3\nv 0.3 2 -0.3\nv 0.3 2 0.3\nv -0.3 2 0.3\n\
         v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\n\
         v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n\
         usemtl floor\nf 4 3 2 1\n\
         usemtl lamp\nf 5 6 7 8\n\
         usemtl floor\nf 13 16 15 14\nf 9 10 14 13\nf 10 11 15 14\nf 11 12 16 15\nf 12 9 13 16\n";
    let mtl = "newmtl floor\nKd 0.6 0.5 0.4\nKs 0.2 0.2 0.2\nNs 40\nillum 2\n\
         newmtl lamp\nKd 0 0 0\nKs 0 0 0\nKe 8 8 8\nillum 1\n";
    let scene = format!(
        "[output]\nwidth = 48\nheight = 40\n[render]\nshading = \"{shading}\"\nmsaa = 4\n\
         [environment]\npreset = \"neutral\"\nintensity = 0.05\n\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [2.5, 2.2, 3.0]\ntarget = [0.0, 0.5, 0.0]\n"
    );
    common::scene_in(&dir, &scene, &[("m.obj", obj), ("m.mtl", mtl)])
}

#[test]
fn area_lights_are_the_same_at_every_lane_width() {
    for shading in ["auto", "pbr"] {
        let scene = box_under_lamp(&format!("emitter_widths_{shading}"), shading);
        assert_eq!(scene.emitters.len(), 1, "{shading}");
        crate::widths::same_at_every_width(&scene, &[0], &format!("box under a lamp, {shading}"));
    }
}

/// A glossy white metal floor (roughness 0.2) with a lamp (side 0.5,
/// radiance 10, facing down) one up and one to the side, in a black
/// environment, seen from where the floor mirrors the lamp: the floor's
/// middle pixel, with `reflections` as given.
fn lamp_in_a_glossy_floor(name: &str, reflections: bool) -> f32 {
    let dir = common::scratch(name);
    let obj = "mtllib m.mtl\n\
         v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\n\
         v -1.25 1 -0.25\nv -0.75 1 -0.25\nv -0.75 1 0.25\nv -1.25 1 0.25\n\
         usemtl floor\nf 4 3 2 1\n\
         usemtl lamp\nf 5 6 7 8\n";
    let mtl = "newmtl floor\nKd 1 1 1\nPm 1\nPr 0.2\n\
         newmtl lamp\nKd 0 0 0\nKe 10 10 10\nPm 0\nPr 1\n";
    let scene = format!(
        "[output]\nwidth = 16\nheight = 16\n[render]\ntonemap = \"clamp\"\nexposure = 0.0\n\
         [environment]\npreset = \"neutral\"\nintensity = 0.0\nreflections = {reflections}\n\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [1.0, 1.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\n\
         projection = \"orthographic\"\nheight = 0.05\n"
    );
    let s = common::scene_in(&dir, &scene, &[("m.obj", obj), ("m.mtl", mtl)]);
    assert_eq!(s.emitters.len(), 1);
    let c = render_frame(&s, 0, 0).color[8 * 16 + 8];
    (c.x + c.y + c.z) / 3.0
}

#[test]
fn a_traced_reflection_leaves_a_lamp_to_its_area_light() {
    // The area light's highlight shows the lamp in the floor. A traced
    // reflection that meets the lamp must not add its emission again
    // (it did: 18.2 against the highlight's 8.2).
    let off = lamp_in_a_glossy_floor("lamp_floor_plain", false);
    let on = lamp_in_a_glossy_floor("lamp_floor_traced", true);
    assert!(off > 1.0, "the highlight: {off}");
    assert!((on - off).abs() < 0.05 * off, "traced {on} against {off}");
}

/// A white wall (x = -3, facing +x) under an opaque plate (y = 1, over
/// x < 0), beside a floor that a lamp (side 0.5, radiance 10, at y = 2
/// over the origin) lights only beyond the plate's shadow, in a black
/// environment: the wall's pixel at height 0.3 with `method` and the
/// light bounced once.
fn wall_beside_a_shadowed_floor(name: &str, method: &str) -> f32 {
    let dir = common::scratch(name);
    let obj = "mtllib m.mtl\n\
         v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\n\
         v -0.25 2 -0.25\nv 0.25 2 -0.25\nv 0.25 2 0.25\nv -0.25 2 0.25\n\
         v -5 1 -5\nv 0 1 -5\nv 0 1 5\nv -5 1 5\n\
         v -3 0 -5\nv -3 0 5\nv -3 1 5\nv -3 1 -5\n\
         usemtl white\nf 4 3 2 1\n\
         usemtl lamp\nf 5 6 7 8\n\
         usemtl white\nf 9 10 11 12\nf 13 14 15 16\n";
    let mtl = "newmtl white\nKd 0.8 0.8 0.8\nKs 0 0 0\nillum 1\n\
         newmtl lamp\nKd 0 0 0\nKs 0 0 0\nKe 10 10 10\nillum 1\n";
    let samples = if method == "sampled" {
        "samples = 1024\n"
    } else {
        ""
    };
    let scene = format!(
        "[output]\nwidth = 16\nheight = 16\n[render]\ntonemap = \"clamp\"\nexposure = 0.0\n\
         [environment]\npreset = \"neutral\"\nintensity = 0.0\nmethod = \"{method}\"\n\
         bounces = 1\n{samples}\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [-1.0, 0.3, 0.0]\ntarget = [-3.0, 0.3, 0.0]\n\
         projection = \"orthographic\"\nheight = 0.05\n"
    );
    let s = common::scene_in(&dir, &scene, &[("m.obj", obj), ("m.mtl", mtl)]);
    let c = render_frame(&s, 0, 0).color[8 * 16 + 8];
    (c.x + c.y + c.z) / 3.0
}

#[test]
fn a_floor_in_a_lamp_s_shadow_bounces_none_of_its_light() {
    // The floor the wall faces lies in the plate's shadow: the bounce's
    // rays that meet it must find it unlit, as the path tracer's do. Lit
    // as if the lamp reached it, the wall was 12 times as bright as the
    // path tracer's (0.0116 against 0.00096; now 0.0013).
    let traced = wall_beside_a_shadowed_floor("shadowed_floor_sampled", "sampled");
    let bounced = wall_beside_a_shadowed_floor("shadowed_floor_prefiltered", "prefiltered");
    assert!(traced > 0.0, "{traced}");
    assert!(
        (bounced - traced).abs() < 0.5 * traced,
        "{bounced} against {traced}"
    );
}
