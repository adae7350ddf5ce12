//! Image-based lighting, prefiltered once per scene (Karis 2013, "Real
//! Shading in Unreal Engine 4"):
//!
//! - diffuse: the irradiance E(n), integrated directly over a
//!   box-filtered level of the image for the normals of a 32x32
//!   octahedral map (`IrradianceMap`; order-2 spherical harmonics, used
//!   before, flattened a sun's lit and unlit sides: a matte sphere in the
//!   courtyard HDRI differed from the sampled reference by FLIP 0.034);
//!   a Lambertian albedo kd reflects kd E(n) / pi, so a uniform
//!   environment of radiance L gives kd L exactly;
//! - specular: the split sum. Radiance prefiltered with the GGX lobe for
//!   `LEVELS` roughnesses (n = v = r, cosine-weighted, filtered importance
//!   sampling from a box-filtered chain of the image) times a 2D table of
//!   the BRDF's scale and bias on f0, integrated once with the same GGX
//!   and separable Smith visibility as the lights' BRDF (`pbr::brdf`).
//!
//! Directions map to the image as the scene format says: u = 0.5 +
//! atan2(x, -z) / 2pi, v = acos(y) / pi, after the environment's rotation.

use std::f32::consts::PI;

use glam::{Mat3, Vec2, Vec3, Vec3A};
use rayon::prelude::*;

use crate::assets::environment::EnvImage;

pub use discs::{Disc, disc_lobe};

pub mod bounce;
mod discs;
pub mod emitters;
mod image_sampler;
mod octahedral;
pub(crate) mod pattern;
pub mod reflect;
pub mod sampled;

use octahedral::Octahedral;

use crate::simd::{Lane, V3};

/// Prefiltered roughness levels: 0, 0.1, ..., 1 (0.2 apart blurred the
/// highlights of roughness 0.1 against Mitsuba: mean FLIP of that sphere
/// 0.17 -> 0.08).
const LEVELS: usize = 11;
/// Widest mirror level (roughness 0 and the sharp background).
const MIRROR_MAX_WIDTH: usize = 2048;
/// Importance samples per prefiltered texel (`prefilter_samples`).
const PREFILTER_SAMPLES: u32 = 128;

/// Samples per texel for a level of `roughness`: the narrow lobes of the
/// sharp levels (the widest images) read a filtered chain level per
/// sample, so fewer samples cover them.
fn prefilter_samples(roughness: f32) -> u32 {
    if roughness <= 0.2 {
        PREFILTER_SAMPLES / 2
    } else {
        PREFILTER_SAMPLES
    }
}
/// BRDF table resolution (n.v by roughness) and samples per entry.
const LUT_SIZE: usize = 32;
const LUT_SAMPLES: u32 = 256;

/// An equirectangular RGB float image (16-byte texels: a bilinear lookup
/// is four SIMD loads and three SIMD lerps).
#[derive(Debug, Clone)]
struct Equirect {
    width: usize,
    height: usize,
    texels: Vec<Vec3A>,
}

impl Equirect {
    /// Bilinear lookup at image coordinates (u, v) (u in [0, 1] as
    /// `direction_to_uv` gives it; any finite u wraps).
    #[inline]
    fn sample_uv(&self, u: f32, v: f32) -> Vec3A {
        let (x0, y0, fx, fy) = self.place(u, v);
        self.blend(x0.lane(0) as i64, y0.lane(0) as usize, fx, fy)
    }

    /// Where bilinear lookups at (u, v) read, per lane: the top-left
    /// texel's column (any: it wraps) and row, and the weights toward
    /// the next ones.
    #[inline(always)]
    fn place<L: Lane>(&self, u: L, v: L) -> (L, L, L, L) {
        let x = u * L::splat(self.width as f32) - L::splat(0.5);
        let y = (v * L::splat(self.height as f32) - L::splat(0.5))
            .max(L::splat(0.0))
            .min(L::splat((self.height - 1) as f32));
        let (x0, y0) = (x.floor(), y.floor());
        (x0, y0, x - x0, y - y0)
    }

