//! Shading several fragments at once: the lane type `L` (`simd::Lane`:
//! one, four or eight lanes) carries one fragment per lane through the
//! shading code, which is written once over it (`shade_pbr`,
//! `shade_blinn_phong`); a lone fragment is its one-lane instance, and
//! every lane of a wider call is bit for bit that instance's answer.
//!
//! What differs between the widths is where texels come from (`Fetch`).
//! A lone fragment reads them through `ShadeContext::sample`. The
//! renderer gathers the visible fragments of a band into wider calls
//! wherever `ShadeContext::lane_material` accepts the material: its maps
//! fall in at most three slots (coordinate set, transform, sampler
//! filters, texture size and chain), and the mode is not wireframe or
//! Gouraud. Their lookups are found four lanes at a time for all maps of
//! one slot (`Texture::taps4`) and gathered per lane; a slot's footprint
//! per fragment carries its filter (the frame's, lowered or magnified
//! with the nearest texel by the map's sampler).
//!
//! The lanes of one call share a material but not a triangle.

// Loops over the lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Affine2, Mat3, Vec2, Vec3, Vec4};
use smallvec::SmallVec;

use super::light::{LightMask, LightSet};
use super::{Fetch, ShadeContext};
use crate::assets::texture::{
    Chain, Filtering, Footprint, Gradients, Taps4, Texture, TextureFilter as Filter, TextureRef,
    Wrap,
};
use crate::scene::Material;
use crate::scene::light::{Light, LightKind};
use crate::scene::material::{AlphaMode, Native, NormalMap, NormalSpace};
use crate::scene::settings::ShadingMode;
use crate::simd::{Lane, Mask, V3, clamp01};

/// At most this many slots (coordinate set and transform, texture size
/// and mip chain) among a lane material's maps: each fragment carries
/// one filter footprint per slot, and the maps of one slot share where
/// their lookups fall (`Texture::taps4`).
pub const MAX_SIZES: usize = 3;

/// A blended fragment's colour over what lies behind it: what it adds,
/// the share of the colour behind that it lets through, its opacity.
pub type Layer = (Vec3, Vec3, f32);

/// The most lanes a call shades (`simd::F8`).
pub const MAX_LANES: usize = crate::simd::MAX_WIDTH;

/// One map of a lane material, ready for four lookups.
pub(super) struct Map<'a> {
    /// The texture with the frame's mip chain.
    pub chain: Chain<'a>,
    pub mode: Wrap,
    /// Which of the fragment's footprints (by texture size and chain) it
    /// reads, and whose taps.
    pub slot: usize,
    /// The material reference it came from.
    pub source: &'a TextureRef,
    /// The first map of the material that is the same lookup (glTF's
    /// packed occlusion, roughness and metallic texture, referred to
    /// twice): its texels serve this one.
    pub same: usize,
    /// Whether other maps are the same lookup as this one.
    pub shared: bool,
}

/// The shading model of a lane material.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum LaneShading {
    BlinnPhong,
    Pbr,
    /// KHR_materials_unlit: the base colour alone.
    Unlit,
    /// The `unlit` mode: the base colour (diffuse) plus the emission.
    Emitted,
    /// Blinn-Phong with the lights summed at the vertices.
    Gouraud,
    /// The data views: the shading normal, the depth, the edges.
    Normals,
    Depth,
    Wireframe,
}

/// A material the lanes can shade, prepared for one frame.
pub struct LaneMaterial<'a> {
    pub(super) material: &'a Material,
    pub(super) kind: LaneShading,
    /// Whether its blended surfaces are layers the lanes shade
    /// (`layer_lanes`): blended, and not transmissive.
    pub layers: bool,
    /// Every map its shading may read, in the order it reads them.
    maps: Vec<Map<'a>>,
    /// Whether the mesh has tangents (without them a tangent-space
    /// normal map leaves the normal as it is).
    tangents: bool,
    /// Where its maps are looked up: the slots of `Map::slot`.
    slots: SmallVec<[Slot; MAX_SIZES]>,
    /// Some slot reads set 1; some slot reads set 1 or has a transform.
    set1: bool,
    moved_or_set1: bool,
    /// Some slot's sampler has filters of its own.
    samplers: bool,
    /// A bump map's coordinate set and texture size (times its
    /// transform's scale along u and v).
    bump: Option<(usize, Vec2)>,
}

/// Where a lane material's maps of one slot are looked up: the same
/// coordinates (set and transform) in textures of the same size and
/// chain, so they share one filter footprint per fragment and where
/// their lookups fall.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Slot {
    /// Texture-coordinate set (0 or 1).
    set: usize,
    /// `TextureRef::transform` (KHR_texture_transform).
    transform: Affine2,
    /// Width and height.
    size: (u32, u32),
    /// Levels of its chain this frame; 0: level 0 alone, without a chain
    /// (never minified), looked up bilinearly (`Texture::sample_grad`).
    levels: usize,
    /// The transform is not the identity.
    moved: bool,
    /// The sampler's filters (`TextureRef::mag_nearest`, `min_limit`).
    mag_nearest: bool,
    min_limit: Option<Filter>,
}

