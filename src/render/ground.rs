//! The ground shadow catcher (`[ground] shadow = true`): an invisible plane
//! under the models that shows only what they take from it, composited over
//! the background: the shadows of shadow-casting lights and a soft contact
//! occlusion. It is not an object: depth and the other buffers do not see
//! it. Per background pixel whose view ray meets the plane:
//!
//!   factor = (sum_i E_i v_i + E_a ao) / (sum_i E_i + E_a)
//!
//! with E_i the light's irradiance on the plane and v_i its visibility (a
//! ray through the scene's BVHs per pixel, the open share of a cone of
//! rays for a light with a disc (`shade::soft_shadow`); 1 for lights that
//! cast no shadows), E_a the irradiance of the environment from above (or of
//! `[ambient]`), and ao the unoccluded fraction of 16 cosine-weighted rays
//! within half the models' radius: a soft contact shadow, computed per
//! frame on a 96x96 grid over the plane within 1.5 radii of the models'
//! center (1 beyond) and interpolated bilinearly. The catcher fades out
//! between 2 and 3 radii from the center.

use std::sync::OnceLock;

use glam::{Vec3, Vec4};

use super::draw_list::DrawList;
use super::rays::CameraRays;
use crate::raytrace::Tracer;
use crate::scene::Light;
use crate::scene::light::LightKind;
use crate::scene::settings::Background;
use crate::shade::ShadeContext;
use crate::shade::ao::{for_each_ray, pixel_hash};
use crate::shade::light::incidence;
use crate::shade::soft_shadow::open_share;

/// Rays of contact occlusion per grid point.
const AO_SAMPLES: u32 = 16;
/// Grid points of contact occlusion per side.
const AO_GRID: usize = 96;
/// The grid's half size, in models' radii.
const AO_EXTENT: f32 = 1.5;

pub(super) struct Ground<'a> {
    rays: CameraRays,
    height: f32,
    center: Vec3,
    radius: f32,
    lights: &'a [Light],
    tracer: &'a Tracer<'a>,
    /// Luminance of the light from above that is not a light.
    ambient: f32,
    /// Contact occlusion on the grid, rows along +Z.
    ao: Vec<f32>,
    transparent: bool,
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl<'a> Ground<'a> {
    /// The frame's catcher, when the scene asks for one.
    pub fn new(
        setup: &'a DrawList<'a>,
        ctx: &ShadeContext<'a>,
        tracer: Option<&'a Tracer<'a>>,
        width: u32,
        height: u32,
    ) -> Option<Ground<'a>> {
        let plane = setup.scene.ground.as_ref()?;
        let tracer = tracer?;
        if setup.scene.settings.shading.is_data_view() {
            return None;
        }
        let ambient = match ctx.env {
            Some(env) => luminance(env.irradiance(Vec3::Y)),
            None => luminance(ctx.ambient) * std::f32::consts::PI,
        };
        let ao = if ambient > 0.0 {
            contact_grid(tracer, plane.height, plane.center, plane.radius)
        } else {
            Vec::new()
        };
        Some(Ground {
            rays: CameraRays::new(&setup.camera, width, height),
            height: plane.height,
            center: plane.center,
            radius: plane.radius,
            lights: &setup.lights,
            tracer,
            ambient,
            ao,
            transparent: setup.scene.settings.background == Background::Transparent,
        })
    }

    /// `bg` with the catcher at pixel (px, py) composited over it: darkened
    /// by the catcher's factor, or, over a transparent background, black
    /// with the shadow's opacity as alpha.
    pub fn over(&self, bg: Vec4, px: i32, py: i32) -> Vec4 {
        let Some(f) = self.factor(px, py) else {
            return bg;
        };
        if self.transparent {
            Vec4::new(0.0, 0.0, 0.0, 1.0 - f)
        } else {
            (bg.truncate() * f).extend(bg.w)
        }
    }

    /// The share of light the plane keeps at the pixel (1: none taken).
    fn factor(&self, px: i32, py: i32) -> Option<f32> {
        let (o, d) = self.rays.ray(px, py);
        if d.y.abs() < 1e-6 {
            return None;
        }
        let t = (self.height - o.y) / d.y;
        if t <= 0.0 {
            return None;
        }
        let p = o + d * t;
        let r = Vec3::new(p.x - self.center.x, 0.0, p.z - self.center.z).length() / self.radius;
        let fade = 1.0 - smoothstep(2.0, 3.0, r);
        if fade <= 0.0 {
            return None;
        }
        let origin = p + Vec3::Y * self.tracer.epsilon;
        let (mut total, mut kept) = (self.ambient, 0.0);
        for light in self.lights {
            let Some(inc) = incidence(light, p) else {
                continue;
            };
            let e = luminance(inc.e) * inc.l.y.max(0.0);
            if e <= 0.0 {
                continue;
            }
            total += e;
            let t_max = if light.kind_is_directional() {
                f32::INFINITY
            } else {
                1.0
            };
            let dir = if t_max.is_finite() {
                light.position_or(p) - origin
            } else {
                inc.l
            };
            kept += e * match light.kind {
                _ if !light.shadows => 1.0,
                LightKind::Directional { angle, .. } if angle > 0.0 => {
                    open_share(self.tracer, angle, p, Vec3::Y, inc.l)
                }
                _ => f32::from(u8::from(!self.tracer.occluded(origin, dir, t_max))),
            };
        }
        if self.ambient > 0.0 {
            kept += self.ambient * self.contact(p);
        }
        if total <= 0.0 {
            return None;
        }
        Some(1.0 - fade * (1.0 - kept / total))
    }
}