    /// `sample_uv` per lane of (u, v), times `scale`, lerped toward
    /// `next`'s lookups by `f` where `f` > 0.
    #[inline(always)]
    fn sample_lanes<L: Lane>(&self, next: &Equirect, u: L, v: L, f: f32, scale: f32) -> V3<L> {
        let (x0, y0, fx, fy) = self.place(u, v);
        // Finite: u and v come from `direction_to_uv` (in [0, 1]) and y
        // is clamped; `as` saturates in any case.
        let at = |e: &Equirect, (x0, y0, fx, fy): (L, L, L, L), k: usize| {
            e.blend(
                x0.lane(k) as i64,
                y0.lane(k) as usize,
                fx.lane(k),
                fy.lane(k),
            )
        };
        if f <= 0.0 {
            return V3::from_fn(|k| Vec3::from(at(self, (x0, y0, fx, fy), k) * scale));
        }
        let p = next.place(u, v);
        V3::from_fn(|k| Vec3::from(at(self, (x0, y0, fx, fy), k).lerp(at(next, p, k), f) * scale))
    }

    /// The bilinear blend of the texels at column `x0` (any: it wraps) and
    /// row `y0` (< height) and their next neighbours, with weights `fx`,
    /// `fy` toward the neighbours.
    #[inline(always)]
    fn blend(&self, x0: i64, y0: usize, fx: f32, fy: f32) -> Vec3A {
        let w = self.width as i64;
        // x0 lies in [-1, w - 1] for u in [0, 1]: one step wraps it.
        let wrap = |k: i64| -> usize {
            if (0..w).contains(&k) {
                k as usize
            } else {
                k.rem_euclid(w) as usize
            }
        };
        let (xa, xb) = (wrap(x0), wrap(x0 + 1));
        let y1 = (y0 + 1).min(self.height - 1);
        let row0 = &self.texels[y0 * self.width..(y0 + 1) * self.width];
        let row1 = &self.texels[y1 * self.width..(y1 + 1) * self.width];
        let top = row0[xa].lerp(row0[xb], fx);
        let bottom = row1[xa].lerp(row1[xb], fx);
        top.lerp(bottom, fy)
    }

    /// Half the size, each texel the solid-angle-weighted mean of the 2x2
    /// it covers (an unweighted box would give the rows near the poles,
    /// which cover little of the sphere, as much say as the equator's).
    fn half(&self) -> Equirect {
        let (w, h) = ((self.width / 2).max(2), (self.height / 2).max(1));
        let mut texels = vec![Vec3A::ZERO; w * h];
        let sin = |y: usize| ((y as f32 + 0.5) / self.height as f32 * PI).sin();
        texels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let (mut acc, mut weight) = (Vec3A::ZERO, 0.0);
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

/// The image coordinates of a direction (u from the left, v from the top);
/// `d` need not be unit length (zero or non-finite reads as +Y).
#[inline]
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let (u, v) = direction_to_uv_lanes(V3::<f32>::from(d));
    Vec2::new(u, v)
}

/// `direction_to_uv` per lane: (u, v).
#[inline(always)]
fn direction_to_uv_lanes<L: Lane>(d: V3<L>) -> (L, L) {
    // acos(y / |d|) = atan2(|(x, z)|, y): both angles are ratios, so no
    // normalization is needed, and the second is exact near the poles.
    let horizontal = (d.x * d.x + d.z * d.z).sqrt();
    let u = L::splat(0.5) + atan2(d.x, -d.z) * L::splat(0.5 / PI);
    let v = atan2(horizontal, d.y) * L::splat(1.0 / PI);
    let finite = d.is_finite_mask();
    (
        L::select(finite, u, L::splat(0.5)),
        L::select(finite, v, L::splat(0.0)),
    )
}

/// The atan polynomial's coefficients (`atan2`).
const ATAN_C: [f32; 7] = [
    0.999_996_1,
    -0.333_173_7,
    0.198_078_17,
    -0.132_333_43,
    0.079_623_66,
    -0.033_604_197,
    0.006_811_782,
];

/// atan2(y, x) per lane, to within 6e-7 radians (f32 rounding included)
/// (libm's is a call and several times slower; a thousandth of a texel
/// of a 2048-wide image is 3e-6 rad). Odd polynomial of degree 13 for
/// atan on [0, 1], fitted to minimize the largest error, then folded
/// into the four quadrants.
#[inline(always)]
fn atan2<L: Lane>(y: L, x: L) -> L {
    let zero = L::splat(0.0);
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    let a = lo / hi;
    let s = a * a;
    let mut p = L::splat(ATAN_C[6]);
    for &c in ATAN_C[..6].iter().rev() {
        p = p * s + L::splat(c);
    }
    let mut r = p * a;
    r = L::select(ay.cmpgt(ax), L::splat(std::f32::consts::FRAC_PI_2) - r, r);
    r = L::select(x.cmplt(zero), L::splat(PI) - r, r);
    r = L::select(y.cmplt(zero), -r, r);
    r = L::select(hi.cmpeq(zero), zero, r);
    L::select(x.is_nan() | y.is_nan(), L::splat(f32::NAN), r)
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
    /// Irradiance E(n) per environment-space normal (`IrradianceMap`).
    irradiance: IrradianceMap,
    /// Prefiltered radiance for roughness k / (LEVELS - 1).
    levels: Vec<Equirect>,
    /// (scale, bias) of f0, by n.v (columns) and roughness (rows).
    lut: Vec<Vec2>,
    /// Environment from world: the inverse of the environment's rotation
    /// (None: not turned, the common case, which skips the product).
    env_from_world: Option<Mat3>,
    intensity: f32,
    /// Per Blinn-Phong roughness the scene uses (`with_phong_roughness`):
    /// the two prefiltered levels around it blended into one octahedral
    /// map, so a lookup reads one level instead of two and needs no arc
    /// tangents.
    phong: Vec<(u32, Octahedral)>,
    /// The image before lights were taken out of it (`with_backdrop`),
    /// for `radiance`: what the background and refraction show.
    backdrop: Option<Equirect>,
}

/// At most this many blended levels (distinct Blinn-Phong exponents) per
/// scene; materials beyond them blend two lookups (the same values to
/// within rounding).
const MAX_PHONG_LEVELS: usize = 16;

impl EnvLight {
    /// Prefilters `image`, seen turned by `rotation_deg` about +Y
    /// (counter-clockwise seen from above) and scaled by `intensity`, with
    /// the default level sizes.
    #[cfg(test)]
    pub fn new(image: &EnvImage, intensity: f32, rotation_deg: f32) -> EnvLight {
        EnvLight::with_size(image, intensity, rotation_deg, 128)
    }

