//! What a light delivers to a shaded point: direction and irradiance (the
//! inverse square law, KHR_lights_punctual's range window and spot cone),
//! and the loop over the lights that both shading models use.

use glam::Vec3;

use crate::scene::light::{Light, LightKind};

/// What one light delivers to a shaded point.
#[derive(Debug, Clone, Copy)]
pub struct Incidence {
    /// Unit vector from the point towards the light.
    pub l: Vec3,
    /// Irradiance on a surface facing the light (RGB), before the cosine.
    pub e: Vec3,
}

/// Unit direction to `light` and its irradiance at `p`; None where the
/// light contributes nothing (outside a spot cone, at the light itself).
#[inline]
pub fn incidence(light: &Light, p: Vec3) -> Option<Incidence> {
    match light.kind {
        LightKind::Directional {
            direction,
            irradiance,
        } => Some(Incidence {
            l: -direction,
            e: light.color * irradiance,
        }),
        LightKind::Point {
            position,
            intensity,
        } => {
            let (l, r2) = towards(position, p)?;
            Some(Incidence {
                l,
                e: light.color * (intensity * window(light, r2) / r2),
            })
        }
        LightKind::Spot {
            position,
            direction,
            intensity,
            cos_inner,
            cos_outer,
        } => {
            let (l, r2) = towards(position, p)?;
            let f = spot_falloff(-l.dot(direction), cos_inner, cos_outer);
            if f <= 0.0 {
                return None;
            }
            Some(Incidence {
                l,
                e: light.color * (intensity * f * window(light, r2) / r2),
            })
        }
    }
}

/// The unit direction from `p` to a light at `position`, and the squared
/// distance; None at the light itself.
#[inline]
fn towards(position: Vec3, p: Vec3) -> Option<(Vec3, f32)> {
    let d = position - p;
    let r2 = d.length_squared();
    if r2 <= 0.0 {
        return None;
    }
    Some((d / r2.sqrt(), r2))
}

#[inline]
fn window(light: &Light, r2: f32) -> f32 {
    match light.range {
        Some(range) if range > 0.0 => {
            let q = r2 / (range * range);
            let w = (1.0 - q * q).clamp(0.0, 1.0);
            w * w
        }
        _ => 1.0,
    }
}

/// Calls `f(l, e)` for each light that reaches a point with unit normal `n`
/// from its front side: the unit direction to it and the irradiance
/// E * (n.l) times `shadow(i, l)`, the fraction of light `i` that is not
/// blocked (asked only of lights with `shadows = true`). (A callback rather
/// than an iterator: the iterator version did not inline and cost 12% of a
/// frame.)
#[inline(always)]
pub fn for_each_lit(
    lights: &[Light],
    shadow: &impl Fn(usize, Vec3) -> f32,
    p: Vec3,
    n: Vec3,
    mut f: impl FnMut(Vec3, Vec3),
) {
    for (i, light) in lights.iter().enumerate() {
        let Some(inc) = incidence(light, p) else {
            continue;
        };
        let ndl = n.dot(inc.l);
        if ndl > 0.0 {
            let s = if light.shadows { shadow(i, inc.l) } else { 1.0 };
            if s > 0.0 {
                f(inc.l, inc.e * (ndl * s));
            }
        }
    }
}

/// The `shadow` argument of `for_each_lit` when nothing casts shadows.
pub fn unshadowed(_: usize, _: Vec3) -> f32 {
    1.0
}

/// KHR_lights_punctual: t = clamp((cos a - cos outer) / (cos inner - cos outer), 0, 1),
/// attenuation t². Equal cone angles give a hard edge.
#[inline]
pub fn spot_falloff(cos_a: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let span = cos_inner - cos_outer;
    if span <= 1e-7 {
        return if cos_a >= cos_outer { 1.0 } else { 0.0 };
    }
    let t = ((cos_a - cos_outer) / span).clamp(0.0, 1.0);
    t * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::light::LightKind;

    #[test]
    fn point_light_follows_inverse_square() {
        let l = Light {
            kind: LightKind::Point {
                position: Vec3::new(0.0, 2.0, 0.0),
                intensity: 8.0,
            },
            color: Vec3::ONE,
            shadows: false,
            range: None,
        };
        let i = incidence(&l, Vec3::ZERO).unwrap();
        assert!((i.e.x - 2.0).abs() < 1e-6);
        assert!((i.l - Vec3::Y).length() < 1e-6);
        // A range window: (1 - (2/4)^4)^2 at half the range, 0 beyond it.
        let ranged = Light {
            range: Some(4.0),
            ..l
        };
        let w = (1.0f32 - 0.0625).powi(2);
        assert!((incidence(&ranged, Vec3::ZERO).unwrap().e.x - 2.0 * w).abs() < 1e-6);
        let far = incidence(&ranged, Vec3::new(0.0, -3.0, 0.0)).unwrap();
        assert_eq!(far.e.x, 0.0);
    }

    #[test]
    fn spot_cone_is_smooth_and_bounded() {
        let (ci, co) = (20f32.to_radians().cos(), 30f32.to_radians().cos());
        assert_eq!(spot_falloff(1.0, ci, co), 1.0);
        assert_eq!(spot_falloff(35f32.to_radians().cos(), ci, co), 0.0);
        let mid = spot_falloff(25f32.to_radians().cos(), ci, co);
        assert!(mid > 0.0 && mid < 1.0);
        assert_eq!(spot_falloff(0.9, 0.5, 0.5), 1.0);
        assert_eq!(spot_falloff(0.4, 0.5, 0.5), 0.0);
    }
}
