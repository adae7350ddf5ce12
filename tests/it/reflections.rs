//! Traced reflections under the prefiltered environment
//! (`environment.reflections`): a mirror shows the surface its dominant
//! direction meets, not the environment behind it, whatever its
//! roughness below `GLOSSY_FROM`; a rougher lobe shows the wall over the
//! share of the lobe it fills, and the edge of what it meets as a
//! gradient (the rough reflections' pass); light bounced once (`environment.bounces = 1`) tints a
//! floor by the wall beside it, and bounces unasked where the camera
//! looks into a box under an image's light; every lane width gives the
//! same bytes.

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
    // A rough lobe (from `GLOSSY_FROM`, 0.3) is traced over its width by
    // the rough reflections' pass: the part of it the wall fills shows
    // the wall's red, the rest the white environment. At roughness 1 the
    // lobe spreads over the hemisphere, about half of which (the half
    // behind the point) the tall, wide wall fills.
    let (rough_on, _) = mirror_floor("reflect_rough_on", 1.0, "reflections = true\n");
    let (rough_off, _) = mirror_floor("reflect_rough_off", 1.0, "");
    let kept = rough_on.y / rough_off.y;
    assert!(
        rough_on.x > rough_off.x && kept > 0.3 && kept < 0.7,
        "roughness 1: {rough_on} against {rough_off} untraced"
    );
    // Half way, the wall fills most of the lobe: mostly its red, some
    // of the environment's white, times the lobe's (lower) albedo.
    let (half, _) = mirror_floor("reflect_half", 0.5, "reflections = true\n");
    let (half_off, _) = mirror_floor("reflect_half_off", 0.5, "");
    assert!(
        half.x > 1.0 && half.x < on.x && half.y < 0.5 * half_off.y,
        "roughness 0.5: {half} against {half_off} untraced"
    );
    same_at_every_width(&scene, &[0], "a mirror floor's traced reflection");
}

/// A metal floor (white, roughness 0.5) seen in perspective, with a low
/// wall (1 high, black, emitting nothing) across it behind the point
/// looked at, under a uniform white environment: the green of the
/// middle column of 48 pixels, from the top.
fn rough_floor_by_a_low_wall(name: &str) -> (Vec<f32>, Scene) {
    let dir = common::scratch(name);
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\n\
         v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\n\
         v -4 0 -1\nv 4 0 -1\nv 4 1 -1\nv -4 1 -1\n\
         usemtl floor\nf 4 3 2 1\n\
         usemtl wall\nf 5 6 7 8\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl floor\nKd 1 1 1\nPm 1\nPr 0.5\n\
         newmtl wall\nKd 0 0 0\nKs 0 0 0\nPm 0\nPr 1\n",
    )
    .unwrap();
    let scene = "[output]\nwidth = 48\nheight = 48\n[render]\ntonemap = \"clamp\"\n\
         exposure = 0.0\n[environment]\npreset = \"neutral\"\nemitters = 0\nreflections = true\n\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [0.0, 1.2, 2.5]\ntarget = [0.0, 0.0, 0.0]\nfov = 40.0\n";
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let frame = render_frame(&s, 0, 0);
    let column = (0..48).map(|y| frame.color[y * 48 + 24].y).collect();
    (column, s)
}

#[test]
fn a_rough_floor_reflects_a_wall_s_edge_as_a_gradient() {
    // Down the floor towards the camera, the wall fills less and less of
    // the lobe of roughness 0.5: the reflection brightens from the
    // wall's black to the environment's white. One ray along the
    // dominant direction drew that as a step of one pixel (the first
    // pixel whose ray clears the wall's top); the lobe's rays, filtered,
    // spread it over many.
    let (column, scene) = rough_floor_by_a_low_wall("reflect_rough_edge");
    // The floor's rows below the wall's foot.
    let floor: Vec<f32> = column.into_iter().filter(|g| g.is_finite()).collect();
    let lo = floor.iter().copied().fold(f32::MAX, f32::min);
    let hi = floor.iter().copied().fold(f32::MIN, f32::max);
    let step = floor
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f32::max);
    assert!(hi - lo > 0.1, "the wall shows in the floor: {floor:?}");
    assert!(
        step < 0.25 * (hi - lo),
        "largest step {step} of a range {lo}..{hi}: {floor:?}"
    );
    same_at_every_width(&scene, &[0], "a rough floor's reflection pass");
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

