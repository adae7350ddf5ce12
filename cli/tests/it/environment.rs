//! Image-based lighting against known answers: a Lambertian sphere under a
//! uniform environment of radiance L is kd L; under a half-white sky it is
//! kd (1 + n_y) / 2 per pixel; the image's middle lies toward -Z and the
//! rotation turns it counter-clockwise seen from above; a white furnace
//! never gains energy; bad environments are refused by name.

use crate::common;

use std::path::Path;

use common::{render_frame, scene_in, scratch};
use glam::Vec3;

/// Writes an equirectangular EXR of `w` x `w/2` texels.
fn write_env(path: &Path, w: usize, f: impl Fn(usize, usize) -> [f32; 3] + Sync) {
    exr::prelude::write_rgb_file(path, w, w / 2, |x, y| {
        let c = f(x, y);
        (c[0], c[1], c[2])
    })
    .unwrap();
}

const MTL: &str = "newmtl m\nKd 0.6 0.6 0.6\nKs 0 0 0\nillum 1\n";

/// A unit sphere seen from `eye` by an orthographic camera 2.4 units high,
/// 64x64, lit by `env.exr` with the extra `[environment]` keys.
fn sphere_scene(dir: &Path, eye: [f32; 3], env_keys: &str, extra: &str) -> String {
    format!(
        "[output]\nwidth = 64\nheight = 64\n[render]\nshading = \"blinn-phong\"\n{extra}\n\
         [environment]\npath = \"env.exr\"\n{env_keys}\n\
         [[model]]\npath = \"sphere.obj\"\n\
         [[camera]]\neye = {eye:?}\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 2.4\n"
    )
    .replace("\n\n", "\n")
        + &format!("# {}\n", dir.display())
}

fn files() -> Vec<(&'static str, String)> {
    let obj = softraster::procedural::sphere(1.0, 96, 48).to_obj("sphere", "m.mtl", "m");
    vec![("sphere.obj", obj.text), ("m.mtl", MTL.to_string())]
}

fn load(dir: &Path, text: &str) -> softraster::scene::Scene {
    let f = files();
    let refs: Vec<(&str, &str)> = f.iter().map(|(n, t)| (*n, t.as_str())).collect();
    scene_in(dir, text, &refs)
}

/// The world-space normal of the unit sphere at pixel (px, py) seen from
/// +Z (None off the sphere, or too near its outline to compare).
fn normal_from_front(px: u32, py: u32) -> Option<Vec3> {
    let x = ((px as f32 + 0.5) / 64.0 * 2.0 - 1.0) * 1.2;
    let y = (1.0 - (py as f32 + 0.5) / 64.0 * 2.0) * 1.2;
    let r2 = x * x + y * y;
    (r2 < 0.85).then(|| Vec3::new(x, y, (1.0 - r2).sqrt()))
}

#[test]
fn lambertian_sphere_under_a_uniform_environment_is_kd_times_l() {
    let dir = scratch("env_uniform");
    write_env(&dir.join("env.exr"), 64, |_, _| [0.5, 0.5, 0.5]);
    let s = load(&dir, &sphere_scene(&dir, [0.0, 0.0, 5.0], "", ""));
    // No headlight and no ambient with an environment.
    assert_eq!(s.settings.ambient, Vec3::ZERO);
    let f = render_frame(&s, 0, 0);
    let mut n = 0;
    for py in 0..64 {
        for px in 0..64 {
            if normal_from_front(px, py).is_some() {
                let c = f.color[(py * 64 + px) as usize];
                assert!((c.x - 0.3).abs() < 0.003, "({px}, {py}): {c}");
                n += 1;
            }
        }
    }
    assert!(n > 1800, "{n}");
}

#[test]
fn lambertian_sphere_under_a_half_white_sky_follows_the_normal() {
    let dir = scratch("env_half");
    // Radiance 1 above the horizon (the top half of the image), 0 below.
    write_env(&dir.join("env.exr"), 256, |_, y| {
        if y < 64 { [1.0; 3] } else { [0.0; 3] }
    });
    let s = load(&dir, &sphere_scene(&dir, [0.0, 0.0, 5.0], "", ""));
    let f = render_frame(&s, 0, 0);
    let mut worst = 0.0f32;
    for py in 0..64 {
        for px in 0..64 {
            if let Some(n) = normal_from_front(px, py) {
                let want = 0.6 * (1.0 + n.y) / 2.0;
                let got = f.color[(py * 64 + px) as usize].x;
                worst = worst.max((got - want).abs());
            }
        }
    }
    // The tessellated sphere's interpolated normals and the image's grid.
    assert!(worst < 0.01, "worst difference {worst}");
}

