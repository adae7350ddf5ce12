//! One bounce of light for `method = "sampled"`: where a ray from a shaded
//! point meets another surface, that surface's light is counted instead
//! of nothing. A path tracer's first indirect bounce: a Cornell box's
//! walls light each other (the red wall tints the floor beside it, the
//! ceiling is lit by the floor), and a metal disc shows the neighbour it
//! faces.
//!
//! The surface met (`Bounce`: its normal, Lambertian and specular
//! reflectance, roughness) is lit by
//! - the environment: one direction drawn from the image and one by the
//!   cosine, combined by the balance heuristic, each tested for
//!   visibility;
//! - the emissive triangles: one point drawn on them, tested;
//! - its specular lobe: the prefiltered environment along its mirror
//!   direction (no visibility).
//!
//! Its own emission is not added: the shaded point counts emitters by
//! drawing points on them, and a ray that meets one would count it twice.
//! Light that bounces twice or more is lost. A surface that transmits
//! (transmission at least a half) lets the ray straight through, as a
//! thin wall.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::EnvLight;
use super::emitters::{Emitters, from_emitter};
use super::image_sampler::EnvSampler;
use super::pattern::position_hash;
use crate::raytrace::{TraceHit, Tracer};
use crate::shade::ao::cosine_direction;

/// A surface a ray met, as the bounce lights it.
#[derive(Debug, Clone, Copy)]
pub struct Bounce {
    /// The point met.
    pub position: Vec3,
    /// Unit shading normal, on the side the ray came from.
    pub normal: Vec3,
    /// Unit geometric normal, on the same side (the rays' offset).
    pub geometric: Vec3,
    /// Lambertian reflectance (the diffuse colour).
    pub diffuse: Vec3,
    /// Specular reflectance at normal incidence.
    pub specular: Vec3,
    /// Perceptual roughness of the specular lobe.
    pub roughness: f32,
    /// The share of light it lets through (KHR_materials_transmission):
    /// a ray refracted into a volume leaves it where it meets a surface
    /// that transmits.
    pub transmission: f32,
    /// The light it emits (counted only where a refracted ray sees it:
    /// `Scene::seen`).
    pub emitted: Vec3,
    /// Its emission lights the scene as an area light already
    /// (`environment.emitters`): a traced reflection leaves it to the
    /// light's highlight.
    pub lamp: bool,
}

/// The frame's surfaces, as a ray meets them.
pub trait Surfaces: Sync {
    /// The surface `hit` found on the ray `o + t d`; None where it cannot
    /// be read (counted as dark).
    fn at(&self, hit: TraceHit, o: Vec3, d: Vec3) -> Option<Bounce>;
}

/// What the bounce reads: the environment's sampler and prefiltered
/// levels, the frame's rays, surfaces and emitters.
#[derive(Clone, Copy)]
pub struct Scene<'a> {
    pub sampler: &'a EnvSampler,
    pub light: Option<&'a EnvLight>,
    pub tracer: &'a Tracer<'a>,
    pub surfaces: &'a dyn Surfaces,
    pub emitters: &'a Emitters,
}

impl Scene<'_> {
    /// Radiance arriving at `o` along unit `d`: the environment where
    /// the ray leaves the scene, else what the surface it meets reflects
    /// towards `o`. `xi`: this sample's two numbers in [0, 1).
    pub fn incoming(&self, o: Vec3, d: Vec3, xi: Vec2) -> Vec3 {
        self.along(o, d, xi, false)
    }

    /// `incoming`, with the light the surface met emits: what a refracted
    /// ray shows (no point drawn on the emitters stands for it).
    pub fn seen(&self, o: Vec3, d: Vec3, xi: Vec2) -> Vec3 {
        self.along(o, d, xi, true)
    }

    fn along(&self, mut o: Vec3, d: Vec3, xi: Vec2, emission: bool) -> Vec3 {
        // Through up to 8 transmissive surfaces, straight on (as thin
        // walls), to the first that reflects.
        for _ in 0..8 {
            let Some(hit) = self.tracer.nearest(o, d, f32::INFINITY) else {
                return self.sampler.radiance(d);
            };
            let Some(b) = self.surfaces.at(hit, o, d) else {
                return Vec3::ZERO;
            };
            if b.transmission >= 0.5 {
                o = b.position - b.geometric * self.tracer.epsilon;
                continue;
            }
            return self.leaving(&b, -d, xi, emission);
        }
        Vec3::ZERO
    }

    /// What surface `b` sends towards unit `wo` (`reflected`), with its
    /// emission where `emission`. The bounce draws its own numbers: `xi`
    /// (the ray's) turned by a hash of the point met, so that its
    /// directions do not follow those that chose the ray.
    pub fn leaving(&self, b: &Bounce, wo: Vec3, xi: Vec2, emission: bool) -> Vec3 {
        let u = xi + position_hash(b.position);
        let own = if emission { b.emitted } else { Vec3::ZERO };
        own + self.reflected(b, wo, u - u.floor())
    }

    /// What surface `b` reflects towards unit `wo`, clamped
    /// (`INDIRECT_CLAMP`).
    fn reflected(&self, b: &Bounce, wo: Vec3, xi: Vec2) -> Vec3 {
        clamped(self.reflected_unclamped(b, wo, xi))
    }

    fn reflected_unclamped(&self, b: &Bounce, wo: Vec3, xi: Vec2) -> Vec3 {
        let (tracer, env) = (self.tracer, self.sampler);
        let n = b.normal;
        let q = b.position + b.geometric * tracer.epsilon;
        let open = |l: Vec3| !tracer.occluded(q, l, f32::INFINITY);
        let mut out = Vec3::ZERO;
        if b.diffuse != Vec3::ZERO {
            let mut lit = Vec3::ZERO;
            // The environment, drawn from the image.
            let l = env.sample(xi);
            let c = n.dot(l);
            if c > 0.0 && open(l) {
                lit += env.radiance(l) * (c / (env.pdf(l) + c / PI).max(1e-12));
            }
            // The environment, drawn by the cosine.
            let l = cosine_direction(n, n.any_orthonormal_pair(), (xi.y, xi.x));
            let c = n.dot(l);
            if c > 0.0 && open(l) {
                lit += env.radiance(l) * (c / (env.pdf(l) + c / PI).max(1e-12));
            }
            // The emitters.
            let shifted = Vec2::new((xi.x + 0.5).fract(), (xi.y + 0.25).fract());
            if let Some(e) = self.emitters.sample(shifted) {
                let cos = |l: Vec3| Vec3::splat(n.dot(l).max(0.0));
                lit += from_emitter(&e, q, &cos, |l, dist| {
                    !tracer.occluded(q, l, dist - 2.0 * tracer.epsilon)
                });
            }
            out += b.diffuse / PI * lit;
        }
        if let (Some(light), true) = (self.light, b.specular != Vec3::ZERO) {
            let r = n * (2.0 * n.dot(wo)) - wo;
            out += b.specular * light.prefiltered(r, b.roughness);
        }
        out
    }
}

