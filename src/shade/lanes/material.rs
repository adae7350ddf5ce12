//! A material prepared for the lanes (`LaneMaterial::new`): its shading
//! kind, the maps its shading reads in reading order, and the slots they
//! fall in (coordinate set, transform, sampler filters, texture size and
//! chain), whose filter footprints each fragment carries
//! (`LaneMaterial::footprints`).

// Loops over the lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Affine2, Vec2};
use smallvec::SmallVec;

use super::{MAX_SIZES, ShadeContext};
use crate::assets::texture::{
    Chain, Filtering, Footprint, Gradients, Texture, TextureFilter as Filter, TextureRef, Wrap,
};
use crate::scene::Material;
use crate::scene::material::{AlphaMode, Native, NormalMap, NormalSpace};
use crate::scene::settings::ShadingMode;
use crate::simd::Lane;

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
    /// The data passes' albedo (`ShadeContext::aov_lanes`): the base
    /// colour of metallic-roughness, or Kd.
    Albedo {
        pbr: bool,
    },
}

/// A material the lanes can shade, prepared for one frame.
pub struct LaneMaterial<'a> {
    pub(super) material: &'a Material,
    pub(super) kind: LaneShading,
    /// Every map its shading may read, in the order it reads them.
    pub(super) maps: Vec<Map<'a>>,
    /// Whether the mesh has tangents (without them a tangent-space
    /// normal map leaves the normal as it is).
    pub(super) tangents: bool,
    /// Where its maps are looked up: the slots of `Map::slot`.
    slots: SmallVec<[Slot; MAX_SIZES]>,
    /// Some slot reads set 1; some slot reads set 1 or has a transform.
    set1: bool,
    moved_or_set1: bool,
    /// Some slot's sampler has filters of its own.
    samplers: bool,
    /// A bump map's coordinate set and texture size (times its
    /// transform's scale along u and v); with `spread`, the tangent-space
    /// normal map's.
    bump: Option<(usize, Vec2)>,
    /// Specular anti-aliasing: the normal map is looked up again one
    /// pixel along u and along v (`Fetch::normal_spread`).
    pub(super) spread: bool,
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
    /// `footprint` of a lookup whose coordinates of sets 0 and 1 change
    /// by `g` across its quad, before the transform.
    #[inline(always)]
    fn transformed_footprint(&self, ctx: &ShadeContext, g: [Gradients; 2]) -> Footprint {
        let mut g = g[self.set];
        if self.moved {
            let m = self.transform.matrix2;
            g = Gradients {
                dx: m * g.dx,
                dy: m * g.dy,
            };
        }
        self.footprint(ctx, g)
    }

    /// The lanes' coordinates of its set (`uv`) through its transform.
    #[inline(always)]
    fn coords<L: Lane>(&self, uv: [(L, L); 2]) -> (L, L) {
        let (u, v) = uv[self.set];
        if !self.moved {
            return (u, v);
        }
        let (m, t) = (self.transform.matrix2, self.transform.translation);
        (
            L::splat(m.x_axis.x) * u + L::splat(m.y_axis.x) * v + L::splat(t.x),
            L::splat(m.x_axis.y) * u + L::splat(m.y_axis.y) * v + L::splat(t.y),
        )
    }

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

impl<'a> LaneMaterial<'a> {
    /// The footprints of a fragment whose texture coordinates (of sets 0
    /// and 1) change by `g` across its quad: one per slot, in the order
    /// `Coords::footprints` takes them (the transform applied to the
    /// derivatives); past `MAX_SIZES`, none (`slot_footprint`).
    pub fn footprints(&self, ctx: &ShadeContext, g: [Gradients; 2]) -> Footprints {
        let mut out = Footprints::NONE;
        if let Some((set, size)) = self.bump {
            // A bump map's central differences step at least a texel; a
            // normal map's spread is its change across one pixel.
            let g = g[set];
            let texels = (g.dx * size).length().max((g.dy * size).length());
            out.bump = if self.spread { texels } else { texels.max(1.0) } / size;
        }
        if ctx.filter == Filter::Nearest {
            out.slots = [Footprint::Nearest; MAX_SIZES];
            return out;
        }
        if !self.samplers && !matches!(ctx.filter, Filter::Trilinear | Filter::Anisotropic) {
            return out;
        }
        for (o, slot) in out.slots.iter_mut().zip(&self.slots) {
            *o = slot.transformed_footprint(ctx, g);
        }
        out
    }