    /// `new` with the level of roughness 0.2 `size` texels wide, the
    /// sharper one (0.1) twice that and the rougher ones half that (at
    /// least 8).
    pub fn with_size(image: &EnvImage, intensity: f32, rotation_deg: f32, size: u32) -> EnvLight {
        let base = Equirect {
            width: image.width as usize,
            height: image.height as usize,
            texels: image.texels.iter().map(|&t| Vec3A::from(t)).collect(),
        };
        let mut chain = vec![base];
        while chain.last().is_some_and(|l| l.height > 4) {
            let next = chain[chain.len() - 1].half();
            chain.push(next);
        }
        let irradiance = IrradianceMap::new(&chain);
        // Mirror level (also the background): the image itself, at most
        // 2048 wide (25 MB). A narrower cap blurred `background =
        // "environment"` against the image: at 512 wide, the courtyard
        // behind a sphere row was the largest part of the difference to
        // Mitsuba's render (benches/mitsuba_env.py).
        let mirror = chain
            .iter()
            .find(|l| l.width <= MIRROR_MAX_WIDTH)
            .unwrap_or(&chain[chain.len() - 1])
            .clone();
        let mut levels = vec![mirror];
        for k in 1..LEVELS {
            let roughness = k as f32 / (LEVELS - 1) as f32;
            let size = (size as usize).max(8);
            let width = match k {
                1 => 2 * size,
                2 => size,
                _ => (size / 2).max(8),
            };
            levels.push(prefilter(&chain, roughness, width));
        }
        EnvLight {
            irradiance,
            levels,
            lut: brdf_lut(),
            env_from_world: (rotation_deg != 0.0)
                .then(|| Mat3::from_rotation_y(-rotation_deg.to_radians())),
            intensity,
            phong: Vec::new(),
            backdrop: None,
        }
    }

    /// `radiance` reads `image` (the environment before lights were taken
    /// out of it), halved to at most 2048 texels wide like the mirror
    /// level.
    pub fn with_backdrop(mut self, image: &EnvImage) -> EnvLight {
        let mut level = Equirect {
            width: image.width as usize,
            height: image.height as usize,
            texels: image.texels.iter().map(|&t| Vec3A::from(t)).collect(),
        };
        while level.width > MIRROR_MAX_WIDTH && level.height > 4 {
            level = level.half();
        }
        self.backdrop = Some(level);
        self
    }

