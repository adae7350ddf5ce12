//! Emissive surfaces as lights (`environment.emitters`): under the
//! prefiltered environment, the most powerful flat emissive surfaces of
//! the models (a Cornell box's ceiling lamp, a panel, a screen) light the
//! scene as area lights with soft ray-traced shadows, as a path tracer's
//! emitters do. `method = "sampled"` draws points on every emissive
//! triangle instead (`shade::env::emitters`).
//!
//! A surface is a connected piece of one material's triangles (joined
//! where they share a vertex or a position). It becomes one light at its
//! area-weighted centre: radiant intensity `along |cos| + around` from a
//! disc of its area (`LightKind::Area`). Only pieces that are mostly flat
//! qualify (the area-weighted normals' sum at least half the area): the
//! light of a closed or curved emitter (a bulb, a glowing sphere) would
//! stand inside it.

use std::collections::HashMap;

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::Model;
use super::environment::Environment;
use super::light::{Light, LightKind};
use super::material::{Material, shades_pbr};
use super::settings::ShadingMode;
use crate::assets::mesh::Mesh;
use crate::assets::texture::TextureRef;

/// The smallest `|sum of area-weighted normals| / area` of a piece that
/// becomes a light.
const MIN_FLATNESS: f32 = 0.5;

/// Share of the environment's irradiance a piece must deliver at the
/// scene's radius to become a light.
const MIN_SHARE: f32 = 0.01;

/// One emissive piece of a model, in its object space.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// Index of the model in the scene.
    pub model: usize,
    /// Area-weighted centre.
    pub center: Vec3,
    /// Unit normal of its main plane.
    pub axis: Vec3,
    /// Projected area along the axis, less `around`.
    pub along: f32,
    /// Projected area every way.
    pub around: f32,
    /// Its area.
    pub area: f32,
    /// Linear radiance it emits (two-sided).
    pub radiance: Vec3,
    /// Its triangles, as indices into the model's mesh, ascending: a
    /// traced reflection that meets one leaves its emission to the light
    /// (`Patch::holds`).
    pub triangles: Vec<u32>,
}

impl Patch {
    /// The light the piece gives with its model placed by
    /// `world_from_object`: areas scale by the placement's stretch.
    pub fn light(&self, world_from_object: Mat4) -> Light {
        let m = Mat3::from_mat4(world_from_object);
        let det = m.determinant().abs();
        let normal = m.inverse().transpose() * self.axis;
        // A flat piece's area scales by |det| |M^-T n|; the rest by the
        // mean stretch squared.
        let flat = det * normal.length();
        let round = det.powf(2.0 / 3.0);
        // A placement that flattens the model (scale 0) leaves no area:
        // the light gives nothing.
        let (flat, round) = if flat.is_finite() && round.is_finite() {
            (flat, round)
        } else {
            (0.0, 0.0)
        };
        let area = self.area * flat;
        Light {
            kind: LightKind::Area {
                position: world_from_object.transform_point3(self.center),
                axis: normal.try_normalize().unwrap_or(self.axis),
                along: self.along * flat,
                around: self.around * round,
                radius: (area / std::f32::consts::PI).sqrt(),
            },
            color: self.radiance,
            shadows: true,
            range: None,
        }
    }

    /// Whether triangle `prim` of model `model` is part of this piece.
    pub fn holds(&self, model: usize, prim: u32) -> bool {
        self.model == model && self.triangles.binary_search(&prim).is_ok()
    }

    fn power(&self) -> f32 {
        luminance(self.radiance) * (self.along + self.around)
    }
}

