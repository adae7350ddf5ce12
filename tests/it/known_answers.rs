//! Rendered numbers against analytic truth: depth, radiance and the camera
//! inside a model. (The raster stages' coverage and interpolation are
//! checked beside them, in `src/raster/known_answers.rs`.)

use crate::common;

use common::render_frame;
use glam::Vec3;

const QUAD_OBJ: &str = "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\n\
f 4/4/1 3/3/1 2/2/1 1/1/1\n";

#[test]
fn depth_of_a_tilted_plane_matches_the_ray_intersection() {
    let dir = common::scratch("depth_plane");
    let scene = common::scene_in(
        &dir,
        "[output]\nwidth = 96\nheight = 64\n[[model]]\npath = \"quad.obj\"\nscale = 20.0\n\
         rotate = [20.0, 0.0, 10.0]\ntranslate = [0.0, -1.0, -3.0]\n\
         [[camera]]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\nfov = 50.0\nnear = 0.1\nfar = 100.0\n",
        &[("quad.obj", QUAD_OBJ)],
    );
    let f = render_frame(&scene, 0, 0);
    let m = scene.models[0].world_from_object;
    let p0 = m.transform_point3(Vec3::ZERO);
    let n = m.transform_vector3(Vec3::Y).normalize();
    let mut checked = 0;
    for py in 0..64 {
        for px in 0..96 {
            let d = common::view_ray(px, py, 96, 64, 50.0);
            let t = n.dot(p0) / n.dot(d);
            let got = f.depth[(py * 96 + px) as usize];
            if t > 0.0 && got.is_finite() {
                let rel = ((got - t) / t).abs();
                assert!(
                    rel < 1e-5,
                    "({px},{py}): depth {got} vs analytic {t}, rel {rel:e}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 2000, "{checked}");
}

/// Ray against the tessellated sphere's triangles (the exact surface drawn).
fn ray_mesh(o: Vec3, d: Vec3, tris: &[[Vec3; 3]]) -> Option<f32> {
    let mut best: Option<f32> = None;
    for t in tris {
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            continue;
        }
        let s = o - t[0];
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let tt = e2.dot(q) / det;
        if u >= -1e-6 && v >= -1e-6 && u + v <= 1.0 + 1e-6 && tt > 0.0 {
            best = Some(best.map_or(tt, |b| b.min(tt)));
        }
    }
    best
}

#[test]
fn depth_of_a_sphere_matches_the_analytic_surface() {
    let dir = common::scratch("depth_sphere");
    let obj = softraster::procedural::sphere(1.0, 32, 16)
        .to_obj("s", "none.mtl", "m")
        .text;
    let obj = obj
        .replace("mtllib none.mtl\n", "")
        .replace("usemtl m\n", "");
    let scene = common::scene_in(
        &dir,
        "[output]\nwidth = 64\nheight = 64\n[[model]]\npath = \"sphere.obj\"\ntranslate = [0.2, -0.1, -4.0]\n\
         [[camera]]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\nfov = 40.0\nnear = 0.5\nfar = 50.0\n",
        &[("sphere.obj", &obj)],
    );
    let f = render_frame(&scene, 0, 0);
    let mesh = &scene.models[0].mesh;
    let m = scene.models[0].world_from_object;
    let tris: Vec<[Vec3; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| m.transform_point3(mesh.positions[i as usize])))
        .collect();
    let center = m.transform_point3(Vec3::ZERO);
    let mut checked = 0;
    for py in 0..64 {
        for px in 0..64 {
            let got = f.depth[(py * 64 + px) as usize];
            let d = common::view_ray(px, py, 64, 64, 40.0);
            let Some(t) = ray_mesh(Vec3::ZERO, d, &tris) else {
                continue;
            };
            if !got.is_finite() {
                // Only silhouette pixels may disagree on coverage.
                continue;
            }
            let rel = ((got - t) / t).abs();
            assert!(rel < 1e-5, "({px},{py}): {got} vs {t}, rel {rel:e}");
            // And the facets lie within their sagitta of the true sphere.
            let b = d.dot(center) / d.length_squared();
            let closest = (d * b - center).length();
            if closest < 0.9 {
                let true_t = b - ((1.0 - closest * closest).sqrt()) / d.length();
                assert!((t - true_t).abs() < 0.02, "{t} vs sphere {true_t}");
            }
            checked += 1;
        }
    }
    assert!(checked > 500, "{checked}");
}

#[test]
fn lambertian_plane_under_a_point_light_gives_kd_i_cos_over_r2() {
    let dir = common::scratch("lambert");
    let scene = common::scene_in(
        &dir,
        "[output]\nwidth = 80\nheight = 60\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n\
         [[model]]\npath = \"quad.obj\"\nscale = 10.0\n[model.material]\nkd = [0.5, 0.25, 0.125]\nks = [0.0, 0.0, 0.0]\nillum = 1\n\
         [[light]]\nkind = \"point\"\nposition = [0.3, 2.0, -0.5]\nintensity = 7.0\n\
         [[camera]]\neye = [0.0, 3.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 60.0\n",
        &[("quad.obj", QUAD_OBJ)],
    );
    let f = render_frame(&scene, 0, 0);
    let cam = &scene.cameras[0];
    let world_from_view = cam.view_from_world().inverse();
    let light = Vec3::new(0.3, 2.0, -0.5);
    let mut checked = 0;
    for py in 0..60 {
        for px in 0..80 {
            let c = f.color[(py * 80 + px) as usize];
            if !f.depth[(py * 80 + px) as usize].is_finite() {
                continue;
            }
            let d = world_from_view.transform_vector3(common::view_ray(px, py, 80, 60, 60.0));
            let t = -cam.eye.y / d.y;
            let p = cam.eye + d * t;
            let to_l = light - p;
            let r2 = to_l.length_squared();
            let cos = to_l.normalize().y;
            let e = 7.0 * cos / r2;
            let want = Vec3::new(0.5, 0.25, 0.125) * e;
            let err = (c.truncate() - want).abs().max_element();
            assert!(err < 1e-3 * want.x.max(1e-3), "({px},{py}): {c} vs {want}");
            checked += 1;
        }
    }
    assert!(checked > 2000, "{checked}");
}

#[test]
fn a_camera_inside_a_box_sees_walls_everywhere_without_nan() {
    let dir = common::scratch("inside_box");
    let obj = softraster::procedural::cube([0.0, 0.0, 0.0], 1.0)
        .to_obj("box", "none.mtl", "m")
        .text;
    let obj = obj
        .replace("mtllib none.mtl\n", "")
        .replace("usemtl m\n", "");
    let scene = common::scene_in(
        &dir,
        "[output]\nwidth = 64\nheight = 64\n[render]\ncull = \"none\"\n[[model]]\npath = \"box.obj\"\n\
         [[camera]]\neye = [0.1, 0.2, 0.3]\ntarget = [1.0, 0.5, -2.0]\nfov = 100.0\nnear = 0.01\n\
         [[light]]\nkind = \"point\"\nposition = [0.0, 0.5, 0.0]\nintensity = 1.0\n",
        &[("box.obj", &obj)],
    );
    let f = render_frame(&scene, 0, 0);
    assert!(f.color.iter().all(|c| c.is_finite()), "no NaN");
    assert!(
        f.depth
            .iter()
            .all(|d| d.is_finite() && *d > 0.0 && *d < 4.0)
    );
    // Triangles behind the eye cross the near plane: their parts in front
    // still render (the wall behind-left of the view is partly visible).
    let lit = f.color.iter().filter(|c| c.x > 0.0).count();
    assert!(lit > 64 * 64 / 2);
}

#[test]
fn pbr_plane_under_a_point_light_matches_appendix_b_by_hand() {
    // The MTL plane shaded as pbr: base color = Kd, metallic 0, roughness 1
    // (alpha 1: D = 1/pi, Vis = 1 / ((n.l + 1)(n.v + 1))), no ambient.
    let dir = common::scratch("pbr_plane");
    let scene = common::scene_in(
        &dir,
        "[output]\nwidth = 80\nheight = 60\n[render]\nshading = \"pbr\"\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n\
         [[model]]\npath = \"quad.obj\"\nscale = 10.0\n[model.material]\nkd = [0.5, 0.25, 0.125]\nmetallic = 0.0\nroughness = 1.0\n\
         [[light]]\nkind = \"point\"\nposition = [0.3, 2.0, -0.5]\nintensity = 7.0\n\
         [[camera]]\neye = [0.0, 3.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 60.0\n",
        &[("quad.obj", QUAD_OBJ)],
    );
    let f = render_frame(&scene, 0, 0);
    let cam = &scene.cameras[0];
    let world_from_view = cam.view_from_world().inverse();
    let light = Vec3::new(0.3, 2.0, -0.5);
    let base = Vec3::new(0.5, 0.25, 0.125);
    let pi = std::f32::consts::PI;
    let mut checked = 0;
    for py in 0..60 {
        for px in 0..80 {
            let i = (py * 80 + px) as usize;
            if !f.depth[i].is_finite() {
                continue;
            }
            let d = world_from_view.transform_vector3(common::view_ray(px, py, 80, 60, 60.0));
            let p = cam.eye + d * (-cam.eye.y / d.y);
            let to_l = light - p;
            let l = to_l.normalize();
            let v = (cam.eye - p).normalize();
            let h = (l + v).normalize();
            let (ndl, ndv) = (l.y, v.y);
            let fresnel = 0.04 + 0.96 * (1.0 - v.dot(h)).powi(5);
            let spec = fresnel / pi / ((ndl + 1.0) * (ndv + 1.0));
            let f_r = base * (1.0 - fresnel) / pi + Vec3::splat(spec);
            let want = f_r * (7.0 / to_l.length_squared()) * ndl;
            let got = f.color[i].truncate();
            let err = (got - want).abs().max_element();
            assert!(
                err < 1e-3 * want.max_element(),
                "({px},{py}): {got} vs {want}"
            );
            checked += 1;
        }
    }
    assert!(checked > 2000, "{checked}");
}

#[test]
fn a_half_transparent_quad_hides_its_diagonal_under_msaa() {
    // Two triangles sharing a diagonal, opacity 0.5, unlit red over black,
    // seen face-on: every covered sample is composited once, so each pixel
    // the quad covers wholly is 0.5 red, on the diagonal too (composited
    // over each pixel by their shares, the two triangles let the black
    // show through the diagonal's pixels twice).
    let dir = common::scratch("ka_blend_diagonal");
    let obj =
        "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nusemtl half\nf 1 2 3\nf 1 3 4\n";
    let mtl = "newmtl half\nKd 1 0 0\nd 0.5\n";
    for msaa in [1, 4, 8] {
        let scene = common::scene_in(
            &dir,
            &format!(
                "[output]\nwidth = 40\nheight = 40\nbackground = [0.0, 0.0, 0.0]\n\
                 [render]\nshading = \"unlit\"\nmsaa = {msaa}\ncull = \"none\"\n\
                 [ambient]\ncolor = [0.0, 0.0, 0.0]\n\
                 [[model]]\npath = \"q.obj\"\n\
                 [[camera]]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n\
                 projection = \"orthographic\"\nheight = 2.5\n"
            ),
            &[("q.obj", obj), ("m.mtl", mtl)],
        );
        let f = render_frame(&scene, 0, 0);
        // The quad spans pixels 4..36 on both axes; keep one pixel off
        // its outer edges.
        let mut diagonal = 0;
        for y in 5..35usize {
            for x in 5..35usize {
                let c = f.color[y * 40 + x];
                assert!(
                    (c.x - 0.5).abs() < 1e-5 && c.y.abs() < 1e-6,
                    "MSAA {msaa}, pixel ({x}, {y}): {c}"
                );
                diagonal += (x + y == 39 || x == y) as u32;
            }
        }
        assert!(diagonal > 25);
    }
}
