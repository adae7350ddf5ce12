//! The frame's surfaces as `method = "sampled"`'s bounce meets them
//! (`shade::env::bounce`): the triangle a ray hit, placed as this frame
//! places it, with its material's reflectance where the ray met it.
//!
//! The material is read plainly: base colour (or Kd) times its map,
//! bilinear at the point's texture coordinates, times vertex colours;
//! metallic and roughness with their map; transmission takes its share
//! from the diffuse colour; emission (or Ke) times its map. Normal maps
//! and the KHR layers are left out: the bounce carries a fraction of the
//! light, averaged over many rays.

use glam::{Vec2, Vec3, Vec4};

use super::draw_list::DrawList;
use super::vertex::ModelVertices;
use crate::assets::texture::{TextureRef, Wrap};
use crate::raytrace::bvh::Hit;
use crate::raytrace::{Cutout, TraceHit};
use crate::scene::Model;
use crate::scene::material::AlphaMode;
use crate::scene::material::{Material, roughness_from_ns};
use crate::scene::settings::ShadingMode;
use crate::shade::env::bounce::{Bounce, Surfaces};
use crate::shade::shades_pbr;

/// Every model of one frame, at its vertices' positions.
pub(super) struct FrameSurfaces<'a> {
    pub setup: &'a DrawList<'a>,
    pub verts: &'a [ModelVertices],
}

/// What a material does with light at one point.
struct Reflectance {
    diffuse: Vec3,
    /// At normal incidence.
    specular: Vec3,
    /// Perceptual.
    roughness: f32,
    /// The share it lets through.
    transmission: f32,
    emitted: Vec3,
}

impl Surfaces for FrameSurfaces<'_> {
    fn at(&self, hit: TraceHit, o: Vec3, d: Vec3) -> Option<Bounce> {
        let model = self.setup.scene.models.get(hit.mesh)?;
        let mv = self.verts.get(hit.mesh)?;
        let mesh = &model.mesh;
        let tri = *mesh.triangles.get(hit.prim as usize)?;
        let corner = |i: u32| mv.world.get(i as usize).copied();
        let (a, b, c) = (corner(tri[0])?, corner(tri[1])?, corner(tri[2])?);
        let position = o + d * hit.t;
        let w = barycentric(position, (a, b, c))?;
        let toward = -d;
        let face = (b - a).cross(c - a).normalize_or_zero();
        if face == Vec3::ZERO {
            return None;
        }
        let geometric = if face.dot(toward) < 0.0 { -face } else { face };
        let normal =
            interpolate(&mv.normal, tri, w).map_or(geometric, |n| n.normalize_or(geometric));
        let normal = if normal.dot(toward) < 0.0 {
            -normal
        } else {
            normal
        };
        let tint = interpolate(&mesh.colors, tri, w).unwrap_or(Vec4::ONE);
        let group = mesh
            .groups
            .iter()
            .find(|g| g.triangles.contains(&hit.prim))?;
        let material = model.materials.get(group.material)?;
        let read = Reading {
            uv: (
                interpolate(&mesh.uvs, tri, w),
                interpolate(&mesh.uvs1, tri, w),
            ),
            wrap: self.setup.scene.settings.address.into(),
        };
        let r = reflectance(self.setup.scene.settings.shading, material, &read, tint);
        Some(Bounce {
            position,
            normal,
            geometric,
            diffuse: r.diffuse,
            specular: r.specular,
            roughness: r.roughness,
            transmission: r.transmission,
            emitted: r.emitted,
            lamp: r.emitted != Vec3::ZERO
                && self
                    .setup
                    .scene
                    .emitters
                    .iter()
                    .any(|p| p.holds(hit.mesh, hit.prim)),
        })
    }
}

/// How a map is read at the point met.
struct Reading {
    /// The point's texture coordinates, sets 0 and 1 (None: the mesh has
    /// none).
    uv: (Option<Vec2>, Option<Vec2>),
    wrap: Wrap,
}

impl Reading {
    /// The map's linear RGBA at the point; white where the mesh has no
    /// coordinates for it.
    fn map(&self, t: &Option<TextureRef>) -> Vec4 {
        t.as_ref().map_or(Vec4::ONE, |t| self.rgba(t))
    }