impl Slot {
    /// The footprint of a lookup in this slot whose coordinates change by
    /// `g` (transformed) across its quad, as `TextureRef::sample_grad`
    /// filters it: the sampler's NEAREST magnification where a texel
    /// covers the pixel, its limit lowering the frame's filter otherwise.
    #[inline]
    fn footprint(&self, ctx: &ShadeContext, g: Gradients) -> Footprint {
        let (w, h) = self.size;
        let mut filter = ctx.filter;
        if self.mag_nearest || self.min_limit.is_some() {
            let size = glam::Vec2::new(w as f32, h as f32);
            let texels = (g.dx * size).length().max((g.dy * size).length());
            if texels <= 1.0 {
                if self.mag_nearest {
                    return Footprint::Nearest;
                }
            } else if let Some(limit) = self.min_limit
                && limit < filter
            {
                filter = limit;
            }
        }
        match filter {
            Filter::Nearest => Footprint::Nearest,
            Filter::Bilinear => Footprint::Lod(0.0),
            _ if self.levels == 0 => Footprint::Lod(0.0),
            _ => {
                let f = Filtering {
                    filter,
                    max_anisotropy: ctx.max_anisotropy,
                    mips: None,
                };
                Texture::footprint_of_size(w, h, g, &f)
            }
        }
    }
}

/// What a fragment's lookups of a lane material cover
/// (`LaneMaterial::footprints`).
#[derive(Debug, Clone, Copy)]
pub struct Footprints {
    /// Per slot of the material.
    pub slots: [Footprint; MAX_SIZES],
    /// Where the material has a bump map: the step between its height
    /// samples, in texture coordinates (one pixel's footprint, at least
    /// a texel).
    pub bump: Vec2,
}

impl Footprints {
    /// Level 0 in every slot, no bump step.
    pub const NONE: Footprints = Footprints {
        slots: [Footprint::Lod(0.0); MAX_SIZES],
        bump: Vec2::ZERO,
    };
}

/// The points of the fragments in the lanes: what shading needs of a
/// fragment besides its texels.
pub struct Lanes<L: Lane = Vec4> {
    pub position: V3<L>,
    /// Unit interpolated normal, on the side the camera sees.
    pub normal: V3<L>,
    /// Vertex colour (RGB), where the mesh has one.
    pub color: Option<V3<L>>,
    /// The triangles' plane normals (shadow lookups), per lane (the
    /// first `L::WIDTH`).
    pub geo_normal: [Vec3; MAX_LANES],
    pub ao: L,
    /// View depth.
    pub depth: L,
    /// Wireframe: the distance to the nearest edge, in pixels.
    pub edge: L,
    /// Gouraud shading: the light sums (diffuse, specular) interpolated
    /// from the vertices.
    pub vertex_light: Option<(V3<L>, V3<L>)>,
    /// The lights that may reach some lane (the union of the lanes'
    /// tiles'); the others give every lane nothing.
    pub lights: LightMask,
}

/// Where the lanes' fragments read a lane material's maps.
pub struct Coords<'p, L: Lane = Vec4> {
    /// Texture coordinates per slot of the material
    /// (`LaneMaterial::coords`).
    pub uv: [(L, L); MAX_SIZES],
    /// Interpolated tangent and its bitangent sign (when the material has
    /// a normal map).
    pub tangent: V3<L>,
    pub sign: L,
    /// Object-space normal maps: object to world for normals, and the
    /// lanes whose surface is seen from behind (the interpolated normal
    /// points away from the shading normal).
    pub normal_from_object: Mat3,
    pub back: L::Mask,
    /// Per slot of the material (`LaneMaterial::footprints`), per lane
    /// from lane `first`.
    pub footprints: &'p [[Footprint; MAX_LANES]; MAX_SIZES],
    pub first: usize,
    /// A bump map's: the lanes' coordinates of sets 0 and 1 (before any
    /// transform), and its steps (`Footprints::bump`) per lane from lane
    /// `first`.
    pub sets: [(L, L); 2],
    pub bump: &'p [Vec2; MAX_LANES],
}

impl<L: Lane> Lanes<L> {
    /// The frame's `lights` that may reach the lanes.
    #[inline(always)]
    pub fn light_set<'l>(&self, lights: &'l [Light]) -> LightSet<'l> {
        LightSet {
            lights,
            mask: self.lights,
        }
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

impl<L: Lane> Coords<'_, L> {
    /// Quad `q`'s footprints of slot `slot`.
    #[inline(always)]
    fn footprints4(&self, slot: usize, q: usize) -> [Footprint; 4] {
        let f = &self.footprints[slot][self.first..];
        if L::WIDTH == 1 {
            return [f[0]; 4];
        }
        [f[4 * q], f[4 * q + 1], f[4 * q + 2], f[4 * q + 3]]
    }
}