    /// The footprint in slot `k` of a fragment whose texture coordinates
    /// change by `g` across its quad (`footprints`).
    #[inline]
    pub fn slot_footprint(&self, ctx: &ShadeContext, k: usize, g: [Gradients; 2]) -> Footprint {
        if ctx.filter == Filter::Nearest {
            return Footprint::Nearest;
        }
        if !self.samplers && !matches!(ctx.filter, Filter::Trilinear | Filter::Anisotropic) {
            return Footprint::Lod(0.0);
        }
        self.slots[k].transformed_footprint(ctx, g)
    }

    /// How many slots past `MAX_SIZES` it has: their footprints are not
    /// in `Footprints` but computed per lane call (`Coords::extra`).
    #[inline(always)]
    pub fn extra_slots(&self) -> usize {
        self.slots.len().saturating_sub(MAX_SIZES)
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
            *o = slot.coords(uv);
        }
        out
    }

    /// Which of the maps `t` is.
    #[inline]
    pub(super) fn index_of(&self, t: &TextureRef) -> Option<usize> {
        self.maps.iter().position(|m| std::ptr::eq(m.source, t))
    }
}

/// The coordinate set of map `t` and its texture's size times its
/// transform's scale along u and v: what one texel is in coordinates.
fn steps_of(t: &TextureRef) -> (usize, Vec2) {
    let m = t.transform.matrix2;
    let size = Vec2::new(t.texture.width as f32, t.texture.height as f32)
        * Vec2::new(m.x_axis.length(), m.y_axis.length());
    ((t.texcoord as usize).min(1), size)
}

/// Collects a lane material's maps, assigning each a slot by its
/// coordinates, transform, texture size and chain. A map of a coordinate set the mesh
/// lacks is left out: it counts as 1.
struct MapSet<'c, 'a> {
    ctx: &'c ShadeContext<'a>,
    /// Whether the mesh has texture coordinates of sets 0 and 1.
    uvs: [bool; 2],
    tangents: bool,
    maps: Vec<Map<'a>>,
    slots: SmallVec<[Slot; MAX_SIZES]>,
    bump: Option<(usize, Vec2)>,
    /// Metallic-roughness with `render.specular_aa`: a tangent-space
    /// normal map's steps are kept in `bump`.
    spread: bool,
}

