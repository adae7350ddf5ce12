//! `[environment] method = "sampled"`: the reference the prefiltered
//! lighting is measured against. Per shaded point, `samples` pairs of
//! directions, one drawn from the environment (by luminance, in solid
//! angle) and one from the BRDF, combined by multiple importance sampling
//! (the balance heuristic), each ray tested for visibility through the
//! scene's BVHs. Deterministic: the sample pattern is a Hammersley set
//! rotated by a hash of the point's position.
//!
//! pbr materials integrate `pbr::brdf`. Blinn-Phong materials integrate
//! what the prefiltered path approximates: Kd / pi (diffuse), and Ks times
//! the average radiance over the GGX lobe whose roughness matches Ns
//! (specular, a normalized lobe).

use std::f32::consts::PI;

use glam::{Mat3, Vec2, Vec3};

use super::emitters::{EmitterPoint, Emitters};
use super::{direction_to_uv, uv_to_direction};
use crate::assets::environment::EnvImage;
use crate::raytrace::Tracer;
use crate::shade::pbr::{self, PbrColor};

/// Luminance-proportional sampling of an environment image.
#[derive(Debug, Clone)]
pub struct EnvSampler {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
    /// Per row: the cumulative weight of the rows above and including it.
    rows: Vec<f32>,
    /// Per texel: the cumulative weight within its row.
    cols: Vec<f32>,
    /// Per texel: its sampling weight (luminance plus a floor, times sin).
    weight: Vec<f32>,
    total: f32,
    env_from_world: Mat3,
    world_from_env: Mat3,
    intensity: f32,
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl EnvSampler {
    pub fn new(image: &EnvImage, intensity: f32, rotation_deg: f32) -> EnvSampler {
        let (w, h) = (image.width as usize, image.height as usize);
        let mean = image.texels.iter().map(|c| luminance(*c)).sum::<f32>() / (w * h) as f32;
        // A floor of a tenth of the mean: no direction has zero density.
        let floor = 0.1 * mean.max(1e-6);
        let mut weight = vec![0.0f32; w * h];
        let mut cols = vec![0.0f32; w * h];
        let mut rows = vec![0.0f32; h];
        let mut total = 0.0f32;
        for (y, row_end) in rows.iter_mut().enumerate() {
            let sin = ((y as f32 + 0.5) / h as f32 * PI).sin();
            let mut acc = 0.0f32;
            for x in 0..w {
                let i = y * w + x;
                weight[i] = (luminance(image.texels[i]) + floor) * sin;
                acc += weight[i];
                cols[i] = acc;
            }
            total += acc;
            *row_end = total;
        }
        let world_from_env = Mat3::from_rotation_y(rotation_deg.to_radians());
        EnvSampler {
            width: w,
            height: h,
            texels: image.texels.clone(),
            rows,
            cols,
            weight,
            total,
            env_from_world: world_from_env.transpose(),
            world_from_env,
            intensity,
        }
    }

    /// The texel a direction (environment space) falls in.
    fn texel(&self, d: Vec3) -> usize {
        let uv = direction_to_uv(d);
        let x = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        y * self.width + x
    }

    /// Radiance from world direction `d`.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        self.texels[self.texel(self.env_from_world * d)] * self.intensity
    }

    /// Density (per steradian) of drawing world direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let i = self.texel(self.env_from_world * d);
        let y = i / self.width;
        let sin = ((y as f32 + 0.5) / self.height as f32 * PI).sin();
        let texel_omega = (2.0 * PI / self.width as f32) * (PI / self.height as f32) * sin;
        if texel_omega <= 0.0 {
            return 0.0;
        }
        self.weight[i] / self.total / texel_omega
    }

    /// A world direction drawn from `xi` (uniform in [0, 1)^2).
    pub fn sample(&self, xi: Vec2) -> Vec3 {
        let t = xi.y * self.total;
        let y = self.rows.partition_point(|&r| r <= t).min(self.height - 1);
        let row = &self.cols[y * self.width..(y + 1) * self.width];
        let before = if y == 0 { 0.0 } else { self.rows[y - 1] };
        let row_total = row[self.width - 1].max(1e-30);
        let tx = (xi.x * row_total).min(row_total * 0.999_999);
        let x = row.partition_point(|&c| c <= tx).min(self.width - 1);
        // Where within the texel: the leftover of each choice.
        let start = if x == 0 { 0.0 } else { row[x - 1] };
        let fx = ((tx - start) / self.weight[y * self.width + x].max(1e-30)).clamp(0.0, 1.0);
        let fy = ((t - before) / (row_total)).clamp(0.0, 1.0);
        let uv = Vec2::new(
            (x as f32 + fx) / self.width as f32,
            (y as f32 + fy) / self.height as f32,
        );
        self.world_from_env * uv_to_direction(uv)
    }
}

