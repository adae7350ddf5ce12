//! Ray-traced visibility, the reference the approximate methods are measured
//! against: one object-space BVH per mesh (the renderer builds it once and
//! keeps it across frames), and per frame a `Tracer` that carries
//! world-space rays into each placed mesh's object space. Nothing here knows
//! about scenes: a tracer is made from BVHs and placements.

pub mod bvh;

use glam::{Mat4, Vec3, Vec3A};

use bvh::Bvh;

/// A mesh as one frame places it.
#[derive(Clone, Copy)]
pub struct Placed<'a> {
    pub bvh: &'a Bvh,
    /// What a ray may pass through on this mesh (masked and blended
    /// materials); None: every triangle stops it.
    pub cutout: Option<&'a dyn Cutout>,
    /// The mesh's object-space bounds (lo, hi).
    pub bounds: (Vec3, Vec3),
    pub world_from_object: Mat4,
}

struct Instance<'a> {
    /// Its place in the `placed` list the tracer was made from.
    index: usize,
    bvh: &'a Bvh,
    cutout: Option<&'a dyn Cutout>,
    object_from_world: Mat4,
    /// World-space bounds (a quick reject before the transform).
    lo: Vec3A,
    hi: Vec3A,
}

/// What a ray may pass through on one mesh: the holes of a masked
/// material, a share of a blended one.
pub trait Cutout: Sync {
    /// The share of light the triangle `hit` met on the object-space ray
    /// `o + t d` lets through: 1 in a hole, 0 where it is solid, 1 -
    /// opacity where it is blended.
    fn pass(&self, hit: bvh::Hit, o: Vec3, d: Vec3) -> f32;

    /// Whether the triangle stops the ray, for queries that take all or
    /// nothing: a share is let through where a number of the ray and the
    /// triangle falls below it.
    fn stops(&self, hit: bvh::Hit, o: Vec3, d: Vec3) -> bool;
}

/// The scene's triangles as placed in one frame.
pub struct Tracer<'a> {
    instances: Vec<Instance<'a>>,
    /// The instances' world-space bounds together, where all are finite:
    /// a ray that misses them meets nothing (one test before the
    /// instances' own).
    bounds: Option<(Vec3A, Vec3A)>,
    /// Offset along the geometric normal that keeps a ray from hitting the
    /// surface it starts on (a ten-thousandth of the scene's radius).
    pub epsilon: f32,
}

