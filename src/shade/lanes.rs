//! Shading a lane group of fragments at once: what `ShadeContext::shade`
//! gives a material, written once over the lane type `L` (`simd::Lane`:
//! one, four or eight lanes) with the operations of the one-fragment code
//! in the same order, so each lane is bit for bit that code's answer at
//! every width.
//!
//! The renderer shades the visible fragments of a band this way wherever
//! `ShadeContext::lane_material` accepts the material: Blinn-Phong
//! (`blinn_phong4`, textured OBJ models) and metallic-roughness with the
//! KHR specular, clearcoat, sheen and iridescence layers of constant
//! factors (`pbr4`, most glTF models). Everything else (the data views,
//! flat and Gouraud shading, unlit, layers with maps of their own,
//! transmission, bump and object-space normal maps, texture
//! transforms, the sampled environment) takes the one-fragment path. The
//! lanes of one call share a material but not a triangle: interpolation
//! and lighting run `L`-wide; texture lookups, shadow-map lookups and
//! powers four lanes at a time (`Lane::quad`); texel loads and some
//! environment lookups per lane.
//!
//! This module holds what both kinds share: the material's maps prepared
//! for four lookups, the interpolated fragments (`Lanes`), the lights'
//! incidence and the tangent-space normal map.

// Loops over the four lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Vec3, Vec4};
use smallvec::SmallVec;

use super::ShadeContext;
use super::light::{LightMask, LightSet};
use crate::assets::texture::{
    Chain, Filtering, Footprint, Gradients, Taps4, Texture, TextureFilter as Filter, TextureRef,
    Wrap,
};
use crate::scene::Material;
use crate::scene::light::{Light, LightKind};
use crate::scene::material::{Native, NormalMap, NormalSpace};
use crate::scene::settings::{ShadingMode, TextureFilter};
use crate::simd::{Lane, Mask, V3, clamp01};

/// At most this many distinct texture sizes (and mip chains) among a lane
/// material's maps: each fragment carries one filter footprint per size,
/// and the maps of one size share where their lookups fall
/// (`Texture::taps4`).
pub const MAX_SIZES: usize = 3;

/// One map of a lane material, ready for four lookups.
pub(super) struct Map<'a> {
    /// The texture with the frame's mip chain.
    pub chain: Chain<'a>,
    pub mode: Wrap,
    /// Which of the fragment's footprints (by texture size and chain) it
    /// reads, and whose taps.
    pub slot: usize,
    /// The material reference it came from (to find maps that are the
    /// same lookup).
    pub source: &'a TextureRef,
}

/// A material the lanes can shade, prepared for one frame.
pub struct LaneMaterial<'a> {
    pub(super) material: &'a Material,
    pub(super) kind: Kind<'a>,
    /// Per slot: the (width, height) of its maps and their number of
    /// levels.
    sizes: SmallVec<[((u32, u32), usize); MAX_SIZES]>,
}

/// The shading model of a lane material and its maps. (One per draw and
/// frame, held in place: the variants' sizes differ by two maps.)
#[allow(clippy::large_enum_variant)]
pub(super) enum Kind<'a> {
    BlinnPhong {
        kd: Option<Map<'a>>,
        ks: Option<Map<'a>>,
        /// Tangent-space normal map and its scale.
        normal: Option<(Map<'a>, f32)>,
    },
    Pbr(PbrMaps<'a>),
}

/// The maps of a metallic-roughness lane material.
pub(super) struct PbrMaps<'a> {
    pub base: Option<Map<'a>>,
    pub metallic_roughness: Option<Map<'a>>,
    pub occlusion: Option<Map<'a>>,
    /// Looked up only where the emissive factor is not zero.
    pub emissive: Option<Map<'a>>,
    pub normal: Option<(Map<'a>, f32)>,
}

/// The most lanes a call shades (`simd::F8`).
pub const MAX_LANES: usize = 8;

/// Fragments of one material, one per lane of `L`, as `Surface` holds
/// one.
pub struct Lanes<'p, L: Lane = Vec4> {
    pub position: V3<L>,
    /// Unit interpolated normal, on the side the camera sees.
    pub normal: V3<L>,
    /// Texture coordinates (set 0).
    pub u: L,
    pub v: L,
    /// Interpolated tangent and its bitangent sign (when the material has
    /// a normal map).
    pub tangent: V3<L>,
    pub sign: L,
    /// Vertex colour (RGB), where the mesh has one.
    pub color: Option<V3<L>>,
    /// The triangles' plane normals (shadow lookups), per lane (the
    /// first `L::WIDTH`).
    pub geo_normal: [Vec3; MAX_LANES],
    pub ao: L,
    /// Per texture size of the material (`LaneMaterial::footprints`), per
    /// lane from lane `first`.
    pub footprints: &'p [[Footprint; MAX_LANES]; MAX_SIZES],
    pub first: usize,
    /// The lights that may reach some lane (the union of the lanes'
    /// tiles'); the others give every lane nothing.
    pub lights: LightMask,
}