/// Mean red of the left and right halves of the sphere's pixels.
fn halves(f: &softraster::render::Frame) -> (f32, f32) {
    let (mut l, mut r) = (0.0, 0.0);
    for py in 0..64 {
        for px in 0..64 {
            let c = f.color[(py * 64 + px) as usize].x;
            if px < 28 {
                l += c;
            } else if px >= 36 {
                r += c;
            }
        }
    }
    (l, r)
}

#[test]
fn the_image_middle_lies_toward_minus_z_and_rotation_turns_it() {
    let dir = scratch("env_patch");
    // A bright patch at the image's middle, dark elsewhere.
    write_env(&dir.join("env.exr"), 128, |x, y| {
        if (56..72).contains(&x) && (24..40).contains(&y) {
            [20.0; 3]
        } else {
            [0.0; 3]
        }
    });
    // Seen from +X, screen right is -Z: the right half faces the patch.
    let s = load(&dir, &sphere_scene(&dir, [5.0, 0.0, 0.0], "", ""));
    let (l, r) = halves(&render_frame(&s, 0, 0));
    assert!(r > 10.0 * l.max(1e-3), "left {l} right {r}");
    // Turned 180 degrees, the patch lies toward +Z: the left half.
    let s = load(
        &dir,
        &sphere_scene(&dir, [5.0, 0.0, 0.0], "rotation = 180.0", ""),
    );
    let (l, r) = halves(&render_frame(&s, 0, 0));
    assert!(l > 10.0 * r.max(1e-3), "left {l} right {r}");
    // Turned 90 degrees counter-clockwise seen from above, -Z goes to -X:
    // from +X the patch is behind the sphere, and both halves are dim.
    let s = load(
        &dir,
        &sphere_scene(&dir, [5.0, 0.0, 0.0], "rotation = -90.0", ""),
    );
    let f = render_frame(&s, 0, 0);
    let center = f.color[32 * 64 + 32].x;
    let (l, r) = halves(&f);
    assert!(
        center > 1.0 && (l - r).abs() < 0.2 * (l + r),
        "{center} {l} {r}"
    );
}

#[test]
fn white_furnace_pbr_never_gains_energy() {
    let dir = scratch("env_furnace");
    write_env(&dir.join("env.exr"), 64, |_, _| [1.0; 3]);
    let mut lowest = f32::INFINITY;
    for (metallic, roughness) in [
        (0.0, 0.0),
        (0.0, 0.5),
        (0.0, 1.0),
        (1.0, 0.0),
        (1.0, 0.5),
        (1.0, 1.0),
    ] {
        let text = sphere_scene(&dir, [0.0, 0.0, 5.0], "", "")
            .replace("shading = \"blinn-phong\"", "shading = \"pbr\"")
            + &format!(
                "[model.material]\nkd = [1.0, 1.0, 1.0]\nmetallic = {metallic}\nroughness = {roughness}\n"
            );
        let s = load(&dir, &text);
        let f = render_frame(&s, 0, 0);
        let (mut lo, mut sum, mut n) = (f32::INFINITY, 0.0, 0);
        for py in 0..64 {
            for px in 0..64 {
                if normal_from_front(px, py).is_some() {
                    let c = f.color[(py * 64 + px) as usize];
                    assert!(
                        c.max_element() <= 1.0 + 2e-3,
                        "m {metallic} r {roughness}: {c}"
                    );
                    lo = lo.min(c.min_element());
                    sum += c.x;
                    n += 1;
                }
            }
        }
        println!(
            "metallic {metallic} roughness {roughness}: lowest {lo:.3}, mean {:.3}",
            sum / n as f32
        );
        lowest = lowest.min(lo);
    }
    // Dielectrics and smooth metals return all of it; rough metals lose
    // what single-scattering GGX loses (the lights' BRDF, which the split
    // sum integrates, has no multiple-scattering term): measured, metal at
    // roughness 0.5 a mean 0.888 (lowest 0.845), at roughness 1 a mean
    // 0.357 (lowest 0.309, at grazing angles).
    println!("white furnace: lowest radiance {lowest:.3}");
    assert!(lowest > 0.3, "{lowest}");
}