/// What a sampled estimate integrates at a point.
pub enum Lobes<'a> {
    Pbr(&'a PbrColor),
    /// Blinn-Phong: diffuse albedo, specular colour, matched roughness.
    BlinnPhong {
        kd: Vec3,
        ks: Vec3,
        roughness: f32,
    },
}

/// Point `i` of `n` of the Hammersley set, rotated by `shift` (mod 1).
fn point(i: u32, n: u32, shift: Vec2) -> Vec2 {
    let p = Vec2::new(
        i as f32 / n as f32,
        i.reverse_bits() as f32 * 2.328_306_4e-10,
    ) + shift;
    p - p.floor()
}

/// Two numbers in [0, 1) from a position (the pattern's rotation).
fn position_hash(p: Vec3) -> Vec2 {
    let mut h = p.x.to_bits().wrapping_mul(0x9E37_79B1)
        ^ p.y.to_bits().wrapping_mul(0x85EB_CA77).rotate_left(13)
        ^ p.z.to_bits().wrapping_mul(0xC2B2_AE3D).rotate_left(7);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7FEB_352D);
    h ^= h >> 15;
    let g = h.wrapping_mul(0x846C_A68B) ^ (h >> 16);
    Vec2::new(
        (h >> 8) as f32 / (1u32 << 24) as f32,
        (g >> 8) as f32 / (1u32 << 24) as f32,
    )
}

/// An orthonormal frame whose third axis is `n`.
fn frame(n: Vec3) -> Mat3 {
    let t = n.any_orthonormal_vector();
    Mat3::from_cols(t, n.cross(t), n)
}

/// GGX alpha of a perceptual roughness.
fn alpha(roughness: f32) -> f32 {
    (roughness * roughness).max(2e-3)
}

/// Anisotropic GGX about frame `m` (tangent, bitangent, normal) with
/// alphas `ax` and `ay` along its first two axes: D(h).
fn ggx_d_aniso(m: Mat3, ax: f32, ay: f32, h: Vec3) -> f32 {
    let local = m.transpose() * h;
    if local.z <= 0.0 {
        return 0.0;
    }
    let s = (local.x / ax).powi(2) + (local.y / ay).powi(2) + local.z * local.z;
    1.0 / (PI * ax * ay * s * s)
}

/// A half vector drawn from D(h) (n.h) of `ggx_d_aniso`: the slopes of
/// the alpha-1 lobe stretched by the alphas.
fn ggx_sample_aniso(m: Mat3, ax: f32, ay: f32, u: Vec2) -> Vec3 {
    let phi = 2.0 * PI * u.x;
    let r = (u.y / (1.0 - u.y).max(1e-7)).sqrt();
    let slope = Vec2::new(ax * r * phi.cos(), ay * r * phi.sin());
    (m * Vec3::new(-slope.x, -slope.y, 1.0)).normalize_or(m.z_axis)
}

fn ggx_d(ndh: f32, a: f32) -> f32 {
    if ndh <= 0.0 {
        return 0.0;
    }
    let t = ndh * ndh * (a * a - 1.0) + 1.0;
    a * a / (PI * t * t)
}

/// The lobes a point's estimate draws directions from (`Mixture::sample`)
/// and their combined density (`Mixture::pdf`): diffuse (cosine about n,
/// probability `q`), diffuse transmission (cosine about -n, `qb`), the
/// base's GGX (isotropic about frame `m` with alpha `a`, or anisotropic),
/// and a clearcoat's GGX (`qc`).
struct Mixture {
    n: Vec3,
    v: Vec3,
    m: Mat3,
    a: f32,
    aniso: Option<(Mat3, f32, f32)>,
    coat: Option<(Mat3, Vec3, f32)>,
    q: f32,
    qb: f32,
    qc: f32,
}