impl<L: Lane> Lanes<'_, L> {
    /// The frame's `lights` that may reach the lanes.
    #[inline(always)]
    pub fn light_set<'l>(&self, lights: &'l [Light]) -> LightSet<'l> {
        LightSet {
            lights,
            mask: self.lights,
        }
    }

    /// Quad `q`'s footprints of slot `slot`.
    #[inline(always)]
    fn footprints4(&self, slot: usize, q: usize) -> [Footprint; 4] {
        let f = &self.footprints[slot][self.first..];
        if L::WIDTH == 1 {
            return [f[0]; 4];
        }
        [f[4 * q], f[4 * q + 1], f[4 * q + 2], f[4 * q + 3]]
    }

    /// Quad `q`'s plane normals.
    #[inline(always)]
    pub(super) fn geo_normal4(&self, q: usize) -> [Vec3; 4] {
        let g = &self.geo_normal;
        if L::WIDTH == 1 {
            return [g[0]; 4];
        }
        [g[4 * q], g[4 * q + 1], g[4 * q + 2], g[4 * q + 3]]
    }
}

impl LaneMaterial<'_> {
    /// The footprints of a fragment whose texture coordinates change by
    /// `g` across its quad: one per texture size the maps have, in the
    /// order `Lanes::footprints` takes them (as `ShadeContext::sample`
    /// derives them).
    pub fn footprints(&self, ctx: &ShadeContext, g: Gradients) -> [Footprint; MAX_SIZES] {
        let mut out = [Footprint::Lod(0.0); MAX_SIZES];
        if !matches!(ctx.filter, Filter::Trilinear | Filter::Anisotropic) {
            return out;
        }
        let f = Filtering {
            filter: ctx.filter,
            max_anisotropy: ctx.max_anisotropy,
            mips: None,
        };
        for (k, &((w, h), _)) in self.sizes.iter().enumerate() {
            out[k] = Texture::footprint_of_size(w, h, g, &f);
        }
        out
    }
}

/// Collects a lane material's maps, assigning each a footprint slot by
/// its texture's size and chain.
pub(super) struct MapSet<'c, 'a> {
    ctx: &'c ShadeContext<'a>,
    uvs: bool,
    sizes: SmallVec<[((u32, u32), usize); MAX_SIZES]>,
}

/// Whether two maps are the same lookup (glTF's packed occlusion,
/// roughness and metallic texture, referred to twice).
pub(super) fn same_lookup(a: &Map, b: &Map) -> bool {
    std::sync::Arc::ptr_eq(&a.source.texture, &b.source.texture) && a.mode == b.mode
}

impl Kind<'_> {
    /// Each map the shading of `m` with these maps reads, in the order it
    /// reads them (a map read twice, once).
    #[inline]
    fn for_each_map(&self, m: &Material, mut visit: impl FnMut(&Map)) {
        match self {
            Kind::BlinnPhong { kd, ks, normal } => {
                kd.iter().for_each(&mut visit);
                if m.illum != 0 {
                    ks.iter().for_each(&mut visit);
                    normal.iter().for_each(|(map, _)| visit(map));
                }
            }
            Kind::Pbr(maps) => {
                maps.base.iter().for_each(&mut visit);
                maps.metallic_roughness.iter().for_each(&mut visit);
                if let Some(o) = &maps.occlusion {
                    let shared = maps
                        .metallic_roughness
                        .as_ref()
                        .is_some_and(|mr| same_lookup(o, mr));
                    if !shared {
                        visit(o);
                    }
                }
                if m.pbr.emissive != Vec3::ZERO {
                    maps.emissive.iter().for_each(&mut visit);
                }
                maps.normal.iter().for_each(|(map, _)| visit(map));
            }
        }
    }
}