/// Bounced light above this (in any channel) is scaled down to it, as a
/// path tracer clamps indirect light (Cycles' default): a ray that meets a
/// wall right by a lamp would otherwise leave a lone bright pixel.
pub const INDIRECT_CLAMP: f32 = 10.0;

/// `c` scaled down to `INDIRECT_CLAMP` in its largest channel.
pub(crate) fn clamped(c: Vec3) -> Vec3 {
    let m = c.max_element();
    if m > INDIRECT_CLAMP {
        c * (INDIRECT_CLAMP / m)
    } else {
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::environment::EnvImage;
    use crate::raytrace::Placed;
    use crate::raytrace::bvh::Bvh;
    use crate::shade::env::sampled::{Lobes, Sampled, radiance};
    use glam::Mat4;

    /// Every surface a grey Lambertian one, facing the ray.
    struct Grey(f32);

    impl Surfaces for Grey {
        fn at(&self, hit: TraceHit, o: Vec3, d: Vec3) -> Option<Bounce> {
            Some(Bounce {
                position: o + d * hit.t,
                normal: -d.y.signum() * Vec3::Y,
                geometric: -d.y.signum() * Vec3::Y,
                diffuse: Vec3::splat(self.0),
                specular: Vec3::ZERO,
                roughness: 1.0,
                transmission: 0.0,
                emitted: Vec3::ZERO,
                lamp: false,
            })
        }
    }

    #[test]
    fn under_a_grey_ceiling_in_a_white_sky_a_floor_sees_the_ceilings_albedo() {
        // A ceiling at y = 1, wide enough to fill the sky above the origin
        // (to within 0.06 degrees of the horizon), in a sky of radiance 1
        // all round. The ceiling's underside sees the sky below it: its
        // radiance is its albedo. A Lambertian point below it, facing up,
        // then sends kd x albedo; without the bounce, nothing.
        let w = 1000.0;
        let positions = [
            Vec3::new(-w, 1.0, -w),
            Vec3::new(w, 1.0, -w),
            Vec3::new(w, 1.0, w),
            Vec3::new(-w, 1.0, w),
        ];
        let bvh = Bvh::build(&positions, &[[0, 1, 2], [0, 2, 3]]);
        let tracer = Tracer::new(
            [Placed {
                bvh: &bvh,
                cutout: None,
                bounds: (Vec3::new(-w, 1.0, -w), Vec3::new(w, 1.0, w)),
                world_from_object: Mat4::IDENTITY,
            }],
            1.0,
        );
        let sampler = EnvSampler::new(&EnvImage::uniform(Vec3::ONE), 1.0, 0.0);
        let (ceiling, emitters) = (Grey(0.5), Emitters::default());
        let lit = |bounce: bool| {
            let s = Sampled {
                env: &sampler,
                tracer: &tracer,
                emitters: &emitters,
                samples: 256,
                surfaces: bounce.then_some(&ceiling as &dyn Surfaces),
                light: None,
            };
            let lobes = Lobes::BlinnPhong {
                kd: Vec3::splat(0.8),
                ks: Vec3::ZERO,
                roughness: 1.0,
            };
            let points = 16;
            (0..points)
                .map(|k| {
                    let p = Vec3::new(0.37 * k as f32, 0.0, -0.21 * k as f32);
                    radiance(&s, (p, &[Vec3::Y], Vec3::Y), Vec3::Y, &lobes)
                })
                .sum::<Vec3>()
                / points as f32
        };
        let with = lit(true);
        assert!(
            (with - Vec3::splat(0.4)).abs().max_element() < 0.012,
            "{with}"
        );
        let without = lit(false);
        assert!(without.max_element() < 0.002, "{without}");
    }
}