impl<'a> Tracer<'a> {
    /// `placed`: every mesh of the frame (empty BVHs are skipped);
    /// `scene_radius`: the scene's bounding radius, which sets `epsilon`.
    pub fn new(placed: impl IntoIterator<Item = Placed<'a>>, scene_radius: f32) -> Tracer<'a> {
        let instances: Vec<Instance> = placed
            .into_iter()
            .enumerate()
            .filter(|(_, p)| !p.bvh.is_empty())
            .map(|(index, p)| {
                let (lo, hi) = p.bounds;
                let w = p.world_from_object;
                let mut wlo = Vec3A::splat(f32::INFINITY);
                let mut whi = Vec3A::splat(f32::NEG_INFINITY);
                for k in 0..8 {
                    let c = Vec3::new(
                        if k & 1 == 0 { lo.x } else { hi.x },
                        if k & 2 == 0 { lo.y } else { hi.y },
                        if k & 4 == 0 { lo.z } else { hi.z },
                    );
                    let q = Vec3A::from(w.transform_point3(c));
                    wlo = wlo.min(q);
                    whi = whi.max(q);
                }
                Instance {
                    index,
                    bvh: p.bvh,
                    cutout: p.cutout,
                    object_from_world: w.inverse(),
                    lo: wlo,
                    hi: whi,
                }
            })
            .collect();
        let finite = instances
            .iter()
            .all(|i| i.lo.is_finite() && i.hi.is_finite());
        let bounds = finite.then(|| {
            instances.iter().fold(
                (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
                |(lo, hi), i| (lo.min(i.lo), hi.max(i.hi)),
            )
        });
        Tracer {
            instances,
            bounds,
            epsilon: scene_radius.max(1e-6) * 1e-4,
        }
    }

    /// Whether some placed mesh's bounds come within `r` of `p` (where
    /// none does, no ray from `p` shorter than `r` meets anything).
    pub fn any_within(&self, p: Vec3, r: f32) -> bool {
        let p = Vec3A::from(p);
        self.instances.iter().any(|i| {
            let nearest = p.clamp(i.lo, i.hi);
            // NaN bounds or points count as near.
            let d2 = (nearest - p).length_squared();
            d2 <= r * r || d2.is_nan()
        })
    }

    /// Whether anything lies on `o + t d` for t in (0, t_max).
    pub fn occluded(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        let (oa, inv) = (Vec3A::from(o), Vec3A::from(d).recip());
        if !self.may_meet(oa, inv, t_max) {
            return false;
        }
        self.instances.iter().any(|i| {
            box_hit(i.lo, i.hi, oa, inv, t_max) && {
                let m = &i.object_from_world;
                let (oo, od) = (m.transform_point3(o), m.transform_vector3(d));
                match i.cutout {
                    None => i.bvh.occluded(oo, od, 0.0, t_max),
                    Some(c) => i
                        .bvh
                        .occluded_where((oo, od), (0.0, t_max), |h| c.stops(h, oo, od)),
                }
            }
        })
    }
}

impl Tracer<'_> {
    /// Whether the ray from `o` (1 / its direction: `inv`) within `t_max`
    /// meets the instances' bounds together: where it does not, it meets
    /// no instance's (each lies inside them).
    #[inline(always)]
    fn may_meet(&self, o: Vec3A, inv: Vec3A, t_max: f32) -> bool {
        self.bounds
            .is_none_or(|(lo, hi)| box_hit(lo, hi, o, inv, t_max))
    }
}

/// The nearest surface a ray meets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceHit {
    /// The mesh: its index in the `placed` list of `Tracer::new`.
    pub mesh: usize,
    /// The triangle within the mesh.
    pub prim: u32,
    /// Where along the ray: the point is `o + t d`.
    pub t: f32,
}

impl Tracer<'_> {
    /// The share of light that comes through along `o + t d` for t in
    /// (0, t_max): 0 past a solid triangle, the product of what blended
    /// ones let through otherwise (`Cutout::pass`), 1 where nothing is in
    /// the way.
    pub fn transmittance(&self, o: Vec3, d: Vec3, t_max: f32) -> f32 {
        let (oa, inv) = (Vec3A::from(o), Vec3A::from(d).recip());
        if !self.may_meet(oa, inv, t_max) {
            return 1.0;
        }
        let mut through = 1.0;
        for i in &self.instances {
            if !box_hit(i.lo, i.hi, oa, inv, t_max) {
                continue;
            }
            let m = &i.object_from_world;
            let (oo, od) = (m.transform_point3(o), m.transform_vector3(d));
            let blocked = match i.cutout {
                None => i.bvh.occluded(oo, od, 0.0, t_max),
                Some(c) => {
                    // Every triangle met is seen once; the walk stops at
                    // the first solid one.
                    let share = std::cell::Cell::new(1.0f32);
                    let solid = i.bvh.occluded_where((oo, od), (0.0, t_max), |h| {
                        let p = c.pass(h, oo, od);
                        share.set(share.get() * p);
                        p <= 0.0
                    });
                    through *= share.get();
                    solid
                }
            };
            if blocked {
                return 0.0;
            }
        }
        through
    }

    /// The nearest surface on `o + t d` for t in (0, t_max).
    pub fn nearest(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<TraceHit> {
        let (oa, inv) = (Vec3A::from(o), Vec3A::from(d).recip());
        if !self.may_meet(oa, inv, t_max) {
            return None;
        }
        let mut best: Option<TraceHit> = None;
        for i in &self.instances {
            let reach = best.map_or(t_max, |b| b.t);
            if !box_hit(i.lo, i.hi, oa, inv, reach) {
                continue;
            }
            let m = &i.object_from_world;
            let (oo, od) = (m.transform_point3(o), m.transform_vector3(d));
            let hit = match i.cutout {
                None => i.bvh.nearest(oo, od, 0.0, reach),
                Some(c) => i
                    .bvh
                    .nearest_where((oo, od), (0.0, reach), |h| c.stops(h, oo, od)),
            };
            if let Some(h) = hit {
                best = Some(TraceHit {
                    mesh: i.index,
                    prim: h.prim,
                    t: h.t,
                });
            }
        }
        best
    }
}