impl<'a> MapSet<'_, 'a> {
    /// `t` ready for four lookups, or None where the lanes cannot look it
    /// up as `ShadeContext::sample` does (a transform, a sampler of its
    /// own, set 1, a mesh without coordinates, a fourth texture size).
    pub fn map(&mut self, t: &'a TextureRef) -> Option<Map<'a>> {
        if !t.is_plain() || t.texcoord != 0 || !self.uvs {
            return None;
        }
        let tex = &*t.texture;
        let mips = self.ctx.mips.get(tex.id).copied().flatten();
        let shape = ((tex.width, tex.height), 1 + mips.map_or(0, |m| m.len()));
        let slot = match self.sizes.iter().position(|s| *s == shape) {
            Some(k) => k,
            None if self.sizes.len() < MAX_SIZES => {
                self.sizes.push(shape);
                self.sizes.len() - 1
            }
            None => return None,
        };
        Some(Map {
            chain: tex.chain(mips),
            mode: t.address.unwrap_or(self.ctx.address.into()),
            slot,
            source: t,
        })
    }

    /// An optional map: Some(None) without one, None where the lanes
    /// cannot look it up.
    pub fn optional(&mut self, t: &'a Option<TextureRef>) -> Option<Option<Map<'a>>> {
        match t {
            Some(t) => Some(Some(self.map(t)?)),
            None => Some(None),
        }
    }

    /// The material's tangent-space normal map and its scale: Some(None)
    /// without one (or without tangents, where the map leaves the normal
    /// as it is), None for the kinds the lanes do not take.
    pub fn normal(&mut self, m: &'a Material, tangents: bool) -> Option<Option<(Map<'a>, f32)>> {
        match &m.normal_map {
            None => Some(None),
            Some(NormalMap::Normals {
                map: t,
                space: NormalSpace::Tangent,
                scale,
            }) => {
                if !self.uvs {
                    return None;
                }
                if tangents {
                    Some(Some((self.map(t)?, *scale)))
                } else {
                    Some(None)
                }
            }
            Some(_) => None,
        }
    }
}

impl<'a> ShadeContext<'a> {
    /// `m` prepared for the lanes, or None where it needs the one-fragment
    /// path. `uvs` and `tangents`: whether the mesh drawn with it has
    /// texture coordinates and tangents.
    pub fn lane_material(
        &self,
        m: &'a Material,
        uvs: bool,
        tangents: bool,
    ) -> Option<LaneMaterial<'a>> {
        if m.unlit || self.env_sampled.is_some() || self.filter == TextureFilter::Nearest {
            return None;
        }
        let mut maps = MapSet {
            ctx: self,
            uvs,
            sizes: SmallVec::new(),
        };
        let kind = match self.mode {
            ShadingMode::BlinnPhong => Kind::blinn_phong(m, &mut maps, tangents)?,
            ShadingMode::Pbr => Kind::pbr(m, &mut maps, tangents)?,
            ShadingMode::Auto if m.native == Native::BlinnPhong => {
                Kind::blinn_phong(m, &mut maps, tangents)?
            }
            ShadingMode::Auto => Kind::pbr(m, &mut maps, tangents)?,
            _ => return None,
        };
        Some(LaneMaterial {
            material: m,
            kind,
            sizes: maps.sizes,
        })
    }

    /// Linear RGB of the fragments of `lm`'s material in `f`'s lanes,
    /// lane by lane `shade` of each (before its non-finite guard).
    pub fn shade_lanes<L: Lane>(&self, lm: &LaneMaterial<'a>, f: &Lanes<'_, L>) -> V3<L> {
        let mut lookups = Lookups::new(f);
        lm.kind
            .for_each_map(lm.material, |map| lookups.prefetch(map));
        match &lm.kind {
            Kind::BlinnPhong { kd, ks, normal } => {
                self.blinn_phong_lanes(lm.material, [kd, ks], normal, &mut lookups, f)
            }
            Kind::Pbr(maps) => self.pbr_lanes(lm.material, maps, &mut lookups, f),
        }
    }

    /// `apply_normal_map` of a tangent-space map whose texels are `c`
    /// (RGB).
    pub(super) fn normal_map_lanes<L: Lane>(
        &self,
        f: &Lanes<'_, L>,
        c: V3<L>,
        scale: f32,
    ) -> V3<L> {
        let n = f.normal;
        let (one, two) = (L::splat(1.0), L::splat(2.0));
        let c = V3 {
            x: c.x * two - one,
            y: c.y * two - one,
            z: c.z * two - one,
        };
        let t = f.tangent;
        let (tt, ok) = (t - n.scale(n.dot(t))).try_normalize();
        let tt = if ok.all() {
            tt
        } else {
            let fallback = V3::from_fn(|k| n.lane(k).any_orthonormal_vector());
            V3::select(ok, tt, fallback)
        };
        let sign = L::select(f.sign.cmplt(L::splat(0.0)), -one, one);
        let b = n.cross(tt).scale(sign);
        let scale = L::splat(scale);
        let mapped = tt.scale(c.x * scale) + b.scale(c.y * scale) + n.scale(c.z);
        mapped.normalize_or(n)
    }

    /// The unit view vectors of the points `p` (`view_vector`).
    #[inline(always)]
    pub(super) fn view_lanes<L: Lane>(&self, p: V3<L>) -> V3<L> {
        if self.orthographic {
            V3::splat(-self.forward)
        } else {
            (V3::splat(self.eye) - p).normalize_or(V3::splat(-self.forward))
        }
    }

    /// Light `i`'s light on the lanes' points with unit normals `n`, as
    /// `for_each_lit` hands it on: the unit directions towards it, the
    /// irradiance times n.l times the shadow, and the lanes it lights.
    #[inline(always)]
    pub(super) fn lit_lanes<L: Lane>(
        &self,
        i: usize,
        light: &Light,
        f: &Lanes<'_, L>,
        n: V3<L>,
    ) -> Lit<L> {
        let p = f.position;
        let (l, e, reaches) = incidence(light, p);
        let ndl = n.dot(l);
        let mut lit = reaches & ndl.cmpgt(L::splat(0.0));
        let mut s = L::splat(1.0);
        if light.shadows {
            // Four lanes at a time.
            let bits = lit.bitmask();
            s = L::from_quads(|q| {
                let quad = |v: V3<L>| V3 {
                    x: v.x.quad(q),
                    y: v.y.quad(q),
                    z: v.z.quad(q),
                };
                let mask = if L::WIDTH == 1 {
                    bits
                } else {
                    bits >> (4 * q) & 0xf
                };
                self.shadows
                    .visibility4(i, quad(p), &f.geo_normal4(q), quad(l), mask)
            });
            lit = lit & s.cmpgt(L::splat(0.0));
        }
        Lit {
            l,
            ndl,
            e: e.scale(ndl * s),
            lit,
        }
    }
}

