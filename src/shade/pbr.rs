//! Metallic-roughness shading as the glTF 2.0 specification's appendix B
//! states it:
//!
//!   c_diff = lerp(base, 0, metallic)      f0 = lerp(0.04, base, metallic)
//!   alpha  = roughness^2
//!   F   = f0 + (1 - f0) (1 - |v.h|)^5                        (Schlick)
//!   D   = alpha^2 X(n.h) / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)  (GGX)
//!   Vis = 1 / ((|n.l| + sqrt(alpha^2 + (1 - alpha^2)(n.l)^2))
//!            (|n.v| + sqrt(alpha^2 + (1 - alpha^2)(n.v)^2)))  (separable Smith)
//!   f   = (1 - F) c_diff / pi + F D Vis
//!
//! lit by the scene's lights: L = emissive + sum_lights E * (n.l) * f, plus
//! the ambient term, which treats `ambient` as uniform light from every
//! direction: ambient * occlusion * (c_diff (1 - S) + S), with S = f0 A + B
//! the specular albedo from the analytic fit of the GGX environment BRDF
//! (Karis, "Physically Based Shading on Mobile", 2014). Under uniform light
//! a white dielectric then reflects exactly what it receives, never more.
//!
//! Layers (the KHR_materials extensions):
//! - clearcoat: a colourless GGX layer (F0 0.04, its own roughness and
//!   normal nc) over the material. With w = factor x F(nc.v) (Schlick),
//!   L = (1 - w) L_base + factor L_coat, emission included in L_base.
//! - transmission t: the diffuse lobe becomes (1 - t) of itself; the
//!   light behind the surface comes through, times
//!   t (1 - metallic) base (1 - S) attenuation (1 - w), with S the
//!   specular albedo (so a white, fully transmissive dielectric in a
//!   uniform environment is invisible) and attenuation
//!   attenuation_color^(thickness / attenuation_distance) (Beer's law,
//!   KHR_materials_volume). Thin-walled: no refraction offset.
//!
//! - sheen (`shade::sheen`): a Charlie lobe over the base, which it
//!   scales by 1 - max(C) E (under the clearcoat; emission is not scaled).
//! - iridescence (`shade::iridescence`): a thin film whose Fresnel
//!   (at v.h for lights, n.v for the split sum, over the base's F0)
//!   replaces Schlick's by its factor, in the specular lobe and in the
//!   1 - F that the diffuse lobe keeps.
//!
//! Note the 1/pi: under the same light, a white Lambertian pbr surface is
//! 1/pi as bright as Blinn-Phong Kd 1, whose formula (the scene format's)
//! has none. Lights are in the same units for both.

use glam::Vec3;

use super::pbr4::{COAT_F0, MIN_ALPHA};
use crate::simd::V3;

use super::env::EnvLight;
pub use super::iridescence::Iridescence;
use super::light::{LightSet, for_each_lit};
pub use super::sheen::Sheen;

/// A material evaluated at one point (factors times texture lookups).
#[derive(Debug, Clone, Copy)]
pub struct PbrColor {
    pub base: Vec3,
    pub metallic: f32,
    /// Perceptual roughness in [0, 1].
    pub roughness: f32,
    /// 1 = unoccluded (occlusion map with its strength applied).
    pub occlusion: f32,
    pub emissive: Vec3,
    /// A dielectric's F0 and F90 when the material gives them (None: 0.04
    /// and 1).
    pub dielectric: Option<(Vec3, f32)>,
    /// A clearcoat layer over the material.
    pub coat: Option<Coat>,
    /// A sheen layer over the base (under the clearcoat).
    pub sheen: Option<Sheen>,
    /// Fraction of the diffuse lobe that is transmitted instead (0..1).
    pub transmission: f32,
    /// Volume transmittance along the thickness (1: none).
    pub attenuation: Vec3,
    /// A thin film over the material (KHR_materials_iridescence).
    pub iridescence: Option<Iridescence>,
}

/// A clearcoat layer at one point.
#[derive(Debug, Clone, Copy)]
pub struct Coat {
    /// clearcoatFactor times its map (0..1).
    pub factor: f32,
    /// Perceptual roughness in [0, 1].
    pub roughness: f32,
    /// The layer's unit normal (its own normal map, else the surface's
    /// interpolated normal).
    pub normal: Vec3,
}