impl<'a> MapSet<'_, 'a> {
    fn map(&mut self, t: &'a TextureRef) {
        let set = (t.texcoord as usize).min(1);
        if !self.uvs[set] {
            // Without its coordinates a map counts as 1 (`Fetch::rgba`
            // finds no lookup for it).
            return;
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
            None => {
                self.slots.push(here);
                self.slots.len() - 1
            }
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
    }

    fn optional(&mut self, t: &'a Option<TextureRef>) {
        if let Some(t) = t {
            self.map(t);
        }
    }

    /// `spread`: the steps of a tangent-space map are kept for its
    /// spread (`LaneMaterial::spread`).
    fn normal(&mut self, m: &'a Option<NormalMap>, spread: bool) {
        if self.ctx.mode == ShadingMode::Flat {
            // Flat shading keeps the triangles' normals: not looked up.
            return;
        }
        let t = match m {
            None => return,
            Some(NormalMap::Normals { map, .. } | NormalMap::Height { map, .. }) => map,
        };
        if !self.uvs[(t.texcoord as usize).min(1)] {
            // Without its coordinates a map leaves the normal as it is.
            return;
        }
        match m {
            Some(NormalMap::Normals {
                space: NormalSpace::Object,
                ..
            }) => self.map(t),
            // Without tangents a tangent-space or bump map leaves the
            // normal as it is.
            _ if !self.tangents => {}
            Some(NormalMap::Height { .. }) => {
                self.map(t);
                self.bump = Some(steps_of(t));
            }
            _ if spread => {
                self.map(t);
                self.bump = Some(steps_of(t));
            }
            _ => self.map(t),
        }
    }

    /// The maps a metallic-roughness material's shading reads, in the
    /// order it reads them (`pbr_color`, then the normal map).
    fn pbr(&mut self, m: &'a Material) {
        let p = &m.pbr;
        for t in [
            &p.base_color_map,
            &p.metallic_roughness_map,
            &p.roughness_map,
            &p.metallic_map,
            &p.occlusion_map,
            &p.emissive_map,
        ] {
            self.optional(t);
        }
        if let Some(d) = &p.specular {
            self.optional(&d.color_map);
            self.optional(&d.weight_map);
        }
        if let Some(k) = &p.clearcoat {
            self.optional(&k.map);
            self.optional(&k.roughness_map);
            self.normal(&k.normal_map, false);
        }
        if let Some(t) = &p.transmission {
            self.optional(&t.map);
            self.optional(&t.thickness_map);
        }
        if let Some(k) = &p.sheen {
            self.optional(&k.color_map);
            self.optional(&k.roughness_map);
        }
        if let Some(k) = &p.iridescence {
            self.optional(&k.map);
            self.optional(&k.thickness_map);
        }
        if let Some(k) = &p.anisotropy {
            self.optional(&k.map);
        }
        if let Some(k) = &p.diffuse_transmission {
            self.optional(&k.map);
            self.optional(&k.color_map);
        }
        self.normal(&m.normal_map, self.spread)
    }

    /// The maps a Blinn-Phong material's shading reads, in the order it
    /// reads them (`surface_color`, then the normal map).
    fn blinn_phong(&mut self, m: &'a Material) {
        for t in [&m.map_kd, &m.map_ka, &m.map_ks, &m.map_ke, &m.map_ns] {
            self.optional(t);
        }
        self.normal(&m.normal_map, false)
    }
}

