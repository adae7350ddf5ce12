//! Shading several fragments at once: the lane type `L` (`simd::Lane`:
//! one, four or eight lanes) carries one fragment per lane through the
//! shading code, which is written once over it (`shade_pbr`,
//! `shade_blinn_phong`); a lone fragment is its one-lane instance, and
//! every lane of a wider call is bit for bit that instance's answer.
//!
//! The renderer gathers the visible fragments of a band into calls of
//! one draw (`LaneMaterial::new`: the material's maps in slots by
//! coordinate set, transform, sampler filters, texture size and chain).
//! A slot's lookups are found four lanes at a time for all its maps
//! (`Texture::taps4`) and gathered per lane; a slot's footprint per
//! fragment carries its filter (the frame's, lowered or magnified with
//! the nearest texel by the map's sampler). A fragment carries the
//! footprints of three slots; those of further slots are computed per
//! lane call (`Coords::extra`).
//!
//! The lanes of one call share a material but not a triangle.

// Loops over the lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Mat3, Vec2, Vec3, Vec4};

use super::light::{LightMask, LightSet};
use super::refraction::{self, RefractedRay};
use super::{Fetch, ShadeContext};
use crate::assets::texture::Footprint;
use crate::scene::light::{Light, LightKind};
use crate::scene::material::Native;
use crate::scene::settings::ShadingMode;
use crate::simd::{Lane, Mask, V3, clamp01};

mod fetch;
pub(in crate::shade) use fetch::tangent_frame;
mod material;

use fetch::{LaneFetch, Lookups};
use material::LaneShading;
pub use material::{Footprints, LaneMaterial};

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
    /// The footprints of the slots past `MAX_SIZES`
    /// (`LaneMaterial::extra_slots`), per lane from lane `first`.
    pub extra: &'p [[Footprint; MAX_LANES]],
    /// The lanes' coordinates of sets 0 and 1 before any transform (a
    /// bump map's offset lookups, the slots past `MAX_SIZES`), and a bump
    /// map's steps (`Footprints::bump`) per lane from lane `first`.
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
}

impl<L: Lane> Coords<'_, L> {
    /// The coordinates of `map`.
    #[inline(always)]
    fn uv(&self, map: &material::Map) -> (L, L) {
        if map.slot < MAX_SIZES {
            self.uv[map.slot]
        } else {
            self.extra_uv(map.source)
        }
    }

    /// `uv` of a map in a slot past `MAX_SIZES`: the coordinates of its
    /// set through its transform (`LaneMaterial::coords`).
    #[cold]
    #[inline(never)]
    fn extra_uv(&self, t: &crate::assets::texture::TextureRef) -> (L, L) {
        let (u, v) = self.sets[(t.texcoord as usize).min(1)];
        if t.transform == glam::Affine2::IDENTITY {
            return (u, v);
        }
        let (m, o) = (t.transform.matrix2, t.transform.translation);
        (
            L::splat(m.x_axis.x) * u + L::splat(m.y_axis.x) * v + L::splat(o.x),
            L::splat(m.x_axis.y) * u + L::splat(m.y_axis.y) * v + L::splat(o.y),
        )
    }

    /// `footprints4` of a slot past `MAX_SIZES`.
    #[cold]
    #[inline(never)]
    fn extra_footprints4(&self, slot: usize, q: usize) -> [Footprint; 4] {
        let f = &self.extra[slot - MAX_SIZES][self.first..];
        if L::WIDTH == 1 {
            return [f[0]; 4];
        }
        [f[4 * q], f[4 * q + 1], f[4 * q + 2], f[4 * q + 3]]
    }

    /// Quad `q`'s footprints of slot `slot`.
    #[inline(always)]
    fn footprints4(&self, slot: usize, q: usize) -> [Footprint; 4] {
        if slot >= MAX_SIZES {
            return self.extra_footprints4(slot, q);
        }
        let f = &self.footprints[slot][self.first..];
        if L::WIDTH == 1 {
            return [f[0]; 4];
        }
        [f[4 * q], f[4 * q + 1], f[4 * q + 2], f[4 * q + 3]]
    }
}

impl<'a> ShadeContext<'a> {
    /// Linear RGB of the fragments of `lm`'s material in `f`'s lanes,
    /// reading its maps at `coords`: lane by lane `shade` of each (before
    /// its non-finite guard).
    pub fn shade_lanes<L: Lane>(
        &self,
        lm: &LaneMaterial<'a>,
        f: &Lanes<L>,
        coords: &Coords<'_, L>,
    ) -> V3<L> {
        self.fetching(lm, f, coords, |fetch| self.shade_fetched(lm, f, fetch))
    }