/// The `max` most powerful flat emissive pieces of `models` (shaded in
/// `mode`) that deliver at least `MIN_SHARE` of `env_irradiance` at the
/// distance `radius`, most powerful first.
pub fn patches(
    models: &[Model],
    mode: ShadingMode,
    max: usize,
    env_irradiance: f32,
    radius: f32,
) -> Vec<Patch> {
    if max == 0 {
        return Vec::new();
    }
    let mut all = Vec::new();
    for (k, model) in models.iter().enumerate() {
        let emitted: Vec<Vec3> = model.materials.iter().map(|m| emitted(mode, m)).collect();
        for g in &model.mesh.groups {
            let Some(&radiance) = emitted.get(g.material).filter(|e| **e != Vec3::ZERO) else {
                continue;
            };
            let range = g.triangles.start as usize..g.triangles.end as usize;
            let tris = model.mesh.triangles.get(range).unwrap_or(&[]);
            for piece in pieces(&model.mesh, tris) {
                let corners: Vec<[u32; 3]> = piece.iter().map(|&i| tris[i]).collect();
                all.extend(patch(&model.mesh, &corners, radiance, k).map(|p| {
                    Patch {
                        triangles: piece
                            .iter()
                            .map(|&i| g.triangles.start + i as u32)
                            .collect(),
                        ..p
                    }
                }));
            }
        }
    }
    // At its scene's scale (the model's rest placement).
    let scaled = |p: &Patch| {
        p.power()
            * models[p.model]
                .world_from_object
                .determinant()
                .abs()
                .powf(2.0 / 3.0)
    };
    let floor = MIN_SHARE * env_irradiance * radius * radius;
    all.retain(|p| scaled(p) >= floor && scaled(p) > 0.0);
    // Stable: equal powers keep the models' order.
    all.sort_by(|a, b| scaled(b).total_cmp(&scaled(a)));
    all.truncate(max);
    all
}

/// A piece's light, if it is flat enough.
fn patch(mesh: &Mesh, piece: &[[u32; 3]], radiance: Vec3, model: usize) -> Option<Patch> {
    let corner = |i: u32| mesh.positions.get(i as usize).copied();
    let faces: Vec<(Vec3, Vec3, f32)> = piece
        .iter()
        .filter_map(|t| {
            let (a, b, c) = (corner(t[0])?, corner(t[1])?, corner(t[2])?);
            let n = (b - a).cross(c - a);
            let area = 0.5 * n.length();
            (area > 0.0 && area.is_finite()).then(|| ((a + b + c) / 3.0, n.normalize(), area))
        })
        .collect();
    let area: f32 = faces.iter().map(|f| f.2).sum();
    let sum: Vec3 = faces.iter().map(|f| f.1 * f.2).sum();
    // Every face's area is finite and positive.
    if area <= 0.0 || sum.length() < MIN_FLATNESS * area {
        return None;
    }
    let axis = sum.normalize();
    let center = faces.iter().map(|f| f.0 * f.2).sum::<Vec3>() / area;
    let (e1, e2) = axis.any_orthonormal_pair();
    let projected = |d: Vec3| faces.iter().map(|f| f.1.dot(d).abs() * f.2).sum::<f32>();
    let around = 0.5 * (projected(e1) + projected(e2));
    let along = (projected(axis) - around).max(0.0);
    Some(Patch {
        model,
        center,
        axis,
        along,
        around,
        area,
        radiance,
        triangles: Vec::new(),
    })
}

