//! The frame's emissive triangles, placed in the world, for
//! `method = "sampled"` to light the scene with (`shade::env::emitters`).

use glam::{Vec3, Vec4};

use super::draw_list::DrawList;
use super::vertex::ModelVertices;
use crate::assets::texture::TextureRef;
use crate::scene::material::Material;
use crate::scene::settings::ShadingMode;
use crate::shade::env::emitters::Emitters;
use crate::shade::shades_pbr;

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

/// The radiance a material emits as shading mode `mode` shades it
/// (metallic-roughness: `emissive`, Blinn-Phong: `Ke`), times its emission
/// map's mean colour; nothing for an unlit material, which shows its base
/// colour alone.
fn emitted(mode: ShadingMode, m: &Material) -> Vec3 {
    if m.unlit {
        return Vec3::ZERO;
    }
    let (color, map) = if shades_pbr(mode, m) {
        (m.pbr.emissive, &m.pbr.emissive_map)
    } else {
        (m.ke, &m.map_ke)
    };
    match map {
        Some(t) if color != Vec3::ZERO => color * mean_color(t),
        _ => color,
    }
}

/// The mean linear colour of a map, over a 16 x 16 grid of its texels.
fn mean_color(map: &TextureRef) -> Vec3 {
    let t = &map.texture;
    let base = t.base();
    let (w, h) = (base.width, base.height);
    let mut sum = Vec4::ZERO;
    let n = 16u32;
    for j in 0..n {
        for i in 0..n {
            let (x, y) = ((2 * i + 1) * w / (2 * n), (2 * j + 1) * h / (2 * n));
            sum += t.decode(base.texel(x.min(w.saturating_sub(1)), y.min(h.saturating_sub(1))));
        }
    }
    sum.truncate() / (n * n) as f32
}
