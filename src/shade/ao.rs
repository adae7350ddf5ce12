//! Ambient occlusion per pixel, from the geometry buffer of the visible
//! surfaces (the pixel-center sample of each pixel): the fraction of the
//! cosine-weighted hemisphere around the normal that reaches no occluder
//! within `radius`. 1 = unoccluded.
//!
//! - `raytraced`: `samples` rays per pixel against the scene's BVH, from a
//!   fixed stratified pattern (Hammersley points, shifted per pixel by a
//!   hash of its coordinates: deterministic, no visible structure).
//! - `ssao`: ground-truth AO in screen space (GTAO, Jimenez et al. 2016):
//!   per pixel, slices through the view vector at rotated screen
//!   directions; in each slice the highest occluder within `radius` on both
//!   sides (from the depth buffer), then the exact cosine-weighted visible
//!   arc between the two horizons around the normal projected into the
//!   slice. The slice rotation and step offset follow a 4x4 pattern that a
//!   5x5 tent blur ([1 2 2 2 1] per axis) averages out exactly on flat
//!   surfaces; the blur's weights fall with a neighbor's distance from the
//!   pixel's tangent plane and with the angle between normals, so it does not
//!   cross depth edges.

use std::f32::consts::{FRAC_PI_2, PI, TAU};

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use crate::raytrace::Tracer;
use crate::scene::camera::{Camera, Projection};

/// One pixel of the geometry buffer.
#[derive(Debug, Clone, Copy)]
pub struct GPixel {
    /// Distance along the view axis; +inf where nothing was drawn.
    pub depth: f32,
    /// World-space position.
    pub position: Vec3,
    /// Interpolated unit normal (world space), facing the camera.
    pub normal: Vec3,
    /// Unit normal of the triangle's plane, facing the camera.
    pub geo_normal: Vec3,
    /// The specular lobe's perceptual roughness where the material's is
    /// one factor (metallic-roughness without a roughness map); -1 where
    /// it is not known here.
    pub roughness: f32,
}

impl GPixel {
    pub const EMPTY: GPixel = GPixel {
        depth: f32::INFINITY,
        position: Vec3::ZERO,
        normal: Vec3::Z,
        geo_normal: Vec3::Z,
        roughness: -1.0,
    };
}

/// The camera as SSAO needs it: pixel <-> view space.
#[derive(Debug, Clone, Copy)]
pub struct AoView {
    pub width: u32,
    pub height: u32,
    pub view_from_world: Mat4,
    /// Perspective: tan of half the vertical field of view; orthographic:
    /// half the view height. Times `aspect` horizontally.
    pub half: f32,
    pub aspect: f32,
    pub orthographic: bool,
}

impl AoView {
    pub fn new(cam: &Camera, width: u32, height: u32) -> AoView {
        let (half, orthographic) = match cam.projection {
            Projection::Perspective { fov_y } => ((fov_y.to_radians() * 0.5).tan(), false),
            Projection::Orthographic { height } => (height * 0.5, true),
        };
        AoView {
            width,
            height,
            view_from_world: cam.view_from_world(),
            half,
            aspect: width as f32 / height as f32,
            orthographic,
        }
    }

    /// View-space position of pixel (x, y)'s center at view depth `d`.
    #[inline]
    fn position(&self, x: f32, y: f32, d: f32) -> Vec3 {
        let sx = x / self.width as f32 * 2.0 - 1.0;
        let sy = 1.0 - y / self.height as f32 * 2.0;
        if self.orthographic {
            Vec3::new(sx * self.half * self.aspect, sy * self.half, -d)
        } else {
            Vec3::new(sx * self.half * self.aspect * d, sy * self.half * d, -d)
        }
    }

