//! The ground shadow catcher (`[ground] shadow = true`): an invisible plane
//! under the models that shows only what they take from it, composited over
//! the background: the shadows of shadow-casting lights and a soft contact
//! occlusion. It is not an object: depth and the other buffers do not see
//! it. Per background pixel whose view ray meets the plane:
//!
//!   factor = (sum_i E_i v_i + E_a ao) / (sum_i E_i + E_a)
//!
//! with E_i the light's irradiance on the plane and v_i its visibility (a
//! ray through the scene's BVHs per pixel; 1 for lights that cast no
//! shadows), E_a the irradiance of the environment from above (or of
//! `[ambient]`), and ao the unoccluded fraction of 16 cosine-weighted rays
//! within half the models' radius: a soft contact shadow, computed per
//! frame on a 96x96 grid over the plane within 1.5 radii of the models'
//! center (1 beyond) and interpolated bilinearly. The catcher fades out
//! between 2 and 3 radii from the center.

use glam::{Vec3, Vec4};

use super::rays::CameraRays;
use super::setup::FrameSetup;
use crate::raytrace::Tracer;
use crate::scene::Light;
use crate::scene::settings::Background;
use crate::shade::ShadeContext;
use crate::shade::ao::{occlusion_at, pixel_hash};
use crate::shade::light::incidence;

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
        fs: &'a FrameSetup<'a>,
        ctx: &ShadeContext<'a>,
        tracer: Option<&'a Tracer<'a>>,
        width: u32,
        height: u32,
    ) -> Option<Ground<'a>> {
        let plane = fs.scene.ground.as_ref()?;
        let tracer = tracer?;
        if fs.scene.settings.shading.is_data_view() {
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
            rays: CameraRays::new(&fs.camera, width, height),
            height: plane.height,
            center: plane.center,
            radius: plane.radius,
            lights: &fs.lights,
            tracer,
            ambient,
            ao,
            transparent: fs.scene.settings.background == Background::Transparent,
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
            if !light.shadows || !self.tracer.occluded(origin, dir, t_max) {
                kept += e;
            }
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
/// 1.5 radii cannot meet the models, so the grid covers the rest.
fn contact_grid(tracer: &Tracer, height: f32, center: Vec3, radius: f32) -> Vec<f32> {
    use rayon::prelude::*;
    let half = AO_EXTENT * radius;
    let step = 2.0 * half / AO_GRID as f32;
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
                let seed = pixel_hash(x as u32, z as u32);
                *v = occlusion_at(tracer, p, Vec3::Y, AO_SAMPLES, radius * 0.5, seed);
            }
        });
    grid
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}
