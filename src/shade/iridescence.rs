//! Thin-film iridescence (KHR_materials_iridescence): a film of index
//! `ior` and `thickness` nanometres over the base material, whose two
//! interfaces interfere. The Fresnel term becomes the film's reflectance,
//! after Belcour and Barla, "A Practical Extension to Microfacet Theory
//! for the Modeling of Varying Iridescence" (SIGGRAPH 2017), as the
//! extension's specification states it:
//!
//! - first interface (outside, ior 1 -> film): R12 = Schlick(R0(1, ior), cos t1),
//!   a phase shift of pi when the film is optically thinner than outside;
//! - second interface (film -> base, whose index per channel comes from the
//!   base's F0): R23 = Schlick(R0(ior, base), cos t2), with cos t2 from
//!   Snell's law and a phase shift of pi where the base is thinner;
//! - the optical path difference 2 ior thickness cos t2, and the Airy sum
//!   of the reflections to second order, each term integrated against the
//!   CIE sensitivities in Fourier space (Gaussian fits) and brought from
//!   XYZ to linear Rec. 709.
//!
//! A film thinner than 30 nm fades to the outside index (no film): seen
//! head on, a thickness of 0 gives the base's F0.

use std::f32::consts::PI;

use glam::Vec3;

use crate::simd::{Lane, V3, clamp01};

/// The film at one point: the one-lane form of `fresnel`, for tests (the
/// shading code calls `fresnel` on its lanes).
#[cfg(test)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Iridescence {
    /// iridescenceFactor times its map (0..1): the blend towards the film's
    /// Fresnel.
    pub factor: f32,
    /// The film's index of refraction.
    pub ior: f32,
    /// The film's thickness in nanometres.
    pub thickness: f32,
}

/// XYZ to linear Rec. 709 (sRGB primaries, D65), by column.
const XYZ_TO_REC709: [[f32; 3]; 3] = [
    [3.240_454_2, -0.969_266, 0.055_643_4],
    [-1.537_138_5, 1.876_010_8, -0.204_025_9],
    [-0.498_531_4, 0.041_556, 1.057_225_2],
];

/// Reflectance at normal incidence between indices `a` and `b`.
#[inline(always)]
fn r0<L: Lane>(a: L, b: f32) -> L {
    let d = (a - L::splat(b)) / (a + L::splat(b));
    d * d
}

/// Schlick's Fresnel from `f0` at cosine `cos`.
#[inline(always)]
fn schlick<L: Lane>(f0: L, cos: L) -> L {
    let x = clamp01(L::splat(1.0) - cos);
    let x2 = x * x;
    // `powi(5)` as LLVM makes it: x (x^2 x^2).
    f0 + (L::splat(1.0) - f0) * (x * (x2 * x2))
}

/// The CIE sensitivities' Fourier transform at optical path difference
/// `opd` (nm) with phase `shift` per channel, as linear Rec. 709: the
/// Gaussian fits of Belcour and Barla (their values). Cosines and
/// exponentials lane by lane (libm's), the rest over the lanes.
#[inline(always)]
fn sensitivity<L: Lane>(opd: L, shift: V3<L>) -> V3<L> {
    let phase = L::splat(2.0 * PI) * opd * L::splat(1.0e-9);
    let val = [5.4856e-13f32, 4.4201e-13, 5.2481e-13];
    let pos = [1.6810e+06f32, 1.7953e+06, 2.2084e+06];
    let var = [4.3278e+09f32, 9.3046e+09, 6.6121e+09];
    let shift = [shift.x, shift.y, shift.z];
    let phase2 = -(phase * phase);
    let mut xyz: [L; 3] = std::array::from_fn(|c| {
        let a = L::splat(val[c] * (2.0 * PI * var[c]).sqrt());
        let cos = (L::splat(pos[c]) * phase + shift[c]).map(f32::cos);
        a * cos * (phase2 * L::splat(var[c])).map(f32::exp)
    });
    let (v2, p2) = (4.5282e+09f32, 2.2399e+06f32);
    let cos = (L::splat(p2) * phase + shift[0]).map(f32::cos);
    let exp = (L::splat(-v2) * phase * phase).map(f32::exp);
    xyz[0] = xyz[0] + L::splat(9.7470e-14 * (2.0 * PI * v2).sqrt()) * cos * exp;
    let xyz = xyz.map(|v| v / L::splat(1.0685e-7));
    // `Mat3 * Vec3`: ((x_axis v.x) + (y_axis v.y)) + (z_axis v.z).
    let m = &XYZ_TO_REC709;
    let row = |r: usize| {
        L::splat(m[0][r]) * xyz[0] + L::splat(m[1][r]) * xyz[1] + L::splat(m[2][r]) * xyz[2]
    };
    V3 {
        x: row(0),
        y: row(1),
        z: row(2),
    }
}