/// A light's contribution at the lanes' points
/// (`ShadeContext::lit_lanes`).
pub(super) struct Lit<L: Lane> {
    pub l: V3<L>,
    pub ndl: L,
    /// Irradiance times n.l times the shadow.
    pub e: V3<L>,
    pub lit: L::Mask,
}

/// `light::incidence(light, p)` at each lane's point: direction,
/// irradiance (before n.l) and the lanes it reaches.
#[inline(always)]
fn incidence<L: Lane>(light: &Light, p: V3<L>) -> (V3<L>, V3<L>, L::Mask) {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let position = match light.kind {
        LightKind::Directional {
            direction,
            irradiance,
        } => {
            return (
                V3::splat(-direction),
                V3::splat(light.color * irradiance),
                one.cmpgt(zero),
            );
        }
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => position,
    };
    // `towards`: only r2 <= 0 misses.
    let d = V3::splat(position) - p;
    let r2 = d.dot(d);
    let l = d / r2.sqrt();
    let mut reaches = !r2.cmple(zero);
    // `window`: 1 without a range.
    let w = match light.range {
        Some(range) if range > 0.0 => {
            let q = r2 / L::splat(range * range);
            let w = clamp01(one - q * q);
            reaches = reaches & !w.cmple(zero);
            w * w
        }
        _ => one,
    };
    let k = match light.kind {
        LightKind::Spot {
            direction,
            intensity,
            cos_inner,
            cos_outer,
            ..
        } => {
            // `spot_falloff` of -l.direction.
            let cos_a = -l.dot(V3::splat(direction));
            let span = cos_inner - cos_outer;
            let f = if span <= 1e-7 {
                L::select(cos_a.cmpge(L::splat(cos_outer)), one, zero)
            } else {
                let t = clamp01((cos_a - L::splat(cos_outer)) / L::splat(span));
                t * t
            };
            reaches = reaches & !f.cmple(zero);
            L::splat(intensity) * f * w / r2
        }
        LightKind::Point { intensity, .. } => L::splat(intensity) * w / r2,
        LightKind::Directional { .. } => zero,
    };
    (l, V3::splat(light.color).scale(k), reaches)
}

