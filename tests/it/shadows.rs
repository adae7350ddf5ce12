//! Shadows, ambient occlusion and the EXR data buffers against analytic
//! and ray-traced truth, and where shadow maps are known to fail (acne at
//! grazing light, peter-panning at contact, SSAO halos).

use crate::common;
use softraster::render::Shot;

use std::path::Path;

use common::render_frame;
use glam::Vec3;
use softraster::batch::RenderJob;
use softraster::output::exr::read_channel;
use softraster::procedural::{self, Builder};
use softraster::render::Frame;
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;

/// A procedural mesh as OBJ text without a material library.
fn obj(b: Builder) -> String {
    b.to_obj("m", "none.mtl", "m")
        .text
        .replace("mtllib none.mtl\n", "")
        .replace("usemtl m\n", "")
}

fn load(dir: &Path, text: &str) -> Scene {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn render(dir: &Path, text: &str) -> Frame {
    render_frame(&load(dir, text), 0, 0)
}

/// Per pixel: the fraction of the (single) light that arrives, as the
/// ratio of the image with `shadows` to the image without; NaN where the
/// unshadowed image is black (background, or facing away from the light).
/// `scene` holds `{shadows}` where `render.shadows` goes.
fn shadow_factor(dir: &Path, scene: &str, shadows: &str) -> Vec<f32> {
    let lit = render(dir, &scene.replace("{shadows}", "off"));
    let sh = render(dir, &scene.replace("{shadows}", shadows));
    lit.color
        .iter()
        .zip(&sh.color)
        .map(|(a, b)| {
            if a.x > 1e-4 {
                (b.x / a.x).clamp(0.0, 1.0)
            } else {
                f32::NAN
            }
        })
        .collect()
}

/// A top-down orthographic camera over the XZ plane: pixel (px, py) looks at
/// world (x, z) with x to the right and z down the image.
const TOP_DOWN: &str = "[[camera]]\neye = [0.0, 10.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\nprojection = \"orthographic\"\nheight = 6.0\nnear = 1.0\nfar = 20.0\n";

fn top_down_point(px: u32, py: u32, size: u32, height: f32) -> (f32, f32) {
    let s = height / size as f32;
    (
        (px as f32 + 0.5) * s - height * 0.5,
        (py as f32 + 0.5) * s - height * 0.5,
    )
}

const MATTE: &str = "[model.material]\nkd = [1.0, 1.0, 1.0]\nks = [0.0, 0.0, 0.0]\n";

#[test]
fn depth_exr_of_a_sphere_over_a_plane_matches_the_ray_intersection() {
    let dir = common::scratch("depth_exr");
    std::fs::write(dir.join("sphere.obj"), obj(procedural::sphere(1.0, 96, 48))).unwrap();
    std::fs::write(
        dir.join("ground.obj"),
        obj(procedural::ground(6.0, 0.0, 1.0)),
    )
    .unwrap();
    let (w, h, fov) = (96u32, 80u32, 50.0f32);
    let text = format!(
        "[output]\nwidth = {w}\nheight = {h}\ndepth = true\ncolor = false\nname = \"f\"\n\
         [[model]]\npath = \"ground.obj\"\n[[model]]\npath = \"sphere.obj\"\ntranslate = [0.3, 1.2, -0.4]\n\
         [[camera]]\neye = [0.5, 2.5, 5.0]\ntarget = [0.0, 0.6, 0.0]\nfov = {fov}\nnear = 0.3\nfar = 40.0\n"
    );
    let mut scene = load(&dir, &text);
    let out = dir.join("out");
    scene.output.dir = out.clone();
    let job = RenderJob::all(scene);
    job.run(|_| {}).unwrap();
    let (ew, eh, z) = read_channel(&out.join("f_depth.exr"), "Z").unwrap();
    assert_eq!((ew, eh), (w, h));
    assert!(!out.join("f.png").exists(), "color = false writes no PNG");

    // The exact surfaces drawn: both meshes' triangles in world space.
    let s = job.scene();
    let mut tris: Vec<[Vec3; 3]> = Vec::new();
    for m in &s.models {
        for t in &m.mesh.triangles {
            tris.push(t.map(|i| {
                m.world_from_object
                    .transform_point3(m.mesh.positions[i as usize])
            }));
        }
    }
    let cam = &s.cameras[0];
    let world_from_view = cam.view_from_world().inverse();
    let forward = cam.forward();
    let center = Vec3::new(0.3, 1.2, -0.4);
    let (mut sphere_px, mut plane_px, mut empty) = (0, 0, 0);
    let mut worst = 0.0f64;
    let mut worst_ideal = 0.0f32;
    for py in 0..h {
        for px in 0..w {
            let got = z[(py * w + px) as usize];
            let d = world_from_view.transform_vector3(common::view_ray(px, py, w, h, fov));
            let Some((t, k)) = ray_mesh(cam.eye, d, &tris) else {
                assert!(
                    got.is_infinite() || near_edge(px, py, &z, w, h),
                    "({px},{py}) {got}"
                );
                if got.is_infinite() {
                    empty += 1;
                }
                continue;
            };
            if !got.is_finite() {
                continue; // silhouette pixel: coverage decided by the rule
            }
            // Distance along the view axis of the hit.
            let want = (d * t as f32).dot(forward) as f64;
            let rel = ((got as f64 - want) / want).abs();
            if rel >= 1e-5 && near_edge(px, py, &z, w, h) {
                continue; // a different triangle won the edge
            }
            assert!(rel < 1e-5, "({px},{py}): {got} vs {want}, rel {rel:e}");
            worst = worst.max(rel);
            if k >= 2 {
                sphere_px += 1;
                // Against the ideal sphere: within the facets' sagitta.
                let dd = d.normalize();
                let oc = cam.eye - center;
                let b = oc.dot(dd);
                let disc = b * b - (oc.length_squared() - 1.0);
                if disc > 0.1 {
                    let ti = -b - disc.sqrt();
                    let ideal = (dd * ti).dot(forward);
                    worst_ideal = worst_ideal.max((got - ideal).abs() / ideal);
                }
            } else {
                plane_px += 1;
            }
        }
    }
    println!(
        "depth EXR: worst relative error {worst:e} over {} pixels; ideal sphere within {worst_ideal:e}",
        sphere_px + plane_px
    );
    assert!(
        sphere_px > 600 && plane_px > 2000 && empty > 50,
        "{sphere_px} {plane_px} {empty}"
    );
    // 96x48 facets: sagitta 1 - cos(pi/48) = 2.1e-3 of the radius.
    assert!(worst_ideal < 2.5e-3 / 3.0, "{worst_ideal}");
}

/// Whether a 4-neighbor has a very different depth (an occlusion edge).
fn near_edge(px: u32, py: u32, z: &[f32], w: u32, h: u32) -> bool {
    let c = z[(py * w + px) as usize];
    [(-1i32, 0i32), (1, 0), (0, -1), (0, 1)]
        .iter()
        .any(|(dx, dy)| {
            let (x, y) = (px as i32 + dx, py as i32 + dy);
            if x < 0 || y < 0 || x >= w as i32 || y >= h as i32 {
                return false;
            }
            let n = z[(y as u32 * w + x as u32) as usize];
            !(n.is_finite() && c.is_finite()) || (n - c).abs() > 0.05 * c
        })
}

/// Nearest hit of a ray with a triangle list, in f64: (t, triangle index).
fn ray_mesh(o: Vec3, d: Vec3, tris: &[[Vec3; 3]]) -> Option<(f64, usize)> {
    let dv = |v: Vec3| glam::DVec3::new(v.x as f64, v.y as f64, v.z as f64);
    let (o, d) = (dv(o), dv(d));
    let mut best: Option<(f64, usize)> = None;
    for (k, t) in tris.iter().enumerate() {
        let (a, b, c) = (dv(t[0]), dv(t[1]), dv(t[2]));
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-15 {
            continue;
        }
        let s = o - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let tt = e2.dot(q) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && tt > 0.0 && best.is_none_or(|b| tt < b.0) {
            best = Some((tt, k));
        }
    }
    best
}

#[test]
fn raytraced_ao_under_a_sphere_matches_the_closed_form() {
    // A point on a plane sees a sphere (radius r, center at height h and
    // distance d) over a cosine-weighted solid angle of r^2 h / d^3.
    let dir = common::scratch("ao_closed_form");
    let (r, hc) = (0.5f32, 1.0f32);
    std::fs::write(dir.join("sphere.obj"), obj(procedural::sphere(r, 128, 64))).unwrap();
    std::fs::write(
        dir.join("ground.obj"),
        obj(procedural::ground(50.0, 0.0, 1.0)),
    )
    .unwrap();
    let size = 48u32;
    let samples = 1024u32;
    let text = format!(
        "[output]\nwidth = {size}\nheight = {size}\n[render]\nao = {{ method = \"raytraced\", samples = {samples} }}\n\
         [[model]]\npath = \"ground.obj\"\n[[model]]\npath = \"sphere.obj\"\ntranslate = [0.0, {hc}, 0.0]\n{TOP_DOWN}"
    );
    let f = render(&dir, &text);
    let mut n = 0;
    let mut sum_sq = 0.0f64;
    let mut worst = 0.0f32;
    for py in 0..size {
        for px in 0..size {
            let (x, z) = top_down_point(px, py, size, 6.0);
            let rho2 = x * x + z * z;
            if rho2 < (r * 1.3) * (r * 1.3) {
                continue; // the sphere itself is seen here
            }
            let d = (rho2 + hc * hc).sqrt();
            let want = 1.0 - r * r * hc / (d * d * d);
            let got = f.ao[(py * size + px) as usize];
            // Binomial noise of `samples` stratified rays: at most
            // sqrt(p (1 - p) / n) = 0.0156 for p = 1/2.
            let sigma = (want * (1.0 - want) / samples as f32).sqrt().max(1e-3);
            assert!(
                (got - want).abs() < 4.0 * sigma + 2e-3,
                "({x:.2},{z:.2}): {got} vs {want} (sigma {sigma})"
            );
            worst = worst.max((got - want).abs());
            sum_sq += ((got - want) as f64).powi(2);
            n += 1;
        }
    }
    let rmse = (sum_sq / n as f64).sqrt();
    println!("raytraced AO vs 1 - r^2 h / d^3: RMSE {rmse:.5}, worst {worst:.5} over {n} pixels");
    assert!(n > 1500);
    assert!(rmse < 0.006, "{rmse}");
}

/// Sphere (radius 1, center at height 1.5) over the plane y = 0, one
/// directional light travelling along `dir` (unit): the shadow is the
/// set of plane points whose ray towards the light passes within 1 of the
/// center.
fn analytic_shadow(x: f32, z: f32, center: Vec3, light_dir: Vec3) -> bool {
    let p = Vec3::new(x, 0.0, z);
    let to_light = -light_dir;
    let c = center - p;
    c.dot(to_light) > 0.0 && c.cross(to_light).length() < 1.0
}

fn sphere_on_plane_scene(dir: &Path, light_dir: Vec3, size: u32, extra: &str) -> String {
    std::fs::write(
        dir.join("sphere.obj"),
        obj(procedural::sphere(1.0, 128, 64)),
    )
    .unwrap();
    std::fs::write(
        dir.join("ground.obj"),
        obj(procedural::ground(8.0, 0.0, 1.0)),
    )
    .unwrap();
    format!(
        "[output]\nwidth = {size}\nheight = {size}\n[render]\nshadows = \"{{shadows}}\"\n{extra}\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n\
         [[model]]\npath = \"ground.obj\"\n{MATTE}[[model]]\npath = \"sphere.obj\"\ntranslate = [0.0, 1.5, 0.0]\n{MATTE}\
         [[light]]\nkind = \"directional\"\ndirection = [{}, {}, {}]\nirradiance = 1.0\nshadows = true\n{TOP_DOWN}",
        light_dir.x, light_dir.y, light_dir.z
    )
}

#[test]
fn shadow_of_a_sphere_is_the_analytic_ellipse() {
    let dir = common::scratch("shadow_ellipse");
    let light = Vec3::new(-1.0, -1.6, -0.5).normalize();
    let size = 300u32;
    let center = Vec3::new(0.0, 1.5, 0.0);
    let scene = sphere_on_plane_scene(&dir, light, size, "");
    for method in ["hard", "pcf", "raytraced"] {
        let f = shadow_factor(&dir, &scene, method);
        let (mut wrong, mut shadowed, mut plane) = (0, 0, 0);
        let px_size = 6.0 / size as f32;
        for py in 0..size {
            for px in 0..size {
                let (x, z) = top_down_point(px, py, size, 6.0);
                if x * x + z * z < 1.05 {
                    continue; // the sphere is seen from above here
                }
                let k = f[(py * size + px) as usize];
                if k.is_nan() {
                    continue;
                }
                plane += 1;
                let want = analytic_shadow(x, z, center, light);
                shadowed += want as u32;
                if (k < 0.5) != want {
                    // Only within 2 pixels of the boundary.
                    let near = (0..16).any(|i| {
                        let a = i as f32 * std::f32::consts::TAU / 16.0;
                        let (dx, dz) = (a.cos() * 2.0 * px_size, a.sin() * 2.0 * px_size);
                        analytic_shadow(x + dx, z + dz, center, light) != want
                    });
                    assert!(near, "{method}: ({px},{py}) factor {k}, analytic {want}");
                    wrong += 1;
                }
            }
        }
        println!(
            "{method}: {wrong} boundary pixels differ of {shadowed} shadowed, {plane} plane pixels"
        );
        assert!(shadowed > 3000 && plane > 50_000, "{shadowed} {plane}");
    }
}

/// Whether any pixel within `r` (a square) of (x, y) in a `w` x `h` image
/// satisfies `f(index)`.
fn any_near(x: i32, y: i32, w: u32, h: u32, r: i32, f: impl Fn(usize) -> bool) -> bool {
    (-r..=r).any(|dy| {
        (-r..=r).any(|dx| {
            let (sx, sy) = (x + dx, y + dy);
            sx >= 0 && sy >= 0 && sx < w as i32 && sy < h as i32 && f((sy * w as i32 + sx) as usize)
        })
    })
}

/// Renders `scene` (with `{shadows}` in it) ray-traced, then with each map
/// filter, and returns per filter (wrongly shadowed, lit) pixels; prints
/// them under `label`.
fn acne_counts(dir: &Path, scene: &str, size: u32, label: &str) -> Vec<(usize, usize)> {
    let truth = shadow_factor(dir, scene, "raytraced");
    ["pcf", "hard"]
        .iter()
        .map(|method| {
            let f = shadow_factor(dir, scene, method);
            let (wrong, lit) = acne(&f, &truth, size, size, 0.5);
            let (partial, _) = acne(&f, &truth, size, size, 0.99);
            println!(
                "{label}: {method}: {wrong} of {lit} lit pixels in shadow ({partial} below 0.99)"
            );
            assert!(lit > 10_000, "{label}: {lit}");
            (wrong, lit)
        })
        .collect()
}

/// Fewer than 0.1% of lit pixels wrongly in shadow, for both filters.
fn assert_no_acne(counts: &[(usize, usize)], label: &str) {
    for &(wrong, lit) in counts {
        assert!(
            (wrong as f64) < lit as f64 * 1e-3,
            "{label}: {wrong} of {lit}"
        );
    }
}

/// Pixels wrongly in shadow among lit-side pixels: shadow-map factor below
/// `below` where the ray-traced factor is 1, away (more than 2 pixels)
/// from any ray-traced shadow.
fn acne(map: &[f32], truth: &[f32], w: u32, h: u32, below: f32) -> (usize, usize) {
    let (mut wrong, mut lit) = (0, 0);
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            let i = (y * w as i32 + x) as usize;
            if truth[i].is_nan() || truth[i] < 1.0 {
                continue;
            }
            if any_near(x, y, w, h, 2, |k| truth[k] < 1.0) {
                continue;
            }
            lit += 1;
            if map[i] < below {
                wrong += 1;
            }
        }
    }
    (wrong, lit)
}

