//! One bounce under `method = "sampled"` (`environment.bounces`): light
//! that a surface reflects lights the surfaces that face it, against the
//! closed form.

use softraster::scene::Scene;

use crate::common::{self, render_frame};

/// Linear radiance leaving a small Lambertian patch (Kd 0.8, at y = 0,
/// facing up) under a grey ceiling (Kd `ceiling`, at y = 1, 4000 wide) in
/// a uniform white sky (radiance 1), seen from between the two, with
/// `bounces`; `tex`: the ceiling's Kd comes from a 2x2 texture of that
/// grey instead of `Kd`.
fn patch_under_ceiling(name: &str, ceiling: f32, bounces: u32, tex: bool) -> f32 {
    let dir = common::scratch(name);
    let obj = "mtllib m.mtl\n\
         v -0.1 0 -0.1\nv 0.1 0 -0.1\nv 0.1 0 0.1\nv -0.1 0 0.1\n\
         v -2000 1 -2000\nv 2000 1 -2000\nv 2000 1 2000\nv -2000 1 2000\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         usemtl patch\nf 4 3 2 1\n\
         usemtl ceiling\nf 5/1 6/2 7/3 8/4\n";
    std::fs::write(dir.join("m.obj"), obj).unwrap();
    let kd = if tex {
        // sRGB of the linear grey, in a 2x2 PNG.
        let srgb = (softraster::color::linear_to_srgb(ceiling) * 255.0).round() as u8;
        let img = image::RgbImage::from_pixel(2, 2, image::Rgb([srgb; 3]));
        img.save(dir.join("grey.png")).unwrap();
        "Kd 1 1 1\nmap_Kd grey.png".to_string()
    } else {
        format!("Kd {ceiling} {ceiling} {ceiling}")
    };
    std::fs::write(
        dir.join("m.mtl"),
        format!(
            "newmtl patch\nKd 0.8 0.8 0.8\nKs 0 0 0\nillum 1\n\
             newmtl ceiling\n{kd}\nKs 0 0 0\nillum 1\n"
        ),
    )
    .unwrap();
    let scene = format!(
        "[output]\nwidth = 16\nheight = 16\n[render]\ntonemap = \"clamp\"\nexposure = 0.0\n\
         [environment]\npreset = \"neutral\"\nmethod = \"sampled\"\nsamples = 256\nbounces = {bounces}\n\
         [[model]]\npath = \"m.obj\"\n\
         [[camera]]\neye = [0.2, 0.5, 0.0]\ntarget = [0.0, 0.0, 0.0]\n\
         projection = \"orthographic\"\nheight = 0.05\nnear = 0.01\nfar = 10.0\n"
    );
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let f = render_frame(&s, 0, 0);
    // The mean over the middle 8x8 pixels.
    let mut sum = 0.0;
    for y in 4..12 {
        for x in 4..12 {
            let c = f.color[y * 16 + x];
            sum += (c.x + c.y + c.z) / 3.0;
        }
    }
    sum / 64.0
}

#[test]
fn a_grey_ceiling_in_a_white_sky_lights_the_floor_below_it_by_its_albedo() {
    // The ceiling's underside sees the sky below it (the patch is too
    // small to matter): its radiance is its albedo. The patch sees the
    // ceiling all over its sky (to 0.03 degrees of the horizon), so it
    // sends 0.8 x the ceiling's albedo. Without the bounce, nothing.
    for (ceiling, tex) in [(0.5, false), (0.25, false), (0.5, true)] {
        let name = format!("bounce_ceiling_{ceiling}_{tex}");
        let got = patch_under_ceiling(&name, ceiling, 1, tex);
        let expect = 0.8 * ceiling;
        assert!(
            (got - expect).abs() < 0.03 * expect,
            "ceiling {ceiling} (texture: {tex}): {got} against {expect}"
        );
    }
    let dark = patch_under_ceiling("bounce_ceiling_off", 0.5, 0, false);
    assert!(dark < 2e-3, "bounces = 0: {dark}");
}
