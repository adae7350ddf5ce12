//! Blinn-Phong shading of four fragments at once: what `ShadeContext::shade`
//! gives a Blinn-Phong material (its textured colours, tangent-space normal
//! map, the lights and shadows, ambient, environment), computed on four
//! lanes with the operations of the one-fragment code in the same order,
//! so each lane is bit for bit that code's answer.
//!
//! The renderer shades the visible fragments of a band this way wherever
//! `ShadeContext::lane_material` accepts the material (the common case of
//! textured OBJ models); everything else (pbr, the data views, flat and
//! Gouraud shading, bump and object-space normal maps, texture transforms,
//! the sampled environment) takes the one-fragment path. The lanes of one
//! call share a material but not a triangle: texture lookups, interpolation
//! and lighting run four-wide, texel loads, shadow lookups, powers and the
//! environment's lookups per lane.

// Loops over the four lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Vec3, Vec4};
use smallvec::SmallVec;

use super::ShadeContext;
use super::light::incidence;
use crate::assets::texture::{
    Chain, Filtering, Footprint, Gradients, Taps4, Texture, TextureFilter as Filter, TextureRef,
    Wrap,
};
use crate::scene::Material;
use crate::scene::light::LightKind;
use crate::scene::material::{Native, NormalMap, NormalSpace};
use crate::scene::settings::{ShadingMode, TextureFilter};
use crate::shade::env::{EnvLight, dominant_direction4};
use crate::simd::V3;

/// At most this many distinct texture sizes (and mip chains) among a lane
/// material's maps: each fragment carries one filter footprint per size,
/// and the maps of one size share where their lookups fall
/// (`Texture::taps4`).
pub const MAX_SIZES: usize = 3;

/// One map of a lane material, ready for four lookups.
struct Map<'a> {
    /// The texture with the frame's mip chain.
    chain: Chain<'a>,
    mode: Wrap,
    /// Which of the fragment's footprints (by texture size and chain) it
    /// reads, and whose taps.
    slot: usize,
}

/// A Blinn-Phong material the lanes can shade, prepared for one frame.
pub struct LaneMaterial<'a> {
    material: &'a Material,
    kd: Option<Map<'a>>,
    ks: Option<Map<'a>>,
    /// Tangent-space normal map and its scale.
    normal: Option<(Map<'a>, f32)>,
    /// Per slot: the (width, height) of its maps and their number of
    /// levels.
    sizes: SmallVec<[((u32, u32), usize); MAX_SIZES]>,
}

