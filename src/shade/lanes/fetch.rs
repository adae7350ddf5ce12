//! Where a lane call reads its material's texels (`LaneFetch`, the
//! lanes' `Fetch`): each distinct lookup once, the lookups of one slot
//! placed once for all its maps (`Lookups`); and the normal maps' math
//! over the lane type (tangent space, object space, bump maps).

// Loops over the lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Affine2, Mat3, Vec2, Vec4};

use super::material::{LaneMaterial, Map};
use super::{Coords, MAX_SIZES};
use crate::assets::texture::{Footprint, Placed4, TextureRef};
use crate::scene::material::{NormalMap, NormalSpace};
use crate::shade::Fetch;
use crate::simd::{Lane, Mask, V3};

/// `Fetch::normal_spread`: a squared change of the unit normal above this
/// (a turn of more than 60 degrees) in one pixel's step is a seam.
const SEAM: f32 = 1.0;

/// Texels of a lane material's maps for the lanes (`Fetch`): through
/// `Lookups`, each distinct lookup once.
pub(super) struct LaneFetch<'x, 'a, 'p, L: Lane> {
    pub lm: &'x LaneMaterial<'a>,
    pub lookups: Lookups<'x, 'p, L>,
    /// The interpolated normals.
    pub normal: V3<L>,
    /// The texels of the last lookup that several maps share (by
    /// `Map::same`), once read.
    pub shared: Option<(usize, V3<L>)>,
    /// The map read next, mostly (the maps are in reading order).
    pub next: usize,
}

impl<L: Lane> LaneFetch<'_, '_, '_, L> {
    /// Starts loading the texels of every distinct lookup.
    #[inline(always)]
    pub(super) fn start(&mut self) {
        for (i, map) in self.lm.maps.iter().enumerate() {
            if map.same == i {
                self.lookups.prefetch(map);
            }
        }
    }
}

impl<L: Lane> LaneFetch<'_, '_, '_, L> {
    /// Red, green and blue of map `i` looked up at the lanes'
    /// coordinates of its set moved by (`du`, `dv`) before its transform,
    /// each lookup filtered over the lanes' footprints (`probe`: one
    /// trilinear probe at the level of anisotropic ones, that many levels
    /// finer).
    fn offset_rgb(&self, i: usize, (du, dv): (L, L), probe: Option<f32>) -> V3<L> {
        let map = &self.lm.maps[i];
        let f = self.lookups.coords;
        let (u, v) = f.sets[(map.source.texcoord as usize).min(1)];
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
        let mut rgb = [[Vec4::ZERO; 3]; 2];
        for (q, r) in rgb.iter_mut().enumerate().take(L::QUADS) {
            let mut fps = f.footprints4(map.slot, q);
            if let Some(finer) = probe {
                for fp in &mut fps {
                    match *fp {
                        Footprint::Probes { lod, .. } if finer == 0.0 => *fp = Footprint::Lod(lod),
                        Footprint::Probes { lod, .. } | Footprint::Lod(lod) if finer > 0.0 => {
                            *fp = Footprint::Lod((lod - finer).max(0.0));
                        }
                        _ => {}
                    }
                }
            }
            *r = map.chain.sample4(u.quad(q), v.quad(q), &fps, map.mode);
        }
        V3 {
            x: L::from_quads(|q| rgb[q][0]),
            y: L::from_quads(|q| rgb[q][1]),
            z: L::from_quads(|q| rgb[q][2]),
        }
    }

    /// A tangent-space normal map's index and scale where its change
    /// across the pixel is measured (`normal_spread`, `normal_samples`):
    /// metallic-roughness with `render.specular_aa`, tangents, and the
    /// map's coordinates.
    fn measured(&self, m: &NormalMap) -> Option<(usize, f32)> {
        let NormalMap::Normals {
            map,
            scale,
            space: NormalSpace::Tangent,
        } = m
        else {
            return None;
        };
        if !self.lm.spread || !self.lm.tangents {
            return None;
        }
        Some((self.lm.index_of(map)?, *scale))
    }

    /// The lanes' steps along u and along v (`Footprints::bump`).
    fn steps(&self) -> (L, L) {
        let f = self.lookups.coords;
        let step = |axis: fn(Vec2) -> f32| L::from_fn(|k| axis(f.bump[f.first + k]));
        (step(|s| s.x), step(|s| s.y))
    }

    /// The interpolated normals bent by the bump map `t` scaled by
    /// `scale` (`ShadeContext::apply_normal_map`): the height's central
    /// differences one step (`Footprints::bump`) along u and along v,
    /// each lookup filtered over the lanes' footprints.
    fn bump(&mut self, t: &TextureRef, scale: f32) -> V3<L> {
        let Some(i) = self.lm.index_of(t) else {
            // No coordinates or no tangents: the normal as it is.
            return self.normal;
        };
        let (su, sv) = self.steps();
        let zero = L::splat(0.0);
        let height = |d: (L, L)| self.offset_rgb(i, d, None).x;
        let half = L::splat(0.5);
        let du = (height((su, zero)) - height((-su, zero))) * half;
        // Image rows run down; the bitangent points up the image.
        let dv = (height((zero, -sv)) - height((zero, sv))) * half;
        let n = self.normal;
        let f = self.lookups.coords;
        let (tt, b) = tangent_frame(n, (f.tangent, f.sign));
        let scale = L::splat(scale);
        (n - tt.scale(du * scale) - b.scale(dv * scale)).normalize_or(n)
    }
}

