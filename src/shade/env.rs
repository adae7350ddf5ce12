//! Image-based lighting, prefiltered once per scene (Karis 2013, "Real
//! Shading in Unreal Engine 4"):
//!
//! - diffuse: the irradiance E(n) from order-2 spherical harmonics of the
//!   radiance (Ramamoorthi and Hanrahan 2001), exact for any environment
//!   whose detail lies in bands 0-2 (a uniform sky, a half-white sky);
//!   a Lambertian albedo kd reflects kd E(n) / pi, so a uniform
//!   environment of radiance L gives kd L;
//! - specular: the split sum. Radiance prefiltered with the GGX lobe for
//!   `LEVELS` roughnesses (n = v = r, cosine-weighted, filtered importance
//!   sampling from a box-filtered chain of the image) times a 2D table of
//!   the BRDF's scale and bias on f0, integrated once with the same GGX
//!   and separable Smith visibility as the lights' BRDF (`pbr::brdf`).
//!
//! Directions map to the image as the scene format says: u = 0.5 +
//! atan2(x, -z) / 2pi, v = acos(y) / pi, after the environment's rotation.

use std::f32::consts::PI;

use glam::{Mat3, Vec2, Vec3};
use rayon::prelude::*;

use crate::assets::environment::EnvImage;

/// Prefiltered roughness levels: 0, 0.2, ..., 1.
const LEVELS: usize = 6;
/// Importance samples per prefiltered texel.
const PREFILTER_SAMPLES: u32 = 128;
/// BRDF table resolution (n.v by roughness) and samples per entry.
const LUT_SIZE: usize = 32;
const LUT_SAMPLES: u32 = 256;

/// An equirectangular RGB float image.
#[derive(Debug, Clone)]
struct Equirect {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

impl Equirect {
    /// Bilinear lookup, wrapping in u and clamping in v.
    fn sample(&self, d: Vec3) -> Vec3 {
        self.sample_uv(direction_to_uv(d))
    }

    /// Bilinear lookup at image coordinates `uv`.
    fn sample_uv(&self, uv: Vec2) -> Vec3 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = (uv.y * self.height as f32 - 0.5).clamp(0.0, (self.height - 1) as f32);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let w = self.width as i64;
        let xi = |k: i64| ((x0 as i64 + k).rem_euclid(w)) as usize;
        let y1 = (y0 as usize + 1).min(self.height - 1);
        let t = |x: usize, y: usize| self.texels[y * self.width + x];
        let (y0, xa, xb) = (y0 as usize, xi(0), xi(1));
        let top = t(xa, y0).lerp(t(xb, y0), fx);
        let bottom = t(xa, y1).lerp(t(xb, y1), fx);
        top.lerp(bottom, fy)
    }

    /// Half the size, each texel the solid-angle-weighted mean of the 2x2
    /// it covers (an unweighted box would give the rows near the poles,
    /// which cover little of the sphere, as much say as the equator's).
    fn half(&self) -> Equirect {
        let (w, h) = ((self.width / 2).max(2), (self.height / 2).max(1));
        let mut texels = vec![Vec3::ZERO; w * h];
        let sin = |y: usize| ((y as f32 + 0.5) / self.height as f32 * PI).sin();
        texels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let (mut acc, mut weight) = (Vec3::ZERO, 0.0);
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let sx = (2 * x + dx).min(self.width - 1);
                    let sy = (2 * y + dy).min(self.height - 1);
                    acc += self.texels[sy * self.width + sx] * sin(sy);
                    weight += sin(sy);
                }
                *out = acc / weight;
            }
        });
        Equirect {
            width: w,
            height: h,
            texels,
        }
    }

    /// Solid angle of a texel at row `y`.
    fn texel_solid_angle(&self, y: usize) -> f32 {
        let theta = (y as f32 + 0.5) / self.height as f32 * PI;
        (2.0 * PI / self.width as f32) * (PI / self.height as f32) * theta.sin()
    }
}

