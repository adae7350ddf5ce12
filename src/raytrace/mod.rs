//! Ray-traced visibility, the reference the approximate methods are measured
//! against: one object-space BVH per mesh (built once, on the first frame
//! that needs it, and shared by every model using the mesh), and per frame
//! a `Tracer` that carries world-space rays into each model's object space.

pub mod bvh;

use glam::{Mat4, Vec3, Vec3A};

use crate::scene::Scene;
use bvh::Bvh;

struct Instance<'a> {
    bvh: &'a Bvh,
    object_from_world: Mat4,
    /// World-space bounds (a quick reject before the transform).
    lo: Vec3A,
    hi: Vec3A,
}

/// The scene's triangles as placed in one frame.
pub struct Tracer<'a> {
    instances: Vec<Instance<'a>>,
    /// Offset along the geometric normal that keeps a ray from hitting the
    /// surface it starts on (a ten-thousandth of the scene's radius).
    pub epsilon: f32,
}

impl<'a> Tracer<'a> {
    /// `world_from_object`: per model, this frame's placement.
    pub fn new(scene: &'a Scene, world_from_object: &[Mat4]) -> Tracer<'a> {
        let instances = scene
            .models
            .iter()
            .zip(world_from_object)
            .filter_map(|(m, &w)| {
                let mesh = &*m.mesh;
                let bvh = mesh
                    .bvh
                    .get_or_init(|| Bvh::build(&mesh.positions, &mesh.triangles));
                if bvh.is_empty() {
                    return None;
                }
                let (lo, hi) = mesh.bounds();
                let mut wlo = Vec3A::splat(f32::INFINITY);
                let mut whi = Vec3A::splat(f32::NEG_INFINITY);
                for k in 0..8 {
                    let c = Vec3::new(
                        if k & 1 == 0 { lo.x } else { hi.x },
                        if k & 2 == 0 { lo.y } else { hi.y },
                        if k & 4 == 0 { lo.z } else { hi.z },
                    );
                    let p = Vec3A::from(w.transform_point3(c));
                    wlo = wlo.min(p);
                    whi = whi.max(p);
                }
                Some(Instance {
                    bvh,
                    object_from_world: w.inverse(),
                    lo: wlo,
                    hi: whi,
                })
            })
            .collect();
        Tracer {
            instances,
            epsilon: scene.bounds_radius.max(1e-6) * 1e-4,
        }
    }

    /// Whether anything lies on `o + t d` for t in (0, t_max).
    pub fn occluded(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        let (oa, inv) = (Vec3A::from(o), Vec3A::from(d).recip());
        self.instances.iter().any(|i| {
            box_hit(i.lo, i.hi, oa, inv, t_max) && {
                let m = &i.object_from_world;
                i.bvh
                    .occluded(m.transform_point3(o), m.transform_vector3(d), 0.0, t_max)
            }
        })
    }

    /// Ray parameter of the nearest hit on `o + t d`, t in (0, t_max).
    pub fn nearest(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let (oa, inv) = (Vec3A::from(o), Vec3A::from(d).recip());
        let mut best = t_max;
        let mut hit = None;
        for i in &self.instances {
            if !box_hit(i.lo, i.hi, oa, inv, best) {
                continue;
            }
            let m = &i.object_from_world;
            if let Some(h) = i
                .bvh
                .nearest(m.transform_point3(o), m.transform_vector3(d), 0.0, best)
            {
                best = h.t;
                hit = Some(h.t);
            }
        }
        hit
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
