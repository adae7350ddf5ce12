//! Emissive surfaces light the scene under `method = "sampled"`, as a
//! path tracer's do: the radiance of a Lambertian plane under a small
//! emissive square against the closed form.

use std::f32::consts::PI;

use softraster::scene::Scene;

use crate::common::{self, render_frame};

/// Radiance leaving a Lambertian floor (albedo 0.5) at the point below
/// the centre of an emissive square (side `side`, radiance 10, facing
/// down) at height 1, seen from the side: its environment is black.
fn floor_under_lamp(name: &str, side: f32, method: &str) -> f32 {
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
         [environment]\npreset = \"neutral\"\nintensity = 0.0\nmethod = \"{method}\"\nsamples = 256\n\
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
    // The prefiltered default shows the lamp without lighting with it.
    let dark = floor_under_lamp("emitter_floor_prefiltered", 1.0, "prefiltered");
    assert!(dark < 1e-6, "{dark}");
}