impl Coat {
    /// The share of the light below that the layer reflects away, towards
    /// `v`: factor times Schlick's Fresnel at nc.v.
    #[inline]
    pub fn weight(&self, v: Vec3) -> f32 {
        self.lanes().weight(V3::from(v))
    }

    /// The layer's BRDF times its cosine, times factor, for light from `l`.
    #[inline]
    pub fn f_cos(&self, v: Vec3, l: Vec3) -> f32 {
        self.lanes().f_cos(V3::from(v), V3::from(l))
    }

    /// The layer as the lanes hold it (one lane: this code is theirs).
    #[inline(always)]
    pub(super) fn lanes(&self) -> super::pbr4::Coat<f32> {
        super::pbr4::Coat {
            factor: self.factor,
            roughness: self.roughness,
            normal: V3::from(self.normal),
        }
    }
}

impl PbrColor {
    #[inline]
    fn alpha(&self) -> f32 {
        (self.roughness * self.roughness).max(MIN_ALPHA)
    }

    #[inline]
    pub fn f0(&self) -> Vec3 {
        match self.dielectric {
            None => Vec3::splat(0.04).lerp(self.base, self.metallic),
            Some((f0, _)) => f0.lerp(self.base, self.metallic),
        }
    }

    /// Reflectance at grazing angles: 1, or a dielectric's specular
    /// factor (metals: 1).
    #[inline]
    pub fn f90(&self) -> f32 {
        match self.dielectric {
            None => 1.0,
            Some((_, w)) => w + (1.0 - w) * self.metallic,
        }
    }

    #[inline]
    pub fn c_diff(&self) -> Vec3 {
        self.base * (1.0 - self.metallic)
    }

    /// The split sum's specular albedo f0 A + f90 B for the environment
    /// BRDF's scale `a` and bias `b`; with a film, blended towards its
    /// Fresnel at n.v = `ndv` times the lobe's albedo A + B.
    #[inline]
    pub fn split_sum(&self, ndv: f32, a: f32, b: f32) -> Vec3 {
        super::pbr4::split_sum(&self.lanes(), ndv, a, b).into()
    }

    /// The point as the lanes hold one (one lane: their code is this
    /// code), the diffuse colour with the transmitted share taken out.
    #[inline(always)]
    fn lanes(&self) -> super::pbr4::Color<f32> {
        let alpha = self.alpha();
        super::pbr4::Color {
            roughness: self.roughness,
            occlusion: self.occlusion,
            f0: V3::from(self.f0()),
            f90: self.f90(),
            c_diff: V3::from(if self.transmission > 0.0 {
                self.c_diff() * (1.0 - self.transmission)
            } else {
                self.c_diff()
            }),
            a2: alpha * alpha,
            sheen: self.sheen,
            iridescence: self.iridescence.filter(|f| f.factor > 0.0),
        }
    }

    /// Specular albedo under uniform light at n.v = `ndv` (the analytic
    /// fit of the environment BRDF, clamped to [0, 1]: the fit overshoots
    /// slightly at grazing angles).
    #[inline]
    pub fn specular_albedo(&self, ndv: f32) -> Vec3 {
        let (a, b) = env_brdf(self.roughness, ndv);
        self.split_sum(ndv, a, b).clamp(Vec3::ZERO, Vec3::ONE)
    }
}

/// The BRDF f(v, l) (no cosine), with unit normal `n`, unit view `v` and
/// unit light direction `l`, all pointing away from the surface (the base
/// layer only: `f_cos` adds the clearcoat).
#[inline]
pub fn brdf(n: Vec3, v: Vec3, l: Vec3, c: &PbrColor) -> Vec3 {
    let ndl = n.dot(l);
    if ndl <= 0.0 {
        return Vec3::ZERO;
    }
    let [n, v, l] = [n, v, l].map(V3::from);
    super::pbr4::brdf(n, v, l, ndl, &c.lanes()).into()
}