/// The texture lookups of one lane call: where each footprint slot's
/// lookups fall, found once for all its maps (`Texture::taps4`), four
/// lanes at a time.
pub(super) struct Lookups<'f, 'p, L: Lane> {
    f: &'f Lanes<'p, L>,
    /// Per quad and slot, once found (bit k of `found` for slot k): where
    /// its lookups fall, or None where some lane takes anisotropic probes.
    taps: [[Option<Taps4>; MAX_SIZES]; 2],
    found: u32,
}

impl<'f, 'p, L: Lane> Lookups<'f, 'p, L> {
    fn new(f: &'f Lanes<'p, L>) -> Lookups<'f, 'p, L> {
        Lookups {
            f,
            taps: [[None, None, None], [None, None, None]],
            found: 0,
        }
    }

    /// Finds where the lanes' lookups of `map` fall (once per slot).
    #[inline(always)]
    fn find(&mut self, map: &Map) {
        let (f, s) = (self.f, map.slot);
        if self.found & (1 << s) == 0 {
            self.found |= 1 << s;
            for q in 0..L::QUADS {
                map.chain.taps4_into(
                    f.u.quad(q),
                    f.v.quad(q),
                    &f.footprints4(s, q),
                    &mut self.taps[q][s],
                );
            }
        }
    }

    /// Starts loading the texels `read(map)` will read.
    #[inline]
    pub fn prefetch(&mut self, map: &Map) {
        self.find(map);
        for q in 0..L::QUADS {
            if let Some(t) = &self.taps[q][map.slot] {
                map.chain.prefetch(t);
            }
        }
    }

