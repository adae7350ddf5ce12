//! Ray-traced visibility, the reference the approximate methods are measured
//! against: one object-space BVH per mesh (the renderer builds it once and
//! keeps it across frames), and per frame a `Tracer` that carries
//! world-space rays into each placed mesh's object space. Nothing here knows
//! about scenes: a tracer is made from BVHs and placements.

pub mod bvh;

use glam::{Mat4, Vec3, Vec3A};

use bvh::Bvh;

/// A mesh as one frame places it.
#[derive(Debug, Clone, Copy)]
pub struct Placed<'a> {
    pub bvh: &'a Bvh,
    /// The mesh's object-space bounds (lo, hi).
    pub bounds: (Vec3, Vec3),
    pub world_from_object: Mat4,
}

struct Instance<'a> {
    /// Its place in the `placed` list the tracer was made from.
    index: usize,
    bvh: &'a Bvh,
    object_from_world: Mat4,
    /// World-space bounds (a quick reject before the transform).
    lo: Vec3A,
    hi: Vec3A,
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
                i.bvh
                    .occluded(m.transform_point3(o), m.transform_vector3(d), 0.0, t_max)
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
            if let Some(h) = i.bvh.nearest(oo, od, 0.0, reach) {
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