#[test]
fn bad_environments_are_refused_by_name() {
    let dir = scratch("env_bad");
    let f = files();
    for (name, text) in &f {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let run = |env_keys: &str| {
        let text = sphere_scene(&dir, [0.0, 0.0, 5.0], env_keys, "");
        std::fs::write(dir.join("s.toml"), text).unwrap();
        crate::binary::run(&[
            "render",
            dir.join("s.toml").to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ])
    };
    // Missing file: names the path and the key's line.
    let (code, _, err) = run("");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("env.exr")
            && err.contains("environment file not found")
            && err.contains("s.toml:"),
        "{err}"
    );
    // Not 2:1.
    exr::prelude::write_rgb_file(dir.join("env.exr"), 32, 32, |_, _| (1.0f32, 1.0f32, 1.0f32))
        .unwrap();
    let (code, _, err) = run("");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("twice as wide as high"), "{err}");
    // Truncated.
    std::fs::write(dir.join("env.exr"), b"v/1\x01\x02").unwrap();
    let (code, _, err) = run("");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("env.exr"), "{err}");
    // Negative intensity: the key, with line and column.
    write_env(&dir.join("env.exr"), 32, |_, _| [1.0; 3]);
    let (code, _, err) = run("intensity = -1.0");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("environment.intensity = -1") && err.contains("s.toml:"),
        "{err}"
    );
    // More lights than 16, or fewer than none.
    for bad in ["lights = 17", "lights = -1"] {
        let (code, _, err) = run(bad);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("environment.lights") && err.contains("s.toml:"),
            "{err}"
        );
    }
    // Bounces other than 0 or 1.
    for bad in [
        "method = \"sampled\"\nbounces = 2",
        "method = \"sampled\"\nbounces = -1",
    ] {
        let (code, _, err) = run(bad);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("environment.bounces") && err.contains("s.toml:"),
            "{err}"
        );
    }
    // And a good one renders.
    let (code, _, err) = run("intensity = 2.0\nlights = 16");
    assert_eq!(code, 0, "{err}");
}

#[test]
fn the_background_shows_the_environment_sharp_or_blurred() {
    let dir = scratch("env_background");
    // The image's left half (u < 0.5: directions toward -X) 1, the right
    // half 0. Seen from +Z looking at -Z, screen left is toward -X.
    write_env(&dir.join("env.exr"), 128, |x, _| {
        if x < 64 { [1.0; 3] } else { [0.0; 3] }
    });
    let scene = |bg: &str| {
        // A perspective camera: each pixel looks its own way.
        let t = sphere_scene(&dir, [0.0, 0.0, 5.0], "", "")
            .replace(
                "height = 64\n",
                &format!("height = 64\nbackground = {bg}\n"),
            )
            .replace("projection = \"orthographic\"\nheight = 2.4", "fov = 60.0");
        load(&dir, &t)
    };
    let f = render_frame(&scene("\"environment\""), 0, 0);
    // Corners: top-left sees -X (lit half), top-right sees +X.
    let (tl, tr) = (f.color[0], f.color[63]);
    assert!((tl.x - 1.0).abs() < 1e-3 && tl.w == 1.0, "{tl}");
    assert!(tr.x.abs() < 1e-3 && tr.w == 1.0, "{tr}");
    // Blurred: the same sides, softened toward each other.
    let f = render_frame(&scene("\"blurred\"\nbackground_blur = 1.0"), 0, 0);
    let (tl, tr) = (f.color[0].x, f.color[63].x);
    assert!(tl > tr && tl < 0.95 && tr > 0.05, "{tl} {tr}");
    // Without an [environment], refused at the key.
    let t = sphere_scene(&dir, [0.0, 0.0, 5.0], "", "")
        .replace("height = 64\n", "height = 64\nbackground = \"blurred\"\n")
        .replace("[environment]\npath = \"env.exr\"\n", "");
    std::fs::write(dir.join("s.toml"), t).unwrap();
    let e = softraster::scene::Scene::load(&dir.join("s.toml"), &Default::default()).unwrap_err();
    assert!(e.to_string().contains("needs an [environment]"), "{e}");
}

#[test]
fn auto_exposure_maps_the_models_log_average_to_middle_grey() {
    let dir = scratch("env_exposure");
    // kd 0.6 under a uniform radiance of 1/0.6: the sphere's radiance is 1.
    write_env(&dir.join("env.exr"), 64, |_, _| [1.0 / 0.6; 3]);
    let text = sphere_scene(&dir, [0.0, 0.0, 5.0], "", "exposure = \"auto\"\n")
        .replace("[[model]]", "[animation]\nframes = 12\n[[model]]");
    let s = load(&dir, &text);
    assert!(s.settings.auto_exposure);
    let stops = softraster::render::Renderer::new(&s).exposure();
    assert!((stops - 0.18f32.log2()).abs() < 0.01, "{stops}");
    // Every shard of a farm run gets the same value.
    std::fs::write(dir.join("s.toml"), &text).unwrap();
    let line = |frames: &str| {
        let (code, _, err) = crate::binary::run(&[
            "render",
            dir.join("s.toml").to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
            "--frames",
            frames,
        ]);
        assert_eq!(code, 0, "{err}");
        err.lines()
            .find(|l| l.starts_with("exposure: auto"))
            .unwrap_or_default()
            .to_string()
    };
    let a = line("0..3");
    assert!(a.contains("-2.47 stops"), "{a}");
    assert_eq!(a, line("9"));
}

