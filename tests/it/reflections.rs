//! Traced reflections under the prefiltered environment
//! (`environment.reflections`): a mirror shows the surface its dominant
//! direction meets, not the environment behind it, whatever its
//! roughness; a lobe whose dominant direction misses the wall keeps the
//! environment; light bounced once (`environment.bounces = 1`) tints a
//! floor by the wall beside it; every lane width gives the same bytes.

use glam::Vec3;
use softraster::scene::Scene;

use crate::common::{self, render_frame};
use crate::widths::same_at_every_width;

/// A metal floor (white, roughness `roughness`) seen from 45 degrees
/// above, whose mirror direction meets a wall emitting (2, 0, 0) and
/// reflecting nothing, under a uniform white environment: the linear
/// colour of the floor's middle pixel, and the scene.
fn mirror_floor(name: &str, roughness: f32, reflections: &str) -> (Vec3, Scene) {
    let dir = common::scratch(name);
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\n\
         v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\n\
         v -20 -1 -3\nv 20 -1 -3\nv 20 20 -3\nv -20 20 -3\n\
         usemtl floor\nf 4 3 2 1\n\
         usemtl wall\nf 5 6 7 8\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        format!(
            "newmtl floor\nKd 1 1 1\nPm 1\nPr {roughness}\n\
             newmtl wall\nKd 0 0 0\nKs 0 0 0\nKe 2 0 0\nPm 0\nPr 1\n"
        ),
    )
    .unwrap();
    let scene = format!(
        "[output]\nwidth = 16\nheight = 16\n[render]\ntonemap = \"clamp\"\nexposure = 0.0\n\
         [environment]\npreset = \"neutral\"\nemitters = 0\n{reflections}\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [0.0, 1.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n\
         projection = \"orthographic\"\nheight = 0.05\n"
    );
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let c = render_frame(&s, 0, 0).color[8 * 16 + 8].truncate();
    (c, s)
}

#[test]
fn a_mirror_shows_the_wall_its_reflection_meets() {
    // Traced: the wall's radiance, times the white metal's specular
    // albedo at roughness 0 (about 1).
    let (on, scene) = mirror_floor("reflect_on", 0.0, "reflections = true\n");
    assert!(
        (on.x - 2.0).abs() < 0.06 && on.y < 0.02 && on.z < 0.02,
        "traced: {on}"
    );
    // Without: the uniform environment behind the wall, white.
    let (off, _) = mirror_floor("reflect_off", 0.0, "");
    assert!(
        (off - Vec3::ONE).abs().max_element() < 0.03,
        "prefiltered: {off}"
    );
    // The presets do not trace by default; `reflections = false` is the
    // same picture.
    let (no, _) = mirror_floor("reflect_no", 0.0, "reflections = false\n");
    assert_eq!(no, off);
    // A lobe of roughness 1 reads along the normal (the dominant
    // direction), which misses the wall: the environment.
    let (rough_on, _) = mirror_floor("reflect_rough_on", 1.0, "reflections = true\n");
    let (rough_off, _) = mirror_floor("reflect_rough_off", 1.0, "");
    assert_eq!(rough_on, rough_off);
    // Half way, the dominant direction still meets the wall: its red
    // replaces the environment, times the lobe's (lower) albedo.
    let (half, _) = mirror_floor("reflect_half", 0.5, "reflections = true\n");
    assert!(
        half.x > 1.0 && half.x < on.x && half.y < 0.03,
        "roughness 0.5: {half}"
    );
    same_at_every_width(&scene, &[0], "a mirror floor's traced reflection");
}