impl<'a> LaneMaterial<'a> {
    /// `m` prepared for the lanes in the frame of `ctx`. `uvs` and
    /// `tangents`: whether the mesh drawn with it has texture coordinates
    /// and tangents.
    pub fn new(
        ctx: &ShadeContext<'a>,
        m: &'a Material,
        uvs: [bool; 2],
        tangents: bool,
    ) -> LaneMaterial<'a> {
        let kind = match ctx.mode {
            ShadingMode::Normals => LaneShading::Normals,
            ShadingMode::Depth => LaneShading::Depth,
            ShadingMode::Wireframe => LaneShading::Wireframe,
            // KHR_materials_unlit: the base colour in every mode but the
            // data views.
            _ if m.unlit => LaneShading::Unlit,
            ShadingMode::Gouraud => LaneShading::Gouraud,
            ShadingMode::Unlit => LaneShading::Emitted,
            // Flat: the triangles' normals (`BandInputs::lanes`).
            ShadingMode::BlinnPhong | ShadingMode::Flat => LaneShading::BlinnPhong,
            ShadingMode::Pbr => LaneShading::Pbr,
            ShadingMode::Auto if m.native == Native::BlinnPhong => LaneShading::BlinnPhong,
            ShadingMode::Auto => LaneShading::Pbr,
        };
        LaneMaterial::of_kind(ctx, m, kind, (uvs, tangents))
    }

    /// `m` prepared for the data passes (`ShadeContext::aov_lanes`): its
    /// albedo, as metallic-roughness in the `pbr` mode and for glTF
    /// materials in the others but `blinn-phong`, `flat` and `gouraud`,
    /// and its normal map.
    pub fn for_aovs(
        ctx: &ShadeContext<'a>,
        m: &'a Material,
        uvs: [bool; 2],
        tangents: bool,
    ) -> LaneMaterial<'a> {
        let pbr = match ctx.mode {
            ShadingMode::Pbr => true,
            ShadingMode::BlinnPhong | ShadingMode::Flat | ShadingMode::Gouraud => false,
            _ => m.native == Native::Pbr,
        };
        LaneMaterial::of_kind(ctx, m, LaneShading::Albedo { pbr }, (uvs, tangents))
    }

    fn of_kind(
        ctx: &ShadeContext<'a>,
        m: &'a Material,
        kind: LaneShading,
        (uvs, tangents): ([bool; 2], bool),
    ) -> LaneMaterial<'a> {
        let mut maps = MapSet {
            ctx,
            uvs,
            tangents,
            maps: Vec::new(),
            slots: SmallVec::new(),
            bump: None,
            spread: kind == LaneShading::Pbr && ctx.specular_aa,
        };
        match kind {
            LaneShading::BlinnPhong | LaneShading::Gouraud => maps.blinn_phong(m),
            LaneShading::Albedo { pbr: false } => maps.blinn_phong(m),
            LaneShading::Emitted if m.native != Native::Pbr => maps.blinn_phong(m),
            LaneShading::Pbr | LaneShading::Unlit | LaneShading::Emitted => maps.pbr(m),
            LaneShading::Albedo { pbr: true } => maps.pbr(m),
            LaneShading::Normals => maps.normal(&m.normal_map, false),
            LaneShading::Depth | LaneShading::Wireframe => {}
        }
        // A blended surface's opacity reads these too (`opacity`).
        if m.alpha == AlphaMode::Blend {
            maps.optional(&m.map_d);
            maps.optional(&m.map_kd);
        }
        let mut maps_read = maps.maps;
        for k in 0..maps_read.len() {
            let same = maps_read[k].same;
            if same != k {
                maps_read[same].shared = true;
                maps_read[k].shared = true;
            }
        }
        LaneMaterial {
            material: m,
            kind,
            maps: maps_read,
            tangents,
            set1: maps.slots.iter().any(|s| s.set == 1),
            moved_or_set1: maps.slots.iter().any(|s| s.set == 1 || s.moved),
            samplers: maps
                .slots
                .iter()
                .any(|s| s.mag_nearest || s.min_limit.is_some()),
            bump: maps.bump,
            spread: maps.spread && maps.bump.is_some(),
            slots: maps.slots,
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
    use glam::Vec3;

    fn map(size: u32) -> TextureRef {
        let texels = vec![[200, 100, 50, 255]; (size * size) as usize];
        TextureRef::new(Arc::new(Texture::from_rgba8(size, size, &texels, false)))
    }

    /// Which materials go to the wider calls: glTF's packed pbr maps, MTL
    /// maps, the KHR layers with their maps, texture transforms, samplers
    /// with filters of their own, unlit materials and any number of
    /// slots do.
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
            let lm = LaneMaterial::new(ctx, m, [true; 2], true);
            let distinct = lm.maps.iter().enumerate().filter(|(i, m)| m.same == *i);
            (lm.kind, lm.maps.len(), distinct.count())
        };
        // The packed texture is one lookup, read twice.
        assert_eq!(kind(&auto, &gltf), (LaneShading::Pbr, 4, 3));
        // Without coordinates its maps count as 1 and its normal map
        // leaves the normal as it is: nothing to look up.
        let bare = LaneMaterial::new(&auto, &gltf, [false; 2], true);
        assert_eq!((bare.kind, bare.maps.len()), (LaneShading::Pbr, 0));
        let mut obj = Material::default_named("obj");
        obj.map_kd = Some(map(16));
        assert_eq!(kind(&auto, &obj), (LaneShading::BlinnPhong, 1, 1));
        // Forced pbr shading takes the OBJ material's pbr view.
        let pbr = context(&shadows, ShadingMode::Pbr);
        assert_eq!(kind(&pbr, &obj), (LaneShading::Pbr, 0, 0));
        // Flat shading reads no normal map.
        let flat = context(&shadows, ShadingMode::Flat);
        let mut bumpy = obj.clone();
        bumpy.normal_map = Some(NormalMap::Normals {
            map: map(32),
            space: NormalSpace::Tangent,
            scale: 1.0,
        });
        assert_eq!(kind(&flat, &bumpy), (LaneShading::BlinnPhong, 1, 1));
        let wireframe = context(&shadows, ShadingMode::Wireframe);
        assert_eq!(kind(&wireframe, &obj), (LaneShading::Wireframe, 0, 0));
        let gouraud = context(&shadows, ShadingMode::Gouraud);
        assert_eq!(kind(&gouraud, &obj), (LaneShading::Gouraud, 1, 1));

        let mut coat = gltf.clone();
        coat.pbr.clearcoat = Some(Clearcoat {
            factor: 1.0,
            map: None,
            roughness: 0.1,
            roughness_map: Some(map(16)),
            normal_map: None,
        });
        assert_eq!(kind(&auto, &coat), (LaneShading::Pbr, 5, 4));
        let mut unlit = gltf.clone();
        unlit.unlit = true;
        assert_eq!(kind(&auto, &unlit), (LaneShading::Unlit, 4, 3));
        let mut moved = gltf.clone();
        if let Some(t) = &mut moved.pbr.base_color_map {
            t.transform = glam::Affine2::from_translation(glam::Vec2::new(0.5, 0.0));
        }
        // A transform is a slot of its own.
        assert_eq!(kind(&auto, &moved), (LaneShading::Pbr, 4, 3));
        let mut limited = gltf.clone();
        if let Some(t) = &mut limited.pbr.base_color_map {
            t.mag_nearest = true;
        }
        // So is a sampler with filters of its own.
        assert_eq!(kind(&auto, &limited), (LaneShading::Pbr, 4, 3));
        let mut nearest = context(&shadows, ShadingMode::Auto);
        nearest.filter = Filter::Nearest;
        assert_eq!(kind(&nearest, &gltf), (LaneShading::Pbr, 4, 3));
        let mut sizes = gltf.clone();
        sizes.pbr.emissive = Vec3::ONE;
        sizes.pbr.emissive_map = Some(map(32));
        assert_eq!(kind(&auto, &sizes), (LaneShading::Pbr, 5, 4));
        let mut four = sizes.clone();
        four.pbr.base_color_map = Some(map(4));
        // A fourth slot too: its footprints are computed per lane call.
        assert_eq!(kind(&auto, &four), (LaneShading::Pbr, 5, 4));
        let extra = |m| LaneMaterial::new(&auto, m, [true; 2], true).extra_slots();
        assert_eq!((extra(&sizes), extra(&four)), (0, 1));
        // An object-space normal map is a map like the others, and so is
        // a bump map.
        let mut object = gltf.clone();
        object.normal_map = Some(NormalMap::Normals {
            map: map(16),
            space: NormalSpace::Object,
            scale: 1.0,
        });
        assert_eq!(kind(&auto, &object), (LaneShading::Pbr, 4, 3));
        let mut bump = gltf.clone();
        bump.normal_map = Some(NormalMap::Height {
            map: map(16),
            scale: 1.0,
        });
        assert_eq!(kind(&auto, &bump), (LaneShading::Pbr, 4, 3));
        let lm = LaneMaterial::new(&auto, &bump, [true; 2], true);
        assert_eq!(lm.bump, Some((0, Vec2::splat(16.0))));
    }
}