#[test]
fn the_sampled_reference_agrees_with_the_known_answers() {
    let dir = scratch("env_sampled");
    write_env(&dir.join("env.exr"), 64, |_, _| [0.5, 0.5, 0.5]);
    let text = sphere_scene(
        &dir,
        [0.0, 0.0, 5.0],
        "method = \"sampled\"\nsamples = 64",
        "",
    );
    let s = load(&dir, &text);
    let f = render_frame(&s, 0, 0);
    let (mut sum, mut n, mut worst) = (0.0f32, 0, 0.0f32);
    for py in 0..64 {
        for px in 0..64 {
            if normal_from_front(px, py).is_some() {
                let c = f.color[(py * 64 + px) as usize].x;
                sum += c;
                n += 1;
                worst = worst.max((c - 0.3).abs());
            }
        }
    }
    // Unbiased: the mean is kd L; each pixel within the noise of 64 pairs.
    let mean = sum / n as f32;
    assert!((mean - 0.3).abs() < 0.003, "mean {mean}");
    assert!(worst < 0.03, "worst {worst}");
    // Deterministic.
    assert_eq!(render_frame(&s, 0, 0).color, f.color);
    // A white furnace, sampled, against the split sum: rough metal loses
    // the same single-scattering energy.
    write_env(&dir.join("env.exr"), 64, |_, _| [1.0; 3]);
    let pbr = |method: &str| {
        let t = sphere_scene(&dir, [0.0, 0.0, 5.0], method, "")
            .replace("shading = \"blinn-phong\"", "shading = \"pbr\"")
            + "[model.material]\nkd = [1.0, 1.0, 1.0]\nmetallic = 1.0\nroughness = 0.6\n";
        let f = render_frame(&load(&dir, &t), 0, 0);
        let v: Vec<f32> = (0..64 * 64)
            .filter(|&i| normal_from_front(i % 64, i / 64).is_some())
            .map(|i| f.color[i as usize].x)
            .collect();
        v.iter().sum::<f32>() / v.len() as f32
    };
    let (sampled, prefiltered) = (pbr("method = \"sampled\"\nsamples = 128"), pbr(""));
    println!("furnace, metal roughness 0.6: sampled {sampled:.4}, prefiltered {prefiltered:.4}");
    assert!(
        sampled <= 1.0 && (sampled - prefiltered).abs() < 0.02,
        "{sampled} {prefiltered}"
    );
}

#[test]
fn presets_light_without_a_file() {
    let dir = scratch("env_preset");
    // "neutral": a uniform radiance of 1, so a Lambertian sphere shows kd.
    let text = sphere_scene(&dir, [0.0, 0.0, 5.0], "", "")
        .replace("path = \"env.exr\"", "preset = \"neutral\"");
    let f = render_frame(&load(&dir, &text), 0, 0);
    let c = f.color[32 * 64 + 32];
    assert!((c.x - 0.6).abs() < 0.003, "{c}");
    // "studio": the key panel above front-left lights the sphere's
    // upper left more than its lower right; nothing is black.
    let text = sphere_scene(&dir, [0.0, 0.0, 5.0], "", "")
        .replace("path = \"env.exr\"", "preset = \"studio\"");
    let s = load(&dir, &text);
    // No lights taken out of it: the one shared image, unchanged.
    let env = s.environment.as_ref().unwrap();
    assert!(s.lights.is_empty() && env.backdrop.is_none());
    let studio = softraster::assets::environment::EnvImage::studio();
    assert!(std::sync::Arc::ptr_eq(&env.image, &studio));
    let f = render_frame(&s, 0, 0);
    let (ul, lr) = (f.color[20 * 64 + 20].x, f.color[44 * 64 + 44].x);
    assert!(ul > 2.0 * lr && lr > 0.05, "{ul} {lr}");
    // Both: refused at the table.
    let t = sphere_scene(&dir, [0.0, 0.0, 5.0], "preset = \"studio\"", "");
    std::fs::write(dir.join("s.toml"), t).unwrap();
    let e = softraster::scene::Scene::load(&dir.join("s.toml"), &Default::default()).unwrap_err();
    assert!(e.to_string().contains("not both"), "{e}");
    // Neither (version 3): the studio, turned by the table's rotation;
    // `preset = "studio"` alone is the default look itself.
    let t = sphere_scene(&dir, [0.0, 0.0, 5.0], "rotation = 90.0", "")
        .replace("path = \"env.exr\"\n", "");
    let turned = load(&dir, &t);
    let env = turned.environment.as_ref().expect("the studio");
    assert_eq!(env.rotation, 90.0);
    let preset = sphere_scene(&dir, [0.0, 0.0, 5.0], "", "")
        .replace("path = \"env.exr\"", "preset = \"studio\"");
    let plain = sphere_scene(&dir, [0.0, 0.0, 5.0], "", "")
        .replace("[environment]\npath = \"env.exr\"\n", "");
    let (a, b) = (
        render_frame(&load(&dir, &preset), 0, 0),
        render_frame(&load(&dir, &plain), 0, 0),
    );
    assert!(
        a.color == b.color,
        "preset = \"studio\" differs from the default look"
    );
}

