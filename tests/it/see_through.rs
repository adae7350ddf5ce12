//! Rays through masked and blended materials: a cut-out's holes let the
//! light through, a blended surface its share 1 - opacity, in ray-traced
//! shadows (`raytrace::Cutout`).

use softraster::scene::Scene;

use crate::common::{self, render_frame};

/// Radiance of a Lambertian floor (Kd 0.5, Blinn-Phong: Kd E n.l under a
/// sun of irradiance 1 straight down, no ambient) at x = `x`, under a
/// quad at height 1 of material `mtl` (its MTL lines, with `map_d`
/// `holes.png` beside it: transparent for x < 0, opaque for x > 0), with
/// ray-traced shadows.
fn floor_under(name: &str, mtl: &str, x: f32) -> f32 {
    let dir = common::scratch(name);
    let img = image::RgbaImage::from_fn(8, 8, |i, _| {
        let v = if i < 4 { 0 } else { 255 };
        image::Rgba([v, v, v, v])
    });
    img.save(dir.join("holes.png")).unwrap();
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\n\
         v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\n\
         v -1 1 -1\nv 1 1 -1\nv 1 1 1\nv -1 1 1\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         usemtl floor\nf 4 3 2 1\n\
         usemtl cover\nf 5/1 6/2 7/3 8/4\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        format!("newmtl floor\nKd 0.5 0.5 0.5\nKs 0 0 0\nillum 1\nnewmtl cover\nKs 0 0 0\nillum 1\n{mtl}\n"),
    )
    .unwrap();
    let scene = format!(
        "[output]\nwidth = 16\nheight = 16\n[render]\ntonemap = \"clamp\"\nshadows = \"raytraced\"\n\
         [ambient]\ncolor = [0.0, 0.0, 0.0]\n\
         [[light]]\nkind = \"directional\"\ndirection = [0.0, -1.0, 0.0]\nirradiance = 1.0\nshadows = true\n\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [{x}, 0.3, 3.0]\ntarget = [{x}, 0.0, 0.0]\n\
         projection = \"orthographic\"\nheight = 0.05\n"
    );
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let c = render_frame(&s, 0, 0).color[8 * 16 + 8];
    (c.x + c.y + c.z) / 3.0
}

#[test]
fn shadow_rays_pass_a_masks_holes_and_a_blends_share() {
    // Opaque: the floor under it is dark.
    let solid = floor_under("see_solid", "Kd 1 1 1", 0.0);
    assert!(solid < 1e-3, "opaque cover: {solid}");
    // Half transparent (d 0.5): half the light.
    let half = floor_under("see_blend", "Kd 1 1 1\nd 0.5", 0.0);
    assert!((half - 0.25).abs() < 0.01, "blended cover, d 0.5: {half}");
    // Two thirds opaque: a third of it.
    let third = floor_under("see_blend_third", "Kd 1 1 1\nd 0.6667", 0.0);
    assert!(
        (third - 0.5 / 3.0).abs() < 0.01,
        "blended cover, d 2/3: {third}"
    );
    // A binary alpha map is a mask: lit under its holes, dark under the
    // rest; away from the cover, lit.
    let mask = "Kd 1 1 1\nmap_d holes.png";
    let hole = floor_under("see_mask_hole", mask, -0.5);
    let cut = floor_under("see_mask_solid", mask, 0.5);
    assert!((hole - 0.5).abs() < 0.01, "under a hole: {hole}");
    assert!(cut < 1e-3, "under the mask's solid half: {cut}");
    let open = floor_under("see_open", mask, 3.0);
    assert!((open - 0.5).abs() < 0.01, "in the open: {open}");
}