    /// `map` of a map that is there.
    fn rgba(&self, t: &TextureRef) -> Vec4 {
        let uv = if t.texcoord == 1 {
            self.uv.1
        } else {
            self.uv.0
        };
        match uv {
            Some(uv) => t.texture.sample_bilinear(
                t.transform.transform_point2(uv),
                t.address.unwrap_or(self.wrap),
            ),
            None => Vec4::ONE,
        }
    }
}

/// The material at the point as shading mode `mode` reads it. An unlit
/// material reflects nothing and shows its colour as if it emitted it.
fn reflectance(mode: ShadingMode, m: &Material, read: &Reading, tint: Vec4) -> Reflectance {
    let pbr = shades_pbr(mode, m);
    if m.unlit {
        let color = if pbr {
            m.pbr.base_color * read.map(&m.pbr.base_color_map)
        } else {
            m.kd.extend(1.0) * read.map(&m.map_kd)
        };
        return Reflectance {
            diffuse: Vec3::ZERO,
            specular: Vec3::ZERO,
            roughness: 1.0,
            transmission: 0.0,
            emitted: (color * tint).truncate(),
        };
    }
    if pbr {
        let p = &m.pbr;
        let base = (p.base_color * read.map(&p.base_color_map) * tint).truncate();
        let mr = read.map(&p.metallic_roughness_map);
        let metal = (p.metallic * mr.z * read.map(&p.metallic_map).x).clamp(0.0, 1.0);
        let rough = (p.roughness * mr.y * read.map(&p.roughness_map).x).clamp(0.0, 1.0);
        let through = p
            .transmission
            .as_ref()
            .map_or(0.0, |t| (t.factor * read.map(&t.map).x).clamp(0.0, 1.0));
        Reflectance {
            diffuse: base * ((1.0 - metal) * (1.0 - through)),
            specular: Vec3::splat(0.04).lerp(base, metal),
            roughness: rough,
            transmission: through,
            emitted: p.emissive * read.map(&p.emissive_map).truncate(),
        }
    } else {
        let kd = m.kd * (read.map(&m.map_kd) * tint).truncate();
        let ks = if m.illum >= 2 {
            m.ks * read.map(&m.map_ks).truncate()
        } else {
            Vec3::ZERO
        };
        Reflectance {
            diffuse: kd,
            specular: ks,
            roughness: roughness_from_ns(m.ns),
            transmission: 0.0,
            emitted: m.ke * read.map(&m.map_ke).truncate(),
        }
    }
}

/// What rays pass through on one model: the holes of its masked
/// materials (opacity below the cutoff at the point met) and a share of
/// its blended ones (a ray goes through where its own number, a hash of
/// the ray and the triangle, is at least the opacity: over the rays of a
/// soft shadow or a pixel's neighbours, the share 1 - opacity). Opacity
/// as the rasterizer reads it (`ShadeContext::opacity_of`: d, map_d,
/// map_kd's alpha, the vertex colours' alpha), the maps read bilinear at
/// full size. Transmissive materials stop rays, as opaque ones do.
pub(super) struct ModelCutout<'a> {
    model: &'a Model,
    wrap: Wrap,
}

impl<'a> ModelCutout<'a> {
    /// The model's cutout; None where every one of its materials stops
    /// rays.
    pub fn of(model: &'a Model, wrap: Wrap) -> Option<ModelCutout<'a>> {
        model
            .materials
            .iter()
            .any(|m| cut_at(m).is_some())
            .then_some(ModelCutout { model, wrap })
    }
}

/// How material `m` lets rays through: Some(false) for a mask's holes,
/// Some(true) for a blend's share; None: it stops them.
fn cut_at(m: &Material) -> Option<bool> {
    match m.alpha {
        AlphaMode::Mask(_) => Some(false),
        AlphaMode::Blend if m.pbr.transmission.is_none() => Some(true),
        _ => None,
    }
}

impl Cutout for ModelCutout<'_> {
    fn pass(&self, hit: Hit, o: Vec3, d: Vec3) -> f32 {
        match self.opacity(hit, o, d) {
            None => 0.0,
            Some((opacity, Some(cutoff))) => f32::from(u8::from(opacity < cutoff)),
            Some((opacity, None)) => (1.0 - opacity).clamp(0.0, 1.0),
        }
    }