#[test]
fn the_ground_catcher_shows_only_the_shadows_of_the_models() {
    let dir = scratch("ground");
    let cube = softraster::procedural::cube([0.0; 3], 0.5)
        .to_obj("cube", "none.mtl", "m")
        .text
        .replace("mtllib none.mtl\n", "")
        .replace("usemtl m\n", "");
    // A unit cube on the catcher, a light travelling 45 degrees down toward
    // -X casting its shadow over x in (-1.5, -0.5); seen from straight
    // above, 16 pixels a unit.
    let text = |bg: &str| {
        format!(
            "[output]\nwidth = 64\nheight = 64\nbackground = {bg}\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n\
             [ground]\nshadow = true\n[[model]]\npath = \"cube.obj\"\n\
             [[light]]\nkind = \"directional\"\ndirection = [-1.0, -1.0, 0.0]\nshadows = true\n\
             [[camera]]\neye = [0.0, 10.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
             projection = \"orthographic\"\nheight = 4.0\n"
        )
    };
    let s = scene_in(&dir, &text("[0.5, 0.5, 0.5]"), &[("cube.obj", &cube)]);
    assert_eq!(s.ground.unwrap().height, -0.5);
    let f = render_frame(&s, 0, 0);
    let at = |x: f32, z: f32| {
        let (px, py) = ((32.0 + x * 16.0) as usize, (32.0 + z * 16.0) as usize);
        (f.color[py * 64 + px], f.depth[py * 64 + px])
    };
    // In the shadow: black; beside it: the background; neither is an object.
    let (shadow, d) = at(-1.0, 0.0);
    assert!(
        shadow.truncate().max_element() < 0.01 && d.is_infinite(),
        "{shadow}"
    );
    let (lit, _) = at(1.0, 0.0);
    assert!((lit.x - 0.5).abs() < 1e-3, "{lit}");
    let (side, _) = at(-1.0, 1.2);
    assert!((side.x - 0.5).abs() < 1e-3, "{side}");
    // Over a transparent background the shadow is alpha.
    let s = scene_in(&dir, &text("\"transparent\""), &[("cube.obj", &cube)]);
    let f = render_frame(&s, 0, 0);
    let (px, py) = (32 - 16, 32);
    let c = f.color[py * 64 + px];
    assert!(c.w > 0.99 && c.truncate().max_element() < 0.01, "{c}");
    assert_eq!(f.color[32 * 64 + 48].w, 0.0);
}

#[test]
fn the_sun_of_real_skies_becomes_a_shadow_casting_light() {
    let Some(assets) = common::shared_assets() else {
        return;
    };
    let dir = scratch("env_sun");
    for hdri in ["sunset", "city"] {
        let path = assets.join(format!("hdri/{hdri}.exr"));
        let text = sphere_scene(&dir, [0.0, 0.0, 5.0], "sun = true\nlights = 0", "").replace(
            "path = \"env.exr\"",
            &format!("path = {:?}", path.display().to_string()),
        );
        let s = load(&dir, &text);
        assert_eq!(s.lights.len(), 1, "{hdri}");
        let l = s.lights[0];
        let softraster::scene::light::LightKind::Directional {
            direction,
            irradiance,
            ..
        } = l.kind
        else {
            panic!("{hdri}: {:?}", l.kind)
        };
        // From above the horizon (the sunset's sun is low), casting
        // shadows, with a good share of what the sky gives a surface facing
        // up once the sun is out of it.
        let env = &s.environment.as_ref().unwrap().image;
        let sky = env.texels.iter().map(|c| c.y).sum::<f32>() / env.texels.len() as f32
            * std::f32::consts::PI;
        println!(
            "{hdri}: sun toward {:?}, irradiance {irradiance:.3}, sky {sky:.3}",
            -direction
        );
        assert!(l.shadows && direction.y < 0.0, "{hdri}: {direction}");
        assert!(irradiance > 0.25 * sky, "{hdri}: {irradiance} vs {sky}");
    }
}