    /// Adds blended levels for these perceptual roughnesses (those of the
    /// scene's Blinn-Phong materials), for `prefiltered_phong`.
    pub fn with_phong_roughness(mut self, roughness: impl IntoIterator<Item = f32>) -> EnvLight {
        for r in roughness {
            if self.phong.len() == MAX_PHONG_LEVELS {
                break;
            }
            if self.phong.iter().any(|(bits, _)| *bits == r.to_bits()) {
                continue;
            }
            // A little more than the sharper level's texels along the
            // equator (about 2.8 n for an n x n map).
            let (k, _) = level_of(r);
            let size = (self.levels[k].width / 2).max(16);
            let level = Octahedral::from_fn(size, |d| self.level_blend(d, r));
            self.phong.push((r.to_bits(), level));
        }
        self
    }

    /// `prefiltered` for a Blinn-Phong material of perceptual `roughness`:
    /// from its blended level where `with_phong_roughness` made one.
    pub fn prefiltered_phong(&self, r: Vec3, roughness: f32) -> Vec3 {
        self.prefiltered_phong_lanes(V3::<f32>::from(r), roughness)
            .into()
    }

    /// `prefiltered_phong` per lane, for one roughness.
    #[inline]
    pub fn prefiltered_phong_lanes<L: Lane>(&self, r: V3<L>, roughness: f32) -> V3<L> {
        match self.phong_level(roughness) {
            Some(level) => {
                let (u, v) = octahedral::encode(self.to_env(r));
                V3::from_fn(|k| Vec3::from(level.at(u.lane(k), v.lane(k)) * self.intensity))
            }
            None => self.prefiltered_lanes(r, roughness),
        }
    }

    /// The two prefiltered levels around `roughness`, blended, along
    /// environment direction `d` (without the intensity).
    fn level_blend(&self, d: Vec3, roughness: f32) -> Vec3A {
        let (u, v) = direction_to_uv_lanes(V3::<f32>::from(d));
        let (k, f) = level_of(roughness);
        let a = self.levels[k].sample_uv(u, v);
        if f <= 0.0 {
            return a;
        }
        a.lerp(self.levels[k + 1].sample_uv(u, v), f)
    }

    fn phong_level(&self, roughness: f32) -> Option<&Octahedral> {
        let bits = roughness.to_bits();
        self.phong.iter().find(|(b, _)| *b == bits).map(|(_, l)| l)
    }

    /// World directions `d` in the environment's frame (`Mat3 * Vec3`'s
    /// sum, lane by lane).
    #[inline(always)]
    fn to_env<L: Lane>(&self, d: V3<L>) -> V3<L> {
        match &self.env_from_world {
            Some(m) => {
                let col = |c: Vec3, s: L| V3::splat(c).scale(s);
                col(m.x_axis, d.x) + col(m.y_axis, d.y) + col(m.z_axis, d.z)
            }
            None => d,
        }
    }

    /// Irradiance on a surface with unit normal `n` (world space).
    pub fn irradiance(&self, n: Vec3) -> Vec3 {
        self.irradiance_lanes(V3::<f32>::from(n)).into()
    }

    /// `irradiance` at each lane's unit normal.
    #[inline]
    pub fn irradiance_lanes<L: Lane>(&self, n: V3<L>) -> V3<L> {
        let (u, v) = octahedral::encode(self.to_env(n));
        V3::from_fn(|k| Vec3::from(self.irradiance.at(u.lane(k), v.lane(k)) * self.intensity))
    }

    /// Radiance arriving from direction `d` (world space), unfiltered,
    /// with any lights taken out of the image.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        let (u, v) = direction_to_uv_lanes(self.to_env(V3::<f32>::from(d)));
        let level = self.backdrop.as_ref().unwrap_or(&self.levels[0]);
        Vec3::from(level.sample_uv(u, v)) * self.intensity
    }

    /// What the image shows along `d` blurred to perceptual `roughness`,
    /// with the lights taken out of it (`discs`) put back: the image as
    /// read at 0, else the prefiltered level plus each light's GGX lobe.
    /// The blurred background and what rough glass shows both read it.
    pub fn seen(&self, d: Vec3, roughness: f32, discs: &[Disc]) -> Vec3 {
        if roughness <= 0.0 {
            return self.radiance(d);
        }
        let lights: Vec3 = discs.iter().map(|&l| disc_lobe(d, roughness, l)).sum();
        self.prefiltered(d, roughness) + lights
    }