impl<'a> LaneMaterial<'a> {
    /// The footprints of a fragment whose texture coordinates (of sets 0
    /// and 1) change by `g` across its quad: one per slot, in the order
    /// `Coords::footprints` takes them (as `ShadeContext::sample` derives
    /// them, the transform applied to the derivatives).
    pub fn footprints(&self, ctx: &ShadeContext, g: [Gradients; 2]) -> Footprints {
        let mut out = Footprints::NONE;
        if let Some((set, size)) = self.bump {
            // As `ShadeContext::apply_normal_map` steps.
            let g = g[set];
            let texels = (g.dx * size).length().max((g.dy * size).length());
            out.bump = texels.max(1.0) / size;
        }
        if ctx.filter == Filter::Nearest {
            out.slots = [Footprint::Nearest; MAX_SIZES];
            return out;
        }
        if !self.samplers && !matches!(ctx.filter, Filter::Trilinear | Filter::Anisotropic) {
            return out;
        }
        for (k, slot) in self.slots.iter().enumerate() {
            let mut g = g[slot.set];
            if slot.moved {
                let m = slot.transform.matrix2;
                g = Gradients {
                    dx: m * g.dx,
                    dy: m * g.dy,
                };
            }
            out.slots[k] = slot.footprint(ctx, g);
        }
        out
    }

    /// Whether some map reads texture coordinates of set 1.
    #[inline(always)]
    pub fn reads_set1(&self) -> bool {
        self.set1
    }

    /// Per slot, the lanes' coordinates of its set (`uv`) through its
    /// transform (as `TextureRef::sample_grad` applies it).
    #[inline(always)]
    pub fn coords<L: Lane>(&self, uv: [(L, L); 2]) -> [(L, L); MAX_SIZES] {
        let mut out = [uv[0]; MAX_SIZES];
        if !self.moved_or_set1 {
            return out;
        }
        for (o, slot) in out.iter_mut().zip(&self.slots) {
            let (u, v) = uv[slot.set];
            *o = if !slot.moved {
                (u, v)
            } else {
                let (m, t) = (slot.transform.matrix2, slot.transform.translation);
                (
                    L::splat(m.x_axis.x) * u + L::splat(m.y_axis.x) * v + L::splat(t.x),
                    L::splat(m.x_axis.y) * u + L::splat(m.y_axis.y) * v + L::splat(t.y),
                )
            };
        }
        out
    }

    /// Which of the maps `t` is.
    #[inline]
    fn index_of(&self, t: &TextureRef) -> Option<usize> {
        self.maps.iter().position(|m| std::ptr::eq(m.source, t))
    }
}

/// Collects a lane material's maps, assigning each a slot by its
/// coordinates, transform, texture size and chain; None where the lanes
/// cannot look one up as `ShadeContext::sample` does (a sampler of its
/// own, a fourth slot, a bump map). A map of a coordinate set the mesh
/// lacks is left out: it counts as 1.
struct MapSet<'c, 'a> {
    ctx: &'c ShadeContext<'a>,
    /// Whether the mesh has texture coordinates of sets 0 and 1.
    uvs: [bool; 2],
    tangents: bool,
    maps: Vec<Map<'a>>,
    slots: SmallVec<[Slot; MAX_SIZES]>,
    bump: Option<(usize, Vec2)>,
}

