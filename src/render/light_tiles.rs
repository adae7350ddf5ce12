//! Light culling per tile: which lights can reach the points a tile of a
//! band shows. A tile is `TILE` columns of the band's rows; its visible
//! points lie in the frustum slice between its pixel edges and its nearest
//! and farthest depth, and a light whose range or spot cone misses that
//! slice's bounding box (`shade::light::may_reach`) is skipped for every
//! fragment of the tile. Such a light gives those fragments exactly
//! nothing, so the frame is bit for bit what shading every light gives.
//!
//! Only lights with a range or a cone can be culled; a frame with none
//! (directional lights, unlimited point lights) never builds tiles.

use glam::{DMat4, DVec4, Vec3};

use crate::raster::coverage::{NO_TRIANGLE, Visibility};
use crate::raster::setup::{SUBPIXEL, Tri};
use crate::scene::light::{Light, LightKind};
use crate::shade::light::{LightMask, may_reach};

/// Columns per tile (even, so a 2x2 quad never straddles two tiles).
pub const TILE: usize = 16;

/// What a frame needs to bound its tiles in world space.
pub(super) struct Culling {
    world_from_clip: DMat4,
    /// The frame's size in pixels.
    size: (f64, f64),
}

impl Culling {
    /// None when no light of `lights` can be culled (or the projection
    /// cannot be inverted), so every fragment gets every light.
    pub fn new(
        lights: &[Light],
        clip_from_world: glam::Mat4,
        width: u32,
        height: u32,
    ) -> Option<Culling> {
        let cullable = lights.iter().any(|l| match l.kind {
            LightKind::Directional { .. } => false,
            LightKind::Point { .. } | LightKind::Area { .. } => l.range.is_some_and(|r| r > 0.0),
            LightKind::Spot { .. } => true,
        });
        let m = clip_from_world.as_dmat4();
        let det = m.determinant();
        (cullable && det.is_finite() && det != 0.0).then(|| Culling {
            world_from_clip: m.inverse(),
            size: (width as f64, height as f64),
        })
    }

    /// The lights that may reach each tile of the band `vis` covers.
    /// `tris`: the frame's triangles (their depth slopes widen a tile's
    /// depth range with MSAA, where the shading point is not a sample).
    pub fn tiles(&self, lights: &[Light], vis: &Visibility, tris: &[Tri]) -> TileLights {
        let rect = vis.rect;
        let (tw, th) = (rect.width(), rect.height());
        let n = vis.samples();
        let count = tw.div_ceil(TILE);
        let mut masks = vec![LightMask::NONE; count];
        // Per tile: the depth range of its visible samples.
        let mut range = vec![(f64::INFINITY, f64::NEG_INFINITY); count];
        let mut slope = (NO_TRIANGLE, 0.0f64);
        for y in 0..th {
            for x in 0..tw {
                let r = &mut range[x / TILE];
                let i = (y * tw + x) * n;
                for s in i..i + n {
                    let id = vis.id()[s];
                    if id == NO_TRIANGLE {
                        continue;
                    }
                    let z = vis.depth()[s] as f64;
                    // With MSAA the shading point lies up to a pixel from
                    // the sample along each axis.
                    let g = if n == 1 {
                        0.0
                    } else {
                        if slope.0 != id {
                            slope = (id, depth_slope(&tris[id as usize]));
                        }
                        slope.1
                    };
                    r.0 = r.0.min(z - g);
                    r.1 = r.1.max(z + g);
                }
            }
        }
        for (k, (mask, &(z0, z1))) in masks.iter_mut().zip(&range).enumerate() {
            if z0 > z1 {
                continue;
            }
            // Pixel edges one pixel out, depths a little beyond (rounding of
            // the interpolated depth and position).
            let x0 = (rect.x0 as usize + k * TILE) as f64 - 1.0;
            let x1 = (rect.x0 as usize + ((k + 1) * TILE).min(tw)) as f64 + 1.0;
            let (y0, y1) = (rect.y0 as f64 - 1.0, rect.y1 as f64 + 1.0);
            let pad = |z: f64| 1e-6 * z.abs().max(1e-3);
            let box_ = self.bound([x0, x1], [y0, y1], [z0 - pad(z0), z1 + pad(z1)]);
            *mask = match box_ {
                Some((lo, hi)) => lights
                    .iter()
                    .enumerate()
                    .filter(|(_, l)| may_reach(l, lo, hi))
                    .fold(LightMask::NONE, |m, (i, _)| m.with(i)),
                None => LightMask::ALL,
            };
        }
        TileLights { masks }
    }

