//! Blinn-Phong exactly as the scene format states it:
//!
//!   L = Ke + Ka * ambient + sum_lights E * max(0, n.l) * (Kd + Ks * max(0, n.h)^Ns)
//!
//! with `illum 0`: L = Kd; `illum 1`: no specular term; `illum 2` and up: all
//! terms. All quantities are linear RGB; textures already multiplied in.

use glam::Vec3;

use super::light::{LightSet, for_each_lit};
#[cfg(test)]
use crate::shade::light::unshadowed;

/// A material evaluated at one point (constants times texture lookups).
#[derive(Debug, Clone, Copy)]
pub struct SurfaceColor {
    pub ka: Vec3,
    pub kd: Vec3,
    pub ks: Vec3,
    pub ke: Vec3,
    pub ns: f32,
    pub illum: u8,
}

/// Sum over lights of E * max(0, n.l) (diffuse) and E * max(0, n.l) *
/// max(0, n.h)^Ns (specular), for Gouraud shading and as the inner loop of
/// `radiance`.
#[inline]
pub fn light_sums(
    p: Vec3,
    n: Vec3,
    v: Vec3,
    ns: f32,
    specular: bool,
    lights: LightSet,
    shadow: &impl Fn(usize, Vec3) -> f32,
) -> (Vec3, Vec3) {
    let mut diffuse = Vec3::ZERO;
    let mut spec = Vec3::ZERO;
    for_each_lit(lights, shadow, p, n, |l, e| {
        diffuse += e;
        if specular {
            let h = (l + v).normalize_or_zero();
            let ndh = n.dot(h).max(0.0);
            if ndh > 0.0 {
                spec += e * crate::powers::pow_unit(ndh, ns);
            }
        }
    });
    (diffuse, spec)
}

/// Outgoing radiance at `p` with unit normal `n` towards unit view vector `v`.
#[inline]
pub fn radiance(
    p: Vec3,
    n: Vec3,
    v: Vec3,
    s: &SurfaceColor,
    ambient: Vec3,
    lights: LightSet,
    shadow: &impl Fn(usize, Vec3) -> f32,
) -> Vec3 {
    if s.illum == 0 {
        return s.kd;
    }
    let (diffuse, spec) = light_sums(p, n, v, s.ns, s.illum >= 2, lights, shadow);
    combine(s, ambient, diffuse, spec)
}

/// The formula's final sum, given the per-light sums.
#[inline]
pub fn combine(s: &SurfaceColor, ambient: Vec3, diffuse: Vec3, spec: Vec3) -> Vec3 {
    if s.illum == 0 {
        return s.kd;
    }
    let spec_term = if s.illum >= 2 {
        s.ks * spec
    } else {
        Vec3::ZERO
    };
    s.ke + s.ka * ambient + s.kd * diffuse + spec_term
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::light::{Light, LightKind};

    fn surface(illum: u8) -> SurfaceColor {
        SurfaceColor {
            ka: Vec3::splat(1.0),
            kd: Vec3::splat(0.5),
            ks: Vec3::splat(0.25),
            ke: Vec3::new(0.1, 0.0, 0.0),
            ns: 8.0,
            illum,
        }
    }

    #[test]
    fn matches_the_formula_for_a_light_straight_above() {
        let lights = [Light {
            kind: LightKind::Point {
                position: Vec3::new(0.0, 2.0, 0.0),
                intensity: 4.0,
            },
            color: Vec3::ONE,
            shadows: false,
            range: None,
        }];
        let (p, n, v) = (Vec3::ZERO, Vec3::Y, Vec3::Y);
        let amb = Vec3::splat(0.1);
        // E = 4/4 = 1, n.l = 1, n.h = 1
        let l2 = radiance(
            p,
            n,
            v,
            &surface(2),
            amb,
            LightSet::all(&lights),
            &unshadowed,
        );
        assert!(
            (l2 - Vec3::new(0.1 + 0.1 + 0.5 + 0.25, 0.1 + 0.5 + 0.25, 0.1 + 0.5 + 0.25)).length()
                < 1e-6
        );
        let l1 = radiance(
            p,
            n,
            v,
            &surface(1),
            amb,
            LightSet::all(&lights),
            &unshadowed,
        );
        assert!((l1 - Vec3::new(0.7, 0.6, 0.6)).length() < 1e-6);
        assert_eq!(
            radiance(
                p,
                n,
                v,
                &surface(0),
                amb,
                LightSet::all(&lights),
                &unshadowed
            ),
            Vec3::splat(0.5)
        );
        // A light below the surface adds nothing.
        let below = radiance(
            p,
            -n,
            v,
            &surface(2),
            amb,
            LightSet::all(&lights),
            &unshadowed,
        );
        assert!((below - Vec3::new(0.2, 0.1, 0.1)).length() < 1e-6);
    }
}