impl Mixture {
    fn new(n: Vec3, v: Vec3, lobes: &Lobes) -> Mixture {
        let (c_diff, spec_weight, roughness, behind) = match lobes {
            Lobes::Pbr(c) => {
                let s = c.specular_albedo(n.dot(v).abs()).into();
                // The diffuse lobe before the transmitted share.
                let c_diff = Vec3::from(c.base) * (1.0 - c.metallic);
                let behind = c.behind.map_or(0.0, |b| luminance(b.into()));
                (c_diff, luminance(s), c.roughness, behind)
            }
            Lobes::BlinnPhong { kd, ks, roughness } => (*kd, luminance(*ks), *roughness, 0.0),
        };
        let a = alpha(roughness);
        // A clearcoat is a third, sharper lobe about its own normal: drawn
        // with probability COAT_SHARE.
        const COAT_SHARE: f32 = 0.3;
        let coat = match lobes {
            Lobes::Pbr(c) => c.coat.filter(|k| k.factor > 0.0),
            Lobes::BlinnPhong { .. } => None,
        };
        let qc = if coat.is_some() { COAT_SHARE } else { 0.0 };
        // Probabilities of drawing the diffuse lobe and the transmitted one.
        let d = luminance(c_diff);
        let total = d + spec_weight + behind;
        let (q, qb) = if total <= 0.0 {
            (1.0, 0.0)
        } else {
            (d / total, behind / total)
        };
        // An anisotropic base lobe: its frame and alphas.
        let aniso = match lobes {
            Lobes::Pbr(c) => c.aniso.map(|k| {
                let m = Mat3::from_cols(Vec3::from(k.t), Vec3::from(k.b), n);
                (m, k.at, k.ab)
            }),
            Lobes::BlinnPhong { .. } => None,
        };
        Mixture {
            n,
            v,
            m: frame(n),
            a,
            aniso,
            coat: coat.map(|k| {
                let nc = Vec3::from(k.normal);
                (frame(nc), nc, alpha(k.roughness))
            }),
            q: q * (1.0 - qc),
            qb: qb * (1.0 - qc),
            qc,
        }
    }

    /// GGX's distribution of reflected directions about normal `n`.
    fn ggx_pdf(&self, n: Vec3, a: f32, l: Vec3) -> f32 {
        let v = self.v;
        let h = (l + v).normalize_or_zero();
        ggx_d(n.dot(h), a) * n.dot(h) / (4.0 * v.dot(h).abs().max(1e-6))
    }

    /// The base lobe's distribution of reflected directions.
    fn base_pdf(&self, l: Vec3) -> f32 {
        let (n, v) = (self.n, self.v);
        match self.aniso {
            Some((m, ax, ay)) => {
                let h = (l + v).normalize_or_zero();
                ggx_d_aniso(m, ax, ay, h) * n.dot(h) / (4.0 * v.dot(h).abs().max(1e-6))
            }
            None => self.ggx_pdf(n, self.a, l),
        }
    }

    /// The density of drawing `l` (`sample`).
    fn pdf(&self, l: Vec3) -> f32 {
        let (q, qb, qc) = (self.q, self.qb, self.qc);
        let ndl = self.n.dot(l);
        if ndl <= 0.0 {
            return qb * -ndl / PI;
        }
        let coat = self
            .coat
            .map_or(0.0, |(_, nc, ac)| qc * self.ggx_pdf(nc, ac, l));
        q * ndl / PI + (1.0 - q - qb - qc) * self.base_pdf(l) + coat
    }

    /// A direction drawn from the lobes by `xi` (uniform in [0, 1)^2).
    fn sample(&self, xi: Vec2) -> Vec3 {
        let (v, m, a) = (self.v, self.m, self.a);
        let (q, qb, qc) = (self.q, self.qb, self.qc);
        // A reflected direction from GGX about frame `m` (alpha `a`).
        let ggx_sample = |m: Mat3, a: f32, u: Vec2| {
            let phi = 2.0 * PI * u.x;
            let cos_t = ((1.0 - u.y) / (1.0 + (a * a - 1.0) * u.y)).max(0.0).sqrt();
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let h = m * Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
            h * (2.0 * v.dot(h)) - v
        };
        // A cosine-distributed direction about m's third axis, or the
        // opposite one.
        let cosine = |u: Vec2, side: f32| {
            let r = u.x.sqrt();
            let phi = 2.0 * PI * u.y;
            m * Vec3::new(
                r * phi.cos(),
                r * phi.sin(),
                side * (1.0 - u.x).max(0.0).sqrt(),
            )
        };
        if xi.x < q {
            cosine(Vec2::new(xi.x / q.max(1e-6), xi.y), 1.0)
        } else if xi.x < q + qb {
            cosine(Vec2::new((xi.x - q) / qb.max(1e-6), xi.y), -1.0)
        } else if xi.x < 1.0 - qc {
            let u = Vec2::new((xi.x - q - qb) / (1.0 - q - qb - qc).max(1e-6), xi.y);
            match self.aniso {
                Some((m, ax, ay)) => {
                    let h = ggx_sample_aniso(m, ax, ay, u);
                    h * (2.0 * v.dot(h)) - v
                }
                None => ggx_sample(m, a, u),
            }
        } else {
            let (mc, _, ac) = self.coat.unwrap_or((m, self.n, a));
            let u = Vec2::new((xi.x - (1.0 - qc)) / qc.max(1e-6), xi.y);
            ggx_sample(mc, ac, u)
        }
    }
}