/// The image coordinates of a direction (u from the left, v from the top).
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let d = d.normalize_or(Vec3::Y);
    Vec2::new(
        0.5 + d.x.atan2(-d.z) / (2.0 * PI),
        d.y.clamp(-1.0, 1.0).acos() / PI,
    )
}

/// The direction at image coordinates `uv` (the inverse of
/// `direction_to_uv`).
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let theta = uv.y * PI;
    let phi = (uv.x - 0.5) * 2.0 * PI;
    Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    )
}

/// An environment ready to shade with.
#[derive(Debug, Clone)]
pub struct EnvLight {
    /// Irradiance in SH: E(n) = sum sh[i] Y_i(n) (environment space).
    sh: [Vec3; 9],
    /// Prefiltered radiance for roughness k / (LEVELS - 1).
    levels: Vec<Equirect>,
    /// (scale, bias) of f0, by n.v (columns) and roughness (rows).
    lut: Vec<Vec2>,
    /// Environment from world: the inverse of the environment's rotation.
    env_from_world: Mat3,
    intensity: f32,
}

impl EnvLight {
    /// Prefilters `image`, seen turned by `rotation_deg` about +Y
    /// (counter-clockwise seen from above) and scaled by `intensity`.
    pub fn new(image: &EnvImage, intensity: f32, rotation_deg: f32) -> EnvLight {
        let base = Equirect {
            width: image.width as usize,
            height: image.height as usize,
            texels: image.texels.clone(),
        };
        let mut chain = vec![base];
        while chain.last().is_some_and(|l| l.height > 4) {
            let next = chain[chain.len() - 1].half();
            chain.push(next);
        }
        let sh = irradiance_sh(&chain[0]);
        // Mirror level: the image itself, at most 512 wide.
        let mirror = chain
            .iter()
            .find(|l| l.width <= 512)
            .unwrap_or(&chain[chain.len() - 1])
            .clone();
        let mut levels = vec![mirror];
        for k in 1..LEVELS {
            let roughness = k as f32 / (LEVELS - 1) as f32;
            let width = if k == 1 { 128 } else { 64 };
            levels.push(prefilter(&chain, roughness, width));
        }
        EnvLight {
            sh,
            levels,
            lut: brdf_lut(),
            env_from_world: Mat3::from_rotation_y(-rotation_deg.to_radians()),
            intensity,
        }
    }

    /// Irradiance on a surface with unit normal `n` (world space).
    pub fn irradiance(&self, n: Vec3) -> Vec3 {
        let y = sh_basis(self.env_from_world * n);
        let mut e = Vec3::ZERO;
        for (c, b) in self.sh.iter().zip(y) {
            e += *c * b;
        }
        e.max(Vec3::ZERO) * self.intensity
    }

    /// Radiance arriving from direction `d` (world space), unfiltered.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        self.levels[0].sample(self.env_from_world * d) * self.intensity
    }

    /// Radiance along reflection direction `r` (world space), prefiltered
    /// for perceptual `roughness`.
    pub fn prefiltered(&self, r: Vec3, roughness: f32) -> Vec3 {
        let uv = direction_to_uv(self.env_from_world * r);
        let x = roughness.clamp(0.0, 1.0) * (LEVELS - 1) as f32;
        let k = (x.floor() as usize).min(LEVELS - 2);
        let f = x - k as f32;
        let a = self.levels[k].sample_uv(uv);
        if f <= 0.0 {
            return a * self.intensity;
        }
        let b = self.levels[k + 1].sample_uv(uv);
        a.lerp(b, f) * self.intensity
    }

    /// The split sum's (scale, bias) of f0 for `n.v` and `roughness`.
    pub fn brdf(&self, ndv: f32, roughness: f32) -> Vec2 {
        let fx = ndv.clamp(0.0, 1.0) * (LUT_SIZE - 1) as f32;
        let fy = roughness.clamp(0.0, 1.0) * (LUT_SIZE - 1) as f32;
        let (x0, y0) = (fx.floor() as usize, fy.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(LUT_SIZE - 1), (y0 + 1).min(LUT_SIZE - 1));
        let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
        let at = |x: usize, y: usize| self.lut[y * LUT_SIZE + x];
        let top = at(x0, y0).lerp(at(x1, y0), tx);
        top.lerp(at(x0, y1).lerp(at(x1, y1), tx), ty)
    }
}

