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

use glam::{Mat3, Vec3};

/// The film at one point.
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

/// Reflectance at normal incidence between indices `a` and `b`.
#[inline]
fn r0(a: Vec3, b: f32) -> Vec3 {
    let d = (a - Vec3::splat(b)) / (a + Vec3::splat(b));
    d * d
}

#[inline]
fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    f0 + (Vec3::ONE - f0) * (1.0 - cos).clamp(0.0, 1.0).powi(5)
}

/// XYZ to linear Rec. 709 (sRGB primaries, D65).
const XYZ_TO_REC709: Mat3 = Mat3::from_cols_array(&[
    3.240_454_2,
    -0.969_266,
    0.055_643_4,
    -1.537_138_5,
    1.876_010_8,
    -0.204_025_9,
    -0.498_531_4,
    0.041_556,
    1.057_225_2,
]);

/// The CIE sensitivities' Fourier transform at optical path difference
/// `opd` (nm) with phase `shift` per channel, as linear Rec. 709: the
/// Gaussian fits of Belcour and Barla (their values).
fn sensitivity(opd: f32, shift: Vec3) -> Vec3 {
    let phase = 2.0 * PI * opd * 1.0e-9;
    let val = Vec3::new(5.4856e-13, 4.4201e-13, 5.2481e-13);
    let pos = Vec3::new(1.6810e+06, 1.7953e+06, 2.2084e+06);
    let var = Vec3::new(4.3278e+09, 9.3046e+09, 6.6121e+09);
    let cos = |v: Vec3| Vec3::new(v.x.cos(), v.y.cos(), v.z.cos());
    let exp = |v: Vec3| Vec3::new(v.x.exp(), v.y.exp(), v.z.exp());
    let sqrt = |v: Vec3| Vec3::new(v.x.sqrt(), v.y.sqrt(), v.z.sqrt());
    let mut xyz =
        val * sqrt(2.0 * PI * var) * cos(pos * phase + shift) * exp(-(phase * phase) * var);
    let (v2, p2) = (4.5282e+09f32, 2.2399e+06f32);
    xyz.x += 9.7470e-14
        * (2.0 * PI * v2).sqrt()
        * (p2 * phase + shift.x).cos()
        * (-v2 * phase * phase).exp();
    XYZ_TO_REC709 * (xyz / 1.0685e-7)
}

impl Iridescence {
    /// The film's reflectance (per linear channel) for light at cosine
    /// `cos1` to the microfacet normal outside, over a base of reflectance
    /// `base_f0` at normal incidence.
    pub fn fresnel(&self, cos1: f32, base_f0: Vec3) -> Vec3 {
        let cos1 = cos1.clamp(0.0, 1.0);
        let outside = 1.0f32;
        // The film fades in over its first 30 nm.
        let t = (self.thickness / 30.0).clamp(0.0, 1.0);
        let ior = outside + (self.ior - outside) * t * t * (3.0 - 2.0 * t);
        let sin2_sq = (outside / ior).powi(2) * (1.0 - cos1 * cos1);
        let cos2_sq = 1.0 - sin2_sq;
        if cos2_sq < 0.0 {
            // Total internal reflection.
            return Vec3::ONE;
        }
        let cos2 = cos2_sq.sqrt();
        // First interface.
        let r12 = schlick(r0(Vec3::splat(ior), outside), cos1);
        let t121 = Vec3::ONE - r12;
        let phi12 = if ior < outside { PI } else { 0.0 };
        let phi21 = PI - phi12;
        // Second interface: the base's index from its F0 (real part only).
        let s = base_f0
            .clamp(Vec3::ZERO, Vec3::splat(0.9999))
            .map(f32::sqrt);
        let base_ior = (Vec3::ONE + s) / (Vec3::ONE - s);
        let r23 = schlick(r0(base_ior, ior), cos2);
        let phi23 = Vec3::select(
            base_ior.cmplt(Vec3::splat(ior)),
            Vec3::splat(PI),
            Vec3::ZERO,
        );
        // Phase and optical path difference.
        let opd = 2.0 * ior * self.thickness * cos2;
        let phi = Vec3::splat(phi21) + phi23;
        // The Airy sum, to second order.
        let r123 = (r12 * r23).clamp(Vec3::splat(1e-5), Vec3::splat(0.9999));
        let r123_sqrt = r123.map(f32::sqrt);
        let rs = t121 * t121 * r23 / (Vec3::ONE - r123);
        let mut i = r12 + rs;
        let mut cm = rs - t121;
        for m in 1..=2 {
            cm *= r123_sqrt;
            let m = m as f32;
            i += cm * 2.0 * sensitivity(m * opd, m * phi);
        }
        i.max(Vec3::ZERO)
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
