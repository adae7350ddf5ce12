//! Rendered numbers against analytic truth: coverage, depth, radiance,
//! perspective-correct interpolation, and the camera inside a model.

use crate::common;

use common::render_frame;
use glam::{Mat4, Vec2, Vec3, Vec4};
use softraster::raster::CullMode;
use softraster::raster::bin::TileRect;
use softraster::raster::clip::{ClipVertex, Clipped, clip_triangle};
use softraster::raster::coverage::raster_triangle;
use softraster::raster::interp;
use softraster::raster::setup::{Viewport, setup};

/// A whole (unclipped) triangle: each vertex is its own barycentric corner.
fn corners(c: [Vec4; 3]) -> [ClipVertex; 3] {
    [
        ClipVertex {
            pos: c[0],
            bary: Vec3::X,
        },
        ClipVertex {
            pos: c[1],
            bary: Vec3::Y,
        },
        ClipVertex {
            pos: c[2],
            bary: Vec3::Z,
        },
    ]
}

fn screen_tri(p: [Vec2; 3], vp: Viewport) -> Option<softraster::raster::setup::Tri> {
    // Screen pixels -> clip space (w = 1).
    let c = p.map(|q| {
        Vec4::new(
            q.x / vp.width as f32 * 2.0 - 1.0,
            1.0 - q.y / vp.height as f32 * 2.0,
            0.5,
            1.0,
        )
    });
    let v = corners(c);
    setup(v, vp, CullMode::None, 0, 0)
}

fn coverage_count(tris: &[[Vec2; 3]], vp: Viewport) -> Vec<u32> {
    let mut count = vec![0u32; (vp.width * vp.height) as usize];
    let rect = TileRect {
        x0: 0,
        y0: 0,
        x1: vp.width as i32,
        y1: vp.height as i32,
    };
    for t in tris {
        if let Some(t) = screen_tri(*t, vp) {
            raster_triangle(&t, rect, |x, y, _| {
                count[(y as u32 * vp.width + x as u32) as usize] += 1
            });
        }
    }
    count
}

#[test]
fn two_triangles_sharing_a_diagonal_cover_every_pixel_once() {
    let vp = Viewport {
        width: 64,
        height: 48,
        msaa: false,
    };
    let (w, h) = (64.0, 48.0);
    let quad = [
        [Vec2::new(0.0, 0.0), Vec2::new(w, h), Vec2::new(w, 0.0)],
        [Vec2::new(0.0, 0.0), Vec2::new(0.0, h), Vec2::new(w, h)],
    ];
    let count = coverage_count(&quad, vp);
    assert!(
        count.iter().all(|&c| c == 1),
        "{:?}",
        count.iter().filter(|&&c| c != 1).count()
    );
    // A fan around an off-grid point, reaching past the screen on all sides:
    // shared edges in every direction, vertices at sub-pixel positions.
    let c = Vec2::new(23.37, 19.81);
    let ring: Vec<Vec2> = (0..9)
        .map(|i| {
            let a = i as f32 / 9.0 * std::f32::consts::TAU + 0.3;
            c + Vec2::new(a.cos(), a.sin()) * 90.0
        })
        .collect();
    let fan: Vec<[Vec2; 3]> = (0..9).map(|i| [c, ring[i], ring[(i + 1) % 9]]).collect();
    let count = coverage_count(&fan, vp);
    let bad = count.iter().filter(|&&c| c != 1).count();
    assert_eq!(bad, 0, "pixels not covered exactly once");
    // Pixel centers exactly on shared edges (integer + 0.5 coordinates).
    let grid = [
        [
            Vec2::new(0.5, 0.5),
            Vec2::new(32.5, 24.5),
            Vec2::new(64.5, 0.5),
        ],
        [
            Vec2::new(0.5, 0.5),
            Vec2::new(0.5, 48.5),
            Vec2::new(32.5, 24.5),
        ],
        [
            Vec2::new(0.5, 48.5),
            Vec2::new(64.5, 48.5),
            Vec2::new(32.5, 24.5),
        ],
        [
            Vec2::new(64.5, 0.5),
            Vec2::new(32.5, 24.5),
            Vec2::new(64.5, 48.5),
        ],
    ];
    let count = coverage_count(&grid, vp);
    for (i, c) in count.iter().enumerate() {
        assert!(*c <= 1, "pixel {i} drawn {c} times");
    }
    assert_eq!(count.iter().filter(|&&c| c == 1).count(), 64 * 48);
}

