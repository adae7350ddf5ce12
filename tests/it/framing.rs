//! Fitted cameras (version 2): cameras without eye and target fill the
//! frame with the models (85% of it), centred, over every frame of a
//! turntable, and see a flat scene from above.

use crate::common;

use common::{render_frame, scene_in, scratch};

/// The covered pixels' bounding box (x0, y0, x1, y1), inclusive.
fn covered(f: &softraster::render::Frame) -> (u32, u32, u32, u32) {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for y in 0..f.height {
        for x in 0..f.width {
            if f.depth[(y * f.width + x) as usize].is_finite() {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            }
        }
    }
    (x0, y0, x1, y1)
}

fn obj(b: softraster::procedural::Builder) -> String {
    b.to_obj("m", "none.mtl", "m")
        .text
        .replace("mtllib none.mtl\n", "")
        .replace("usemtl m\n", "")
}

#[test]
fn fitted_cameras_fill_the_frame_with_a_margin_over_a_turntable() {
    use softraster::procedural::{cube, sphere};
    let dir = scratch("framing");
    // A sphere, a long bar, and the bar turning on a turntable.
    let cases = [
        ("sphere", obj(sphere(1.0, 48, 24)), "", 1),
        (
            "bar",
            obj(cube([0.0; 3], 0.5)),
            "scale = [8.0, 1.0, 1.0]\n",
            1,
        ),
        (
            "bar",
            obj(cube([0.0; 3], 0.5)),
            "scale = [8.0, 1.0, 1.0]\n",
            12,
        ),
    ];
    for (name, mesh, placement, frames) in cases {
        let turntable = if frames > 1 {
            format!("[animation]\nframes = {frames}\nturntable = {{ axis = [0.0, 1.0, 0.0] }}\n")
        } else {
            String::new()
        };
        let text = format!(
            "[output]\nwidth = 160\nheight = 120\n{turntable}[[model]]\npath = \"{name}.obj\"\n{placement}"
        );
        let s = scene_in(&dir, &text, &[(&format!("{name}.obj"), &mesh)]);
        let mut widest = (0u32, 0u32);
        for frame in 0..frames {
            let f = render_frame(&s, 0, frame);
            let (x0, y0, x1, y1) = covered(&f);
            // Never touching the border: the margin holds on every frame.
            assert!(
                x0 > 0 && y0 > 0 && x1 < 159 && y1 < 119,
                "{name} frame {frame}: {x0} {y0} {x1} {y1}"
            );
            widest = (widest.0.max(x1 - x0 + 1), widest.1.max(y1 - y0 + 1));
        }
        // At least 60% of the width or height is covered (the fit's 85%
        // on the binding axis, less the perspective of a turning model).
        let fill = (widest.0 as f32 / 160.0).max(widest.1 as f32 / 120.0);
        assert!(fill >= 0.6, "{name} ({frames} frames): {fill}");
        if frames == 1 {
            // One view: 80-90% of the frame in the larger direction, and
            // room below for the contact shadow (at least 3% of the
            // height).
            let (_, _, _, y1) = covered(&render_frame(&s, 0, 0));
            let below = (119 - y1) as f32 / 120.0;
            assert!((0.8..=0.9).contains(&fill), "{name}: {fill}");
            assert!(below >= 0.03, "{name}: {below} below");
        }
    }
}

