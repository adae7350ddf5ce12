//! The frame's emissive triangles, placed in the world, for
//! `method = "sampled"` to light the scene with (`shade::env::emitters`).

use glam::Vec3;

use super::draw_list::DrawList;
use super::vertex::ModelVertices;
use crate::scene::emitters::emitted;
use crate::shade::env::emitters::Emitters;

/// Every triangle whose material emits, at this frame's vertex positions.
pub(super) fn emitters(setup: &DrawList, verts: &[ModelVertices]) -> Emitters {
    let mode = setup.scene.settings.shading;
    let mut triangles = Vec::new();
    for (model, mv) in setup.scene.models.iter().zip(verts) {
        let emitted: Vec<Vec3> = model.materials.iter().map(|m| emitted(mode, m)).collect();
        for g in &model.mesh.groups {
            let Some(&radiance) = emitted.get(g.material).filter(|e| **e != Vec3::ZERO) else {
                continue;
            };
            let range = g.triangles.start as usize..g.triangles.end as usize;
            for t in model.mesh.triangles.get(range).unwrap_or(&[]) {
                let corner = |i: u32| mv.world.get(i as usize).copied();
                if let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) {
                    triangles.push(([a, b, c], radiance));
                }
            }
        }
    }
    Emitters::new(triangles)
}