/// A white Lambertian floor beside a red Lambertian wall (the wall from
/// x = 0.5 on, facing -x), under a uniform white environment, seen from
/// straight above: the linear colour of the pixel at `x` (of 32 across
/// [-2, 2]) on the floor's middle row. `pbr`: metallic-roughness
/// materials (`Pm`, `Pr`), else Blinn-Phong ones (Kd alone).
fn floor_by_a_wall(name: &str, bounces: u32, x: usize, pbr: bool) -> (Vec3, Scene) {
    let dir = common::scratch(name);
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\n\
         v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\n\
         v 0.5 0 -4\nv 0.5 0 4\nv 0.5 8 4\nv 0.5 8 -4\n\
         usemtl floor\nf 4 3 2 1\n\
         usemtl wall\nf 5 6 7 8\n",
    )
    .unwrap();
    let mtl = if pbr {
        "newmtl floor\nKd 1 1 1\nPm 0\nPr 1\nPs 0\n\
         newmtl wall\nKd 1 0 0\nPm 0\nPr 1\n"
    } else {
        "newmtl floor\nKd 1 1 1\nKs 0 0 0\nillum 1\n\
         newmtl wall\nKd 1 0 0\nKs 0 0 0\nillum 1\n"
    };
    std::fs::write(dir.join("m.mtl"), mtl).unwrap();
    let scene = format!(
        "[output]\nwidth = 32\nheight = 32\n[render]\ntonemap = \"clamp\"\nexposure = 0.0\n\
         [environment]\npreset = \"neutral\"\nemitters = 0\nbounces = {bounces}\n\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [-1.5, 6.0, 0.0]\ntarget = [-1.5, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
         projection = \"orthographic\"\nheight = 4.0\n"
    );
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let c = render_frame(&s, 0, 0).color[16 * 32 + x].truncate();
    (c, s)
}

#[test]
fn bounced_light_tints_a_floor_by_the_wall_beside_it() {
    for pbr in [true, false] {
        let kind = if pbr { "pbr" } else { "blinn" };
        // The view spans x in [-3.5, 0.5]: pixel 31 lies against the wall,
        // pixel 0 four units from it.
        let (near0, _) = floor_by_a_wall(&format!("bounce_off_near_{kind}"), 0, 31, pbr);
        let (near1, scene) = floor_by_a_wall(&format!("bounce_on_near_{kind}"), 1, 31, pbr);
        let (far1, _) = floor_by_a_wall(&format!("bounce_on_far_{kind}"), 1, 0, pbr);
        // Without the bounce, the floor sees the whole white sky:
        // grey-white.
        assert!(
            (near0.x - near0.y).abs() < 0.01 && (near0.y - near0.z).abs() < 0.01,
            "{kind}, no bounce: {near0}"
        );
        // With it, at the foot of the wall, the wall fills half the
        // floor's cosine-weighted hemisphere: green and blue lose half the
        // sky, and the wall, lit as an open point (radiance: its red
        // albedo times the sky's 1), gives red back: (1, 0.5, 0.5).
        assert!(
            (near1 - Vec3::new(1.0, 0.5, 0.5)).abs().max_element() < 0.05,
            "{kind}, bounce, at the wall's foot: {near1}"
        );
        // Four units from the wall (8 high, 8 long, centred on the
        // pixel's row), the wall hides 19% of the floor's cosine-weighted
        // sky (integrated by 2 million rays): (1, 0.81, 0.81). Four rays
        // a pixel see it in steps of a quarter; the bounce pass's filter
        // averages the neighbours' (the pixel's own four read 0.72).
        assert!(
            (far1 - Vec3::new(1.0, 0.81, 0.81)).abs().max_element() < 0.05,
            "{kind}, bounce, far: {far1}"
        );
        // Along the wall, at one distance from it, the floor is lit
        // alike: no grain from pixel to pixel.
        let frame = render_frame(&scene, 0, 0);
        let column: Vec<f32> = (8..24).map(|y| frame.color[y * 32 + 16].y).collect();
        let (lo, hi) = column
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), &g| (lo.min(g), hi.max(g)));
        assert!(
            hi - lo < 0.05,
            "{kind}, bounce, two units from the wall: {column:?}"
        );
        same_at_every_width(&scene, &[0], "a floor's bounced light");
    }
}