/// The film's reflectance (per linear channel) at the lanes: a film of
/// index `ior` and `thickness` nanometres, for light at cosine `cos1` to
/// the microfacet normal outside, over a base of reflectance `base_f0` at
/// normal incidence.
#[inline(always)]
pub fn fresnel<L: Lane>(ior: f32, thickness: L, cos1: L, base_f0: V3<L>) -> V3<L> {
    let (zero, one, pi) = (L::splat(0.0), L::splat(1.0), L::splat(PI));
    let cos1 = clamp01(cos1);
    let outside = 1.0f32;
    // The film fades in over its first 30 nm.
    let t = clamp01(thickness / L::splat(30.0));
    let ior =
        L::splat(outside) + L::splat(ior - outside) * t * t * (L::splat(3.0) - L::splat(2.0) * t);
    let k = L::splat(outside) / ior;
    let sin2_sq = k * k * (one - cos1 * cos1);
    let cos2_sq = one - sin2_sq;
    let cos2 = cos2_sq.sqrt();
    // First interface.
    let r12 = schlick(r0(ior, outside), cos1);
    let t121 = one - r12;
    let phi12 = L::select(ior.cmplt(L::splat(outside)), pi, zero);
    let phi21 = pi - phi12;
    // Second interface: the base's index from its F0 (real part only).
    let channel = |f0: L| {
        let s = f0.max(zero).min(L::splat(0.9999)).sqrt();
        let base_ior = (one + s) / (one - s);
        // Schlick of R0(base, ior), the base's index per lane.
        let d = (base_ior - ior) / (base_ior + ior);
        let r23 = schlick(d * d, cos2);
        let phi23 = L::select(base_ior.cmplt(ior), pi, zero);
        (r23, phi21 + phi23)
    };
    let (rx, px) = channel(base_f0.x);
    let (ry, py) = channel(base_f0.y);
    let (rz, pz) = channel(base_f0.z);
    let (r23, phi) = (
        V3 {
            x: rx,
            y: ry,
            z: rz,
        },
        V3 {
            x: px,
            y: py,
            z: pz,
        },
    );
    // Phase and optical path difference.
    let opd = L::splat(2.0) * ior * thickness * cos2;
    // The Airy sum, to second order.
    let r12v = V3 {
        x: r12,
        y: r12,
        z: r12,
    };
    let t121v = V3 {
        x: t121,
        y: t121,
        z: t121,
    };
    let clamp = |v: L| v.max(L::splat(1e-5)).min(L::splat(0.9999));
    let r123 = r12v * r23;
    let r123 = V3 {
        x: clamp(r123.x),
        y: clamp(r123.y),
        z: clamp(r123.z),
    };
    let r123_sqrt = V3 {
        x: r123.x.sqrt(),
        y: r123.y.sqrt(),
        z: r123.z.sqrt(),
    };
    let ones = V3::splat(Vec3::ONE);
    let (num, den) = (t121v * t121v * r23, ones - r123);
    let rs = V3 {
        x: num.x / den.x,
        y: num.y / den.y,
        z: num.z / den.z,
    };
    let mut i = r12v + rs;
    let mut cm = rs - t121v;
    for m in 1..=2 {
        cm = cm * r123_sqrt;
        let m = m as f32;
        let s = sensitivity(L::splat(m) * opd, phi.scale(L::splat(m)));
        i = i + cm.scale(L::splat(2.0)) * s;
    }
    // Total internal reflection: all of it.
    V3::select(cos2_sq.cmplt(zero), ones, i.max(V3::zero()))
}

#[cfg(test)]
impl Iridescence {
    /// The film's reflectance (per linear channel) for light at cosine
    /// `cos1` to the microfacet normal outside, over a base of reflectance
    /// `base_f0` at normal incidence (`fresnel` at one lane).
    pub fn fresnel(&self, cos1: f32, base_f0: Vec3) -> Vec3 {
        fresnel(self.ior, self.thickness, cos1, V3::from(base_f0)).into()
    }