#[test]
fn keys_without_effect_warn_and_illum_0_takes_no_environment_light() {
    let dir = scratch("env_warn");
    let text = sphere_scene(
        &dir,
        [0.0, 0.0, 5.0],
        "preset = \"neutral\"\nsamples = 8\nsun = true",
        "",
    )
    .replace("path = \"env.exr\"\n", "")
    .replace(
        "projection = \"orthographic\"",
        "elevation = 30.0\nprojection = \"orthographic\"",
    );
    let s = load(&dir, &text);
    let all = s.warnings.join("\n");
    for what in [
        "environment.samples has no effect",
        "camera.elevation has no effect",
        "no sun light",
    ] {
        assert!(all.contains(what), "{what}: {all}");
    }
    // illum 0 is Kd alone: the environment adds nothing.
    let f = |illum: u32| {
        let t = sphere_scene(&dir, [0.0, 0.0, 5.0], "preset = \"neutral\"", "")
            .replace("path = \"env.exr\"\n", "");
        let d = scratch(&format!("env_illum{illum}"));
        let obj = softraster::procedural::sphere(1.0, 96, 48)
            .to_obj("sphere", "m.mtl", "m")
            .text;
        let mtl = MTL.replace("illum 1", &format!("illum {illum}"));
        let s = scene_in(&d, &t, &[("sphere.obj", &obj), ("m.mtl", &mtl)]);
        render_frame(&s, 0, 0).color[32 * 64 + 32].x
    };
    assert!(
        (f(0) - 0.6).abs() < 1e-4 && (f(1) - 0.6).abs() < 0.003,
        "{} {}",
        f(0),
        f(1)
    );
}

#[test]
fn a_changed_intensity_is_not_served_from_the_lighting_cache() {
    // The prefiltered lighting is cached per process (by image and
    // parameters): the scene changed after a render takes a renderer of
    // its own (the borrow forbids changing it under one), which must not
    // get the first intensity's lighting.
    use softraster::render::{Frame, Renderer, Shot};
    let dir = scratch("env_stale");
    write_env(&dir.join("env.exr"), 64, |_, _| [0.5; 3]);
    let mut s = load(&dir, &sphere_scene(&dir, [0.0, 0.0, 5.0], "", ""));
    Renderer::new(&s)
        .render(Shot::new(0, 0), &mut Frame::new(0, 0))
        .unwrap();
    s.environment.as_mut().unwrap().intensity = 2.0;
    let mut f = Frame::new(0, 0);
    Renderer::new(&s).render(Shot::new(0, 0), &mut f).unwrap();
    // kd 0.6 under radiance 0.5 x 2.
    assert!(
        (f.color[32 * 64 + 32].x - 0.6).abs() < 0.003,
        "{}",
        f.color[32 * 64 + 32]
    );
}

#[test]
fn prefilter_size_is_checked_and_changes_only_the_glossy_levels() {
    use softraster::render::{Frame, Renderer, Shot};
    let dir = scratch("env_prefilter_size");
    // A sharp vertical bar of light toward -Z on a dark sky: a glossy
    // sphere seen from -Z shows it blurred by the roughness-0.2 level.
    write_env(&dir.join("env.exr"), 256, |x, _| {
        if (126..130).contains(&x) {
            [20.0; 3]
        } else {
            [0.05; 3]
        }
    });
    let f = files();
    for (name, text) in &f {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let scene = |keys: &str| {
        format!(
            "[output]\nwidth = 64\nheight = 64\n[render]\nshading = \"pbr\"\n\
             [environment]\npath = \"env.exr\"\n{keys}\n\
             [[model]]\npath = \"sphere.obj\"\n\
             [model.material]\nkd = [0.9, 0.9, 0.9]\nmetallic = 1.0\nroughness = 0.2\n\
             [[camera]]\neye = [0.0, 0.0, -5.0]\ntarget = [0.0, 0.0, 0.0]\n\
             projection = \"orthographic\"\nheight = 2.4\n# {}\n",
            dir.display()
        )
    };
    // The command line on the scene with `keys`: exit code and stderr.
    let cli = |keys: &str| {
        std::fs::write(dir.join("s.toml"), scene(keys)).unwrap();
        let (code, _, err) = crate::binary::run(&[
            "render",
            dir.join("s.toml").to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ]);
        (code, err)
    };
    // Out of range: exit 2 naming the key with its line.
    let (code, err) = cli("prefilter_size = 4");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("environment.prefilter_size") && err.contains("s.toml:"),
        "{err}"
    );
    // With the sampled method it does nothing, and says so.
    let (code, err) = cli("method = \"sampled\"\nsamples = 1\nprefilter_size = 64");
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("environment.prefilter_size has no effect"),
        "{err}"
    );

    let render = |keys: &str| {
        let s = load(&dir, &scene(keys));
        let mut f = Frame::new(0, 0);
        Renderer::new(&s).render(Shot::new(0, 0), &mut f).unwrap();
        f
    };
    let default = render("");
    let explicit = render("prefilter_size = 128");
    assert_eq!(default.color, explicit.color, "128 is the default");
    // The bar's reflection down the sphere's middle column: its peak over
    // its surroundings. A coarser level smears the bar wider and lower.
    let contrast = |f: &Frame| {
        let row: Vec<f32> = (0..64).map(|x| f.color[32 * 64 + x].x).collect();
        let peak = row[28..36].iter().cloned().fold(0.0, f32::max);
        let side = (row[14] + row[50]) / 2.0;
        peak / side.max(1e-6)
    };
    let (coarse, fine) = (contrast(&render("prefilter_size = 16")), contrast(&default));
    let finer = contrast(&render("prefilter_size = 512"));
    println!("bar contrast: size 16 {coarse:.2}, 128 {fine:.2}, 512 {finer:.2}");
    assert!(
        coarse < fine && fine <= finer * 1.05,
        "{coarse} {fine} {finer}"
    );

    // The same image at another size is prefiltered again, not served
    // from the lighting cache.
    let mut s = load(&dir, &scene("prefilter_size = 16"));
    Renderer::new(&s)
        .render(Shot::new(0, 0), &mut Frame::new(0, 0))
        .unwrap();
    s.environment.as_mut().unwrap().prefilter_size = 128;
    let mut f = Frame::new(0, 0);
    Renderer::new(&s).render(Shot::new(0, 0), &mut f).unwrap();
    assert_eq!(f.color, default.color);
}