/// Four fragments of one material, one lane each, as `Surface` holds one.
pub struct Lanes {
    pub position: V3,
    /// Unit interpolated normal, on the side the camera sees.
    pub normal: V3,
    /// Texture coordinates (set 0).
    pub u: Vec4,
    pub v: Vec4,
    /// Interpolated tangent and its bitangent sign (when the material has
    /// a normal map).
    pub tangent: V3,
    pub sign: Vec4,
    /// Vertex colour (RGB), where the mesh has one.
    pub color: Option<V3>,
    /// The triangles' plane normals (shadow lookups).
    pub geo_normal: [Vec3; 4],
    pub ao: Vec4,
    /// Per texture size of the material (`LaneMaterial::footprints`).
    pub footprints: [[Footprint; 4]; MAX_SIZES],
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
        let blinn_phong = match self.mode {
            ShadingMode::BlinnPhong => true,
            ShadingMode::Auto => m.native == Native::BlinnPhong,
            _ => false,
        };
        if !blinn_phong
            || m.unlit
            || self.env_sampled.is_some()
            || self.filter == TextureFilter::Nearest
            || m.map_ns.is_some()
            || (m.ka.is_some() && m.map_ka.is_some())
            || (m.ke != Vec3::ZERO && m.map_ke.is_some())
        {
            return None;
        }
        let mut sizes: SmallVec<[((u32, u32), usize); MAX_SIZES]> = SmallVec::new();
        let mut map = |t: &'a TextureRef| -> Option<Map<'a>> {
            if !t.is_plain() || t.texcoord != 0 || !uvs {
                return None;
            }
            let tex = &*t.texture;
            let mips = self.mips.get(tex.id).copied().flatten();
            let shape = ((tex.width, tex.height), 1 + mips.map_or(0, |m| m.len()));
            let slot = match sizes.iter().position(|s| *s == shape) {
                Some(k) => k,
                None if sizes.len() < MAX_SIZES => {
                    sizes.push(shape);
                    sizes.len() - 1
                }
                None => return None,
            };
            Some(Map {
                chain: tex.chain(mips),
                mode: t.address.unwrap_or(self.address.into()),
                slot,
            })
        };
        let kd = match &m.map_kd {
            Some(t) => Some(map(t)?),
            None => None,
        };
        let ks = match &m.map_ks {
            Some(t) if m.illum >= 2 => Some(map(t)?),
            _ => None,
        };
        let normal = match &m.normal_map {
            None => None,
            Some(NormalMap::Normals {
                map: t,
                space: NormalSpace::Tangent,
                scale,
            }) => {
                if !uvs {
                    return None;
                }
                // Without tangents the map leaves the normal as it is.
                if tangents {
                    Some((map(t)?, *scale))
                } else {
                    None
                }
            }
            Some(_) => return None,
        };
        Some(LaneMaterial {
            material: m,
            kd,
            ks,
            normal,
            sizes,
        })
    }

    /// Linear RGB of four fragments of `lm`'s material, lane by lane
    /// `shade` of each (before its non-finite guard).
    pub fn shade_lanes(&self, lm: &LaneMaterial<'a>, f: &Lanes) -> V3 {
        let m = lm.material;
        // Where each slot's lookups fall, found once for its maps.
        let mut taps: [Option<Taps4>; MAX_SIZES] = Default::default();
        let mut found = [false; MAX_SIZES];
        let maps = [
            lm.kd.as_ref(),
            lm.ks.as_ref(),
            lm.normal.as_ref().map(|n| &n.0),
        ];
        for map in maps.into_iter().flatten() {
            if !found[map.slot] {
                found[map.slot] = true;
                taps[map.slot] = map.chain.taps4(f.u, f.v, &f.footprints[map.slot]);
            }
        }
        let tex = |map: &Map| {
            let [r, g, b] = match &taps[map.slot] {
                Some(t) => map.chain.read4(t, map.mode),
                None => map
                    .chain
                    .sample4(f.u, f.v, &f.footprints[map.slot], map.mode),
            };
            V3 { x: r, y: g, z: b }
        };
        // `surface_color`: constants times maps times the vertex colour.
        let mut kd = V3::splat(m.kd);
        if let Some(map) = &lm.kd {
            kd = kd * tex(map);
        }
        if let Some(c) = f.color {
            kd = kd * c;
        }
        if m.illum == 0 {
            return kd;
        }
        let ka = match m.ka {
            Some(ka) => V3::splat(ka),
            None => kd,
        };
        let specular = m.illum >= 2;
        let ks = match (&lm.ks, specular) {
            (Some(map), true) => V3::splat(m.ks) * tex(map),
            (None, true) => V3::splat(m.ks),
            (_, false) => V3::ZERO,
        };
        let p = f.position;
        let v = if self.orthographic {
            V3::splat(-self.forward)
        } else {
            (V3::splat(self.eye) - p).normalize_or(V3::splat(-self.forward))
        };
        let n = match &lm.normal {
            Some((map, scale)) => self.normal_map_lanes(f, tex(map), *scale),
            None => f.normal,
        };

        // `blinn_phong::light_sums`.
        let mut diffuse = V3::ZERO;
        let mut spec = V3::ZERO;
        for (i, light) in self.lights.iter().enumerate() {
            let (l, e, reaches) = match light.kind {
                LightKind::Directional {
                    direction,
                    irradiance,
                } => (
                    V3::splat(-direction),
                    V3::splat(light.color * irradiance),
                    Vec4::ONE.cmpgt(Vec4::ZERO),
                ),
                LightKind::Point {
                    position,
                    intensity,
                } if light.range.is_none() => {
                    let d = V3::splat(position) - p;
                    let r2 = d.dot(d);
                    let k = Vec4::splat(intensity * 1.0) / r2;
                    (
                        d / r2.sqrt(),
                        V3::splat(light.color).scale(k),
                        // As `towards`: only r2 <= 0 misses.
                        !r2.cmple(Vec4::ZERO),
                    )
                }
                _ => {
                    // Spot cones and range windows: lane by lane.
                    let mut l = [Vec3::ZERO; 4];
                    let mut e = [Vec3::ZERO; 4];
                    let mut ok = [0.0f32; 4];
                    for k in 0..4 {
                        if let Some(inc) = incidence(light, p.lane(k)) {
                            (l[k], e[k], ok[k]) = (inc.l, inc.e, 1.0);
                        }
                    }
                    (
                        V3::from_lanes(l),
                        V3::from_lanes(e),
                        Vec4::from(ok).cmpgt(Vec4::ZERO),
                    )
                }
            };
            let ndl = n.dot(l);
            let mut lit = reaches & ndl.cmpgt(Vec4::ZERO);
            let mut s = Vec4::ONE;
            if light.shadows {
                let bits = lit.bitmask();
                for k in 0..4 {
                    if bits & (1 << k) != 0 {
                        s[k] = self
                            .shadows
                            .visibility(i, p.lane(k), f.geo_normal[k], l.lane(k));
                    }
                }
                lit &= s.cmpgt(Vec4::ZERO);
            }
            let e = e.scale(ndl * s);
            diffuse = diffuse + V3::select(lit, e, V3::ZERO);
            if specular {
                let h = (l + v).normalize_or(V3::ZERO);
                let ndh = n.dot(h).max(Vec4::ZERO);
                let shine = lit & ndh.cmpgt(Vec4::ZERO);
                let bits = shine.bitmask();
                if bits != 0 {
                    let mut pw = Vec4::ZERO;
                    for k in 0..4 {
                        if bits & (1 << k) != 0 {
                            pw[k] = ndh[k].powf(m.ns);
                        }
                    }
                    spec = spec + V3::select(shine, e.scale(pw), V3::ZERO);
                }
            }
        }
        // `blinn_phong::combine`.
        let ambient = V3::splat(self.ambient).scale(f.ao);
        let spec_term = if specular { ks * spec } else { V3::ZERO };
        let mut out = V3::splat(m.ke) + ka * ambient + kd * diffuse + spec_term;
        if let Some(env) = self.env {
            out = out + self.env_lanes(env, n, v, kd, ks, f.ao, m.ns);
        }
        out
    }

    /// `ShadeContext::env_blinn_phong` on four lanes (illum > 0, and
    /// not the sampled environment: those never reach the lanes).
    #[allow(clippy::too_many_arguments)]
    fn env_lanes(&self, env: &EnvLight, n: V3, v: V3, kd: V3, ks: V3, ao: Vec4, ns: f32) -> V3 {
        let roughness = crate::scene::material::roughness_from_ns(ns);
        let diffuse = (kd * env.irradiance4(n)).scale(ao / Vec4::splat(std::f32::consts::PI));
        let no_ks = ks.x.cmpeq(Vec4::ZERO) & ks.y.cmpeq(Vec4::ZERO) & ks.z.cmpeq(Vec4::ZERO);
        if no_ks.all() {
            return diffuse;
        }
        let r = n.scale(Vec4::splat(2.0) * n.dot(v)) - v;
        let r = dominant_direction4(n, r, roughness);
        let lit = diffuse + ks * env.prefiltered_phong4(r, roughness);
        V3::select(no_ks, diffuse, lit)
    }

    /// `apply_normal_map` of a tangent-space map whose four texels are
    /// `c` (RGB).
    fn normal_map_lanes(&self, f: &Lanes, c: V3, scale: f32) -> V3 {
        let n = f.normal;
        let c = V3 {
            x: c.x * Vec4::splat(2.0) - Vec4::ONE,
            y: c.y * Vec4::splat(2.0) - Vec4::ONE,
            z: c.z * Vec4::splat(2.0) - Vec4::ONE,
        };
        let t = f.tangent;
        let (tt, ok) = (t - n.scale(n.dot(t))).try_normalize();
        let tt = if ok.all() {
            tt
        } else {
            let mut fallback = [Vec3::ZERO; 4];
            for (k, o) in fallback.iter_mut().enumerate() {
                *o = n.lane(k).any_orthonormal_vector();
            }
            V3::select(ok, tt, V3::from_lanes(fallback))
        };
        let sign = Vec4::select(f.sign.cmplt(Vec4::ZERO), -Vec4::ONE, Vec4::ONE);
        let b = n.cross(tt).scale(sign);
        let scale = Vec4::splat(scale);
        let mapped = tt.scale(c.x * scale) + b.scale(c.y * scale) + n.scale(c.z);
        mapped.normalize_or(n)
    }
}