    /// The point of plane `pl` (view-space normal, n.p) seen at screen
    /// position (x, y) in pixels; None when the ray grazes it.
    #[inline]
    fn on_plane(&self, x: f32, y: f32, pl: glam::Vec4) -> Option<Vec3> {
        let n = pl.truncate();
        if self.orthographic {
            let o = self.position(x, y, 0.0);
            // o + t (0, 0, -1): n.o - t n.z = c.
            if n.z.abs() < 1e-4 {
                return None;
            }
            let t = (n.dot(o) - pl.w) / n.z;
            Some(o - Vec3::Z * t)
        } else {
            let r = self.position(x, y, 1.0);
            let nr = n.dot(r);
            if nr.abs() < 1e-4 * r.length() {
                return None;
            }
            let t = pl.w / nr;
            (t > 0.0).then_some(r * t)
        }
    }

    /// World size of one pixel at view depth `d`.
    #[inline]
    fn pixel_size(&self, d: f32) -> f32 {
        let h = 2.0 * self.half / self.height as f32;
        if self.orthographic { h } else { h * d }
    }
}

/// A hash of a pixel's coordinates to two numbers in [0, 1).
#[inline]
pub fn pixel_hash(x: u32, y: u32) -> (f32, f32) {
    let mut h = x.wrapping_mul(0x9E37_79B1) ^ y.wrapping_mul(0x85EB_CA77);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297A_2D39);
    h ^= h >> 15;
    let a = (h & 0xFFFF) as f32 / 65536.0;
    let b = (h >> 16) as f32 / 65536.0;
    (a, b)
}

#[inline]
fn radical_inverse(mut i: u32) -> f32 {
    i = i.reverse_bits();
    i as f32 * (1.0 / 4_294_967_296.0)
}

/// Ray-traced AO of every pixel of `g` (rows of `width` pixels).
pub fn raytraced(
    tracer: &Tracer,
    g: &[GPixel],
    width: u32,
    samples: u32,
    radius: Option<f32>,
) -> Vec<f32> {
    let t_max = radius.unwrap_or(f32::INFINITY);
    let n = samples.max(1);
    let w = width as usize;
    let mut out = vec![1.0f32; g.len()];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let p = &g[y * w + x];
            if !p.depth.is_finite() {
                continue;
            }
            let origin = p.position + p.geo_normal * tracer.epsilon;
            let seed = pixel_hash(x as u32, y as u32);
            *o = occlusion_at(tracer, origin, p.normal, n, t_max, seed);
        }
    });
    out
}

/// The unoccluded fraction of `n` cosine-weighted rays from `origin`
/// around unit `normal` (within `t_max`), a stratified pattern shifted by
/// `seed` (two numbers in [0, 1)).
pub fn occlusion_at(
    tracer: &Tracer,
    origin: Vec3,
    normal: Vec3,
    n: u32,
    t_max: f32,
    seed: (f32, f32),
) -> f32 {
    let mut open = 0u32;
    for_each_ray(normal, n, seed, |dir| {
        if !tracer.occluded(origin, dir, t_max) {
            open += 1;
        }
    });
    open as f32 / n as f32
}

/// The directions `occlusion_at` casts, in its order: `n` cosine-weighted
/// directions around unit `normal`, a stratified pattern shifted by
/// `seed`.
#[inline]
pub fn for_each_ray(normal: Vec3, n: u32, (su, sv): (f32, f32), mut f: impl FnMut(Vec3)) {
    let (tx, ty) = normal.any_orthonormal_pair();
    for i in 0..n {
        let u = ((i as f32 + 0.5) / n as f32 + su).fract();
        let v = (radical_inverse(i) + sv).fract();
        f(cosine_direction(normal, (tx, ty), (u, v)));
    }
}

/// The cosine-weighted direction about unit `normal` (with unit tangents
/// `tx`, `ty` across it) for (u, v) in [0, 1)^2: radius sqrt(u) at angle
/// 2 pi v on the disc, lifted to the hemisphere.
#[inline]
pub fn cosine_direction(normal: Vec3, (tx, ty): (Vec3, Vec3), (u, v): (f32, f32)) -> Vec3 {
    let r = u.sqrt();
    let phi = TAU * v;
    tx * (r * phi.cos()) + ty * (r * phi.sin()) + normal * (1.0 - u).max(0.0).sqrt()
}