#[test]
fn no_acne_on_a_sphere_and_plane_at_grazing_light() {
    let dir = common::scratch("acne_sphere");
    let size = 320u32;
    // 10 degrees above the horizon, from several azimuths.
    let e = 10f32.to_radians();
    for az in [0.0f32, 35.0, 100.0] {
        let a = az.to_radians();
        let light = Vec3::new(-e.cos() * a.cos(), -e.sin(), -e.cos() * a.sin());
        // A low camera, so the sphere's lit side fills the frame.
        let scene = |bias: &str| {
            sphere_on_plane_scene(&dir, light, size, bias).replace(
                TOP_DOWN,
                "[[camera]]\neye = [4.0, 2.5, 3.0]\ntarget = [0.0, 1.0, 0.0]\nfov = 45.0\n",
            )
        };
        let label = format!("sphere, azimuth {az}");
        assert_no_acne(&acne_counts(&dir, &scene(""), size, &label), &label);
        if az == 0.0 {
            // The measurement sees acne: without bias it is everywhere.
            let unbiased = "shadow_bias = { constant = 0.0, slope = 0.0, normal = 0.0 }";
            let counts = acne_counts(&dir, &scene(unbiased), size, "no bias");
            assert!(counts.iter().all(|&(w, l)| w * 100 > l), "{counts:?}");
        }
    }
}

