//! The raster stages against analytic truth: shared edges covered exactly
//! once, a quad's pixel count against its area, and perspective-correct
//! interpolation on a receding plane.

use glam::{Mat4, Vec2, Vec3, Vec4};

use super::CullMode;
use super::bin::TileRect;
use super::clip::{ClipVertex, Clipped, clip_triangle};
use super::coverage::raster_triangle;
use super::interp;
use super::setup::{Tri, Viewport, setup};

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

fn screen_tri(p: [Vec2; 3], vp: Viewport) -> Option<Tri> {
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

#[test]
fn uvs_are_perspective_correct_on_a_tilted_plane() {
    // A large triangle receding from the camera; its UVs are its local x, z.
    let vp = Viewport {
        width: 120,
        height: 90,
        msaa: false,
    };
    // The camera at (0, 1, 0) looking down -Z and a little down, 70 degrees
    // of vertical field of view.
    let eye = Vec3::new(0.0, 1.0, 0.0);
    let f = (Vec3::new(0.0, 0.0, -5.0) - eye).normalize();
    let s = f.cross(Vec3::Y).normalize();
    let u = s.cross(f);
    let world_from_view = Mat4::from_cols(
        s.extend(0.0),
        u.extend(0.0),
        (-f).extend(0.0),
        eye.extend(1.0),
    );
    let view_from_world = world_from_view.inverse();
    // Right-handed, depth 0 at near (0.1) to 1 at far (100).
    let (near, far) = (0.1f32, 100.0f32);
    let g = 1.0 / 35f32.to_radians().tan();
    let clip_from_view = Mat4::from_cols(
        Vec4::new(g * 90.0 / 120.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, g, 0.0, 0.0),
        Vec4::new(0.0, 0.0, far / (near - far), -1.0),
        Vec4::new(0.0, 0.0, near * far / (near - far), 0.0),
    );
    let clip_from_world = clip_from_view * view_from_world;
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
        let d = world_from_view.transform_vector3(view_ray(px, py));
        let hit = eye + d * (-eye.y / d.y);
        let want = Vec2::new(hit.x, hit.z);
        assert!(
            (got - want).length() < 1e-4 * want.length().max(1.0),
            "({px},{py}) {got} vs {want}"
        );
        n += 1;
    });
    assert!(n > 1000);
}

/// The view-space direction through pixel (`px`, `py`) of a 120x90 frame
/// with a vertical field of view of 70 degrees.
fn view_ray(px: i32, py: i32) -> Vec3 {
    let t = 35f32.to_radians().tan();
    let x = ((px as f32 + 0.5) / 120.0 * 2.0 - 1.0) * t * (120.0 / 90.0);
    let y = (1.0 - (py as f32 + 0.5) / 90.0 * 2.0) * t;
    Vec3::new(x, y, -1.0)
}