    /// Radiance along reflection direction `r` (world space), prefiltered
    /// for perceptual `roughness`.
    pub fn prefiltered(&self, r: Vec3, roughness: f32) -> Vec3 {
        self.prefiltered_lanes(V3::<f32>::from(r), roughness).into()
    }

    /// `prefiltered` along each lane's direction, for one roughness.
    #[inline]
    pub fn prefiltered_lanes<L: Lane>(&self, r: V3<L>, roughness: f32) -> V3<L> {
        let (u, v) = direction_to_uv_lanes(self.to_env(r));
        let (k, f) = level_of(roughness);
        self.levels[k].sample_lanes(&self.levels[k + 1], u, v, f, self.intensity)
    }

    /// The split sum's (scale, bias) of f0 for `n.v` and `roughness`.
    pub fn brdf(&self, ndv: f32, roughness: f32) -> Vec2 {
        let fx = ndv.clamp(0.0, 1.0) * (LUT_SIZE - 1) as f32;
        let fy = roughness.clamp(0.0, 1.0) * (LUT_SIZE - 1) as f32;
        // Both are >= 0: truncation is floor.
        let (x0, y0) = (fx as usize, fy as usize);
        let (x1, y1) = ((x0 + 1).min(LUT_SIZE - 1), (y0 + 1).min(LUT_SIZE - 1));
        let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
        let at = |x: usize, y: usize| self.lut[y * LUT_SIZE + x];
        let top = at(x0, y0).lerp(at(x1, y0), tx);
        top.lerp(at(x0, y1).lerp(at(x1, y1), tx), ty)
    }
}

/// The prefiltered level below `roughness` and the weight of the next.
#[inline]
fn level_of(roughness: f32) -> (usize, f32) {
    let x = roughness.clamp(0.0, 1.0) * (LEVELS - 1) as f32;
    // x >= 0: truncation is floor.
    let k = (x as usize).min(LEVELS - 2);
    (k, x - k as f32)
}

/// Where to look up the prefiltered radiance for lobes of `roughness`
/// reflecting about unit normals `n` along mirror directions `r`, per
/// lane, each with its roughness: rough lobes lean toward the normal
/// (their off-specular peak), which the split sum's n = v = r prefilter
/// does not see (Lagarde and de Rousiers 2014, "Moving Frostbite to PBR",
/// the dominant direction).
#[inline(always)]
pub fn dominant_direction_lanes<L: Lane>(n: V3<L>, r: V3<L>, roughness: L) -> V3<L> {
    let one = L::splat(1.0);
    let a = roughness * roughness;
    let f = (one - a) * ((one - a).sqrt() + a);
    // `Vec3::lerp`: n (1 - f) + r f.
    let l = n.scale(one - f) + r.scale(f);
    l.normalize_or(r)
}

/// Radiance projected on bands 0-2, convolved with the clamped cosine
/// (A0 = pi, A1 = 2pi/3, A2 = pi/4): irradiance coefficients.
/// Samples per side of the irradiance map, less one (`IrradianceMap`).
const IRRADIANCE_SIZE: usize = 32;
/// The widest chain level `IrradianceMap::new` integrates.
const IRRADIANCE_SOURCE_WIDTH: usize = 128;

/// Irradiance E(n) = integral of L(w) max(0, n.w) dw over the normals of
/// an octahedral grid whose samples lie on the cell corners, the map's
/// edges included (the lower hemisphere's folds then need no border: a
/// lookup on an edge reads the edge's own samples).
#[derive(Debug, Clone)]
struct IrradianceMap {
    /// (IRRADIANCE_SIZE + 1)^2 samples, row by row.
    samples: Vec<Vec3A>,
}