/// 4x4 ordered pattern (0..16), for the per-pixel slice rotation and step
/// offset of SSAO.
const BAYER4: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];

/// Slices and steps per side for a budget of `samples` depth reads.
pub fn gtao_layout(samples: u32) -> (u32, u32) {
    let slices = (samples / 8).max(1);
    let steps = (samples / (2 * slices)).max(1);
    (slices, steps)
}

/// acos to within 7e-5 radians (Abramowitz and Stegun 4.4.45).
#[inline]
fn fast_acos(x: f32) -> f32 {
    let a = x.abs().min(1.0);
    let r =
        (1.0 - a).sqrt() * (1.570_728_8 + a * (-0.212_114_4 + a * (0.074_261 - a * 0.018_729_3)));
    if x < 0.0 { PI - r } else { r }
}

/// Screen-space (GTAO) AO of every pixel of `g`, blurred.
pub fn gtao(g: &[GPixel], view: &AoView, radius: f32, samples: u32) -> Vec<f32> {
    let raw = gtao_raw(g, view, radius, samples);
    blur(g, view, &raw)
}

/// GTAO before the blur.
pub fn gtao_raw(g: &[GPixel], view: &AoView, radius: f32, samples: u32) -> Vec<f32> {
    let (w, h) = (view.width as usize, view.height as usize);
    let (slices, steps) = gtao_layout(samples);
    let rot = view.view_from_world;
    // Each pixel's tangent plane in view space (n, n.p), NaN where empty:
    // a sample at an exact point of the slice's screen line is the ray
    // there met with the plane of the pixel it falls in (exact on planes;
    // a pixel center would sit off the slice and tilt flat horizons).
    let planes: Vec<glam::Vec4> = g
        .par_iter()
        .map(|p| {
            if !p.depth.is_finite() {
                return glam::Vec4::NAN;
            }
            let n = rot.transform_vector3(p.geo_normal);
            let q = rot.transform_point3(p.position);
            n.extend(n.dot(q))
        })
        .collect();
    // Slice directions per pattern value: (cos, sin) of (k + turn) pi / slices.
    let dirs: Vec<(f32, f32)> = (0..16 * slices)
        .map(|i| {
            let (t, k) = (i / slices, i % slices);
            let phi = (k as f32 + (t as f32 + 0.5) / 16.0) * PI / slices as f32;
            (phi.cos(), phi.sin())
        })
        .collect();
    let mut out = vec![1.0f32; g.len()];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let c = &g[y * w + x];
            if !c.depth.is_finite() {
                continue;
            }
            let (fx, fy) = (x as f32 + 0.5, y as f32 + 0.5);
            let p = view.position(fx, fy, c.depth);
            let n = rot.transform_vector3(c.normal).normalize_or(Vec3::Z);
            let v = if view.orthographic {
                Vec3::Z
            } else {
                (-p).normalize_or(Vec3::Z)
            };
            let r_px = (radius / view.pixel_size(c.depth)).min(h.max(w) as f32 * 0.5);
            if r_px < 1.0 {
                continue;
            }
            let turn = BAYER4[y % 4][x % 4] as u32;
            let jitter = (BAYER4[(y + 1) % 4][(x + 2) % 4] as f32 + 0.5) / 16.0;
            let mut sum = 0.0f32;
            let mut norm = 0.0f32;
            for k in 0..slices {
                let (dx, dy) = dirs[(turn * slices + k) as usize];
                let dv = Vec3::new(dx, -dy, 0.0);
                let Some(t_axis) = (dv - v * dv.dot(v)).try_normalize() else {
                    continue;
                };
                let axis = v.cross(t_axis);
                let np = n - axis * n.dot(axis);
                let len = np.length();
                if len < 1e-6 {
                    continue;
                }
                let cos_g = (np.dot(v) / len).clamp(-1.0, 1.0);
                let sign = if np.dot(t_axis) < 0.0 { -1.0 } else { 1.0 };
                let gamma = sign * fast_acos(cos_g);
                let sin_g = gamma.sin();
                let mut horizon = [-1.0f32; 2];
                for (side, best) in [(1.0f32, 0usize), (-1.0, 1)] {
                    for j in 0..steps {
                        let s = (j as f32 + jitter) / steps as f32;
                        let dist = 1.0 + s * (r_px - 1.0);
                        let sx = fx + side * dx * dist;
                        let sy = fy + side * dy * dist;
                        if sx < 0.0 || sy < 0.0 || sx >= w as f32 || sy >= h as f32 {
                            break;
                        }
                        let (ix, iy) = (sx as usize, sy as usize);
                        if ix == x && iy == y {
                            continue;
                        }
                        let pl = planes[iy * w + ix];
                        if pl.w.is_nan() {
                            continue;
                        }
                        let Some(q) = view.on_plane(sx, sy, pl) else {
                            continue;
                        };
                        let d = q - p;
                        if d.length_squared() > radius * radius {
                            continue;
                        }
                        // The sample's pixel center is off the slice by up
                        // to a pixel: measure its angle within the slice.
                        let ds = d - axis * d.dot(axis);
                        let l = ds.length();
                        if l <= 0.0 {
                            continue;
                        }
                        horizon[best] = horizon[best].max(ds.dot(v) / l);
                    }
                }
                let h2 = gamma + (fast_acos(horizon[0]) - gamma).min(FRAC_PI_2);
                let h1 = gamma + (-fast_acos(horizon[1]) - gamma).max(-FRAC_PI_2);
                let arc = |hh: f32| 0.25 * (-(2.0 * hh - gamma).cos() + cos_g + 2.0 * hh * sin_g);
                sum += len * (arc(h1) + arc(h2));
                norm += len * (cos_g + gamma * sin_g);
            }
            if norm > 0.0 {
                *o = (sum / norm).clamp(0.0, 1.0);
            }
        }
    });
    out
}