/// Where to look up the prefiltered radiance for a lobe of `roughness`
/// reflecting about unit normal `n` along mirror direction `r`: rough
/// lobes lean toward the normal (their off-specular peak), which the split
/// sum's n = v = r prefilter does not see (Lagarde and de Rousiers 2014,
/// "Moving Frostbite to PBR", the dominant direction).
pub fn dominant_direction(n: Vec3, r: Vec3, roughness: f32) -> Vec3 {
    let a = roughness * roughness;
    let f = (1.0 - a) * ((1.0 - a).sqrt() + a);
    n.lerp(r, f).normalize_or(r)
}

/// The real SH basis, bands 0-2, at unit direction `d`.
fn sh_basis(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_095,
        0.488_603 * y,
        0.488_603 * z,
        0.488_603 * x,
        1.092_548 * x * y,
        1.092_548 * y * z,
        0.315_392 * (3.0 * z * z - 1.0),
        1.092_548 * x * z,
        0.546_274 * (x * x - y * y),
    ]
}

/// Radiance projected on bands 0-2, convolved with the clamped cosine
/// (A0 = pi, A1 = 2pi/3, A2 = pi/4): irradiance coefficients.
fn irradiance_sh(img: &Equirect) -> [Vec3; 9] {
    let rows: Vec<[Vec3; 9]> = (0..img.height)
        .into_par_iter()
        .map(|y| {
            let mut acc = [Vec3::ZERO; 9];
            let dw = img.texel_solid_angle(y);
            for x in 0..img.width {
                let uv = Vec2::new(
                    (x as f32 + 0.5) / img.width as f32,
                    (y as f32 + 0.5) / img.height as f32,
                );
                let b = sh_basis(uv_to_direction(uv));
                let l = img.texels[y * img.width + x] * dw;
                for (a, bi) in acc.iter_mut().zip(b) {
                    *a += l * bi;
                }
            }
            acc
        })
        .collect();
    // The texels' solid angles, scaled to sum to exactly 4 pi.
    let total: f32 = (0..img.height)
        .map(|y| img.texel_solid_angle(y) * img.width as f32)
        .sum();
    let norm = 4.0 * PI / total;
    let mut sh = [Vec3::ZERO; 9];
    for r in rows {
        for (s, v) in sh.iter_mut().zip(r) {
            *s += v * norm;
        }
    }
    let band = [PI, 2.0 * PI / 3.0, 2.0 * PI / 3.0, 2.0 * PI / 3.0];
    for (i, s) in sh.iter_mut().enumerate() {
        *s *= if i < 4 { band[i] } else { PI / 4.0 };
    }
    sh
}

/// Point `i` of `n` of the Hammersley set.
fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new(
        i as f32 / n as f32,
        i.reverse_bits() as f32 * 2.328_306_4e-10,
    )
}