impl IrradianceMap {
    /// By direct sums over a level of the chain at most
    /// `IRRADIANCE_SOURCE_WIDTH` wide (box-filtered: a sun keeps its
    /// energy). Each sum is divided by the same sum of a uniform
    /// environment of radiance 1 and times pi, so a uniform environment
    /// gives exactly pi L. Unlike order-2 spherical harmonics (exact only
    /// for detail in bands 0-2), this keeps a sun's contrast between lit
    /// and unlit sides.
    fn new(chain: &[Equirect]) -> IrradianceMap {
        let img = chain
            .iter()
            .find(|l| l.width <= IRRADIANCE_SOURCE_WIDTH)
            .unwrap_or(&chain[chain.len() - 1]);
        // Per texel: its direction and radiance, both times its solid angle.
        let texels: Vec<(Vec3A, Vec3A)> = (0..img.height)
            .flat_map(|y| {
                let dw = img.texel_solid_angle(y);
                (0..img.width).map(move |x| {
                    let uv = Vec2::new(
                        (x as f32 + 0.5) / img.width as f32,
                        (y as f32 + 0.5) / img.height as f32,
                    );
                    let d = Vec3A::from(uv_to_direction(uv));
                    (d * dw, img.texels[y * img.width + x] * dw)
                })
            })
            .collect();
        let n = IRRADIANCE_SIZE;
        let samples = (0..(n + 1) * (n + 1))
            .into_par_iter()
            .map(|i| {
                let uv = Vec2::new((i % (n + 1)) as f32, (i / (n + 1)) as f32) / n as f32;
                let normal = Vec3A::from(octahedral::decode(uv));
                let (mut e, mut w) = (Vec3A::ZERO, 0.0f32);
                for (d, l) in &texels {
                    // cos x solid angle.
                    let c = normal.dot(*d);
                    if c > 0.0 {
                        e += *l * (c / d.length());
                        w += c;
                    }
                }
                if w > 0.0 { e * (PI / w) } else { Vec3A::ZERO }
            })
            .collect();
        IrradianceMap { samples }
    }

    /// Bilinear at octahedral map coordinates (u, v) in [0, 1]^2.
    #[inline(always)]
    fn at(&self, u: f32, v: f32) -> Vec3A {
        let n = IRRADIANCE_SIZE;
        let hi = n as f32;
        // A NaN clamps to NaN and converts to 0.
        let (x, y) = ((u * hi).clamp(0.0, hi), (v * hi).clamp(0.0, hi));
        let (x0, y0) = ((x as usize).min(n - 1), (y as usize).min(n - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let t = |x: usize, y: usize| self.samples[y * (n + 1) + x];
        let top = t(x0, y0).lerp(t(x0 + 1, y0), fx);
        let bottom = t(x0, y0 + 1).lerp(t(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }
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
/// of the lobe's solid angle (Colbert and Krivanek's filtered importance
/// sampling, without their one level of extra blur: that bias bled bright
/// light into dark regions, a dark cap of 15 degrees' half-angle in a
/// white sky read 0.138 at roughness 0.2 where the lobe's mean is 0.074,
/// and reads 0.094).
fn prefilter(chain: &[Equirect], roughness: f32, width: usize) -> Equirect {
    let height = width / 2;
    let a = (roughness * roughness).max(1e-3);
    let base = &chain[0];
    let texel_omega = 4.0 * PI / (base.width * base.height) as f32;
    let n = prefilter_samples(roughness);
    let samples: Vec<(Vec3, f32)> = (0..n)
        .filter_map(|i| {
            let h = ggx_half(hammersley(i, n), a);
            // l = reflect(-v, h) with v = n = +Z.
            let l = Vec3::new(2.0 * h.z * h.x, 2.0 * h.z * h.y, 2.0 * h.z * h.z - 1.0);
            if l.z <= 0.0 {
                return None;
            }
            // pdf of l: D(h) (n.h) / (4 v.h), with n = v: D / 4.
            let t = h.z * h.z * (a * a - 1.0) + 1.0;
            let d = a * a / (PI * t * t);
            let pdf = d / 4.0;
            let omega = 1.0 / (n as f32 * pdf);
            let lod = (0.5 * (omega / texel_omega).log2()).max(0.0);
            Some((l, lod))
        })
        .collect();
    let mut texels = vec![Vec3A::ZERO; width * height];
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
                let (mut acc, mut weight) = (Vec3A::ZERO, 0.0);
                for &(l, lod) in &samples {
                    let k = (lod.floor() as usize).min(chain.len() - 1);
                    let k1 = (k + 1).min(chain.len() - 1);
                    let f = (lod - k as f32).clamp(0.0, 1.0);
                    let uv = direction_to_uv(m * l);
                    let c = chain[k]
                        .sample_uv(uv.x, uv.y)
                        .lerp(chain[k1].sample_uv(uv.x, uv.y), f);
                    acc += c * l.z;
                    weight += l.z;
                }
                *out = if weight > 0.0 {
                    acc / weight
                } else {
                    Vec3A::ZERO
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
mod tests;