#[test]
fn a_box_on_the_plane_meets_its_shadow() {
    // Peter-panning: the gap between a box's base and its shadow. A solid
    // box hides depth bias (the map holds its far, light-facing side, a
    // whole box width from the plane behind it); a thin wall (0.04 thick
    // along the light) shows any bias above its thickness.
    let dir = common::scratch("peter_panning");
    std::fs::write(
        dir.join("box.obj"),
        obj(procedural::cube([0.0, 0.5, 0.0], 0.5)),
    )
    .unwrap();
    std::fs::write(
        dir.join("ground.obj"),
        obj(procedural::ground(8.0, 0.0, 1.0)),
    )
    .unwrap();
    let size = 400u32;
    for (what, thick) in [("box", 1.0f32), ("wall", 0.04)] {
        for elevation in [30.0f32, 10.0] {
            for method in ["pcf", "hard"] {
                let gap = widest_gap(&dir, size, thick, elevation, method, "");
                println!("{what}, elevation {elevation}: {method}: widest gap {gap} px");
                assert!(
                    gap < 2,
                    "{what}, {method} at {elevation} degrees: gap {gap} px"
                );
            }
        }
    }
    // The measurement sees peter-panning: a depth bias above the wall's
    // thickness opens a gap.
    let biased = "shadow_bias = { constant = 16.0 }";
    let gap = widest_gap(&dir, size, 0.04, 10.0, "pcf", biased);
    println!("wall, elevation 10, constant bias 16 texels: widest gap {gap} px");
    assert!(gap >= 2, "{gap}");
}