impl Ground<'_> {
    /// Contact occlusion at plane point `p`, from the grid.
    fn contact(&self, p: Vec3) -> f32 {
        let half = AO_EXTENT * self.radius;
        let n = AO_GRID as f32;
        let gx = (p.x - self.center.x + half) / (2.0 * half) * n - 0.5;
        let gz = (p.z - self.center.z + half) / (2.0 * half) * n - 0.5;
        if !(gx > -0.5 && gz > -0.5 && gx < n - 0.5 && gz < n - 0.5) {
            return 1.0;
        }
        let (gx, gz) = (gx.clamp(0.0, n - 1.0), gz.clamp(0.0, n - 1.0));
        let (x0, z0) = (gx as usize, gz as usize);
        let (x1, z1) = ((x0 + 1).min(AO_GRID - 1), (z0 + 1).min(AO_GRID - 1));
        let (fx, fz) = (gx - x0 as f32, gz - z0 as f32);
        let at = |x: usize, z: usize| self.ao[z * AO_GRID + x];
        let a = at(x0, z0) + (at(x1, z0) - at(x0, z0)) * fx;
        let b = at(x0, z1) + (at(x1, z1) - at(x0, z1)) * fx;
        a + (b - a) * fz
    }
}

/// Contact occlusion on the grid: rays of half a radius from farther than
/// 1.5 radii cannot meet the models, so the grid covers the rest. Each
/// point casts `occlusion_at`'s rays (their directions depend only on the
/// point's place in the grid, so they are made once per process); a point
/// whose rays cannot reach any model's bounds is open without casting.
fn contact_grid(tracer: &Tracer, height: f32, center: Vec3, radius: f32) -> Vec<f32> {
    use rayon::prelude::*;
    let half = AO_EXTENT * radius;
    let step = 2.0 * half / AO_GRID as f32;
    let t_max = radius * 0.5;
    // The rays' directions are unit to within a few ulps: 1% is room.
    let reach = t_max * 1.01 + tracer.epsilon;
    let dirs = contact_rays();
    let mut grid = vec![1.0f32; AO_GRID * AO_GRID];
    grid.par_chunks_mut(AO_GRID)
        .enumerate()
        .for_each(|(z, row)| {
            for (x, v) in row.iter_mut().enumerate() {
                let p = Vec3::new(
                    center.x - half + (x as f32 + 0.5) * step,
                    height + tracer.epsilon,
                    center.z - half + (z as f32 + 0.5) * step,
                );
                if !tracer.any_within(p, reach) {
                    continue;
                }
                let at = (z * AO_GRID + x) * AO_SAMPLES as usize;
                let rays = &dirs[at..at + AO_SAMPLES as usize];
                let open = rays
                    .iter()
                    .filter(|&&d| !tracer.occluded(p, d, t_max))
                    .count();
                // As `occlusion_at` divides.
                *v = open as u32 as f32 / AO_SAMPLES as f32;
            }
        });
    grid
}

/// Per grid point (rows along +Z), the directions of its contact rays:
/// `occlusion_at`'s, around +Y with the point's `pixel_hash` seed.
fn contact_rays() -> &'static [Vec3] {
    static RAYS: OnceLock<Vec<Vec3>> = OnceLock::new();
    RAYS.get_or_init(|| {
        let mut dirs = Vec::with_capacity(AO_GRID * AO_GRID * AO_SAMPLES as usize);
        for z in 0..AO_GRID {
            for x in 0..AO_GRID {
                let seed = pixel_hash(x as u32, z as u32);
                for_each_ray(Vec3::Y, AO_SAMPLES, seed, |d| dirs.push(d));
            }
        }
        dirs
    })
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raytrace::Placed;
    use crate::raytrace::bvh::Bvh;
    use crate::shade::ao::occlusion_at;
    use glam::Mat4;

    /// The grid (its kept ray table and the skip of points far from every
    /// model) equals `occlusion_at` at every point, bit for bit: a box
    /// standing on the plane off the center, so that some points are near
    /// it, some under its overhang and most far from it.
    #[test]
    fn the_contact_grid_is_occlusion_at_every_point() {
        let (lo, hi) = (Vec3::new(0.2, 0.0, -0.4), Vec3::new(0.9, 0.6, 0.1));
        let corner = |k: u32| {
            Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let positions: Vec<Vec3> = (0..8).map(corner).collect();
        let quads = [
            [0, 1, 3, 2],
            [4, 6, 7, 5],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 5, 7, 3],
        ];
        let triangles: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let bvh = Bvh::build(&positions, &triangles);
        let tracer = Tracer::new(
            [Placed {
                bvh: &bvh,
                bounds: (lo, hi),
                world_from_object: Mat4::from_rotation_y(0.3),
            }],
            1.0,
        );
        let (height, center, radius) = (0.0, Vec3::new(0.1, 0.0, 0.0), 1.2);
        let grid = contact_grid(&tracer, height, center, radius);
        let half = AO_EXTENT * radius;
        let step = 2.0 * half / AO_GRID as f32;
        let mut shaded = 0;
        for z in 0..AO_GRID {
            for x in 0..AO_GRID {
                let p = Vec3::new(
                    center.x - half + (x as f32 + 0.5) * step,
                    height + tracer.epsilon,
                    center.z - half + (z as f32 + 0.5) * step,
                );
                let seed = pixel_hash(x as u32, z as u32);
                let want = occlusion_at(&tracer, p, Vec3::Y, AO_SAMPLES, radius * 0.5, seed);
                let got = grid[z * AO_GRID + x];
                assert_eq!(got.to_bits(), want.to_bits(), "point ({x}, {z})");
                shaded += (want < 1.0) as u32;
            }
        }
        // The box darkens part of the grid, and not all of it.
        assert!(
            shaded > 100 && shaded < (AO_GRID * AO_GRID) as u32 / 2,
            "{shaded}"
        );
    }
}