/// The connected pieces of `tris`: triangles sharing a vertex, or a
/// vertex position, are one piece. Each piece is its triangles' indices
/// into `tris`, ascending; the pieces in order of their first triangle.
fn pieces(mesh: &Mesh, tris: &[[u32; 3]]) -> Vec<Vec<usize>> {
    let mut id: HashMap<[u32; 3], usize> = HashMap::new();
    let mut parent: Vec<usize> = Vec::new();
    let mut node = |i: u32, parent: &mut Vec<usize>| {
        let p = mesh.positions.get(i as usize).copied().unwrap_or(Vec3::NAN);
        *id.entry(p.to_array().map(f32::to_bits)).or_insert_with(|| {
            parent.push(parent.len());
            parent.len() - 1
        })
    };
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let nodes: Vec<[usize; 3]> = tris
        .iter()
        .map(|t| t.map(|i| node(i, &mut parent)))
        .collect();
    for n in &nodes {
        for &o in &n[1..] {
            let (a, b) = (root(&mut parent, n[0]), root(&mut parent, o));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut slot: HashMap<usize, usize> = HashMap::new();
    let mut out: Vec<Vec<usize>> = Vec::new();
    for (t, n) in nodes.iter().enumerate() {
        let r = root(&mut parent, n[0]);
        let k = *slot.entry(r).or_insert_with(|| {
            out.push(Vec::new());
            out.len() - 1
        });
        out[k].push(t);
    }
    out
}

/// The radiance a material emits as shading mode `mode` shades it
/// (metallic-roughness: `emissive`, Blinn-Phong: `Ke`), times its emission
/// map's mean colour; nothing for an unlit material, which shows its base
/// colour alone.
pub fn emitted(mode: ShadingMode, m: &Material) -> Vec3 {
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

/// The environment's irradiance on a surface, roughly: pi times the mean
/// luminance of its image as read (over the sphere) times its intensity.
pub fn irradiance(env: &Environment) -> f32 {
    let img = env.backdrop.as_deref().unwrap_or(&env.image);
    let (w, h) = (img.width as usize, img.height as usize);
    let (mut sum, mut weight) = (0.0f64, 0.0f64);
    for (y, row) in img.texels.chunks(w.max(1)).enumerate().take(h) {
        // An equirectangular row's solid angle goes as the sine of its
        // polar angle.
        let s = (std::f64::consts::PI * (y as f64 + 0.5) / h as f64).sin();
        let row_sum: f64 = row.iter().map(|c| luminance(*c) as f64).sum();
        sum += row_sum * s;
        weight += row.len() as f64 * s;
    }
    let mean = if weight > 0.0 { sum / weight } else { 0.0 };
    std::f32::consts::PI * mean as f32 * env.intensity
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of side `s` at height `y` facing down, as two triangles
    /// whose shared corners are separate vertices at the same positions.
    fn square(mesh: &mut Mesh, s: f32, y: f32) -> Vec<[u32; 3]> {
        let h = s / 2.0;
        let c = [
            Vec3::new(-h, y, -h),
            Vec3::new(h, y, -h),
            Vec3::new(h, y, h),
            Vec3::new(-h, y, h),
        ];
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([c[0], c[1], c[2], c[0], c[2], c[3]]);
        vec![[base, base + 1, base + 2], [base + 3, base + 4, base + 5]]
    }

    #[test]
    fn a_square_lamp_is_one_flat_light_at_its_centre() {
        let mut mesh = Mesh::default();
        let mut tris = square(&mut mesh, 0.5, 2.0);
        let other = square(&mut mesh, 1.0, -3.0);
        tris.extend(other);
        let pieces = pieces(&mesh, &tris);
        // Joined by position, not by index: two pieces of two triangles.
        assert_eq!(pieces, [vec![0, 1], vec![2, 3]]);
        let p = patch(&mesh, &tris[0..2], Vec3::splat(10.0), 0).unwrap();
        assert!((p.center - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6);
        assert!((p.axis.dot(Vec3::Y).abs() - 1.0).abs() < 1e-6);
        assert!((p.area - 0.25).abs() < 1e-6);
        assert!((p.along - 0.25).abs() < 1e-6 && p.around.abs() < 1e-6);
        // Placed twice as large: four times the area, its disc's radius.
        let light = p.light(Mat4::from_scale(Vec3::splat(2.0)));
        let LightKind::Area {
            position,
            along,
            radius,
            ..
        } = light.kind
        else {
            panic!("{light:?}");
        };
        assert!((position - Vec3::new(0.0, 4.0, 0.0)).length() < 1e-5);
        assert!((along - 1.0).abs() < 1e-5);
        assert!((radius - (1.0 / std::f32::consts::PI).sqrt()).abs() < 1e-5);
        assert_eq!(light.color, Vec3::splat(10.0));
        // Scaled to nothing, it gives nothing.
        let gone = p.light(Mat4::from_scale(Vec3::ZERO));
        let LightKind::Area { along, around, .. } = gone.kind else {
            panic!("{gone:?}");
        };
        assert_eq!((along, around), (0.0, 0.0));
    }

    #[test]
    fn a_closed_emitter_is_no_light() {
        // A unit cube: its normals cancel.
        let mut mesh = Mesh::default();
        for i in 0..8u32 {
            mesh.positions.push(Vec3::new(
                (i & 1) as f32,
                ((i >> 1) & 1) as f32,
                ((i >> 2) & 1) as f32,
            ));
        }
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let tris: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let pieces = pieces(&mesh, &tris);
        assert_eq!(pieces, [(0..12).collect::<Vec<_>>()]);
        assert!(patch(&mesh, &tris, Vec3::ONE, 0).is_none());
        // One face alone is a light.
        assert!(patch(&mesh, &tris[2..4], Vec3::ONE, 0).is_some());
    }
}