/// Widest run (pixels) of plane lit by the map but shadowed by rays, next
/// to the base of a unit-high box `thick` wide along the light, which
/// travels along -x at `elevation` degrees; top-down view, rows across the
/// box. `extra`: more `[render]` keys.
fn widest_gap(dir: &Path, size: u32, thick: f32, elevation: f32, method: &str, extra: &str) -> u32 {
    let e = elevation.to_radians();
    let light = Vec3::new(-e.cos(), -e.sin(), 0.0);
    let scene = format!(
        "[output]\nwidth = {size}\nheight = {size}\n[render]\nshadows = \"{{shadows}}\"\n{extra}\n\
         [ambient]\ncolor = [0.0, 0.0, 0.0]\n\
         [[model]]\npath = \"ground.obj\"\n{MATTE}[[model]]\npath = \"box.obj\"\nscale = [{thick}, 1.0, 1.0]\n{MATTE}\
         [[light]]\nkind = \"directional\"\ndirection = [{}, {}, 0.0]\nirradiance = 1.0\nshadows = true\n{TOP_DOWN}",
        light.x, light.y
    );
    let truth = shadow_factor(dir, &scene, "raytraced");
    let f = shadow_factor(dir, &scene, method);
    // The first pixel column left of the base.
    let edge = ((-thick * 0.5 + 3.0) / 6.0 * size as f32).floor() as u32;
    let mut worst = 0;
    let mut rows = 0;
    for py in 0..size {
        let (_, z) = top_down_point(0, py, size, 6.0);
        if z.abs() > 0.45 {
            continue;
        }
        rows += 1;
        // Walk left from the base: pixels the ray tracer shadows before the
        // map's shadow begins.
        let mut gap = 0;
        for px in (0..edge).rev() {
            let i = (py * size + px) as usize;
            if f[i] < 0.5 {
                break;
            }
            if truth[i] < 0.5 {
                gap += 1;
            }
        }
        worst = worst.max(gap);
    }
    assert!(rows > 50, "{rows}");
    worst
}