/// The whole material's f(v, l) cos: the base layer's BRDF times n.l,
/// under the clearcoat when there is one.
#[inline]
pub fn f_cos(n: Vec3, v: Vec3, l: Vec3, c: &PbrColor) -> Vec3 {
    let ndl = n.dot(l).max(0.0);
    let mut base = brdf(n, v, l, c) * ndl;
    if let Some(s) = &c.sheen {
        base = base * s.scaling(n.dot(v).abs(), Some(ndl)) + s.color * s.lobe_cos(n, v, l);
    }
    match &c.coat {
        None => base,
        Some(coat) => base * (1.0 - coat.weight(v)) + Vec3::splat(coat.f_cos(v, l)),
    }
}

/// What of the light behind the surface comes through towards `v`, per
/// channel (zero without transmission).
pub fn transmittance(n: Vec3, v: Vec3, c: &PbrColor) -> Vec3 {
    if c.transmission <= 0.0 {
        return Vec3::ZERO;
    }
    let spec = c.specular_albedo(n.dot(v).abs());
    let coat = c.coat.map_or(1.0, |k| 1.0 - k.weight(v));
    let sheen = c.sheen.map_or(1.0, |s| s.scaling(n.dot(v).abs(), None));
    (Vec3::ONE - spec)
        * c.base
        * c.attenuation
        * (c.transmission * (1.0 - c.metallic) * coat * sheen)
}

/// Specular albedo under uniform light for reflectance `f0`, from the
/// analytic fit of the split-sum environment BRDF (clamped to [0, 1]: the
/// fit overshoots slightly at grazing angles).
#[inline]
pub fn specular_albedo(f0: Vec3, f90: f32, roughness: f32, ndv: f32) -> Vec3 {
    let (a, b) = env_brdf(roughness, ndv);
    (f0 * a + Vec3::splat(b * f90)).clamp(Vec3::ZERO, Vec3::ONE)
}

/// Scale and bias of f0 in the fit (`pbr4::env_brdf` at one lane).
#[inline]
fn env_brdf(roughness: f32, ndv: f32) -> (f32, f32) {
    super::pbr4::env_brdf(roughness, ndv)
}

/// The environment's light reflected towards `v` (the split sum): the
/// specular lobe's prefiltered radiance times f0 A + B, the diffuse part
/// c_diff (1 - (f0 A + B)) E(n) / pi, so that a white furnace never gains
/// energy. `ao` multiplies the diffuse part, and the specular part through
/// Lagarde's specular occlusion; the occlusion map multiplies both.
pub fn environment(env: &EnvLight, n: Vec3, v: Vec3, c: &PbrColor, ao: f32) -> Vec3 {
    // The lanes' code at one lane (the sheen's lobe: its albedo times the
    // cosine-weighted mean radiance E(n) / pi, closer to the sampled
    // reference than the GGX level at its roughness; the clearcoat: a
    // dielectric lobe, F0 0.04, about its own normal).
    let coat = c.coat.as_ref().map(Coat::lanes);
    super::pbr4::layered_environment(env, [n, v].map(V3::from), &c.lanes(), coat.as_ref(), ao)
        .into()
}

/// Outgoing radiance at `p` towards `v`.
#[inline]
pub fn radiance(
    p: Vec3,
    n: Vec3,
    v: Vec3,
    c: &PbrColor,
    ambient: Vec3,
    lights: LightSet,
    shadow: &impl Fn(usize, Vec3) -> f32,
) -> Vec3 {
    if c.coat.is_some() || c.sheen.is_some() {
        return layered_radiance(p, n, v, c, ambient, lights, shadow);
    }
    let mut out = c.emissive;
    for_each_lit(lights, shadow, p, n, |l, e| out += e * brdf(n, v, l, c));
    if ambient != Vec3::ZERO {
        let spec = c.specular_albedo(n.dot(v).abs());
        let c_diff = if c.transmission > 0.0 {
            c.c_diff() * (1.0 - c.transmission)
        } else {
            c.c_diff()
        };
        out += ambient * c.occlusion * (c_diff * (Vec3::ONE - spec) + spec);
    }
    out
}