/// A uniform white Radiance image of 16 x 8 (flat scanlines of RGBE
/// (128, 128, 128, 129): radiance 1).
fn white_sky() -> Vec<u8> {
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n".to_vec();
    hdr.extend([128u8, 128, 128, 129].repeat(16 * 8));
    hdr
}

/// A scene under a white image (`environment.bounces` as `bounces`
/// gives it, or unset), seen through the open side of a box (floor,
/// ceiling, back and two side walls, 2 units a side, the left wall red)
/// when `inside`, else from above a floor with a low red wall on one
/// side: its frame.
fn box_or_floor(name: &str, inside: bool, bounces: Option<u32>) -> Vec<glam::Vec4> {
    let dir = common::scratch(name);
    std::fs::write(dir.join("sky.hdr"), white_sky()).unwrap();
    let obj = if inside {
        "mtllib m.mtl\n\
         v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n\
         v -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\n\
         usemtl grey\nf 4 3 2 1\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\n\
         usemtl red\nf 4 1 5 8\n"
    } else {
        "mtllib m.mtl\n\
         v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv 1 1 -1\nv 1 1 1\n\
         usemtl grey\nf 4 3 2 1\nusemtl red\nf 2 3 6 5\n"
    };
    let camera = if inside {
        "eye = [0.0, 1.0, 3.5]\ntarget = [0.0, 1.0, 0.0]"
    } else {
        "eye = [0.0, 4.0, 0.5]\ntarget = [0.0, 0.0, 0.0]"
    };
    let bounces = bounces.map_or(String::new(), |b| format!("bounces = {b}\n"));
    let scene = format!(
        "[output]\nwidth = 48\nheight = 48\n[render]\ntonemap = \"clamp\"\nexposure = 0.0\n\
         [environment]\npath = \"sky.hdr\"\nemitters = 0\nlights = 0\n{bounces}\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\n{camera}\nfov = 45.0\n"
    );
    let mtl = "newmtl grey\nKd 0.8 0.8 0.8\nPm 0\nPr 1\nnewmtl red\nKd 0.8 0.1 0.1\nPm 0\nPr 1\n";
    let s = common::scene_in(&dir, &scene, &[("m.obj", obj), ("m.mtl", mtl)]);
    render_frame(&s, 0, 0).color
}

#[test]
fn an_image_s_light_bounces_where_the_camera_looks_into_a_box() {
    // Into a box, with `bounces` unset: as with the bounce, not as without.
    let auto = box_or_floor("enclosed_auto", true, None);
    let on = box_or_floor("enclosed_on", true, Some(1));
    let off = box_or_floor("enclosed_off", true, Some(0));
    assert!(
        auto == on,
        "into a box, bounces unset: not the bounce's frame"
    );
    // The bounce's own effect there: the box's floor loses the sky its
    // ceiling hides (to the grey surfaces' 0.8 and the red wall's 0.1 in
    // green), and the red wall tints the floor beside it (measured: green
    // 0.78 of the unbounced, red 0.08 above green).
    let floor_left = 40 * 48 + 12;
    let (a, o) = (auto[floor_left], off[floor_left]);
    assert!(
        a.y < 0.9 * o.y,
        "the floor by the red wall: {a} against {o} without"
    );
    assert!(a.x > a.y + 0.04, "the floor by the red wall, not red: {a}");
    // A floor in the open by a low wall: as without the bounce (with it,
    // the wall would tint the floor at its foot).
    let open = box_or_floor("open_auto", false, None);
    let open_off = box_or_floor("open_off", false, Some(0));
    assert!(
        open == open_off,
        "a floor in the open, bounces unset: not the frame without"
    );
}