#[test]
fn no_acne_on_diablo3_at_grazing_light() {
    let Some(assets) = common::shared_assets() else {
        return;
    };
    let dir = common::scratch("acne_diablo3");
    let t = assets.join("tinyrenderer");
    let size = 400u32;
    let e = 10f32.to_radians();
    for az in [20.0f32, 135.0, 250.0] {
        let a = az.to_radians();
        let light = Vec3::new(-e.cos() * a.cos(), -e.sin(), -e.cos() * a.sin());
        let scene = format!(
            "[output]\nwidth = {size}\nheight = {size}\n[render]\nshadows = \"{{shadows}}\"\n\
             [ambient]\ncolor = [0.0, 0.0, 0.0]\n\
             [[model]]\npath = \"{}\"\nscale = [2.0, 1.0, 2.0]\n{MATTE}\
             [[model]]\npath = \"{}\"\n{MATTE}\
             [[light]]\nkind = \"directional\"\ndirection = [{}, {}, {}]\nirradiance = 1.0\nshadows = true\n\
             [[camera]]\neye = [1.2, 0.6, 3.2]\ntarget = [0.0, -0.1, 0.0]\nfov = 45.0\n",
            t.join("floor.obj").display(),
            t.join("diablo3_pose/diablo3_pose.obj").display(),
            light.x,
            light.y,
            light.z
        );
        let label = format!("diablo3, azimuth {az}");
        assert_no_acne(&acne_counts(&dir, &scene, size, &label), &label);
    }
}