/// Version 3: the studio look composes. A one-line white model plus one
/// directional light keeps the studio's blurred background and the ground
/// shadow, and is not clipped; `[environment]` with only a rotation turns
/// the studio; `[ambient]` asks for version 1's look.
#[test]
fn a_light_adds_to_the_studio_look() {
    let dir = scratch("look_composes");
    let obj = softraster::procedural::sphere(1.0, 64, 32).to_obj("ball", "none.mtl", "m");
    let files = [("ball.obj", obj.text.as_str())];
    let base = "[output]\nwidth = 96\nheight = 96\n[[model]]\npath = \"ball.obj\"\n";
    let lit = scene_in(
        &dir,
        &format!("{base}[[light]]\nkind = \"directional\"\n"),
        &files,
    );
    assert!(lit.environment.is_some() && lit.ground.is_some());
    assert_eq!(
        lit.settings.tonemap,
        softraster::scene::settings::Tonemap::PbrNeutral
    );
    let img = softraster::output::resolve(&render_frame(&lit, 0, 0), &lit.settings);
    let px = |x: usize, y: usize| {
        let i = (y * 96 + x) * img.channels as usize;
        [img.data[i], img.data[i + 1], img.data[i + 2]]
    };
    // The corner is the studio's grey, not black.
    assert!(px(2, 2).iter().all(|&c| c > 60), "{:?}", px(2, 2));
    // Of the ball's pixels (those the depth buffer covers), at most 2%
    // pure white.
    let frame = render_frame(&lit, 0, 0);
    let covered: Vec<usize> = (0..96 * 96)
        .filter(|&i| frame.depth[i].is_finite() && frame.depth[i] != 0.0)
        .collect();
    let white = covered
        .iter()
        .filter(|&&i| px(i % 96, i / 96) == [255, 255, 255])
        .count();
    assert!(
        !covered.is_empty() && white * 50 <= covered.len(),
        "{white} of {} pure white",
        covered.len()
    );
    // `[environment]` with a rotation only: the studio, turned.
    let turned = scene_in(
        &dir,
        &format!("{base}[environment]\nrotation = 90.0\n"),
        &files,
    );
    assert_eq!(turned.environment.as_ref().map(|e| e.rotation), Some(90.0));
    assert!(turned.ground.is_some());
    // `[ambient]`: version 1's look.
    let v1 = scene_in(
        &dir,
        &format!("{base}[[light]]\n[ambient]\ncolor = [0.03, 0.03, 0.03]\n"),
        &files,
    );
    assert!(v1.environment.is_none() && v1.ground.is_none());
    assert_eq!(
        v1.settings.background,
        softraster::scene::settings::Background::Color(Vec3::ZERO)
    );
}

