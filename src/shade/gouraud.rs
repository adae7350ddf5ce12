//! Gouraud shading's vertex half: Blinn-Phong light summed at each vertex
//! (diffuse and specular apart, shadowed at the vertex), to be
//! interpolated across the triangles and combined with the surface color
//! per pixel (`ShadeContext::shade`).

use glam::Vec3;
use rayon::prelude::*;

use super::{ShadeContext, blinn_phong};
use crate::scene::Model;

/// Per vertex of `model` placed at `world` with unit normals `normal`:
/// the (diffuse, specular) light sums, each vertex lit with the exponent
/// of a material that uses it (the last one in triangle order).
pub fn vertex_light(
    ctx: &ShadeContext,
    model: &Model,
    world: &[Vec3],
    normal: &[Vec3],
) -> Vec<(Vec3, Vec3)> {
    let mesh = &model.mesh;
    let n = mesh.positions.len();
    let mut ns = vec![32.0f32; n];
    let mut spec = vec![false; n];
    for g in &mesh.groups {
        let mat = &model.materials[g.material];
        for t in &mesh.triangles[g.triangles.start as usize..g.triangles.end as usize] {
            for &i in t {
                ns[i as usize] = mat.ns;
                spec[i as usize] = mat.illum >= 2;
            }
        }
    }
    (0..n)
        .into_par_iter()
        .map(|i| {
            let (p, nn) = (world[i], normal[i]);
            let v = ctx.view_vector(p);
            let shadow = |k: usize, l: Vec3| ctx.shadows.visibility(k, p, nn, l);
            blinn_phong::light_sums(
                p,
                nn,
                v,
                ns[i],
                spec[i],
                super::light::LightSet::all(ctx.lights),
                &shadow,
            )
        })
        .collect()
}