#[test]
fn ssao_leaves_no_halo_behind_a_floating_sphere() {
    // A sphere 3 units in front of a wall, AO radius 0.5: nothing on the
    // wall is within reach, so the wall around the silhouette stays 1.
    let dir = common::scratch("ssao_halo");
    std::fs::write(dir.join("sphere.obj"), obj(procedural::sphere(0.5, 64, 32))).unwrap();
    std::fs::write(dir.join("wall.obj"), obj(procedural::ground(4.0, 0.0, 1.0))).unwrap();
    let size = 200u32;
    let scene = format!(
        "[output]\nwidth = {size}\nheight = {size}\n[render]\nao = {{ method = \"ssao\", radius = 0.5 }}\n\
         [[model]]\npath = \"wall.obj\"\nrotate = [90.0, 0.0, 0.0]\ntranslate = [0.0, 0.0, -3.0]\n\
         [[model]]\npath = \"sphere.obj\"\n\
         [[camera]]\neye = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 40.0\n"
    );
    let f = render(&dir, &scene);
    let z = &f.depth;
    let (mut checked, mut worst) = (0, 1.0f32);
    for y in 0..size as i32 {
        for x in 0..size as i32 {
            let i = (y * size as i32 + x) as usize;
            if z[i] < 6.0 {
                continue; // the sphere
            }
            // Wall pixels within 8 pixels of the sphere's silhouette.
            if any_near(x, y, size, size, 8, |k| z[k] < 6.0) {
                checked += 1;
                worst = worst.min(f.ao[i]);
            }
        }
    }
    println!("halo: lowest wall AO next to the silhouette {worst} over {checked} pixels");
    assert!(checked > 300, "{checked}");
    assert!(worst > 0.98, "halo: {worst}");
}