/// A lamp of radiance 40, 10 degrees across, 45 degrees up toward +X, in a
/// sky of 0.2 (a 512 x 256 image), and what a floor facing up receives
/// from the lamp (its painted texels' radiance times solid angle times
/// cosine).
fn lamp_in_sky(path: &Path) -> f32 {
    use std::f32::consts::PI;
    let (w, h) = (512usize, 256usize);
    let dir = |x: usize, y: usize| {
        let theta = (y as f32 + 0.5) / h as f32 * PI;
        let phi = ((x as f32 + 0.5) / w as f32 - 0.5) * 2.0 * PI;
        Vec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        )
    };
    let lamp = Vec3::new(1.0, 1.0, 0.0).normalize();
    let inside = |x: usize, y: usize| dir(x, y).dot(lamp) >= 5f32.to_radians().cos();
    write_env(path, w, |x, y| {
        let c = if inside(x, y) { 40.2 } else { 0.2 };
        [c, c, c]
    });
    let mut e = 0.0;
    for y in 0..h {
        let omega =
            (2.0 * PI / w as f32) * (PI / h as f32) * ((y as f32 + 0.5) / h as f32 * PI).sin();
        for x in (0..w).filter(|&x| inside(x, y)) {
            e += 40.0 * omega * dir(x, y).y;
        }
    }
    e
}

#[test]
fn a_lamp_in_the_image_casts_a_soft_shadow_and_keeps_its_energy() {
    use std::f32::consts::PI;
    let dir = scratch("env_lamp");
    let e_lamp = lamp_in_sky(&dir.join("env.exr"));
    let floor = "mtllib m.mtl\nusemtl m\nv -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nf 4 3 2 1\n";
    // A ball of radius 0.5 at height 1.5 over a grey floor; the lamp's
    // shadow falls around (-1.5, 0, 0), an umbra: from there the ball is
    // 27 degrees across, the lamp 10. Seen from straight above, 64 x 64
    // over 4 units.
    let text = |lights: &str| {
        format!(
            "[output]\nwidth = 64\nheight = 64\n[render]\nshading = \"blinn-phong\"\n\
             [environment]\npath = \"env.exr\"\n{lights}\n\
             [[model]]\npath = \"sphere.obj\"\nscale = 0.5\ntranslate = [0.0, 1.5, 0.0]\n\
             [[model]]\npath = \"floor.obj\"\n\
             [[camera]]\neye = [0.0, 10.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
             projection = \"orthographic\"\nheight = 4.0\n"
        )
    };
    let mut f = files();
    f.push(("floor.obj", floor.to_string()));
    let refs: Vec<(&str, &str)> = f.iter().map(|(n, t)| (*n, t.as_str())).collect();
    let at = |frame: &softraster::render::Frame, x: f32, z: f32| {
        let (px, py) = ((32.0 + x * 16.0) as usize, (32.0 + z * 16.0) as usize);
        frame.color[py * 64 + px].x
    };
    let s = scene_in(&dir, &text(""), &refs);
    assert_eq!(s.lights.len(), 1, "the lamp is the image's one light");
    let lit = render_frame(&s, 0, 0);
    let s = scene_in(&dir, &text("lights = 0"), &refs);
    assert!(s.lights.is_empty());
    let unlit = render_frame(&s, 0, 0);
    // In the open, taking the lamp out of the image changes nothing.
    let (open, open0) = (at(&lit, 1.5, 1.5), at(&unlit, 1.5, 1.5));
    assert!((open / open0 - 1.0).abs() < 0.01, "{open} against {open0}");
    // In the umbra the floor loses what the lamp gave it (but the 2% of
    // the lamp's level the image keeps).
    let lamp = 0.6 / PI * e_lamp;
    let umbra = at(&lit, -1.5, 0.0);
    let want = open0 - 0.98 * lamp;
    assert!((umbra - want).abs() < 0.03 * lamp, "{umbra} against {want}");
    // Without the light, nothing casts a shadow there.
    assert!((at(&unlit, -1.5, 0.0) / open0 - 1.0).abs() < 0.01);
    // Across the shadow's edge (sideways along z, at z = 0.5: the ball
    // lies 2.1 from the floor along the light, so the penumbra spans
    // 2.1 tan 5 degrees = 0.19 either side) the floor brightens gradually
    // (to within the rays' noise).
    let edge: Vec<f32> = (0..12)
        .map(|k| at(&lit, -1.5, 0.2 + 0.0625 * k as f32))
        .collect();
    assert!(
        edge.windows(2).all(|w| w[1] >= w[0] - 0.1 * lamp),
        "{edge:?}"
    );
    assert!(
        edge.iter()
            .filter(|&&v| v > umbra + 0.1 * lamp && v < open - 0.1 * lamp)
            .count()
            >= 3,
        "{edge:?}"
    );
}
