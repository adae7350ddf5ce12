//! The lights taken out of an environment image (`environment.lights`),
//! as the image blurred by roughness shows them: the blurred background,
//! and what rough glass shows (`EnvLight::seen`).

use std::f32::consts::PI;

use glam::Vec3;

/// A light taken out of the image (`environment.lights`): the unit
/// direction towards it, its irradiance and its angular radius.
pub type Disc = (Vec3, Vec3, f32);

/// What a disc light adds to the image prefiltered at perceptual
/// roughness `blur`, along `d`: its irradiance times the density of the
/// GGX lobe (alpha = blur^2, widened by the disc) around `d` at the light,
/// D(d.h) / 4, as the prefiltered levels spread the image.
pub fn disc_lobe(d: Vec3, blur: f32, (l, e, angle): Disc) -> Vec3 {
    let w = 0.5 * angle.tan();
    let a2 = (blur.powi(4) + w * w).min(1.0);
    let h = (l + d).normalize_or_zero();
    let c = d.dot(h).max(0.0);
    let q = c * c * (a2 - 1.0) + 1.0;
    e * (a2 / (PI * q * q) * 0.25)
}