impl<'a> MapSet<'_, 'a> {
    fn map(&mut self, t: &'a TextureRef) -> Option<()> {
        let set = (t.texcoord as usize).min(1);
        if !self.uvs[set] {
            // Without its coordinates a map counts as 1 (`Fetch::rgba`
            // finds no lookup for it).
            return Some(());
        }
        let tex = &*t.texture;
        let mips = self.ctx.mips.get(tex.id).copied().flatten();
        let here = Slot {
            set,
            transform: t.transform,
            size: (tex.width, tex.height),
            levels: mips.map_or(0, |m| 1 + m.len()),
            moved: t.transform != Affine2::IDENTITY,
            mag_nearest: t.mag_nearest,
            min_limit: t.min_limit,
        };
        let slot = match self.slots.iter().position(|s| *s == here) {
            Some(k) => k,
            None if self.slots.len() < MAX_SIZES => {
                self.slots.push(here);
                self.slots.len() - 1
            }
            None => return None,
        };
        let mode = t.address.unwrap_or(self.ctx.address.into());
        let same = self
            .maps
            .iter()
            .position(|m| {
                std::sync::Arc::ptr_eq(&m.source.texture, &t.texture)
                    && m.mode == mode
                    && m.slot == slot
            })
            .unwrap_or(self.maps.len());
        self.maps.push(Map {
            chain: tex.chain(mips),
            mode,
            slot,
            source: t,
            same,
            shared: false,
        });
        Some(())
    }

    fn optional(&mut self, t: &'a Option<TextureRef>) -> Option<()> {
        match t {
            Some(t) => self.map(t),
            None => Some(()),
        }
    }

    fn normal(&mut self, m: &'a Option<NormalMap>) -> Option<()> {
        if self.ctx.mode == ShadingMode::Flat {
            // Flat shading keeps the triangles' normals: not looked up.
            return Some(());
        }
        let t = match m {
            None => return Some(()),
            Some(NormalMap::Normals { map, .. } | NormalMap::Height { map, .. }) => map,
        };
        if !self.uvs[(t.texcoord as usize).min(1)] {
            // Without its coordinates a map leaves the normal as it is.
            return Some(());
        }
        match m {
            Some(NormalMap::Normals {
                space: NormalSpace::Tangent,
                ..
            }) => {
                if self.tangents {
                    self.map(t)?;
                }
                Some(())
            }
            Some(NormalMap::Normals {
                space: NormalSpace::Object,
                ..
            }) => self.map(t),
            Some(NormalMap::Height { .. }) => {
                if self.tangents {
                    self.map(t)?;
                    let m = t.transform.matrix2;
                    let size = Vec2::new(t.texture.width as f32, t.texture.height as f32)
                        * Vec2::new(m.x_axis.length(), m.y_axis.length());
                    self.bump = Some(((t.texcoord as usize).min(1), size));
                }
                Some(())
            }
            None => Some(()),
        }
    }

    /// The maps a metallic-roughness material's shading reads, in the
    /// order it reads them (`pbr_color`, then the normal map).
    fn pbr(&mut self, m: &'a Material) -> Option<()> {
        let p = &m.pbr;
        for t in [
            &p.base_color_map,
            &p.metallic_roughness_map,
            &p.roughness_map,
            &p.metallic_map,
            &p.occlusion_map,
            &p.emissive_map,
        ] {
            self.optional(t)?;
        }
        if let Some(d) = &p.specular {
            self.optional(&d.color_map)?;
            self.optional(&d.weight_map)?;
        }
        if let Some(k) = &p.clearcoat {
            self.optional(&k.map)?;
            self.optional(&k.roughness_map)?;
            self.normal(&k.normal_map)?;
        }
        if let Some(t) = &p.transmission {
            self.optional(&t.map)?;
            self.optional(&t.thickness_map)?;
        }
        if let Some(k) = &p.sheen {
            self.optional(&k.color_map)?;
            self.optional(&k.roughness_map)?;
        }
        if let Some(k) = &p.iridescence {
            self.optional(&k.map)?;
            self.optional(&k.thickness_map)?;
        }
        self.normal(&m.normal_map)
    }

    /// The maps a Blinn-Phong material's shading reads, in the order it
    /// reads them (`surface_color`, then the normal map).
    fn blinn_phong(&mut self, m: &'a Material) -> Option<()> {
        for t in [&m.map_kd, &m.map_ka, &m.map_ks, &m.map_ke, &m.map_ns] {
            self.optional(t)?;
        }
        self.normal(&m.normal_map)
    }
}