#[test]
fn a_quads_pixel_count_matches_its_area() {
    let vp = Viewport {
        width: 96,
        height: 96,
        msaa: false,
    };
    for (angle, half) in [
        (0.0f32, Vec2::new(20.3, 13.7)),
        (0.47, Vec2::new(31.1, 9.4)),
        (1.1, Vec2::new(25.0, 25.0)),
    ] {
        let c = Vec2::new(48.2, 47.6);
        let (s, co) = angle.sin_cos();
        let r = |v: Vec2| c + Vec2::new(v.x * co - v.y * s, v.x * s + v.y * co);
        let p = [
            r(Vec2::new(-half.x, -half.y)),
            r(Vec2::new(half.x, -half.y)),
            r(Vec2::new(half.x, half.y)),
            r(Vec2::new(-half.x, half.y)),
        ];
        let count = coverage_count(&[[p[0], p[1], p[2]], [p[0], p[2], p[3]]], vp);
        assert!(count.iter().all(|&c| c <= 1));
        let n = count.iter().sum::<u32>() as f32;
        let area = 4.0 * half.x * half.y;
        let perimeter = 4.0 * (half.x + half.y);
        // Only pixels along the boundary may differ from the area.
        assert!(
            (n - area).abs() <= perimeter * 0.5,
            "angle {angle}: {n} pixels for area {area}"
        );
    }
}

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
fn uvs_are_perspective_correct_on_a_tilted_plane() {
    // A large triangle receding from the camera; its UVs are its local x, z.
    let vp = Viewport {
        width: 120,
        height: 90,
        msaa: false,
    };
    let cam = softraster::scene::Camera {
        name: "c".into(),
        eye: Vec3::new(0.0, 1.0, 0.0),
        target: Vec3::new(0.0, 0.0, -5.0),
        up: Vec3::Y,
        projection: softraster::scene::camera::Projection::Perspective { fov_y: 70.0 },
        near: 0.1,
        far: 100.0,
        path: None,
    };
    let clip_from_world: Mat4 =
        cam.clip_from_view(120.0 / 90.0, Default::default()) * cam.view_from_world();
    let p = [
        Vec3::new(-4.0, 0.0, -1.0),
        Vec3::new(4.0, 0.0, -1.0),
        Vec3::new(0.0, 0.0, -30.0),
    ];
    let uv = p.map(|q| Vec2::new(q.x, q.z));
    let c = p.map(|q| clip_from_world * q.extend(1.0));
    assert!(matches!(clip_triangle(c, 10.0, 10.0), Clipped::Inside));
    let v = corners(c);
    let t = setup(v, vp, CullMode::None, 0, 0).unwrap();
    let world_from_view = cam.view_from_world().inverse();
    let rect = TileRect {
        x0: 0,
        y0: 0,
        x1: 120,
        y1: 90,
    };
    let mut n = 0;
    raster_triangle(&t, rect, |px, py, _| {
        let f = interp::at_pixel(&t, px, py);
        let got = uv[0] * f.lambda.x + uv[1] * f.lambda.y + uv[2] * f.lambda.z;
        let d = world_from_view
            .transform_vector3(common::view_ray(px as u32, py as u32, 120, 90, 70.0));
        let hit = cam.eye + d * (-cam.eye.y / d.y);
        let want = Vec2::new(hit.x, hit.z);
        assert!(
            (got - want).length() < 1e-4 * want.length().max(1.0),
            "({px},{py}) {got} vs {want}"
        );
        n += 1;
    });
    assert!(n > 1000);
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