/// The depth- and normal-aware 5x5 tent blur: weights fall as
/// 1/(1+p^2)^2 with p the neighbor's distance from the pixel's tangent plane
/// in pixel footprints, times the squared cosine between the normals.
fn blur(g: &[GPixel], view: &AoView, raw: &[f32]) -> Vec<f32> {
    edge_aware_blur(g, view, raw, (&[1.0, 2.0, 2.0, 2.0, 1.0], 1), None, 1.0)
}

/// What `edge_aware_blur` filters: values that add and scale (an AO
/// factor, a colour, a colour with a share).
pub trait Blurred:
    Copy
    + Default
    + Send
    + Sync
    + std::ops::Add<Output = Self>
    + std::ops::Mul<f32, Output = Self>
    + std::ops::Div<f32, Output = Self>
{
}

impl Blurred for f32 {}
impl Blurred for glam::Vec3 {}
impl Blurred for glam::Vec4 {}

/// `raw` (a value per pixel of `g`) averaged over the square `tent` (its
/// weights along one axis, an odd count) whose taps lie `step` pixels
/// apart, weighted by how near each tap lies to the
/// centre's tangent plane (in footprints of `step` pixels) and how well
/// their normals agree: it does not cross depth edges or creases. With
/// `reach` (per pixel, a world distance), a tap also counts less the
/// farther it lies from the centre beyond the centre's reach. Pixels where
/// nothing was drawn take `empty` and are not read.
pub fn edge_aware_blur<T: Blurred>(
    g: &[GPixel],
    view: &AoView,
    raw: &[T],
    (tent, step): (&[f32], i32),
    reach: Option<&[f32]>,
    empty: T,
) -> Vec<T> {
    let (w, h) = (view.width as i32, view.height as i32);
    let half = (tent.len() / 2) as i32;
    let mut out = vec![empty; raw.len()];
    out.par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as i32;
            for (x, o) in row.iter_mut().enumerate() {
                let x = x as i32;
                let c = &g[(y * w + x) as usize];
                if !c.depth.is_finite() {
                    continue;
                }
                let px = view.pixel_size(c.depth) * step as f32;
                let inv_reach = reach.map_or(0.0, |r| 1.0 / r[(y * w + x) as usize]);
                let mut sum = T::default();
                let mut wsum = 0.0;
                for (j, wy) in tent.iter().enumerate() {
                    let sy = y + (j as i32 - half) * step;
                    if sy < 0 || sy >= h {
                        continue;
                    }
                    for (i, wx) in tent.iter().enumerate() {
                        let sx = x + (i as i32 - half) * step;
                        if sx < 0 || sx >= w {
                            continue;
                        }
                        let k = (sy * w + sx) as usize;
                        let s = &g[k];
                        if !s.depth.is_finite() {
                            continue;
                        }
                        // Distance from the center's tangent plane, in
                        // pixel footprints, and the normals' agreement.
                        let plane = c.normal.dot(s.position - c.position).abs() / px;
                        let agree = c.normal.dot(s.normal).max(0.0);
                        let fall = 1.0 / (1.0 + plane * plane);
                        let mut wt = wx * wy * fall * fall * agree * agree;
                        if reach.is_some() {
                            let far = (s.position - c.position).length() * inv_reach;
                            wt /= 1.0 + far * far;
                        }
                        sum = sum + raw[k] * wt;
                        wsum += wt;
                    }
                }
                *o = if wsum > 0.0 {
                    sum / wsum
                } else {
                    raw[(y * w + x) as usize]
                };
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_directions_lie_above_the_plane_with_mean_height_two_thirds() {
        let n = Vec3::new(0.6, 0.0, 0.8);
        let basis = n.any_orthonormal_pair();
        let count = 4096;
        let mut sum = 0.0;
        for i in 0..count {
            let uv = (
                (i as f32 + 0.5) / count as f32,
                (i * 37 % count) as f32 / count as f32,
            );
            let d = cosine_direction(n, basis, uv);
            assert!(d.dot(n) >= 0.0 && (d.length() - 1.0).abs() < 1e-4);
            sum += d.dot(n);
        }
        // E[cos] under p = cos / pi is 2/3.
        assert!((sum / count as f32 - 2.0 / 3.0).abs() < 0.01);
    }

    #[test]
    fn fast_acos_is_within_its_bound() {
        for i in 0..=2000 {
            let x = i as f32 / 1000.0 - 1.0;
            assert!((fast_acos(x) - x.acos()).abs() < 1e-4, "{x}");
        }
    }

    #[test]
    fn an_open_plane_is_unoccluded_at_any_tilt() {
        // A plane seen at an angle: every sample lies in the tangent plane,
        // so the horizons are the tangent and the visibility is exactly 1.
        let (w, h) = (64u32, 48u32);
        let cam = Camera {
            name: "c".into(),
            eye: Vec3::new(0.0, 2.0, 3.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y: 50.0 },
            near: 0.1,
            far: 50.0,
            path: None,
        };
        let view = AoView::new(&cam, w, h);
        let world_from_view = view.view_from_world.inverse();
        let mut g = vec![GPixel::EMPTY; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                // Intersect the pixel's ray with y = 0.
                let p = view.position(x as f32 + 0.5, y as f32 + 0.5, 1.0);
                let d = world_from_view.transform_vector3(p);
                if d.y >= -1e-3 {
                    continue;
                }
                let t = -cam.eye.y / d.y;
                let world = cam.eye + d * t;
                g[(y * w + x) as usize] = GPixel {
                    depth: t,
                    position: world,
                    normal: Vec3::Y,
                    geo_normal: Vec3::Y,
                    roughness: -1.0,
                };
            }
        }
        let ao = gtao(&g, &view, 0.5, 32);
        for (i, a) in ao.iter().enumerate() {
            assert!((a - 1.0).abs() < 2e-3, "pixel {i}: {a}");
        }
    }
}