impl<L: Lane> Fetch<L> for LaneFetch<'_, '_, '_, L> {
    #[inline(always)]
    fn tangents(&self) -> Option<(V3<L>, L)> {
        let f = self.lookups.coords;
        self.lm.tangents.then_some((f.tangent, f.sign))
    }

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
            *out = map
                .chain
                .sample4_rgba(f.uv(map).0.quad(q), f.uv(map).1.quad(q), &fps, map.mode);
        }
        let channel = |c: usize| L::from_quads(|q| rgba[q][c]);
        let rgb = V3 {
            x: channel(0),
            y: channel(1),
            z: channel(2),
        };
        Some((rgb, channel(3)))
    }

    fn normal_samples(&mut self, m: &NormalMap) -> Option<[V3<L>; 4]> {
        let (i, scale) = self.measured(m)?;
        let (su, sv) = self.steps();
        let frame = (self.lookups.coords.tangent, self.lookups.coords.sign);
        // A rotated grid: each point a quarter step from its neighbours'
        // rows and columns.
        const GRID: [(f32, f32); 4] = [
            (-0.375, -0.125),
            (0.125, -0.375),
            (0.375, 0.125),
            (-0.125, 0.375),
        ];
        Some(GRID.map(|(a, b)| {
            let d = (su * L::splat(a), sv * L::splat(b));
            // Each point covers a quarter of the pixel: a level finer.
            tangent_space(self.normal, frame, self.offset_rgb(i, d, Some(1.0)), scale)
        }))
    }

    fn normal_spread(&mut self, m: &NormalMap, n: V3<L>) -> L {
        let zero = L::splat(0.0);
        let Some((i, scale)) = self.measured(m) else {
            return zero;
        };
        let (su, sv) = self.steps();
        let f = self.lookups.coords;
        let frame = (f.tangent, f.sign);
        // The change one step along each axis; a turn of more than 60
        // degrees in one step is taken for a step off the map's island (a
        // seam, the edge of an atlas chart) and does not count.
        let change = |d: (L, L)| {
            let m = tangent_space(self.normal, frame, self.offset_rgb(i, d, Some(0.0)), scale) - n;
            counted(m.dot(m))
        };
        change((su, zero)) + change((zero, sv))
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

/// A squared change of the normal in one step as `normal_spread` counts
/// it: 0 past `SEAM` (a seam), so at most `SEAM` (or NaN).
#[inline(always)]
fn counted<L: Lane>(m2: L) -> L {
    L::select(m2.cmpgt(L::splat(SEAM)), L::splat(0.0), m2)
}

/// An object-space normal map whose texels are `c` (RGB) at unit normals
/// `n`: its normals taken to world space by `m` (object to world for
/// normals) and flipped in the lanes `back` (seen from behind), unit (`n`
/// where they have no length).
#[inline(always)]
pub(in crate::shade) fn object_space<L: Lane>(n: V3<L>, back: L::Mask, m: Mat3, c: V3<L>) -> V3<L> {
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
pub(in crate::shade) fn tangent_space<L: Lane>(
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
pub(in crate::shade) fn tangent_frame<L: Lane>(n: V3<L>, (t, sign): (V3<L>, L)) -> (V3<L>, V3<L>) {
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

/// The texture lookups of one lane call: where each footprint slot's
/// lookups fall, found once for all its maps (`Texture::taps4`), four
/// lanes at a time.
pub(super) struct Lookups<'f, 'p, L: Lane> {
    coords: &'f Coords<'p, L>,
    /// Per quad and slot, once found (bit k of `found` for slot k): where
    /// its lookups fall.
    taps: [[Placed4; MAX_SIZES]; 2],
    found: u32,
}

impl<'f, 'p, L: Lane> Lookups<'f, 'p, L> {
    pub(super) fn new(coords: &'f Coords<'p, L>) -> Lookups<'f, 'p, L> {
        Lookups {
            coords,
            taps: Default::default(),
            found: 0,
        }
    }

    /// Finds where the lanes' lookups of `map` fall (once per slot).
    #[inline(always)]
    fn find(&mut self, map: &Map) {
        let (f, s) = (self.coords, map.slot);
        // Past `MAX_SIZES` a slot's lookups are not kept: `read` samples.
        if s < MAX_SIZES && self.found & (1 << s) == 0 {
            self.found |= 1 << s;
            for q in 0..L::QUADS {
                map.chain.place4_into(
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
            if let Some(placed) = self.taps[q].get(map.slot) {
                map.chain.prefetch_placed(placed);
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
            let placed = self.taps[q].get(map.slot);
            // (Read into place: a copy of a returned result would load
            // wide over the lookup's narrow stores, and wait on them.)
            if !placed.is_some_and(|p| map.chain.read_placed_into(p, map.mode, out)) {
                *out = map.chain.sample4(
                    f.uv(map).0.quad(q),
                    f.uv(map).1.quad(q),
                    &f.footprints4(map.slot, q),
                    map.mode,
                );
            }
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
    use super::*;

    /// `normal_spread` is at most `MAX_SPREAD` whatever the map holds,
    /// which lets `pbr_color` skip measuring it where no spread could
    /// pass `FAST_TURN` (the frames are the same either way).
    #[test]
    fn a_step_counts_at_most_the_seam() {
        for m2 in [
            0.0,
            0.5,
            1.0,
            1.0 + f32::EPSILON,
            2.0,
            4.0,
            f32::MAX,
            f32::INFINITY,
        ] {
            let c = counted(m2);
            assert!(c <= SEAM, "{m2} counted as {c}");
            assert!(counted(m2) + counted(m2) <= crate::shade::MAX_SPREAD);
        }
        assert!(counted(f32::NAN).is_nan());
        // Lanes alike: eight at once give each lane's one-lane value.
        let m2 = crate::simd::F8::from_fn(|k| [0.0, 0.9, 1.0, 1.5, 3.0, 0.25, 8.0, 1e30][k]);
        let c = counted(m2);
        for k in 0..8 {
            assert_eq!(c.lane(k), counted(m2.lane(k)));
        }
    }
}