#[inline]
fn box_hit(lo: Vec3A, hi: Vec3A, o: Vec3A, inv: Vec3A, t_max: f32) -> bool {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(t_max);
    near <= far
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lets through half the light at every triangle, or none.
    struct Half(f32);

    impl Cutout for Half {
        fn pass(&self, _: bvh::Hit, _: Vec3, _: Vec3) -> f32 {
            self.0
        }
        fn stops(&self, _: bvh::Hit, _: Vec3, _: Vec3) -> bool {
            self.0 <= 0.0
        }
    }

    #[test]
    fn transmittance_multiplies_what_each_surface_lets_through() {
        // Two unit squares in the planes z = 0 and z = 1.
        let (pos, tris) = (
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(1.0, 1.0, 1.0),
                Vec3::new(0.0, 1.0, 1.0),
            ],
            vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]],
        );
        let bvh = Bvh::build(&pos, &tris);
        let (half, none) = (Half(0.5), Half(0.0));
        for (cutout, through, occluded) in [
            (None, 0.0, true),
            (Some(&half as &dyn Cutout), 0.25, false),
            (Some(&none as &dyn Cutout), 0.0, true),
        ] {
            let t = Tracer::new(
                [Placed {
                    bvh: &bvh,
                    cutout,
                    bounds: (Vec3::ZERO, Vec3::ONE),
                    world_from_object: Mat4::IDENTITY,
                }],
                1.0,
            );
            let (o, d) = (Vec3::new(0.3, 0.4, -1.0), Vec3::Z);
            assert_eq!(t.transmittance(o, d, f32::INFINITY), through);
            assert_eq!(t.occluded(o, d, f32::INFINITY), occluded);
            // Beyond both, or beside them: all of it.
            assert_eq!(t.transmittance(o, d, 0.5), 1.0);
            assert_eq!(
                t.transmittance(Vec3::new(3.0, 0.4, -1.0), d, f32::INFINITY),
                1.0
            );
            // The nearest surface the cutout keeps.
            assert_eq!(t.nearest(o, d, f32::INFINITY).is_some(), occluded);
        }
    }

    /// The bounds of all instances together (`may_meet`) change no answer:
    /// two boxes apart, one turned, and rays from a grid of points towards
    /// a spread of directions, some through the gap between them, some
    /// past both, with and without a length, as `occluded` and `nearest`
    /// give them without those bounds.
    #[test]
    fn the_scene_bounds_change_no_ray() {
        let positions = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let bvh = Bvh::build(&positions, &[[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]);
        let bounds = (Vec3::ZERO, Vec3::ONE);
        let placed = [
            Mat4::from_translation(Vec3::new(-2.0, 0.0, 0.0)),
            Mat4::from_translation(Vec3::new(1.5, 0.5, 0.0)) * Mat4::from_rotation_y(0.7),
        ]
        .map(|world_from_object| Placed {
            bvh: &bvh,
            cutout: None,
            bounds,
            world_from_object,
        });
        let tracer = Tracer::new(placed, 4.0);
        assert!(tracer.bounds.is_some());
        let unbounded = Tracer {
            bounds: None,
            ..Tracer::new(placed, 4.0)
        };
        let (mut hits, mut rays) = (0, 0);
        for i in 0..9 {
            for j in 0..9 {
                let o = Vec3::new(i as f32 - 4.0, 3.0, j as f32 - 4.0);
                for k in 0..24 {
                    let a = k as f32 * 0.26;
                    let d = Vec3::new(a.cos(), -0.4 - 0.1 * (k % 5) as f32, a.sin()).normalize();
                    for t_max in [f32::INFINITY, 4.0] {
                        let hit = unbounded.occluded(o, d, t_max);
                        assert_eq!(tracer.occluded(o, d, t_max), hit, "{o} {d} {t_max}");
                        assert_eq!(tracer.nearest(o, d, t_max), unbounded.nearest(o, d, t_max));
                        hits += u32::from(hit);
                        rays += 1;
                    }
                }
            }
        }
        // Some rays meet the boxes, most miss both.
        assert!(hits > 20 && hits < rays / 2, "{hits} of {rays}");
    }
}