#[test]
fn a_flat_scene_is_seen_from_above() {
    use softraster::procedural::{cube, ground};
    let dir = scratch("framing_flat");
    // A 10x10 floor with a small box on it: thin along Y.
    let mut text = obj(ground(5.0, 0.0, 4.0));
    let boxes = obj(cube([1.0, 0.2, 1.0], 0.2));
    text.push('\n');
    let s = scene_in(
        &dir,
        "[output]\nwidth = 100\nheight = 100\n[[model]]\npath = \"floor.obj\"\n[[model]]\npath = \"box.obj\"\n",
        &[("floor.obj", &text), ("box.obj", &boxes)],
    );
    let cam = &s.cameras[0];
    let down = -cam.forward().y;
    // Looking along -Y tilted by the 20-degree elevation: cos 20 = 0.94.
    assert!((down - 20f32.to_radians().cos()).abs() < 1e-3, "{down}");
    let f = render_frame(&s, 0, 0);
    let (x0, y0, x1, y1) = covered(&f);
    let span = (x1 - x0 + 1).max(y1 - y0 + 1);
    assert!((80..=90).contains(&span), "{x0} {y0} {x1} {y1}");
    // Elevation and azimuth are keys of a fitted camera.
    let s = scene_in(
        &dir,
        "[output]\nwidth = 100\nheight = 100\n[[model]]\npath = \"box.obj\"\n[[camera]]\nelevation = 45.0\nazimuth = 90.0\n",
        &[("box.obj", &boxes)],
    );
    let fwd = s.cameras[0].forward();
    // From +X (azimuth 90), 45 degrees up: looking toward -X and down.
    assert!(
        (fwd.x + 45f32.to_radians().cos()).abs() < 1e-3
            && (fwd.y + 45f32.to_radians().sin()).abs() < 1e-3,
        "{fwd}"
    );
}

/// The default look on one-line scenes of varied real models (a game
/// character, a sphere, a terrain tile, a flat scene with props): the
/// models span at least 65% of the width or height, the background is not
/// black, and where a model stands on the catcher its ground shadow shows.
#[test]
fn one_line_scenes_of_varied_models_fill_the_frame_over_a_lit_background() {
    use softraster::procedural::sphere;
    let Some(assets) = common::shared_assets() else {
        return;
    };
    let dir = scratch("framing_varied");
    let tr = assets.join("tinyrenderer");
    let common_dir = assets.join("common");
    std::fs::write(dir.join("sphere.obj"), obj(sphere(1.0, 64, 32))).unwrap();
    let model = |p: &std::path::Path, extra: &str| {
        format!("[[model]]\npath = {:?}\n{extra}", p.display().to_string())
    };
    let cases = [
        (
            "character",
            model(&tr.join("diablo3_pose/diablo3_pose.obj"), ""),
            true,
        ),
        ("sphere", model(&dir.join("sphere.obj"), ""), true),
        ("terrain tile", model(&tr.join("floor.obj"), ""), false),
        (
            "flat scene with props",
            model(&tr.join("floor.obj"), "scale = 4.0\n")
                // Suzanne's mesh sits off its origin: these put both
                // props on the floor (y = -4), left and right of centre.
                + &model(
                    &common_dir.join("suzanne.obj"),
                    "translate = [0.5, -4.21, -3.3]\nscale = 0.8\n",
                )
                + &model(
                    &common_dir.join("teapot.obj"),
                    "translate = [1.7, -4.0, 1.0]\nscale = 0.5\n",
                ),
            false,
        ),
    ];
    for (name, models, shadow) in cases {
        let text = format!("[output]\nwidth = 160\nheight = 120\n{models}");
        let s = scene_in(&dir, &text, &[]);
        let f = render_frame(&s, 0, 0);
        let (x0, y0, x1, y1) = covered(&f);
        let fill = ((x1 - x0 + 1) as f32 / 160.0).max((y1 - y0 + 1) as f32 / 120.0);
        let corner = f.color[0].truncate();
        let luminance = |c: glam::Vec3| c.dot(glam::Vec3::new(0.2126, 0.7152, 0.0722));
        println!(
            "{name}: fill {fill:.2}, background corner luminance {:.3}",
            luminance(corner)
        );
        assert!(fill >= 0.65, "{name}: fill {fill}");
        assert!(luminance(corner) > 0.05, "{name}: background {corner}");
        if shadow {
            // The same scene without the catcher's shadow: pixels the
            // shadow darkens, below the model's middle.
            let plain = scene_in(&dir, &format!("{text}[ground]\nshadow = false\n"), &[]);
            let g = render_frame(&plain, 0, 0);
            let darker = f
                .color
                .iter()
                .zip(&g.color)
                .enumerate()
                .filter(|(i, (a, b))| {
                    (*i as u32 / 160) > (y0 + y1) / 2
                        && luminance(b.truncate()) - luminance(a.truncate()) > 0.02
                })
                .count();
            println!("{name}: {darker} pixels darkened by the ground shadow");
            assert!(darker > 160, "{name}: {darker} shadowed pixels");
        }
    }
}