    fn stops(&self, hit: Hit, o: Vec3, d: Vec3) -> bool {
        match self.opacity(hit, o, d) {
            None => true,
            Some((opacity, Some(cutoff))) => opacity >= cutoff,
            Some((opacity, None)) => opacity > ray_number(hit.prim, o, d),
        }
    }
}

impl ModelCutout<'_> {
    /// The opacity at the point `hit` met, with the mask's cutoff (None
    /// for a blend); None where the triangle is solid (an opaque or
    /// transmissive material, or one that cannot be read).
    fn opacity(&self, hit: Hit, o: Vec3, d: Vec3) -> Option<(f32, Option<f32>)> {
        let mesh = &self.model.mesh;
        let &tri = mesh.triangles.get(hit.prim as usize)?;
        let m = mesh
            .groups
            .iter()
            .find(|g| g.triangles.contains(&hit.prim))
            .and_then(|g| self.model.materials.get(g.material))?;
        let cutoff = match m.alpha {
            AlphaMode::Mask(c) => Some(c),
            _ if cut_at(m).is_some() => None,
            _ => return None,
        };
        let corner = |i: u32| mesh.positions.get(i as usize).copied();
        let (a, b, c) = (corner(tri[0])?, corner(tri[1])?, corner(tri[2])?);
        let w = barycentric(o + d * hit.t, (a, b, c))?;
        let read = Reading {
            uv: (
                interpolate(&mesh.uvs, tri, w),
                interpolate(&mesh.uvs1, tri, w),
            ),
            wrap: self.wrap,
        };
        let tint = interpolate(&mesh.colors, tri, w).map_or(1.0, |c| c.w);
        let mut opacity = m.d * tint;
        if let Some(t) = &m.map_d {
            let c = read.rgba(t);
            opacity *= if t.texture.has_alpha { c.w } else { c.x };
        }
        if let Some(t) = &m.map_kd
            && t.texture.has_alpha
        {
            opacity *= read.rgba(t).w;
        }
        Some((opacity, cutoff))
    }
}

/// A number in [0, 1) of the ray `o + t d` and triangle `prim`.
fn ray_number(prim: u32, o: Vec3, d: Vec3) -> f32 {
    let mut h = prim.wrapping_mul(0x9E37_79B9);
    for x in [o.x, o.y, o.z, d.x, d.y, d.z] {
        h = (h ^ x.to_bits()).wrapping_mul(0x85EB_CA6B);
        h ^= h >> 13;
    }
    h = h.wrapping_mul(0xC2B2_AE35);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// A vertex attribute at the point of triangle `tri` with barycentric
/// weights `w`; None where the mesh lacks it (or it is short).
fn interpolate<T>(values: &[T], tri: [u32; 3], w: Vec3) -> Option<T>
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let at = |i: u32| values.get(i as usize).copied();
    Some(at(tri[0])? * w.x + at(tri[1])? * w.y + at(tri[2])? * w.z)
}

/// The barycentric weights of `p` in triangle (a, b, c); None for a
/// degenerate triangle.
fn barycentric(p: Vec3, (a, b, c): (Vec3, Vec3, Vec3)) -> Option<Vec3> {
    let (e0, e1, e2) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (e2.dot(e0), e2.dot(e1));
    let den = d00 * d11 - d01 * d01;
    if den.abs() <= f32::MIN_POSITIVE || !den.is_finite() {
        return None;
    }
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    Some(Vec3::new(1.0 - v - w, v, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_weights_rebuild_the_point() {
        let (a, b, c) = (
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 1.0),
        );
        let w = Vec3::new(0.2, 0.5, 0.3);
        let p = a * w.x + b * w.y + c * w.z;
        let got = barycentric(p, (a, b, c)).unwrap();
        assert!((got - w).abs().max_element() < 1e-5, "{got}");
        assert!(barycentric(p, (a, a, a)).is_none());
    }
}
