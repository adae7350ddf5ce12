//! Traced reflections for the prefiltered environment
//! (`environment.reflections`): where the specular lobe's dominant
//! direction meets another surface of the scene, the prefiltered
//! environment along it is replaced by what that surface sends back.
//!
//! The split sum lights every point as if nothing stood between it and
//! the environment. A path tracer's sphere beside another shows its
//! neighbour, dark or lit, in its reflection; a metal disc under another
//! shows the other's back. One ray per point, along the direction the
//! split sum reads the environment, finds the surface met (`bounce::
//! Surfaces`); that surface is lit as the prefiltered method lights an
//! open point: its Lambertian colour times the irradiance E(n) / pi, its
//! specular colour times the split sum along its own mirror direction,
//! its emission, and the shadow-free light of the scene's directional
//! lights on its Lambertian colour (the lights taken out of the image
//! among them). What lies behind it, and its own shadows, are not
//! counted.
//!
//! One ray stands for a lobe: a mirror's reflection is the ray's, a rough
//! lobe's is wider than the surface the ray met. The ray's share fades
//! with the roughness, from 1 at 0 to none at `FADE_END`: wide lobes
//! keep the prefiltered light (the AO's specular occlusion stands for
//! them).

use glam::Vec3;

use super::EnvLight;
use super::bounce::{Bounce, Surfaces};
use crate::raytrace::Tracer;
use crate::scene::light::Light;
use crate::shade::light::incidence;
use crate::simd::{Lane, V3};

/// Roughness from which the traced reflection has no share.
pub const FADE_END: f32 = 1.0;

/// What the traced reflections read: the frame's rays and surfaces, the
/// prefiltered environment and the scene's lights.
#[derive(Clone, Copy)]
pub struct Reflections<'a> {
    pub tracer: &'a Tracer<'a>,
    pub surfaces: &'a dyn Surfaces,
    pub light: &'a EnvLight,
    pub lights: &'a [Light],
}

/// The traced reflections at a group of points: their positions and
/// geometric normals.
#[derive(Clone, Copy)]
pub struct At<'a, L: Lane> {
    pub with: &'a Reflections<'a>,
    pub position: V3<L>,
    pub geo_normal: &'a [Vec3],
}

impl<L: Lane> At<'_, L> {
    /// `Reflections::along` at these points.
    #[inline]
    pub fn along(&self, r: V3<L>, roughness: L) -> (V3<L>, L) {
        self.with
            .along(self.position, self.geo_normal, r, roughness)
    }

    /// `light` (the prefiltered environment along `r`) with the traced
    /// reflection along `r` in its share.
    #[inline]
    pub fn blend(&self, light: V3<L>, r: V3<L>, roughness: L) -> V3<L> {
        let (seen, share) = self.along(r, roughness);
        light.scale(L::splat(1.0) - share) + seen.scale(share)
    }
}

/// The traced reflection's share at `roughness`: 1 - (r / FADE_END)^2,
/// 0 from `FADE_END` on.
#[inline]
pub fn share(roughness: f32) -> f32 {
    let x = (roughness / FADE_END).clamp(0.0, 1.0);
    1.0 - x * x
}

impl Reflections<'_> {
    /// Per lane: the radiance arriving at `p` along unit `r` from the
    /// surface the ray meets, and its share (0 where the ray meets
    /// nothing or the lobe is too rough), for lobes of `roughness`. `ng`:
    /// the geometric normals, toward the viewer (the rays' offset).
    pub fn along<L: Lane>(&self, p: V3<L>, ng: &[Vec3], r: V3<L>, roughness: L) -> (V3<L>, L) {
        let mut seen = [Vec3::ZERO; 16];
        let mut shares = [0.0f32; 16];
        for k in 0..L::WIDTH {
            let s = share(roughness.lane(k));
            if s <= 0.0 {
                continue;
            }
            let d = r.lane(k);
            let n = ng[k];
            let off = if n.dot(d) < 0.0 { -n } else { n };
            if let Some(c) = self.incoming(p.lane(k) + off * self.tracer.epsilon, d) {
                seen[k] = c;
                shares[k] = s;
            }
        }
        (V3::from_fn(|k| seen[k]), L::from_fn(|k| shares[k]))
    }

    /// The radiance along the ray `o + t d` from the first surface that
    /// reflects (through up to 8 that mostly transmit); None where it
    /// leaves the scene.
    fn incoming(&self, mut o: Vec3, d: Vec3) -> Option<Vec3> {
        for _ in 0..8 {
            let hit = self.tracer.nearest(o, d, f32::INFINITY)?;
            let Some(b) = self.surfaces.at(hit, o, d) else {
                return Some(Vec3::ZERO);
            };
            if b.transmission >= 0.5 {
                o = b.position - b.geometric * self.tracer.epsilon;
                continue;
            }
            return Some(self.leaving(&b, -d));
        }
        Some(Vec3::ZERO)
    }

    /// What surface `b` sends towards unit `wo`, lit as an open point.
    fn leaving(&self, b: &Bounce, wo: Vec3) -> Vec3 {
        let env = self.light;
        let n = b.normal;
        let ndv = n.dot(wo).clamp(1e-4, 1.0);
        let mut diffuse_light = env.irradiance(n) / std::f32::consts::PI;
        for light in self.lights {
            if let Some(i) = incidence(light, b.position) {
                diffuse_light += i.e * (n.dot(i.l).max(0.0) / std::f32::consts::PI);
            }
        }
        let mirror = n * (2.0 * n.dot(wo)) - wo;
        let ab = env.brdf(ndv, b.roughness);
        let specular = env.prefiltered(mirror, b.roughness) * (b.specular * ab.x + ab.y);
        b.diffuse * diffuse_light + specular + b.emitted
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_share_fades_from_one_at_a_mirror_to_none_at_fade_end() {
        assert_eq!(share(0.0), 1.0);
        assert_eq!(share(FADE_END), 0.0);
        assert_eq!(share(2.0 * FADE_END), 0.0);
        assert!((share(0.5 * FADE_END) - 0.75).abs() < 1e-6);
        let mut last = 1.0;
        for i in 1..=20 {
            let s = share(i as f32 / 20.0 * FADE_END);
            assert!(s < last, "{i}: {s}");
            last = s;
        }
    }
}