    /// `base` (a Fresnel reflectance) blended towards the film's at cosine
    /// `cos1` by the factor.
    #[inline]
    pub fn blend(&self, base: Vec3, cos1: f32, base_f0: Vec3) -> Vec3 {
        if self.factor <= 0.0 {
            return base;
        }
        base.lerp(self.fresnel(cos1, base_f0), self.factor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(thickness: f32) -> Iridescence {
        Iridescence {
            factor: 1.0,
            ior: 1.3,
            thickness,
        }
    }

    #[test]
    fn head_on_films_of_400_and_250_nm_give_the_values_the_render_test_expects() {
        // `tests/it/gltf.rs` (KHR_materials_iridescence) checks a rendered
        // cube face against these numbers.
        let base = Vec3::splat(0.04);
        for (t, want) in [
            (400.0, Vec3::new(0.007_456_456, 0.038_351_72, 0.016_038_207)),
            (250.0, Vec3::new(0.047_993_07, 0.026_858_89, 0.004_917_93)),
        ] {
            let got = film(t).fresnel(1.0, base);
            assert!((got - want).abs().max_element() < 1e-7, "{t}: {got}");
        }
    }

    #[test]
    fn no_film_is_the_base_fresnel_head_on() {
        // Thickness 0: the film's index fades to the outside's and, seen
        // head on, the base's F0 remains (within the spectral fits'
        // error). Off the normal the model does not reduce exactly: the
        // first interface's Schlick term of a zero F0 is (1 - cos)^5, not
        // 0, and the Airy sum adds its echoes; films are given 100 nm and
        // up in practice (the extension's default range is 100-400 nm).
        for f0 in [Vec3::splat(0.04), Vec3::new(0.95, 0.64, 0.54)] {
            let f = film(0.0).fresnel(1.0, f0);
            assert!((f - f0).abs().max_element() < 0.01, "f0 {f0}: {f}");
        }
    }

    #[test]
    fn a_film_colours_the_reflection_and_the_colour_turns_with_angle() {
        let base = Vec3::splat(0.04);
        let hue = |c: Vec3| c / c.max_element();
        let head_on = film(400.0).fresnel(1.0, base);
        let grazing = film(400.0).fresnel(0.4, base);
        // Coloured: the channels differ clearly (a plain dielectric is grey).
        assert!(
            head_on.max_element() - head_on.min_element() > 0.02,
            "{head_on}"
        );
        // The colour shifts with the angle (a shorter path at grazing view).
        assert!((hue(head_on) - hue(grazing)).abs().max_element() > 0.1);
        // Bounded like a reflectance.
        for t in [50.0, 100.0, 250.0, 400.0, 800.0, 1200.0] {
            for cos in [1.0, 0.8, 0.5, 0.2, 0.0] {
                let f = film(t).fresnel(cos, base);
                assert!(
                    f.min_element() >= 0.0 && f.max_element() <= 1.05,
                    "{t} nm cos {cos}: {f}"
                );
            }
        }
        // Factor 0 leaves the base untouched.
        let off = Iridescence {
            factor: 0.0,
            ..film(400.0)
        };
        assert_eq!(off.blend(Vec3::splat(0.3), 0.5, base), Vec3::splat(0.3));
    }

    #[test]
    fn thin_films_of_soap_show_their_known_colours() {
        // A soap bubble: a film of index 1.33 with air (F0 0) behind it,
        // viewed head on.
        let soap = |t: f32| {
            Iridescence {
                factor: 1.0,
                ior: 1.33,
                thickness: t,
            }
            .fresnel(1.0, Vec3::ZERO)
        };
        // Constructive interference where 2 n d = (k + 1/2) lambda with
        // the pi shift at the first interface: for d = 113 nm, lambda =
        // 601 nm (orange) reflects most; destructive for 2 n d = lambda,
        // around 300 nm (ultraviolet), so blue is weaker than red.
        let f = soap(113.0);
        assert!(f.x > f.z, "{f}");
        // For d = 190 nm: 2 n d = 505 nm cancels green-cyan; red and blue
        // (magenta) stay.
        let f = soap(190.0);
        assert!(f.y < f.x && f.y < f.z, "{f}");
    }
}