impl<'a> ShadeContext<'a> {
    /// `m` prepared for the lanes, or None where it needs the one-fragment
    /// path. `uvs` and `tangents`: whether the mesh drawn with it has
    /// texture coordinates and tangents.
    pub fn lane_material(
        &self,
        m: &'a Material,
        uvs: [bool; 2],
        tangents: bool,
    ) -> Option<LaneMaterial<'a>> {
        let kind = match self.mode {
            ShadingMode::Normals => LaneShading::Normals,
            ShadingMode::Depth => LaneShading::Depth,
            ShadingMode::Wireframe => LaneShading::Wireframe,
            // KHR_materials_unlit: the base colour in every mode but the
            // data views.
            _ if m.unlit => LaneShading::Unlit,
            ShadingMode::Gouraud => LaneShading::Gouraud,
            ShadingMode::Unlit => LaneShading::Emitted,
            // Flat: the triangles' normals (`FrameData::lanes`).
            ShadingMode::BlinnPhong | ShadingMode::Flat => LaneShading::BlinnPhong,
            ShadingMode::Pbr => LaneShading::Pbr,
            ShadingMode::Auto if m.native == Native::BlinnPhong => LaneShading::BlinnPhong,
            ShadingMode::Auto => LaneShading::Pbr,
        };
        let mut maps = MapSet {
            ctx: self,
            uvs,
            tangents,
            maps: Vec::new(),
            slots: SmallVec::new(),
            bump: None,
        };
        match kind {
            LaneShading::BlinnPhong | LaneShading::Gouraud => maps.blinn_phong(m)?,
            LaneShading::Emitted if m.native != Native::Pbr => maps.blinn_phong(m)?,
            LaneShading::Pbr | LaneShading::Unlit | LaneShading::Emitted => maps.pbr(m)?,
            LaneShading::Normals => maps.normal(&m.normal_map)?,
            LaneShading::Depth | LaneShading::Wireframe => {}
        }
        // A blended surface's opacity reads these too (`opacity`).
        let layers = m.alpha == AlphaMode::Blend;
        if layers {
            maps.optional(&m.map_d)?;
            maps.optional(&m.map_kd)?;
        }
        let mut maps_read = maps.maps;
        for k in 0..maps_read.len() {
            let same = maps_read[k].same;
            if same != k {
                maps_read[same].shared = true;
                maps_read[k].shared = true;
            }
        }
        Some(LaneMaterial {
            material: m,
            kind,
            layers,
            maps: maps_read,
            tangents,
            set1: maps.slots.iter().any(|s| s.set == 1),
            moved_or_set1: maps.slots.iter().any(|s| s.set == 1 || s.moved),
            samplers: maps
                .slots
                .iter()
                .any(|s| s.mag_nearest || s.min_limit.is_some()),
            bump: maps.bump,
            slots: maps.slots,
        })
    }

    /// Linear RGB of the fragments of `lm`'s material in `f`'s lanes,
    /// reading its maps at `coords`: lane by lane `shade` of each (before
    /// its non-finite guard).
    pub fn shade_lanes<L: Lane>(
        &self,
        lm: &LaneMaterial<'a>,
        f: &Lanes<L>,
        coords: &Coords<'_, L>,
    ) -> V3<L> {
        // (Built here, not returned by a function: the fetch is large,
        // and a returned one was copied at every call.)
        let mut fetch = LaneFetch {
            lm,
            lookups: Lookups::new(coords),
            normal: f.normal,
            shared: None,
            next: 0,
        };
        fetch.start();
        self.shade_fetched(lm, f, &mut fetch)
    }

    /// The fragments of a blended lane material (`LaneMaterial::layers`)
    /// as layers, lane by lane `layer`'s into `out` (from lane 0): what
    /// it adds, the share of the colour behind that it lets through, its
    /// opacity. `alpha`: the vertex colours' alpha.
    pub fn layer_lanes<L: Lane>(
        &self,
        lm: &LaneMaterial<'a>,
        f: &Lanes<L>,
        coords: &Coords<'_, L>,
        alpha: L,
        out: &mut [Layer; MAX_LANES],
    ) {
        let mut fetch = LaneFetch {
            lm,
            lookups: Lookups::new(coords),
            normal: f.normal,
            shared: None,
            next: 0,
        };
        fetch.start();
        let m = lm.material;
        let c = self.shade_fetched(lm, f, &mut fetch);
        if m.pbr.transmission.is_some() && self.shades_pbr(m) {
            // Thin transmission: the base colour lets the light through,
            // less what the surface reflects (`layer`).
            let pc = self.pbr_color(m, &mut fetch, f);
            let n = match &m.normal_map {
                Some(map) => fetch.normal(map),
                None => f.normal,
            };
            let v = self.view_lanes(f.position);
            for (k, o) in out.iter_mut().enumerate().take(L::WIDTH) {
                let t = pc.at(k).transmittance(n.lane(k), v.lane(k));
                let t = t.clamp(Vec3::ZERO, Vec3::ONE);
                *o = (c.lane(k), t, 1.0 - (t.x + t.y + t.z) / 3.0);
            }
            return;
        }
        let a = clamp01(self.opacity_of(m, |t| fetch.rgba(t), alpha));
        let (add, through) = (c.scale(a), L::splat(1.0) - a);
        for (k, o) in out.iter_mut().enumerate().take(L::WIDTH) {
            *o = (add.lane(k), Vec3::splat(through.lane(k)), a.lane(k));
        }
    }

    fn shade_fetched<L: Lane>(
        &self,
        lm: &LaneMaterial<'a>,
        f: &Lanes<L>,
        fetch: &mut LaneFetch<'_, 'a, '_, L>,
    ) -> V3<L> {
        let m = lm.material;
        match lm.kind {
            LaneShading::BlinnPhong => self.shade_blinn_phong(m, fetch, f, None),
            LaneShading::Pbr => self.shade_pbr(m, fetch, f),
            LaneShading::Gouraud => {
                let none = (V3::zero(), V3::zero());
                self.shade_blinn_phong(m, fetch, f, Some(f.vertex_light.unwrap_or(none)))
            }
            LaneShading::Unlit => self.pbr_color(m, fetch, f).base,
            LaneShading::Emitted if m.native == Native::Pbr => {
                let c = self.pbr_color(m, fetch, f);
                c.base + c.emissive
            }
            LaneShading::Emitted => {
                let c = self.surface_color(m, fetch, f.color);
                c.kd + c.ke
            }
            LaneShading::Normals => {
                let n = match &m.normal_map {
                    Some(map) => fetch.normal(map),
                    None => f.normal,
                };
                let half = L::splat(0.5);
                V3 {
                    x: n.x * half + half,
                    y: n.y * half + half,
                    z: n.z * half + half,
                }
            }
            LaneShading::Depth => {
                let (lo, hi) = self.depth_range;
                let d = L::splat(1.0) - clamp01((f.depth - L::splat(lo)) / L::splat(hi - lo));
                V3 { x: d, y: d, z: d }
            }
            LaneShading::Wireframe => {
                // Lines two output pixels wide centered on the edges
                // (each triangle draws its half), box-filtered: the
                // fraction of a pixel at distance d within one pixel of
                // the edge is clamp(1.5 - d) (`shade`).
                let d = f.edge / L::splat(self.pixel_scale);
                let a = clamp01(L::splat(1.5) - d);
                // 0.04 to 1 by a, as `Vec3::lerp`.
                let one = L::splat(1.0);
                let c = L::splat(0.04) * (one - a) + one * a;
                V3 { x: c, y: c, z: c }
            }
        }
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

    /// Light `i`'s light on the lanes' points with unit normals `n`: the
    /// unit directions towards it, the irradiance times n.l times the
    /// shadow, and the lanes it lights.
    #[inline(always)]
    pub(super) fn lit_lanes<L: Lane>(
        &self,
        i: usize,
        light: &Light,
        f: &Lanes<L>,
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

/// A light's contribution at the lanes' points (`ShadeContext::lit_lanes`).
pub(super) struct Lit<L: Lane> {
    pub l: V3<L>,
    pub ndl: L,
    /// Irradiance times n.l times the shadow.
    pub e: V3<L>,
    pub lit: L::Mask,
}

/// Texels of a lane material's maps for the lanes (`Fetch`): through
/// `Lookups`, each distinct lookup once.
struct LaneFetch<'x, 'a, 'p, L: Lane> {
    lm: &'x LaneMaterial<'a>,
    lookups: Lookups<'x, 'p, L>,
    /// The interpolated normals.
    normal: V3<L>,
    /// The texels of the last lookup that several maps share (by
    /// `Map::same`), once read.
    shared: Option<(usize, V3<L>)>,
    /// The map read next, mostly (the maps are in reading order).
    next: usize,
}

impl<L: Lane> LaneFetch<'_, '_, '_, L> {
    /// Starts loading the texels of every distinct lookup.
    #[inline(always)]
    fn start(&mut self) {
        for (i, map) in self.lm.maps.iter().enumerate() {
            if map.same == i {
                self.lookups.prefetch(map);
            }
        }
    }
}

