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

use smallvec::SmallVec;
use std::f32::consts::PI;

use glam::{Mat3, Vec2, Vec3};

use super::EnvLight;
use super::bounce::{self, Surfaces};
use super::emitters::{Emitters, from_emitter};
pub use super::image_sampler::EnvSampler;
use super::image_sampler::luminance;
pub(crate) use super::pattern::{frame, point, position_hash};
use crate::raytrace::Tracer;
use crate::shade::pbr::{self, PbrColor};

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

/// GGX alpha of a perceptual roughness.
pub(crate) fn alpha(roughness: f32) -> f32 {
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
pub(crate) fn ggx_sample_aniso(m: Mat3, ax: f32, ay: f32, u: Vec2) -> Vec3 {
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
    /// The frame's surfaces, for one bounce (`bounce`); None: a ray that
    /// meets a surface brings nothing.
    pub surfaces: Option<&'a dyn Surfaces>,
    /// The prefiltered environment, for the bounce's specular lobes.
    pub light: Option<&'a EnvLight>,
}

impl<'a> Sampled<'a> {
    /// The frame's scene as rays meet it, where light bounces.
    pub fn bounce(&self) -> Option<bounce::Scene<'a>> {
        self.surfaces.map(|surfaces| bounce::Scene {
            sampler: self.env,
            light: self.light,
            tracer: self.tracer,
            surfaces,
            emitters: self.emitters,
        })
    }
}

/// Outgoing radiance towards `v` at `p` (unit normals `ns`, geometric
/// normal `ng` for the rays' offset) from the environment, `samples`
/// pairs of directions, and from the emissive triangles, `samples` points
/// drawn on them, with visibility through the frame's rays. With several
/// normals (a normal map's, spread over the pixel) sample `i` is taken
/// about `ns[i % ns.len()]`: the pixel's average, as a path tracer's
/// samples spread over the pixel find it.
pub fn radiance(s: &Sampled, (p, ns, ng): (Vec3, &[Vec3], Vec3), v: Vec3, lobes: &Lobes) -> Vec3 {
    let (env, tracer, samples) = (s.env, s.tracer, s.samples);
    let mixes: SmallVec<[(Vec3, Mixture); 4]> =
        ns.iter().map(|&n| (n, Mixture::new(n, v, lobes))).collect();
    let bounce = s.bounce();
    let shift = position_hash(p);
    let mut sum = Vec3::ZERO;
    for i in 0..samples {
        let (n, mix) = &mixes[i as usize % mixes.len()];
        let (n, mix) = (*n, mix);
        let f_cos = |l: Vec3| f_cos(lobes, n, v, mix.a, l);
        // Rays towards the front leave off the front; those of a diffuse
        // transmission, behind the surface, off the back.
        let start = |l: Vec3| {
            let off = if n.dot(l) < 0.0 { -ng } else { ng };
            p + off * tracer.epsilon
        };
        // What arrives along a ray: the environment where nothing is in
        // the way; with the frame's surfaces, what the one met reflects.
        let incoming = |l: Vec3, xi: Vec2| match &bounce {
            Some(b) => b.incoming(start(l), l, xi),
            None if tracer.occluded(start(l), l, f32::INFINITY) => Vec3::ZERO,
            None => env.radiance(l),
        };
        // From the environment.
        let xi = point(i, samples, shift);
        let l = env.sample(xi);
        let fc = f_cos(l);
        if fc != Vec3::ZERO {
            let pe = env.pdf(l);
            sum += fc * incoming(l, xi) / (pe + mix.pdf(l)).max(1e-12);
        }
        // From the BRDF.
        let xi = point(i, samples, Vec2::new(shift.y, shift.x));
        let l = mix.sample(xi);
        let fc = f_cos(l);
        if fc != Vec3::ZERO {
            let pb = mix.pdf(l);
            sum += fc * incoming(l, xi) / (env.pdf(l) + pb).max(1e-12);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::environment::EnvImage;

    /// A white Lambertian surface under a sky white above the horizon and
    /// black below: radiance 1 facing up, 1/2 facing sideways. Given both
    /// normals (a pixel whose normal map turns half its area sideways),
    /// `radiance` gives their average, 3/4.
    #[test]
    fn several_normals_give_their_average() {
        let (w, h) = (256u32, 128u32);
        let texels = (0..w * h)
            .map(|i| if i / w < h / 2 { Vec3::ONE } else { Vec3::ZERO })
            .collect();
        let sky = EnvSampler::new(&EnvImage::new(w, h, texels).unwrap(), 1.0, 0.0);
        let tracer = Tracer::new([], 1.0);
        let emitters = Emitters::default();
        let s = Sampled {
            env: &sky,
            tracer: &tracer,
            emitters: &emitters,
            samples: 256,
            surfaces: None,
            light: None,
        };
        let lobes = Lobes::BlinnPhong {
            kd: Vec3::ONE,
            ks: Vec3::ZERO,
            roughness: 1.0,
        };
        let (up, side) = (Vec3::Y, Vec3::X);
        let points = 16;
        let at = |normals: &[Vec3]| {
            (0..points)
                .map(|k| {
                    let p = Vec3::new(0.37 * k as f32, 0.0, -0.21 * k as f32);
                    radiance(&s, (p, normals, Vec3::Y), Vec3::new(0.0, 0.6, 0.8), &lobes).x
                })
                .sum::<f32>()
                / points as f32
        };
        for (normals, expected) in [
            (&[up][..], 1.0),
            (&[side][..], 0.5),
            (&[up, side, up, side][..], 0.75),
        ] {
            let got = at(normals);
            assert!(
                (got - expected).abs() < 0.02,
                "{normals:?}: {got}, expected {expected}"
            );
        }
    }
}