    /// The world-space box around the frustum slice between screen
    /// columns `x`, rows `y` (pixels) and depths `z` (as the visibility
    /// stores them), widened against rounding; None where it does not lie
    /// in front of the camera.
    fn bound(&self, x: [f64; 2], y: [f64; 2], z: [f64; 2]) -> Option<(Vec3, Vec3)> {
        let (w, h) = self.size;
        let mut lo = glam::DVec3::splat(f64::INFINITY);
        let mut hi = glam::DVec3::splat(f64::NEG_INFINITY);
        for sx in x {
            for sy in y {
                for sz in z {
                    let ndc = DVec4::new(sx / w * 2.0 - 1.0, 1.0 - sy / h * 2.0, sz, 1.0);
                    let p = self.world_from_clip * ndc;
                    // Behind the eye, or not a number.
                    if p.w.is_nan() || p.w <= 0.0 {
                        return None;
                    }
                    let p = p.truncate() / p.w;
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
        }
        let pad = 1e-4 * (hi - lo).length() + 1e-5 * lo.abs().max(hi.abs()).max_element() + 1e-6;
        let (lo, hi) = ((lo - pad).as_vec3(), (hi + pad).as_vec3());
        (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
    }
}

/// The change of a triangle's depth over one pixel along x plus along y
/// (the most it changes between two points of one pixel).
fn depth_slope(t: &Tri) -> f64 {
    let s = SUBPIXEL as f64;
    let (x, y, z) = (
        t.x.map(|v| v as f64 / s),
        t.y.map(|v| v as f64 / s),
        t.z.map(f64::from),
    );
    let d = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if d == 0.0 {
        return f64::INFINITY;
    }
    let dzdx = ((z[1] - z[0]) * (y[2] - y[0]) - (z[2] - z[0]) * (y[1] - y[0])) / d;
    let dzdy = ((z[2] - z[0]) * (x[1] - x[0]) - (z[1] - z[0]) * (x[2] - x[0])) / d;
    let g = dzdx.abs() + dzdy.abs();
    if g.is_finite() { g } else { f64::INFINITY }
}

/// Per tile of a band, the lights that may reach its visible points.
pub(super) struct TileLights {
    masks: Vec<LightMask>,
}

impl TileLights {
    /// The lights of the tile holding band column `x`.
    #[inline]
    pub fn at(&self, x: usize) -> LightMask {
        self.masks.get(x / TILE).copied().unwrap_or(LightMask::ALL)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::bin::TileRect;
    use crate::scene::camera::{Camera, Projection};
    use crate::scene::settings::DepthMode;
    use glam::Vec4;

    fn point(position: Vec3, range: Option<f32>) -> Light {
        Light {
            kind: LightKind::Point {
                position,
                intensity: 1.0,
            },
            color: Vec3::ONE,
            shadows: false,
            range,
        }
    }

    /// A 64x64 frame looking down -Z at a wall 5 away; the band of rows
    /// 24..40, four tiles of 16 columns.
    #[test]
    fn tiles_keep_only_the_lights_that_reach_them() {
        let camera = Camera {
            name: "test".into(),
            eye: Vec3::ZERO,
            target: Vec3::NEG_Z,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y: 60.0 },
            near: 0.1,
            far: 100.0,
            path: None,
        };
        let clip_from_world =
            camera.clip_from_view(1.0, DepthMode::Standard) * camera.view_from_world();
        let wall = clip_from_world * Vec4::new(0.0, 0.0, -5.0, 1.0);
        let rect = TileRect {
            x0: 0,
            y0: 24,
            x1: 64,
            y1: 40,
        };
        let mut id = vec![0; 64 * 16];
        // The middle 16 columns only: the left tile shows nothing.
        for y in 0..16 {
            id[y * 64..y * 64 + 16].fill(NO_TRIANGLE);
        }
        let vis = Visibility::from_parts(rect, &[(0, 0)], vec![wall.z / wall.w; 64 * 16], id);
        let lights = [
            // A small pool at the wall's center (x within 0.5 of 0, that
            // is columns 26..38: tiles 1 and 2).
            point(Vec3::new(0.0, 0.0, -5.0), Some(0.5)),
            // A spot facing away from the wall.
            Light {
                kind: LightKind::Spot {
                    position: Vec3::ZERO,
                    direction: Vec3::Z,
                    intensity: 1.0,
                    cos_inner: 0.95,
                    cos_outer: 0.9,
                },
                color: Vec3::ONE,
                shadows: false,
                range: None,
            },
            Light {
                kind: LightKind::Directional {
                    direction: -Vec3::Z,
                    irradiance: 1.0,
                    angle: 0.0,
                },
                color: Vec3::ONE,
                shadows: false,
                range: None,
            },
            // Unlimited.
            point(Vec3::new(30.0, 0.0, -5.0), None),
            // A spot on the wall's right edge (x from about 1.8 on, column
            // 52 on: tile 3 only).
            Light {
                kind: LightKind::Spot {
                    position: Vec3::new(2.5, 0.0, -1.0),
                    direction: Vec3::NEG_Z,
                    intensity: 1.0,
                    cos_inner: 8f32.to_radians().cos(),
                    cos_outer: 10f32.to_radians().cos(),
                },
                color: Vec3::ONE,
                shadows: false,
                range: None,
            },
        ];
        let culling = Culling::new(&lights, clip_from_world, 64, 64).unwrap();
        let tiles = culling.tiles(&lights, &vis, &[]);
        let has = |x: usize| {
            (0..lights.len())
                .filter(|&i| tiles.at(x).has(i))
                .collect::<Vec<_>>()
        };
        assert_eq!(has(0), Vec::<usize>::new(), "nothing visible");
        assert_eq!(has(16), vec![0, 2, 3]);
        assert_eq!(has(47), vec![0, 2, 3]);
        assert_eq!(has(63), vec![2, 3, 4]);
        // No light that can be culled: no tiles.
        assert!(Culling::new(&lights[2..4], clip_from_world, 64, 64).is_none());
    }

    #[test]
    fn a_steep_triangle_widens_its_tile_with_msaa() {
        // A triangle rising 0.1 in depth per pixel: the shading point may
        // be a pixel from its samples, so the depth range grows by 0.2.
        let s = SUBPIXEL as i32;
        let t = Tri {
            x: [0, 10 * s, 0],
            y: [0, 0, 10 * s],
            min_x: 0,
            min_y: 0,
            max_x: 9,
            max_y: 9,
            z: [0.1, 1.1, 0.1],
            inv_w: [1.0; 3],
            bary: [Vec3::X, Vec3::Y, Vec3::Z],
            area2: 1,
            draw: 0,
            prim: 0,
            front: true,
        };
        assert!((depth_slope(&t) - 0.1).abs() < 1e-6, "{}", depth_slope(&t));
    }
}
