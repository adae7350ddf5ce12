//! Gouraud shading's vertex half: Blinn-Phong light summed at each vertex
//! (diffuse and specular apart, shadowed at the vertex), to be
//! interpolated across the triangles and combined with the surface color
//! per pixel (`ShadeContext::shade_lanes`).

use glam::Vec3;
use rayon::prelude::*;

use super::ShadeContext;
use super::lanes::{Lanes, MAX_LANES};
use super::light::LightMask;
use crate::scene::Model;
use crate::simd::V3;

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
            // The vertex as the one-lane instance of the shading code
            // takes a point (its normal is its plane's for shadows).
            let f = Lanes::<f32> {
                position: V3::from(p),
                normal: V3::from(nn),
                color: None,
                geo_normal: [nn; MAX_LANES],
                ao: 1.0,
                depth: 0.0,
                edge: f32::INFINITY,
                lights: LightMask::ALL,
                vertex_light: None,
            };
            let (d, s) = ctx.light_sums(&f, [nn, v].map(V3::from), ns[i], spec[i]);
            (d.into(), s.into())
        })
        .collect()
}