/// A GGX half vector around +Z for alpha `a` from a uniform point `xi`.
fn ggx_half(xi: Vec2, a: f32) -> Vec3 {
    let phi = 2.0 * PI * xi.x;
    let cos_t = ((1.0 - xi.y) / (1.0 + (a * a - 1.0) * xi.y))
        .max(0.0)
        .sqrt();
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// An orthonormal frame whose third axis is `n`.
fn frame(n: Vec3) -> Mat3 {
    let t = n.any_orthonormal_vector();
    Mat3::from_cols(t, n.cross(t), n)
}

/// Radiance convolved with the GGX lobe of `roughness` around each
/// direction (n = v = r), cosine-weighted, into a `width` x `width/2`
/// image; each sample reads the chain level whose texels match its share
/// of the lobe's solid angle.
fn prefilter(chain: &[Equirect], roughness: f32, width: usize) -> Equirect {
    let height = width / 2;
    let a = (roughness * roughness).max(1e-3);
    let base = &chain[0];
    let texel_omega = 4.0 * PI / (base.width * base.height) as f32;
    let samples: Vec<(Vec3, f32)> = (0..PREFILTER_SAMPLES)
        .filter_map(|i| {
            let h = ggx_half(hammersley(i, PREFILTER_SAMPLES), a);
            // l = reflect(-v, h) with v = n = +Z.
            let l = Vec3::new(2.0 * h.z * h.x, 2.0 * h.z * h.y, 2.0 * h.z * h.z - 1.0);
            if l.z <= 0.0 {
                return None;
            }
            // pdf of l: D(h) (n.h) / (4 v.h), with n = v: D / 4.
            let t = h.z * h.z * (a * a - 1.0) + 1.0;
            let d = a * a / (PI * t * t);
            let pdf = d / 4.0;
            let omega = 1.0 / (PREFILTER_SAMPLES as f32 * pdf);
            let lod = (0.5 * (omega / texel_omega).log2() + 1.0).max(0.0);
            Some((l, lod))
        })
        .collect();
    let mut texels = vec![Vec3::ZERO; width * height];
    texels
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let uv = Vec2::new(
                    (x as f32 + 0.5) / width as f32,
                    (y as f32 + 0.5) / height as f32,
                );
                let m = frame(uv_to_direction(uv));
                let (mut acc, mut weight) = (Vec3::ZERO, 0.0);
                for &(l, lod) in &samples {
                    let k = (lod.floor() as usize).min(chain.len() - 1);
                    let k1 = (k + 1).min(chain.len() - 1);
                    let f = (lod - k as f32).clamp(0.0, 1.0);
                    let d = m * l;
                    let c = chain[k].sample(d).lerp(chain[k1].sample(d), f);
                    acc += c * l.z;
                    weight += l.z;
                }
                *out = if weight > 0.0 {
                    acc / weight
                } else {
                    Vec3::ZERO
                };
            }
        });
    Equirect {
        width,
        height,
        texels,
    }
}