impl<L: Lane> LaneFetch<'_, '_, '_, L> {
    /// The interpolated normals bent by the bump map `t` scaled by
    /// `scale` (`ShadeContext::apply_normal_map`): the height's central
    /// differences one step (`Footprints::bump`) along u and along v,
    /// each lookup filtered over the lanes' footprints.
    fn bump(&mut self, t: &TextureRef, scale: f32) -> V3<L> {
        let Some(i) = self.lm.index_of(t) else {
            // No coordinates or no tangents: the normal as it is.
            return self.normal;
        };
        let map = &self.lm.maps[i];
        let f = self.lookups.coords;
        let (u, v) = f.sets[(t.texcoord as usize).min(1)];
        let step = |axis: fn(Vec2) -> f32| L::from_fn(|k| axis(f.bump[f.first + k]));
        let (su, sv) = (step(|s| s.x), step(|s| s.y));
        let zero = L::splat(0.0);
        let height = |du: L, dv: L| {
            let (u, v) = (u + du, v + dv);
            let (u, v) = if map.source.transform == Affine2::IDENTITY {
                (u, v)
            } else {
                let (m, o) = (
                    map.source.transform.matrix2,
                    map.source.transform.translation,
                );
                (
                    L::splat(m.x_axis.x) * u + L::splat(m.y_axis.x) * v + L::splat(o.x),
                    L::splat(m.x_axis.y) * u + L::splat(m.y_axis.y) * v + L::splat(o.y),
                )
            };
            let mut red = [Vec4::ZERO; 2];
            for (q, r) in red.iter_mut().enumerate().take(L::QUADS) {
                let fps = f.footprints4(map.slot, q);
                *r = map.chain.sample4(u.quad(q), v.quad(q), &fps, map.mode)[0];
            }
            L::from_quads(|q| red[q])
        };
        let half = L::splat(0.5);
        let du = (height(su, zero) - height(-su, zero)) * half;
        // Image rows run down; the bitangent points up the image.
        let dv = (height(zero, -sv) - height(zero, sv)) * half;
        let n = self.normal;
        let (tt, b) = tangent_frame(n, (f.tangent, f.sign));
        let scale = L::splat(scale);
        (n - tt.scale(du * scale) - b.scale(dv * scale)).normalize_or(n)
    }
}