/// Pixels where the map and the ray tracer disagree (factor on either side
/// of 1/2) that are more than 2 pixels from any ray-traced shadow edge.
fn disagreements_off_edges(map: &[f32], truth: &[f32], w: u32, h: u32) -> (usize, usize) {
    let shadowed = |x: i32, y: i32| truth[(y * w as i32 + x) as usize] < 0.5;
    let (mut far, mut near) = (0, 0);
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            let i = (y * w as i32 + x) as usize;
            if truth[i].is_nan() || map[i].is_nan() || (map[i] < 0.5) == shadowed(x, y) {
                continue;
            }
            let here = shadowed(x, y);
            let edge = any_near(x, y, w, h, 2, |k| {
                !truth[k].is_nan() && (truth[k] < 0.5) != here
            });
            if edge { near += 1 } else { far += 1 }
        }
    }
    (far, near)
}

/// Renders `models` under each of `lights` (name, `[[light]]` body) with
/// shadow maps, hard and PCF, and with ray-traced shadows: the maps must
/// agree with the rays except along shadow edges (at most 3 pixels), and
/// more than `min_shadowed` pixels must be in shadow.
fn maps_agree_with_ray_tracing(
    dir: &Path,
    models: &str,
    lights: &[(&str, &str)],
    camera: &str,
    min_shadowed: usize,
) {
    let size = 240u32;
    for (what, light) in lights {
        let scene = format!(
            "[output]\nwidth = {size}\nheight = {size}\n[render]\nshadows = \"{{shadows}}\"\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n\
             {models}[[light]]\n{light}\nshadows = true\n{camera}"
        );
        let truth = shadow_factor(dir, &scene, "raytraced");
        let in_shadow = truth.iter().filter(|k| **k < 0.5).count();
        for method in ["hard", "pcf"] {
            let f = shadow_factor(dir, &scene, method);
            let (far, near) = disagreements_off_edges(&f, &truth, size, size);
            println!(
                "{what} light, {method}: {far} pixels disagree away from edges, {near} along edges; {in_shadow} shadowed"
            );
            assert!(in_shadow > min_shadowed, "{what}: {in_shadow}");
            assert!(far <= 3, "{what} {method}: {far}");
        }
    }
}

#[test]
fn point_and_spot_shadow_maps_agree_with_ray_tracing() {
    // Spheres all around a point light (every cube face casts), and a spot
    // light over them; the maps must agree with ray-traced shadows except
    // along shadow edges.
    let dir = common::scratch("point_spot_shadows");
    std::fs::write(
        dir.join("sphere.obj"),
        obj(procedural::sphere(0.35, 64, 32)),
    )
    .unwrap();
    std::fs::write(
        dir.join("ground.obj"),
        obj(procedural::ground(6.0, 0.0, 1.0)),
    )
    .unwrap();
    let mut models = format!("[[model]]\npath = \"ground.obj\"\n{MATTE}");
    for (x, y, z) in [
        (1.0, 1.6, 0.2),
        (-1.1, 1.2, -0.3),
        (0.2, 1.4, 1.2),
        (-0.3, 1.8, -1.2),
        (0.5, 3.3, 0.3),
        (0.0, 0.9, 0.0),
    ] {
        models.push_str(&format!(
            "[[model]]\npath = \"sphere.obj\"\ntranslate = [{x}, {y}, {z}]\n{MATTE}"
        ));
    }
    let camera = "[[camera]]\neye = [3.5, 6.0, 5.0]\ntarget = [0.0, 0.8, 0.0]\nfov = 50.0\n";
    let lights = [
        (
            "point",
            "kind = \"point\"\nposition = [0.0, 1.9, 0.0]\nintensity = 10.0",
        ),
        (
            "spot",
            "kind = \"spot\"\nposition = [1.5, 4.0, 1.0]\ndirection = [-0.3, -1.0, -0.2]\nintensity = 40.0\ninner_angle = 30.0\nouter_angle = 40.0",
        ),
    ];
    maps_agree_with_ray_tracing(&dir, &models, &lights, camera, 2000);
}

