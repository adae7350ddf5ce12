//! The vertex pass: each model's vertices placed for this frame (world
//! position, unit normal, clip position) and its per-corner tangents
//! turned with it.

use glam::{Mat3, Mat4, Vec3, Vec4};
use rayon::prelude::*;

use super::setup::FrameSetup;

/// Vertices of one model after the vertex pass.
pub(super) struct ModelVertices {
    pub world: Vec<Vec3>,
    pub normal: Vec<Vec3>,
    pub clip: Vec<Vec4>,
    /// Gouraud only: per-vertex (diffuse, specular) light sums.
    pub light: Vec<(Vec3, Vec3)>,
    /// Per triangle corner: world-space tangent and bitangent sign (empty
    /// when the mesh has no tangents).
    pub tangent: Vec<Vec4>,
    pub normal_from_object: Mat3,
}

/// Every model of the frame, in scene order.
pub(super) fn transform_all(fs: &FrameSetup) -> Vec<ModelVertices> {
    fs.scene
        .models
        .iter()
        .zip(&fs.world_from_object)
        .zip(&fs.posed)
        .map(|((m, world), posed)| {
            let (positions, normals, tangents) = match posed {
                Some((p, _)) => (&p.positions, &p.normals, &p.tangents),
                None => (&m.mesh.positions, &m.mesh.normals, &m.mesh.tangents),
            };
            transform(fs.clip_from_world, positions, normals, tangents, *world)
        })
        .collect()
}

/// A model's vertices (at rest or posed) placed by `world_from_object`.
fn transform(
    clip_from_world: Mat4,
    positions: &[Vec3],
    normals: &[Vec3],
    tangents: &[Vec4],
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
    // Tangents follow the surface (not the inverse transpose); a mirroring
    // transform flips the bitangent.
    let m3 = Mat3::from_mat4(world_from_object);
    let flip = if m3.determinant() < 0.0 { -1.0 } else { 1.0 };
    let tangent = tangents
        .par_iter()
        .map(|t| (m3 * t.truncate()).normalize_or(Vec3::X).extend(t.w * flip))
        .collect();
    ModelVertices {
        world,
        normal,
        clip,
        light: Vec::new(),
        tangent,
        normal_from_object,
    }
}
