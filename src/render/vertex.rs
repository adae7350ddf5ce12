//! The vertex pass: each model's vertices placed for this frame (world
//! position, unit normal, clip position) and its per-corner tangents
//! turned with it.

use glam::{Mat3, Mat4, Vec3, Vec4};
use rayon::prelude::*;

use super::draw_list::DrawList;

/// Vertices of one model after the vertex pass.
pub(super) struct ModelVertices {
    pub world: Vec<Vec3>,
    pub normal: Vec<Vec3>,
    pub clip: Vec<Vec4>,
    /// Gouraud only: per-vertex (diffuse, specular) light sums.
    pub light: Vec<(Vec3, Vec3)>,
    pub normal_from_object: Mat3,
    /// Tangents turn with the surface (not the inverse transpose); a
    /// mirroring transform flips the bitangent. The geometry pass turns
    /// the corners of the triangles it keeps (`turn_tangents`,
    /// `Geometry::tangents`).
    tangent_from_object: Mat3,
    tangent_flip: f32,
}

impl ModelVertices {
    /// Writes the world-space tangents of mesh triangle `prim`'s three
    /// corners, read from `source` (the model's per-corner tangents), to
    /// `out`.
    #[inline]
    pub(super) fn turn_tangents(&self, source: &[Vec4], prim: u32, out: &mut [Vec4; 3]) {
        let c = prim as usize * 3;
        for (o, t) in out.iter_mut().zip(&source[c..c + 3]) {
            *o = (self.tangent_from_object * t.truncate())
                .normalize_or(Vec3::X)
                .extend(t.w * self.tangent_flip);
        }
    }
}

/// Model `m`'s per-corner tangents (at rest or posed) in object space.
pub(super) fn tangent_source<'a>(setup: &'a DrawList, m: usize) -> &'a [Vec4] {
    match &setup.posed[m] {
        Some((p, _)) => &p.tangents,
        None => &setup.scene.models[m].mesh.tangents,
    }
}

/// Every model of the frame, in scene order.
pub(super) fn transform_all(setup: &DrawList) -> Vec<ModelVertices> {
    setup
        .scene
        .models
        .iter()
        .zip(&setup.world_from_object)
        .zip(&setup.posed)
        .map(|((m, world), posed)| {
            let (positions, normals) = match posed {
                Some((p, _)) => (&p.positions, &p.normals),
                None => (&m.mesh.positions, &m.mesh.normals),
            };
            transform(setup.clip_from_world, positions, normals, *world)
        })
        .collect()
}

/// A model's vertices (at rest or posed) placed by `world_from_object`.
fn transform(
    clip_from_world: Mat4,
    positions: &[Vec3],
    normals: &[Vec3],
    world_from_object: Mat4,
) -> ModelVertices {
    let normal_from_object = Mat3::from_mat4(world_from_object).inverse().transpose();
    let n = positions.len();
    let mut world = vec![Vec3::ZERO; n];
    let mut normal = vec![Vec3::ZERO; n];
    let mut clip = vec![Vec4::ZERO; n];
    const V_CHUNK: usize = 8192;
    world
        .par_chunks_mut(V_CHUNK)
        .zip(normal.par_chunks_mut(V_CHUNK))
        .zip(clip.par_chunks_mut(V_CHUNK))
        .enumerate()
        .for_each(|(c, ((w, nn), cl))| {
            let base = c * V_CHUNK;
            for i in 0..w.len() {
                let p = world_from_object.transform_point3(positions[base + i]);
                w[i] = p;
                nn[i] = (normal_from_object * normals[base + i]).normalize_or(Vec3::Y);
                cl[i] = clip_from_world * p.extend(1.0);
            }
        });
    let m3 = Mat3::from_mat4(world_from_object);
    ModelVertices {
        world,
        normal,
        clip,
        light: Vec::new(),
        normal_from_object,
        tangent_from_object: m3,
        tangent_flip: if m3.determinant() < 0.0 { -1.0 } else { 1.0 },
    }
}