#[test]
fn shadow_maps_reused_across_frames_match_maps_rendered_afresh() {
    // One renderer for all frames keeps the last frame's maps while the
    // lights and models stand still (a turntable that turns the camera):
    // those frames must equal frames whose maps are rendered afresh, and a
    // turntable that turns the models must never reuse a stale map.
    let dir = common::scratch("shadow_map_reuse");
    std::fs::write(
        dir.join("box.obj"),
        obj(procedural::cube([0.3, 0.5, 0.0], 0.5)),
    )
    .unwrap();
    std::fs::write(
        dir.join("ground.obj"),
        obj(procedural::ground(3.0, 0.0, 1.0)),
    )
    .unwrap();
    for rotate in ["camera", "models"] {
        let scene = load(
            &dir,
            &format!(
                "[output]\nwidth = 96\nheight = 72\n[render]\nshadows = \"pcf\"\nshadow_map_size = 256\n\
                 [[model]]\npath = \"box.obj\"\n[[model]]\npath = \"ground.obj\"\n\
                 [[light]]\nkind = \"directional\"\ndirection = [-0.6, -1.0, -0.3]\nshadows = true\n\
                 [[camera]]\neye = [0.0, 3.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n\
                 [animation]\nframes = 4\nturntable = {{ axis = [0.0, 1.0, 0.0], degrees = 360.0, rotate = \"{rotate}\" }}\n"
            ),
        );
        let shared = softraster::render::Renderer::new(&scene);
        let mut frames = Vec::new();
        for f in 0..4 {
            let mut out = Frame::new(0, 0);
            shared.render(Shot::new(0, f), &mut out).unwrap();
            let fresh = render_frame(&scene, 0, f);
            assert!(
                out.color == fresh.color,
                "rotate = {rotate}, frame {f}: the shared renderer's frame differs"
            );
            frames.push(out.color);
        }
        // The frames differ from each other (the turntable moves something,
        // and the shadow is in view).
        assert!(frames[0] != frames[2], "rotate = {rotate}");
    }
}

#[test]
fn a_flat_model_left_out_of_the_map_still_shadows_what_lies_beyond_it() {
    // A shelf (a flat square at height 1) over a floor, under a sun and
    // a lamp: the floor, below everything, is left out of the maps; the
    // shelf, with the floor beyond it, is not. The maps must agree with
    // ray-traced shadows away from edges, the shelf's shadow on the floor
    // included.
    let dir = common::scratch("flat_casters");
    std::fs::write(
        dir.join("floor.obj"),
        obj(procedural::ground(6.0, 0.0, 1.0)),
    )
    .unwrap();
    std::fs::write(
        dir.join("shelf.obj"),
        obj(procedural::ground(0.8, 1.0, 1.0)),
    )
    .unwrap();
    let camera = "[[camera]]\neye = [3.5, 6.0, 5.0]\ntarget = [0.0, 0.3, 0.0]\nfov = 50.0\n";
    let models =
        format!("[[model]]\npath = \"floor.obj\"\n{MATTE}[[model]]\npath = \"shelf.obj\"\n{MATTE}");
    let lights = [
        (
            "sun",
            "kind = \"directional\"\ndirection = [0.6, -1.0, 0.3]\nirradiance = 1.0",
        ),
        (
            "lamp",
            "kind = \"point\"\nposition = [-0.4, 2.6, 0.3]\nintensity = 10.0",
        ),
    ];
    maps_agree_with_ray_tracing(&dir, &models, &lights, camera, 1500);
}