/// f(l) cos(l) of `lobes` towards `v` at unit normal `n`: the integrand
/// without radiance and visibility (`a`: the Blinn-Phong lobe's alpha).
fn f_cos(lobes: &Lobes, n: Vec3, v: Vec3, a: f32, l: Vec3) -> Vec3 {
    let ndl = n.dot(l);
    if ndl <= 0.0 {
        // Only a diffuse transmission lets light through from behind.
        return match lobes {
            Lobes::Pbr(c) => c.behind.map_or(Vec3::ZERO, |b| {
                let f: Vec3 = pbr::btdf(n.into(), v.into(), l.into(), b, c).into();
                f * -ndl
            }),
            Lobes::BlinnPhong { .. } => Vec3::ZERO,
        };
    }
    match lobes {
        Lobes::Pbr(c) => pbr::f_cos(n.into(), v.into(), l.into(), ndl, c).into(),
        Lobes::BlinnPhong { kd, ks, .. } => {
            // The normalized lobe: D (n.h) / (4 v.h) integrates to ~1.
            let h = (l + v).normalize_or_zero();
            let lobe = ggx_d(n.dot(h), a) * n.dot(h) / (4.0 * v.dot(h).abs().max(1e-6));
            *kd * (ndl / PI) + *ks * lobe
        }
    }
}

/// What `method = "sampled"` lights a frame with: the environment's
/// sampler, the frame's rays, its emissive triangles and the sample
/// count.
#[derive(Clone, Copy)]
pub struct Sampled<'a> {
    pub env: &'a EnvSampler,
    pub tracer: &'a Tracer<'a>,
    pub emitters: &'a Emitters,
    pub samples: u32,
}

/// Outgoing radiance towards `v` at `p` (unit normal `n`, geometric normal
/// `ng` for the rays' offset) from the environment, `samples` pairs of
/// directions, and from the emissive triangles, `samples` points drawn
/// on them, with visibility through the frame's rays.
pub fn radiance(s: &Sampled, (p, n, ng): (Vec3, Vec3, Vec3), v: Vec3, lobes: &Lobes) -> Vec3 {
    let (env, tracer, samples) = (s.env, s.tracer, s.samples);
    let mix = Mixture::new(n, v, lobes);
    let f_cos = |l: Vec3| f_cos(lobes, n, v, mix.a, l);
    // Rays towards the front leave off the front; those of a diffuse
    // transmission, behind the surface, off the back.
    let start = |l: Vec3| {
        let off = if n.dot(l) < 0.0 { -ng } else { ng };
        p + off * tracer.epsilon
    };
    let visible = |l: Vec3| !tracer.occluded(start(l), l, f32::INFINITY);
    let shift = position_hash(p);
    let mut sum = Vec3::ZERO;
    for i in 0..samples {
        // From the environment.
        let xi = point(i, samples, shift);
        let l = env.sample(xi);
        let fc = f_cos(l);
        if fc != Vec3::ZERO && visible(l) {
            let pe = env.pdf(l);
            sum += fc * env.radiance(l) / (pe + mix.pdf(l)).max(1e-12);
        }
        // From the BRDF.
        let xi = point(i, samples, Vec2::new(shift.y, shift.x));
        let l = mix.sample(xi);
        let fc = f_cos(l);
        if fc != Vec3::ZERO && visible(l) {
            let pb = mix.pdf(l);
            sum += fc * env.radiance(l) / (env.pdf(l) + pb).max(1e-12);
        }
        // From the emitters (the rays above that reach one count as
        // blocked: each emitter is counted here alone).
        if let Some(q) = s.emitters.sample(point(i, samples, shift * 0.5 + 0.25)) {
            sum += from_emitter(&q, p, &f_cos, |l, d| {
                !tracer.occluded(start(l), l, d - 2.0 * tracer.epsilon)
            });
        }
    }
    sum / samples as f32
}

/// The light point `q` sends towards `p` as the lobe `f_cos` takes it:
/// f cos L cos_q / (d^2 pdf_area), where `visible(l, d)` (the unit
/// direction and the distance to `q`); zero where it is hidden.
fn from_emitter(
    q: &EmitterPoint,
    p: Vec3,
    f_cos: &impl Fn(Vec3) -> Vec3,
    visible: impl Fn(Vec3, f32) -> bool,
) -> Vec3 {
    let to = q.at - p;
    let d2 = to.length_squared();
    if d2 <= 0.0 || !d2.is_finite() {
        return Vec3::ZERO;
    }
    let d = d2.sqrt();
    let l = to / d;
    let cos_q = q.normal.dot(l).abs();
    let fc = f_cos(l);
    if cos_q <= 0.0 || fc == Vec3::ZERO || !visible(l, d) {
        return Vec3::ZERO;
    }
    fc * q.radiance * (cos_q / (d2 * q.pdf_area))
}