    /// `body` given the texel fetch of `lm`'s maps at the lanes `f` and
    /// `coords`, its lookups started. (Built here and lent, not returned:
    /// the fetch is large, and a returned one was copied at every call.)
    #[inline(always)]
    fn fetching<'x, 'p, L: Lane, R>(
        &self,
        lm: &'x LaneMaterial<'a>,
        f: &Lanes<L>,
        coords: &'x Coords<'p, L>,
        body: impl FnOnce(&mut LaneFetch<'x, 'a, 'p, L>) -> R,
    ) -> R {
        let mut fetch = LaneFetch {
            lm,
            lookups: Lookups::new(coords),
            normal: f.normal,
            shared: None,
            next: 0,
        };
        fetch.start();
        body(&mut fetch)
    }

    /// The data passes' values of the fragments of `lm` (prepared by
    /// `LaneMaterial::for_aovs`) in `f`'s lanes: their shading normals
    /// (normal and bump maps applied; the triangles' in flat mode), world
    /// space, unit, facing the camera; and their albedos, linear (glTF's
    /// base colour, or Kd, after textures), times the vertex colours.
    pub fn aov_lanes<L: Lane>(
        &self,
        lm: &LaneMaterial<'a>,
        f: &Lanes<L>,
        coords: &Coords<'_, L>,
    ) -> (V3<L>, V3<L>) {
        self.fetching(lm, f, coords, |fetch| {
            let albedo = self.shade_fetched(lm, f, fetch);
            let n = match &lm.material.normal_map {
                Some(map) if self.mode != ShadingMode::Flat => fetch.normal(map),
                _ => f.normal,
            };
            (n.normalize_or(V3::splat(Vec3::Z)), albedo)
        })
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
        self.fetching(lm, f, coords, |fetch| {
            self.layers_fetched(lm, f, alpha, fetch, out)
        });
    }

    /// `layer_lanes` with its texels from `fetch`.
    #[inline(always)]
    fn layers_fetched<L: Lane>(
        &self,
        lm: &LaneMaterial<'a>,
        f: &Lanes<L>,
        alpha: L,
        fetch: &mut LaneFetch<'_, 'a, '_, L>,
        out: &mut [Layer; MAX_LANES],
    ) {
        let m = lm.material;
        if m.pbr.transmission.is_some() && self.shades_pbr(m) {
            // Transmission: the base colour lets the light through, less
            // what the surface reflects (`layer`).
            let pc = self.pbr_color(m, fetch, f);
            let c = match lm.kind {
                LaneShading::Pbr => self.shade_pbr_color(m, fetch, f, &pc),
                _ => self.shade_fetched(lm, f, fetch),
            };
            let n = match &m.normal_map {
                Some(map) => fetch.normal(map),
                None => f.normal,
            };
            let v = self.view_lanes(f.position);
            let behind = self.refraction.get();
            for (k, o) in out.iter_mut().enumerate().take(L::WIDTH) {
                let p = pc.at(k);
                let (n, v) = (n.lane(k), v.lane(k));
                let t = p.transmittance(n, v).clamp(Vec3::ZERO, Vec3::ONE);
                let opacity = 1.0 - (t.x + t.y + t.z) / 3.0;
                *o = match behind {
                    // What the refracted ray meets replaces the colour
                    // directly behind.
                    Some(frame) => {
                        let ray = RefractedRay {
                            position: f.position.lane(k),
                            // Towards the eye, as the back of a
                            // two-sided surface is seen.
                            normal: if n.dot(v) < 0.0 { -n } else { n },
                            view: v,
                            ior: p.volume.1,
                            dispersion: p.volume.2,
                            thickness: p.volume.0,
                            roughness: p.roughness,
                        };
                        // `sampled` traces the refracted ray; the
                        // default reads the opaque frame.
                        let seen = match self
                            .env_sampled
                            .as_ref()
                            .and_then(|s| s.bounce().map(|scene| (scene, s.samples)))
                        {
                            Some((scene, samples)) => refraction::traced(&scene, &ray, samples),
                            None => frame.through(&ray, self.env),
                        };
                        (c.lane(k) + t * seen, Vec3::ZERO, opacity)
                    }
                    None => (c.lane(k), t, opacity),
                };
            }
            return;
        }
        let c = self.shade_fetched(lm, f, fetch);
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
            LaneShading::Unlit | LaneShading::Albedo { pbr: true } => {
                self.pbr_color(m, fetch, f).base
            }
            LaneShading::Albedo { pbr: false } => self.surface_color(m, fetch, f.color).kd,
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
        self.lit_side(i, light, f, n, false)
    }

    /// `lit_lanes` of the surfaces' far sides (`n` the normals turned
    /// round): a light behind the surface, its shadow looked up off the
    /// far side (KHR_materials_diffuse_transmission).
    #[inline(always)]
    pub(in crate::shade) fn lit_behind<L: Lane>(
        &self,
        i: usize,
        light: &Light,
        f: &Lanes<L>,
        n: V3<L>,
    ) -> Lit<L> {
        self.lit_side(i, light, f, -n, true)
    }

    #[inline(always)]
    fn lit_side<L: Lane>(
        &self,
        i: usize,
        light: &Light,
        f: &Lanes<L>,
        n: V3<L>,
        behind: bool,
    ) -> Lit<L> {
        let p = f.position;
        let (l, e, reaches) = incidence(light, p);
        let ndl = n.dot(l);
        let mut lit = reaches & ndl.cmpgt(L::splat(0.0));
        let mut s = L::splat(1.0);
        if light.shadows {
            let bits = lit.bitmask();
            s = if behind {
                let ng = f.geo_normal.map(|g| -g);
                self.shadows.visibility(i, p, &ng, l, bits)
            } else {
                self.shadows.visibility(i, p, &f.geo_normal, l, bits)
            };
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
pub(in crate::shade) struct Lit<L: Lane> {
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
            ..
        } => {
            return (
                V3::splat(-direction),
                V3::splat(light.color * irradiance),
                one.cmpgt(zero),
            );
        }
        LightKind::Point { position, .. }
        | LightKind::Spot { position, .. }
        | LightKind::Area { position, .. } => position,
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
        LightKind::Area {
            axis,
            along,
            around,
            radius,
            ..
        } => {
            // `incidence`'s along |l.axis| + around, over r^2 + radius^2.
            let f = L::splat(along) * l.dot(V3::splat(axis)).abs() + L::splat(around);
            reaches = reaches & !f.cmple(zero);
            f * w / (r2 + L::splat(radius * radius))
        }
        LightKind::Point { intensity, .. } => L::splat(intensity) * w / r2,
        LightKind::Directional { .. } => zero,
    };
    (l, V3::splat(light.color).scale(k), reaches)
}