impl<L: Lane> Fetch<L> for LaneFetch<'_, '_, '_, L> {
    #[inline(always)]
    fn rgb(&mut self, t: &TextureRef) -> Option<V3<L>> {
        let maps = &self.lm.maps;
        let i = match maps.get(self.next) {
            Some(m) if std::ptr::eq(m.source, t) => self.next,
            _ => self.lm.index_of(t)?,
        };
        self.next = i + 1;
        let same = maps[i].same;
        if !maps[i].shared {
            return Some(self.lookups.read(&maps[same]));
        }
        if let Some((k, c)) = self.shared
            && k == same
        {
            return Some(c);
        }
        let c = self.lookups.read(&self.lm.maps[same]);
        self.shared = Some((same, c));
        Some(c)
    }

    fn rgba(&mut self, t: &TextureRef) -> Option<(V3<L>, L)> {
        let i = self.lm.index_of(t)?;
        let map = &self.lm.maps[i];
        let f = self.lookups.coords;
        let mut rgba = [[Vec4::ZERO; 4]; 2];
        for (q, out) in rgba.iter_mut().enumerate().take(L::QUADS) {
            let fps = f.footprints4(map.slot, q);
            *out = map.chain.sample4_rgba(
                f.uv[map.slot].0.quad(q),
                f.uv[map.slot].1.quad(q),
                &fps,
                map.mode,
            );
        }
        let channel = |c: usize| L::from_quads(|q| rgba[q][c]);
        let rgb = V3 {
            x: channel(0),
            y: channel(1),
            z: channel(2),
        };
        Some((rgb, channel(3)))
    }

    #[inline(always)]
    fn normal(&mut self, m: &NormalMap) -> V3<L> {
        let (t, scale, space) = match m {
            NormalMap::Normals { map, scale, space } => (map, *scale, *space),
            NormalMap::Height { map, scale } => return self.bump(map, *scale),
        };
        if space == NormalSpace::Tangent && !self.lm.tangents {
            return self.normal;
        }
        let Some(c) = self.rgb(t) else {
            return self.normal;
        };
        let coords = self.lookups.coords;
        match space {
            NormalSpace::Tangent => {
                tangent_space(self.normal, (coords.tangent, coords.sign), c, scale)
            }
            NormalSpace::Object => {
                object_space(self.normal, coords.back, coords.normal_from_object, c)
            }
        }
    }
}

/// An object-space normal map whose texels are `c` (RGB) at unit normals
/// `n`: its normals taken to world space by `m` (object to world for
/// normals) and flipped in the lanes `back` (seen from behind), unit (`n`
/// where they have no length).
#[inline(always)]
pub(super) fn object_space<L: Lane>(n: V3<L>, back: L::Mask, m: Mat3, c: V3<L>) -> V3<L> {
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    let w = V3::splat(m.x_axis).scale(c.x * two - one)
        + V3::splat(m.y_axis).scale(c.y * two - one)
        + V3::splat(m.z_axis).scale(c.z * two - one);
    V3::select(back, -w, w).normalize_or(n)
}

/// A tangent-space normal map whose texels are `c` (RGB), scaled by
/// `scale`, applied to unit normals `n` with the interpolated tangents and
/// their bitangent signs `(t, sign)`.
#[inline(always)]
pub(super) fn tangent_space<L: Lane>(
    n: V3<L>,
    (t, sign): (V3<L>, L),
    c: V3<L>,
    scale: f32,
) -> V3<L> {
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    let c = V3 {
        x: c.x * two - one,
        y: c.y * two - one,
        z: c.z * two - one,
    };
    let (tt, b) = tangent_frame(n, (t, sign));
    let scale = L::splat(scale);
    let mapped = tt.scale(c.x * scale) + b.scale(c.y * scale) + n.scale(c.z);
    mapped.normalize_or(n)
}

/// The unit tangents and bitangents of unit normals `n` given the
/// interpolated tangents and their bitangent signs `(t, sign)`: `t` made
/// orthogonal to `n` (any such vector where it has no length left), and
/// n x t, negated where the sign is negative.
#[inline(always)]
fn tangent_frame<L: Lane>(n: V3<L>, (t, sign): (V3<L>, L)) -> (V3<L>, V3<L>) {
    let one = L::splat(1.0);
    let (tt, ok) = (t - n.scale(n.dot(t))).try_normalize();
    let tt = if ok.all() {
        tt
    } else {
        let fallback = V3::from_fn(|k| n.lane(k).any_orthonormal_vector());
        V3::select(ok, tt, fallback)
    };
    let sign = L::select(sign.cmplt(L::splat(0.0)), -one, one);
    (tt, n.cross(tt).scale(sign))
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
    coords: &'f Coords<'p, L>,
    /// Per quad and slot, once found (bit k of `found` for slot k): where
    /// its lookups fall, or None where some lane takes anisotropic probes.
    taps: [[Option<Taps4>; MAX_SIZES]; 2],
    found: u32,
}

impl<'f, 'p, L: Lane> Lookups<'f, 'p, L> {
    fn new(coords: &'f Coords<'p, L>) -> Lookups<'f, 'p, L> {
        Lookups {
            coords,
            taps: [[None, None, None], [None, None, None]],
            found: 0,
        }
    }