/// `radiance` with a sheen or a clearcoat: each light through `f_cos`;
/// the ambient term of the base scaled by the sheen plus the sheen's own,
/// then (with the emission) under the coat, plus the coat's.
fn layered_radiance(
    p: Vec3,
    n: Vec3,
    v: Vec3,
    c: &PbrColor,
    ambient: Vec3,
    lights: LightSet,
    shadow: &impl Fn(usize, Vec3) -> f32,
) -> Vec3 {
    let mut direct = Vec3::ZERO;
    // e carries n.l, and so does f_cos.
    for_each_lit(lights, shadow, p, n, |l, e| {
        direct += e * (f_cos(n, v, l, c) / n.dot(l))
    });
    let ndv = n.dot(v).abs();
    let mut under = Vec3::ZERO;
    if ambient != Vec3::ZERO {
        let spec = c.specular_albedo(ndv);
        let c_diff = c.c_diff() * (1.0 - c.transmission);
        under = ambient * c.occlusion * (c_diff * (Vec3::ONE - spec) + spec);
        if let Some(s) = &c.sheen {
            under = under * s.scaling(ndv, None) + ambient * c.occlusion * s.reflectance(ndv);
        }
    }
    under += c.emissive;
    if let Some(coat) = &c.coat {
        under *= 1.0 - coat.weight(v);
        if ambient != Vec3::ZERO {
            let nc = coat.normal;
            let s = specular_albedo(Vec3::splat(COAT_F0), 1.0, coat.roughness, nc.dot(v).abs());
            under += ambient * c.occlusion * s * coat.factor;
        }
    }
    under + direct
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shade::light::unshadowed;
    use std::f32::consts::PI;

    fn dielectric(base: f32, roughness: f32) -> PbrColor {
        PbrColor {
            base: Vec3::splat(base),
            metallic: 0.0,
            roughness,
            occlusion: 1.0,
            emissive: Vec3::ZERO,
            dielectric: None,
            coat: None,
            sheen: None,
            transmission: 0.0,
            attenuation: Vec3::ONE,
            iridescence: None,
        }
    }

    #[test]
    fn matches_hand_computed_values_at_normal_incidence() {
        // n = v = l: n.h = v.h = 1, F = f0, D = 1 / (pi alpha^2),
        // Vis = 1 / ((1 + 1)(1 + 1)) = 1/4.
        let (n, v, l) = (Vec3::Z, Vec3::Z, Vec3::Z);
        let c = dielectric(0.8, 0.5);
        let alpha: f32 = 0.25;
        let spec = 0.04 / (PI * alpha * alpha) / 4.0;
        let diff = 0.96 * 0.8 / PI;
        let f = brdf(n, v, l, &c);
        assert!((f.x - (spec + diff)).abs() < 1e-6, "{f} vs {}", spec + diff);
        assert!((spec - 0.050_93).abs() < 1e-4);
        // A metal has no diffuse part and reflects its base color.
        let metal = PbrColor {
            base: Vec3::new(1.0, 0.5, 0.2),
            metallic: 1.0,
            ..c
        };
        let f = brdf(n, v, l, &metal);
        let d_vis = 1.0 / (PI * alpha * alpha) / 4.0;
        assert!((f - metal.base * d_vis).abs().max_element() < 1e-5, "{f}");
        // Light below the surface: nothing.
        assert_eq!(brdf(n, v, -l, &c), Vec3::ZERO);
    }

    #[test]
    fn matches_hand_computed_values_off_axis() {
        // l at 60 degrees from n in the xz plane, v along n, roughness 1
        // (alpha 1: D = 1/pi, Vis = 1 / ((n.l + 1)(n.v + 1))).
        let n = Vec3::Z;
        let v = Vec3::Z;
        let l = Vec3::new(60f32.to_radians().sin(), 0.0, 0.5);
        let c = dielectric(1.0, 1.0);
        let h = (l + v).normalize();
        let vdh = v.dot(h);
        let fresnel = 0.04 + 0.96 * (1.0 - vdh).powi(5);
        let expect = (1.0 - fresnel) / PI + fresnel / PI / ((0.5 + 1.0) * (1.0 + 1.0));
        let f = brdf(n, v, l, &c);
        assert!((f.x - expect).abs() < 1e-6, "{} vs {expect}", f.x);
    }

    /// Directional albedo: the integral of f * cos over the hemisphere of
    /// light directions, by a midpoint rule in (cos theta, phi).
    fn albedo(c: &PbrColor, view_deg: f32) -> f32 {
        let n = Vec3::Z;
        let t = view_deg.to_radians();
        let v = Vec3::new(t.sin(), 0.0, t.cos());
        let (nu, np) = (400, 400);
        let mut sum = 0.0f64;
        for i in 0..nu {
            let mu = (i as f32 + 0.5) / nu as f32;
            let s = (1.0 - mu * mu).sqrt();
            for j in 0..np {
                let phi = (j as f32 + 0.5) / np as f32 * 2.0 * PI;
                let l = Vec3::new(s * phi.cos(), s * phi.sin(), mu);
                sum += (brdf(n, v, l, c).x * mu) as f64;
            }
        }
        (sum * 2.0 * PI as f64 / (nu * np) as f64) as f32
    }

    #[test]
    fn white_furnace_rough_dielectric_does_not_gain_energy() {
        for roughness in [0.8, 1.0] {
            for view in [0.0, 30.0, 60.0, 85.0] {
                let a = albedo(&dielectric(1.0, roughness), view);
                assert!(a <= 1.0, "roughness {roughness} view {view}: albedo {a}");
                // ... and loses little (single scattering, Fresnel).
                assert!(a > 0.95, "roughness {roughness} view {view}: albedo {a}");
            }
        }
        // The appendix-B mix is not energy-conserving everywhere: weighting
        // the diffuse lobe by 1 - F(v.h) per light direction leaves too much
        // of it at grazing views on smoother surfaces (1.27 at roughness
        // 0.3, 85 degrees). Recorded here so a change of model shows.
        let smooth_grazing = albedo(&dielectric(1.0, 0.3), 85.0);
        assert!(
            smooth_grazing > 1.2 && smooth_grazing < 1.35,
            "{smooth_grazing}"
        );
        let smooth_head_on = albedo(&dielectric(1.0, 0.3), 0.0);
        assert!(smooth_head_on <= 1.0, "{smooth_head_on}");
        // A white metal loses only to the missing multiple scattering.
        let metal = PbrColor {
            metallic: 1.0,
            ..dielectric(1.0, 0.5)
        };
        let a = albedo(&metal, 30.0);
        assert!(a <= 1.0 && a > 0.8, "{a}");
    }

    #[test]
    fn uniform_ambient_is_conserved_for_a_white_dielectric() {
        let c = dielectric(1.0, 0.7);
        let l = radiance(
            Vec3::ZERO,
            Vec3::Z,
            Vec3::Z,
            &c,
            Vec3::splat(0.5),
            LightSet::all(&[]),
            &unshadowed,
        );
        assert!((l - Vec3::splat(0.5)).abs().max_element() < 1e-5, "{l}");
        // Occlusion scales it.
        let occluded = PbrColor {
            occlusion: 0.5,
            ..c
        };
        let l = radiance(
            Vec3::ZERO,
            Vec3::Z,
            Vec3::Z,
            &occluded,
            Vec3::splat(0.5),
            LightSet::all(&[]),
            &unshadowed,
        );
        assert!((l - Vec3::splat(0.25)).abs().max_element() < 1e-5, "{l}");
        // The fit's specular albedo stays within [0, 1].
        for r in [0.0, 0.25, 0.5, 1.0] {
            for ndv in [0.0, 0.3, 1.0] {
                let s = specular_albedo(Vec3::splat(0.04), 1.0, r, ndv).x;
                assert!((0.0..=1.0).contains(&s), "{r} {ndv}: {s}");
            }
        }
        // Near the fit's known values: a smooth dielectric seen head-on
        // reflects about f0; a mirror metal about 1.
        assert!((specular_albedo(Vec3::splat(0.04), 1.0, 0.0, 1.0).x - 0.04).abs() < 0.01);
        assert!(specular_albedo(Vec3::ONE, 1.0, 0.0, 1.0).x > 0.95);
    }
}