/// The split sum's second factor: for each (n.v, roughness), the scale
/// and bias of f0 in the directional albedo of the specular lobe, with the
/// lights' GGX and separable Smith visibility.
fn brdf_lut() -> Vec<Vec2> {
    (0..LUT_SIZE * LUT_SIZE)
        .into_par_iter()
        .map(|i| {
            let (ix, iy) = (i % LUT_SIZE, i / LUT_SIZE);
            let ndv = (ix as f32 / (LUT_SIZE - 1) as f32).max(1e-3);
            let roughness = iy as f32 / (LUT_SIZE - 1) as f32;
            let a = (roughness * roughness).max(2e-3);
            let a2 = a * a;
            let v = Vec3::new((1.0 - ndv * ndv).sqrt(), 0.0, ndv);
            let (mut scale, mut bias) = (0.0, 0.0);
            for k in 0..LUT_SAMPLES {
                let h = ggx_half(hammersley(k, LUT_SAMPLES), a);
                let vdh = v.dot(h);
                let l = h * (2.0 * vdh) - v;
                let (ndl, ndh) = (l.z, h.z);
                if ndl <= 0.0 || vdh <= 0.0 {
                    continue;
                }
                let vis = 1.0
                    / ((ndl + (a2 + (1.0 - a2) * ndl * ndl).sqrt())
                        * (ndv + (a2 + (1.0 - a2) * ndv * ndv).sqrt()));
                // f * cos / pdf with pdf = D (n.h) / (4 v.h): D cancels.
                let g = vis * 4.0 * vdh * ndl / ndh;
                let fc = (1.0 - vdh).powi(5);
                scale += (1.0 - fc) * g;
                bias += fc * g;
            }
            Vec2::new(scale, bias) / LUT_SAMPLES as f32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_and_image_coordinates_are_inverse() {
        // The middle of the image lies toward -Z, the top is +Y.
        assert!((direction_to_uv(-Vec3::Z) - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!(direction_to_uv(Vec3::Y).y.abs() < 1e-6);
        assert!((direction_to_uv(Vec3::X).x - 0.75).abs() < 1e-6);
        for d in [Vec3::new(0.3, 0.5, -0.8), Vec3::new(-0.9, -0.1, 0.2)] {
            let d = d.normalize();
            assert!((uv_to_direction(direction_to_uv(d)) - d).length() < 1e-5);
        }
    }

    fn half_white() -> EnvImage {
        let (w, h) = (256u32, 128u32);
        let texels = (0..w * h)
            .map(|i| if i / w < h / 2 { Vec3::ONE } else { Vec3::ZERO })
            .collect();
        EnvImage::new(w, h, texels).unwrap()
    }

    #[test]
    fn irradiance_of_uniform_and_half_white_skies() {
        let u = EnvLight::new(&EnvImage::uniform(Vec3::splat(2.0)), 1.0, 0.0);
        for n in [Vec3::X, -Vec3::Y, Vec3::new(0.6, 0.0, 0.8)] {
            let e = u.irradiance(n);
            // Within 0.3%: the 32x16 grid integrates band 2 only approximately.
            assert!(
                (e - Vec3::splat(2.0 * PI)).abs().max_element() < 0.02,
                "{e}"
            );
        }
        // Radiance 1 above the horizon: E = pi (1 + n_y) / 2.
        let s = EnvLight::new(&half_white(), 1.0, 0.0);
        for ny in [-1.0f32, -0.5, 0.0, 0.3, 1.0] {
            let n = Vec3::new((1.0 - ny * ny).sqrt(), ny, 0.0);
            let e = s.irradiance(n).x / PI;
            assert!((e - (1.0 + ny) / 2.0).abs() < 0.01, "n_y {ny}: {e}");
        }
    }

    #[test]
    fn the_split_sum_table_never_gains_energy() {
        let e = EnvLight::new(&EnvImage::uniform(Vec3::ONE), 1.0, 0.0);
        for r in [0.0, 0.3, 0.7, 1.0] {
            for ndv in [0.05, 0.5, 1.0] {
                let ab = e.brdf(ndv, r);
                // f0 = 1 reflects a + b of the light.
                assert!(
                    ab.x + ab.y <= 1.0 + 1e-3 && ab.x >= 0.0 && ab.y >= 0.0,
                    "{r} {ndv}: {ab}"
                );
            }
            // A prefiltered uniform environment stays uniform.
            let p = e.prefiltered(Vec3::new(0.2, 0.9, 0.1).normalize(), r);
            assert!((p - Vec3::ONE).abs().max_element() < 1e-3, "{p}");
        }
        // Smooth at normal incidence: nearly all of f0 = 1 comes back.
        let ab = e.brdf(1.0, 0.0);
        assert!(ab.x + ab.y > 0.98, "{ab}");
    }

    #[test]
    fn rotation_turns_the_environment_counter_clockwise_seen_from_above() {
        // A bright patch at the image's middle (toward -Z).
        let (w, h) = (64u32, 32u32);
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if (30..34).contains(&x) && (14..18).contains(&y) {
                    Vec3::ONE
                } else {
                    Vec3::ZERO
                }
            })
            .collect();
        let img = EnvImage::new(w, h, texels).unwrap();
        let e = EnvLight::new(&img, 1.0, 0.0);
        assert!(e.radiance(-Vec3::Z).x > 0.9);
        assert!(e.irradiance(-Vec3::Z).x > e.irradiance(Vec3::Z).x);
        // Turned by 90 degrees counter-clockwise seen from above, -Z goes to -X.
        let r = EnvLight::new(&img, 1.0, 90.0);
        assert!(r.radiance(-Vec3::X).x > 0.9, "{}", r.radiance(-Vec3::X));
        assert!(r.radiance(-Vec3::Z).x < 0.1);
    }
}