    /// Finds where the lanes' lookups of `map` fall (once per slot).
    #[inline(always)]
    fn find(&mut self, map: &Map) {
        let (f, s) = (self.coords, map.slot);
        if self.found & (1 << s) == 0 {
            self.found |= 1 << s;
            for q in 0..L::QUADS {
                map.chain.taps4_into(
                    f.uv[s].0.quad(q),
                    f.uv[s].1.quad(q),
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
        let f = self.coords;
        let mut rgb = [[Vec4::ZERO; 3]; 2];
        for (q, out) in rgb.iter_mut().enumerate().take(L::QUADS) {
            *out = match &self.taps[q][map.slot] {
                Some(t) => map.chain.read4(t, map.mode),
                None => map.chain.sample4(
                    f.uv[map.slot].0.quad(q),
                    f.uv[map.slot].1.quad(q),
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
    use crate::scene::material::Clearcoat;
    use crate::shade::shadow::Shadows;
    use crate::shade::testing::context;

    fn map(size: u32) -> TextureRef {
        let texels = vec![[200, 100, 50, 255]; (size * size) as usize];
        TextureRef::new(Arc::new(Texture::from_rgba8(size, size, texels, false)))
    }

    /// Which materials go to the wider calls: glTF's packed pbr maps, MTL
    /// maps, the KHR layers with their maps, texture transforms, samplers
    /// with filters of their own and unlit materials do; a fourth slot
    /// does not.
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
        let kind = |ctx: &ShadeContext, m| {
            ctx.lane_material(m, [true; 2], true).map(|lm| {
                let distinct = lm.maps.iter().enumerate().filter(|(i, m)| m.same == *i);
                (lm.kind, lm.maps.len(), distinct.count())
            })
        };
        // The packed texture is one lookup, read twice.
        assert_eq!(kind(&auto, &gltf), Some((LaneShading::Pbr, 4, 3)));
        // Without coordinates its maps count as 1 and its normal map
        // leaves the normal as it is: nothing to look up.
        assert_eq!(
            auto.lane_material(&gltf, [false; 2], true)
                .map(|lm| (lm.kind, lm.maps.len())),
            Some((LaneShading::Pbr, 0))
        );
        let mut obj = Material::default_named("obj");
        obj.map_kd = Some(map(16));
        assert_eq!(kind(&auto, &obj), Some((LaneShading::BlinnPhong, 1, 1)));
        // Forced pbr shading takes the OBJ material's pbr view.
        let pbr = context(&shadows, ShadingMode::Pbr);
        assert_eq!(kind(&pbr, &obj), Some((LaneShading::Pbr, 0, 0)));
        // Flat shading reads no normal map.
        let flat = context(&shadows, ShadingMode::Flat);
        let mut bumpy = obj.clone();
        bumpy.normal_map = Some(NormalMap::Normals {
            map: map(32),
            space: NormalSpace::Tangent,
            scale: 1.0,
        });
        assert_eq!(kind(&flat, &bumpy), Some((LaneShading::BlinnPhong, 1, 1)));
        let wireframe = context(&shadows, ShadingMode::Wireframe);
        assert_eq!(kind(&wireframe, &obj), Some((LaneShading::Wireframe, 0, 0)));
        let gouraud = context(&shadows, ShadingMode::Gouraud);
        assert_eq!(kind(&gouraud, &obj), Some((LaneShading::Gouraud, 1, 1)));

        let mut coat = gltf.clone();
        coat.pbr.clearcoat = Some(Clearcoat {
            factor: 1.0,
            map: None,
            roughness: 0.1,
            roughness_map: Some(map(16)),
            normal_map: None,
        });
        assert_eq!(kind(&auto, &coat), Some((LaneShading::Pbr, 5, 4)));
        let mut unlit = gltf.clone();
        unlit.unlit = true;
        assert_eq!(kind(&auto, &unlit), Some((LaneShading::Unlit, 4, 3)));
        let mut moved = gltf.clone();
        if let Some(t) = &mut moved.pbr.base_color_map {
            t.transform = glam::Affine2::from_translation(glam::Vec2::new(0.5, 0.0));
        }
        // A transform is a slot of its own.
        assert_eq!(kind(&auto, &moved), Some((LaneShading::Pbr, 4, 3)));
        let mut limited = gltf.clone();
        if let Some(t) = &mut limited.pbr.base_color_map {
            t.mag_nearest = true;
        }
        // So is a sampler with filters of its own.
        assert_eq!(kind(&auto, &limited), Some((LaneShading::Pbr, 4, 3)));
        let mut nearest = context(&shadows, ShadingMode::Auto);
        nearest.filter = Filter::Nearest;
        assert_eq!(kind(&nearest, &gltf), Some((LaneShading::Pbr, 4, 3)));
        let mut sizes = gltf.clone();
        sizes.pbr.emissive = Vec3::ONE;
        sizes.pbr.emissive_map = Some(map(32));
        assert_eq!(kind(&auto, &sizes), Some((LaneShading::Pbr, 5, 4)));
        let mut four = sizes.clone();
        four.pbr.base_color_map = Some(map(4));
        assert_eq!(kind(&auto, &four), None);
        // An object-space normal map is a map like the others, and so is
        // a bump map.
        let mut object = gltf.clone();
        object.normal_map = Some(NormalMap::Normals {
            map: map(16),
            space: NormalSpace::Object,
            scale: 1.0,
        });
        assert_eq!(kind(&auto, &object), Some((LaneShading::Pbr, 4, 3)));
        let mut bump = gltf.clone();
        bump.normal_map = Some(NormalMap::Height {
            map: map(16),
            scale: 1.0,
        });
        assert_eq!(kind(&auto, &bump), Some((LaneShading::Pbr, 4, 3)));
        let lm = auto.lane_material(&bump, [true; 2], true);
        assert_eq!(lm.and_then(|lm| lm.bump), Some((0, Vec2::splat(16.0))));
    }
}