    /// `map`'s red, green and blue at the lanes.
    #[inline]
    pub fn read(&mut self, map: &Map) -> V3<L> {
        self.find(map);
        let f = self.f;
        let mut rgb = [[Vec4::ZERO; 3]; 2];
        for (q, out) in rgb.iter_mut().enumerate().take(L::QUADS) {
            *out = match &self.taps[q][map.slot] {
                Some(t) => map.chain.read4(t, map.mode),
                None => map.chain.sample4(
                    f.u.quad(q),
                    f.v.quad(q),
                    &f.footprints4(map.slot, q),
                    map.mode,
                ),
            };
        }
        V3 {
            x: L::from_quads(|q| rgb[q][0]),
            y: L::from_quads(|q| rgb[q][1]),
            z: L::from_quads(|q| rgb[q][2]),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::scene::material::{Clearcoat, Native};
    use crate::scene::settings::AddressMode;
    use crate::shade::shadow::Shadows;

    fn context<'a>(shadows: &'a Shadows<'a>, mode: ShadingMode) -> ShadeContext<'a> {
        ShadeContext {
            mode,
            lights: &[],
            ambient: Vec3::ZERO,
            eye: Vec3::Z,
            forward: -Vec3::Z,
            orthographic: false,
            filter: TextureFilter::Trilinear,
            max_anisotropy: 16.0,
            address: AddressMode::Repeat,
            mips: &[],
            depth_range: (0.0, 1.0),
            shadows,
            env: None,
            env_sampled: None,
            pixel_scale: 1.0,
        }
    }

    fn map(size: u32) -> TextureRef {
        let texels = vec![[200, 100, 50, 255]; (size * size) as usize];
        TextureRef::new(Arc::new(Texture::from_rgba8(size, size, texels, false)))
    }

    /// The lane materials the e2e tests (tests/lanes.rs) count on: glTF's
    /// packed pbr maps and MTL maps go to the lanes; layers, unlit,
    /// texture transforms and a fourth texture size do not.
    #[test]
    fn which_materials_the_lanes_take() {
        let shadows = Shadows::none();
        let auto = context(&shadows, ShadingMode::Auto);
        let orm = map(8);
        let mut gltf = Material::default_named("helmet");
        gltf.native = Native::Pbr;
        gltf.pbr.base_color_map = Some(map(16));
        gltf.pbr.metallic_roughness_map = Some(orm.clone());
        gltf.pbr.occlusion_map = Some(orm);
        gltf.normal_map = Some(NormalMap::Normals {
            map: map(16),
            space: NormalSpace::Tangent,
            scale: 1.0,
        });
        let kind = |ctx: &ShadeContext, m| match ctx.lane_material(m, true, true) {
            Some(LaneMaterial {
                kind: Kind::Pbr(p), ..
            }) => Some(("pbr", p.occlusion.is_some() && p.normal.is_some())),
            Some(LaneMaterial {
                kind: Kind::BlinnPhong { kd, .. },
                ..
            }) => Some(("blinn-phong", kd.is_some())),
            None => None,
        };
        assert_eq!(kind(&auto, &gltf), Some(("pbr", true)));
        // Without coordinates its maps cannot be looked up.
        assert!(auto.lane_material(&gltf, false, true).is_none());
        let mut obj = Material::default_named("obj");
        obj.map_kd = Some(map(16));
        assert_eq!(kind(&auto, &obj), Some(("blinn-phong", true)));
        // Forced pbr shading takes the OBJ material's pbr view.
        let pbr = context(&shadows, ShadingMode::Pbr);
        assert_eq!(kind(&pbr, &obj), Some(("pbr", false)));
        let flat = context(&shadows, ShadingMode::Flat);
        assert_eq!(kind(&flat, &obj), None);

        let mut coat = gltf.clone();
        coat.pbr.clearcoat = Some(Clearcoat {
            factor: 1.0,
            map: None,
            roughness: 0.1,
            roughness_map: None,
            normal_map: None,
        });
        // A constant clearcoat is shaded in lanes; one with a map is not.
        assert_eq!(kind(&auto, &coat), Some(("pbr", true)));
        let mut coat_map = coat.clone();
        if let Some(k) = &mut coat_map.pbr.clearcoat {
            k.roughness_map = Some(map(16));
        }
        assert_eq!(kind(&auto, &coat_map), None);
        let mut unlit = gltf.clone();
        unlit.unlit = true;
        assert_eq!(kind(&auto, &unlit), None);
        let mut moved = gltf.clone();
        if let Some(t) = &mut moved.pbr.base_color_map {
            t.transform = glam::Affine2::from_translation(glam::Vec2::new(0.5, 0.0));
        }
        assert_eq!(kind(&auto, &moved), None);
        let mut sizes = gltf.clone();
        sizes.pbr.emissive = Vec3::ONE;
        sizes.pbr.emissive_map = Some(map(32));
        assert_eq!(kind(&auto, &sizes), Some(("pbr", true)));
        let mut four = sizes.clone();
        four.pbr.base_color_map = Some(map(4));
        assert_eq!(kind(&auto, &four), None);
    }
}
