//! Shadow lookups: how much of a light reaches a point, from a shadow map
//! (hard or PCF) or from a ray towards the light.
//!
//! Shadow maps hold reverse-Z depth (near 1, nothing 0): orthographic maps
//! (directional lights) are linear in distance, perspective maps (spot
//! lights, the six faces of a point light's cube) use an infinite far plane,
//! z = near / distance, whose float precision is relative to the distance.
//!
//! Bias, all in texels of the map at the receiver (`render.shadow_bias`):
//! - normal offset: the lookup point moves along the geometric normal by
//!   `normal * sin(angle between normal and light)` texels;
//! - receiver plane: every texel the filter reads is compared with the depth
//!   of the receiver's own (geometric) plane at that texel's center, not
//!   with the depth at the shaded point, so a tilted surface never shadows
//!   itself across the filter's footprint;
//! - depth bias: `constant + slope * tan(angle)` texels (tan capped at 10),
//!   which absorbs curvature and rasterization rounding.
//!
//! The PCF kernel: a 3x3-texel box, area-weighted, around the lookup point
//! (so 4x4 texels are read, the outer ones partially); "hard" reads the one
//! texel under the point.

use glam::{Mat4, Vec3, Vec4};

use crate::raytrace::Tracer;
use crate::scene::ShadowBias;
use crate::simd::{Lane, Mask, V3};

mod kernel;

#[cfg(test)]
use kernel::{Kernels, pcf_one};
use kernel::{hard, kernels, pcf};

/// How a map projects light-view space (looking down -Z) to texels.
#[derive(Debug, Clone, Copy)]
pub enum MapProjection {
    /// A box of light-view space.
    Ortho(OrthoBox),
    /// tan of the half field of view (square), near plane distance.
    Perspective { tan_half: f32, near: f32 },
}

/// x in [x0, x1], y in [y0, y1]; distance (-z) in [near, far].
#[derive(Debug, Clone, Copy)]
pub struct OrthoBox {
    pub x0: f32,
    pub x1: f32,
    pub y0: f32,
    pub y1: f32,
    pub near: f32,
    pub far: f32,
}

impl MapProjection {
    /// Clip from light view: the matrix the depth pass rasterizes with.
    pub fn clip_from_view(&self) -> Mat4 {
        use glam::Vec4;
        match *self {
            MapProjection::Ortho(o) => {
                let (sx, sy) = (2.0 / (o.x1 - o.x0), 2.0 / (o.y1 - o.y0));
                // z_clip = (far - d) / (far - near) with d = -z_view.
                let a = 1.0 / (o.far - o.near);
                Mat4::from_cols(
                    Vec4::new(sx, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, sy, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, a, 0.0),
                    Vec4::new(
                        -(o.x0 + o.x1) / (o.x1 - o.x0),
                        -(o.y0 + o.y1) / (o.y1 - o.y0),
                        o.far * a,
                        1.0,
                    ),
                )
            }
            MapProjection::Perspective { tan_half, near } => {
                let s = 1.0 / tan_half;
                // z_clip = near, w = d: z = near / d.
                Mat4::from_cols(
                    Vec4::new(s, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, s, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, 0.0, -1.0),
                    Vec4::new(0.0, 0.0, near, 0.0),
                )
            }
        }
    }
}

/// One depth map.
#[derive(Debug, Clone)]
pub struct ShadowMap {
    pub size: u32,
    pub view_from_world: Mat4,
    pub projection: MapProjection,
    /// Reverse-Z depth per texel, rows from the top; 0 where nothing was
    /// drawn.
    pub depth: crate::bigbuf::BigBuf<f32>,
    /// The tiles something was drawn into (elsewhere every texel is 0).
    pub drawn: Drawn,
}

/// Side of a `Drawn` tile, in texels.
pub const DRAWN_TILE: usize = 16;

/// Which tiles of `DRAWN_TILE` x `DRAWN_TILE` texels of a square map may
/// hold a depth other than 0: a tile whose bit is clear holds 0 in every
/// texel (nothing was drawn there), so a lookup there need not read the
/// map, and a buffer drawn into again need not be cleared there. Marks
/// that do not fit the map (`Drawn::default()`, another size) say nothing:
/// every tile may hold a depth.
#[derive(Debug, Clone, Default)]
pub struct Drawn {
    /// 64-bit words per row of tiles.
    words: usize,
    bits: Vec<u64>,
}

impl Drawn {
    /// No tile drawn, for a `size` x `size` map.
    pub fn none(size: u32) -> Drawn {
        let tiles = (size as usize).div_ceil(DRAWN_TILE);
        let words = tiles.div_ceil(64);
        Drawn {
            words,
            bits: vec![0; words * tiles],
        }
    }

    /// Every tile marked (a map whose texels were written by hand).
    pub fn all(size: u32) -> Drawn {
        let mut d = Drawn::none(size);
        d.bits.fill(u64::MAX);
        d
    }

    /// The rows of tiles, each `words` words: to mark them in parallel.
    pub fn rows_mut(&mut self) -> std::slice::ChunksMut<'_, u64> {
        self.bits.chunks_mut(self.words.max(1))
    }

    /// Marks the tiles holding texel columns `x0..=x1` in one row's words.
    pub fn mark(row: &mut [u64], x0: usize, x1: usize) {
        for t in x0 / DRAWN_TILE..=x1 / DRAWN_TILE {
            row[t / 64] |= 1 << (t % 64);
        }
    }

    /// Whether these marks are a `size` x `size` map's.
    pub fn fits(&self, size: u32) -> bool {
        let tiles = (size as usize).div_ceil(DRAWN_TILE);
        self.words == tiles.div_ceil(64) && self.bits.len() == self.words * tiles
    }

    /// Whether tile (`tx`, `ty`) may hold a depth: marked, or beyond the
    /// marks (which then say nothing about it).
    #[inline]
    pub fn tile(&self, tx: usize, ty: usize) -> bool {
        tx / 64 >= self.words
            || self
                .bits
                .get(ty * self.words + tx / 64)
                .is_none_or(|w| w & (1 << (tx % 64)) != 0)
    }

    /// The marked tiles of tile row `ty`, as texel column ranges.
    pub fn columns(&self, ty: usize) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        let row = self.bits.get(ty * self.words..(ty + 1) * self.words);
        row.into_iter()
            .flatten()
            .enumerate()
            .flat_map(|(w, &bits)| {
                (0..64)
                    .filter(move |b| bits & (1 << b) != 0)
                    .map(move |b| (w * 64 + b) * DRAWN_TILE..(w * 64 + b + 1) * DRAWN_TILE)
            })
    }

    /// Whether every texel of columns `x0..=x1` and rows `y0..=y1` (each
    /// span at most one tile boundary wide) is 0 by the marks.
    #[inline]
    fn clear_box(&self, x0: usize, x1: usize, y0: usize, y1: usize) -> bool {
        let (tx0, tx1, ty0, ty1) = (
            x0 / DRAWN_TILE,
            x1 / DRAWN_TILE,
            y0 / DRAWN_TILE,
            y1 / DRAWN_TILE,
        );
        !(self.tile(tx0, ty0) || self.tile(tx1, ty0) || self.tile(tx0, ty1) || self.tile(tx1, ty1))
    }
}

/// What a light with `shadows = true` is tested against this frame.
#[derive(Debug, Clone)]
pub enum LightShadow {
    /// Casts no shadows (the light does not ask, or `render.shadows = off`).
    None,
    Map(ShadowMap),
    /// A point light's cube at `position`: faces +X, -X, +Y, -Y, +Z, -Z.
    Cube {
        position: Vec3,
        faces: Box<[ShadowMap; 6]>,
    },
    /// Rays towards the light: to its position (point, spot), or
    /// unbounded (directional); a directional light with an angular
    /// radius `cone` (radians, > 0) gets soft shadows from rays spread
    /// over its disc (`soft_shadow`).
    Ray {
        position: Option<Vec3>,
        cone: f32,
    },
    /// Rays towards points of an area light's disc (`soft_shadow::
    /// open_share_to`): centre, unit axis, radius.
    Disc {
        center: Vec3,
        axis: Vec3,
        radius: f32,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Filter {
    Hard,
    Pcf,
}

/// Every light's shadow for one frame.
pub struct Shadows<'a> {
    /// Per light of the frame, in the same order (shared between frames
    /// whose lights and shadow casters stand where they stood).
    pub lights: std::sync::Arc<[LightShadow]>,
    pub filter: Filter,
    pub bias: ShadowBias,
    /// The frame's ray tracer (ray-traced shadows only).
    pub tracer: Option<&'a Tracer<'a>>,
}

const MAX_TAN: f32 = 10.0;

impl Shadows<'_> {
    /// No shadows at all.
    pub fn none() -> Shadows<'static> {
        Shadows {
            lights: std::sync::Arc::new([]),
            filter: Filter::Pcf,
            bias: ShadowBias::default(),
            tracer: None,
        }
    }

    /// Fraction of light `i` reaching the points `p`, one per lane of `L`
    /// (geometric unit normals `ng`, one per lane, facing the viewer; `l`
    /// unit towards the light), for the lanes k in `lanes` (bit k; the
    /// others are 1): 0 in shadow, 1 lit. A surface facing away from the
    /// light is in its own shadow. A map's lookups are placed for all
    /// lanes at once (`place`; a point light's cube once per face the
    /// lanes look into), then filtered: by the PCF kernel all at once
    /// (`pcf`), by the hard one lane by lane; rays are cast lane by lane.
    /// No lane in `lanes`: nothing is looked up. Each lane is bit for bit
    /// its lookup alone, at every width.
    #[inline(always)]
    pub fn visibility<L: Lane>(&self, i: usize, p: V3<L>, ng: &[Vec3], l: V3<L>, lanes: u32) -> L {
        let mut out = L::splat(1.0);
        let Some(s) = self.lights.get(i).filter(|_| lanes != 0) else {
            return out;
        };
        let n = V3::<L>::from_fn(|k| ng[k]);
        let cos = n.dot(l);
        let zero = L::splat(0.0);
        let mut lookup = |m: &ShadowMap, lanes: u32| {
            let placed = self.place(m, p, n, cos);
            let at = kernels(m, &placed);
            // The lanes that read the map: facing the light, beyond the
            // near plane, inside the map. The others: 0 facing away, else 1.
            let read = lanes & !cos.cmple(zero).bitmask() & !placed.before_near & at.inside;
            let unread = L::select(cos.cmple(zero), zero, L::splat(1.0));
            out = L::select(lanes_in::<L>(lanes & !read), unread, out);
            match self.filter {
                Filter::Pcf if read != 0 => {
                    out = L::select(lanes_in::<L>(read), pcf(m, &at, read), out);
                }
                Filter::Pcf => {}
                Filter::Hard => {
                    let hard = L::from_fn(|k| {
                        let (fx, fy) = (at.fx.lane(k), at.fy.lane(k));
                        let g = (at.gx.lane(k), at.gy.lane(k));
                        if read & (1 << k) != 0 {
                            hard(m, (fx, fy), at.z.lane(k), g)
                        } else {
                            0.0
                        }
                    });
                    out = L::select(lanes_in::<L>(read), hard, out);
                }
            }
        };
        match s {
            LightShadow::None => {}
            LightShadow::Map(m) => lookup(m, lanes),
            LightShadow::Cube { position, faces } => {
                let face: [usize; 8] = std::array::from_fn(|k| {
                    if k < L::WIDTH {
                        cube_face(p.lane(k) - *position)
                    } else {
                        0
                    }
                });
                let mut left = lanes;
                while left != 0 {
                    let f = face[left.trailing_zeros() as usize];
                    let same = (0..L::WIDTH)
                        .filter(|&k| left & (1 << k) != 0 && face[k] == f)
                        .fold(0, |m, k| m | 1 << k);
                    lookup(&faces[f], same);
                    left &= !same;
                }
            }
            LightShadow::Ray { position, cone } => {
                out = L::from_fn(|k| {
                    if lanes & (1 << k) == 0 {
                        1.0
                    } else if *cone > 0.0 && position.is_none() {
                        self.soft_ray(*cone, p.lane(k), ng[k], l.lane(k))
                    } else {
                        self.ray(position, p.lane(k), ng[k], l.lane(k))
                    }
                });
            }
            LightShadow::Disc {
                center,
                axis,
                radius,
            } => {
                out = L::from_fn(|k| {
                    if lanes & (1 << k) == 0 {
                        return 1.0;
                    }
                    let disc = (*center, *axis, *radius);
                    self.soft_ray_to(disc, p.lane(k), ng[k])
                });
            }
        }
        out
    }

    /// A ray's visibility of the light (at `position`, or directional
    /// along `l`) from `p`, lifted off its surface along `ng`.
    fn ray(&self, position: &Option<Vec3>, p: Vec3, ng: Vec3, l: Vec3) -> f32 {
        if ng.dot(l) <= 0.0 {
            return 0.0;
        }
        let Some(t) = &self.tracer else { return 1.0 };
        let o = p + ng * t.epsilon;
        match position {
            Some(q) => t.transmittance(o, *q - o, 1.0 - 1e-4),
            None => t.transmittance(o, l, f32::INFINITY),
        }
    }
}

/// Lookups placed in a map (`Shadows::place`), one per lane: its texel
/// coordinates, the receiver plane's depth there and its slopes per
/// texel (and their cap's scale), and the lanes nearer than the map's
/// near plane (bit k: lane k), which it leaves lit.
struct Placed<L: Lane> {
    before_near: u32,
    fx: L,
    fy: L,
    z: L,
    gx: L,
    gy: L,
    z_per_texel: L,
}

impl Shadows<'_> {
    /// Where the points `p` with geometric normals `n` (`cos` = n.l) fall
    /// in map `m`, biased (the module's notes): the point moved along
    /// its normal, its depth and the plane's slopes in the map's texels.
    #[inline(always)]
    fn place<L: Lane>(&self, m: &ShadowMap, p: V3<L>, n: V3<L>, cos: L) -> Placed<L> {
        let b = &self.bias;
        let sp = L::splat;
        let (zero, one) = (sp(0.0), sp(1.0));
        // (Lane max and min: a NaN first operand takes the second, at
        // every width; no second operand here is NaN.)
        let sin = (one - cos * cos).max(zero).sqrt();
        let tan = (sin / cos).min(sp(MAX_TAN));
        let size = m.size as f32;
        let v = &m.view_from_world;
        let q0 = point(v, p);
        // The size of a texel at distance d.
        let texel = |d: L| match m.projection {
            MapProjection::Ortho(o) => sp((o.x1 - o.x0) / size),
            MapProjection::Perspective { tan_half, .. } => sp(2.0) * d * sp(tan_half) / sp(size),
        };
        let nv = vector(v, n);
        // Normal offset.
        let q = q0 + nv.scale(sp(b.normal) * sin * texel(-q0.z));
        let d = -q.z;
        let t = texel(d);
        let depth_bias = t * (sp(b.constant) + sp(b.slope) * tan);
        match m.projection {
            MapProjection::Ortho(o) => {
                let fx = (q.x - sp(o.x0)) / sp(o.x1 - o.x0) * sp(size);
                let fy = (sp(o.y1) - q.y) / sp(o.y1 - o.y0) * sp(size);
                let a = 1.0 / (o.far - o.near);
                let z = (sp(o.far) - (d - depth_bias)) * sp(a);
                // d' = d + (nv.x dx + nv.y dy) / nv.z along the plane.
                let (tx, ty) = ((o.x1 - o.x0) / size, (o.y1 - o.y0) / size);
                let inv = L::select(nv.z.abs().cmpgt(sp(1e-12)), one / nv.z, zero);
                Placed {
                    before_near: d.cmplt(sp(o.near)).bitmask(),
                    fx,
                    fy,
                    z,
                    gx: -(nv.x * sp(tx) * inv) * sp(a),
                    gy: (nv.y * sp(ty) * inv) * sp(a),
                    z_per_texel: t * sp(a),
                }
            }
            MapProjection::Perspective { tan_half, near } => {
                let sx = q.x / (d * sp(tan_half));
                let sy = q.y / (d * sp(tan_half));
                // 1/d' = (nv . r) / (nv . q), r = (sx tan, sy tan, -1):
                // affine in sx, sy.
                let nq = nv.dot(q);
                let k = sp(near * tan_half) / nq * sp(2.0 / size);
                let usable = nq.abs().cmpgt(sp(1e-20));
                Placed {
                    before_near: d.cmple(sp(near)).bitmask(),
                    fx: (sx * sp(0.5) + sp(0.5)) * sp(size),
                    fy: (sp(0.5) - sy * sp(0.5)) * sp(size),
                    z: sp(near) / (d - depth_bias).max(sp(near * 1e-3)),
                    gx: L::select(usable, nv.x * k, zero),
                    gy: L::select(usable, -nv.y * k, zero),
                    z_per_texel: sp(near) * t / (d * d),
                }
            }
        }
    }
}

/// The mask of the lanes in `bits` (bit k: lane k; bits < 2^8): lane k
/// is set where floor(bits / 2^k) is odd (exact in f32), without taking
/// the lanes apart.
#[inline(always)]
fn lanes_in<L: Lane>(bits: u32) -> L::Mask {
    const STEP: [f32; 8] = [
        1.0,
        0.5,
        0.25,
        0.125,
        0.0625,
        0.031_25,
        0.015_625,
        0.007_812_5,
    ];
    let t = (L::splat(bits as f32) * L::from_fn(|k| STEP[k])).floor();
    let half = L::splat(0.5);
    (t - (t * half).floor() * L::splat(2.0)).cmpgt(half)
}

/// `m.transform_point3(p)` per lane: per coordinate ((x p.x + y p.y) +
/// z p.z) + w, as glam sums the columns.
#[inline(always)]
fn point<L: Lane>(m: &Mat4, p: V3<L>) -> V3<L> {
    let c = |k: usize| {
        let col = |v: Vec4| L::splat(v[k]);
        ((col(m.x_axis) * p.x + col(m.y_axis) * p.y) + col(m.z_axis) * p.z) + col(m.w_axis)
    };
    V3 {
        x: c(0),
        y: c(1),
        z: c(2),
    }
}

/// `m.transform_vector3(v)` per lane: (x v.x + y v.y) + z v.z.
#[inline(always)]
fn vector<L: Lane>(m: &Mat4, v: V3<L>) -> V3<L> {
    let c = |k: usize| {
        let col = |a: Vec4| L::splat(a[k]);
        (col(m.x_axis) * v.x + col(m.y_axis) * v.y) + col(m.z_axis) * v.z
    };
    V3 {
        x: c(0),
        y: c(1),
        z: c(2),
    }
}

/// The cube face (+X, -X, +Y, -Y, +Z, -Z) a direction falls on.
#[inline]
pub fn cube_face(d: Vec3) -> usize {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        if d.x >= 0.0 { 0 } else { 1 }
    } else if a.y >= a.z {
        if d.y >= 0.0 { 2 } else { 3 }
    } else if d.z >= 0.0 {
        4
    } else {
        5
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::F8;

    /// An 8x8 orthographic map of a light 5 units up, looking down -Y over
    /// [-1, 1] x [-1, 1], distances 0..10, with an occluder at height 1
    /// over x < 0 (texel columns 0..4).
    fn map() -> ShadowMap {
        let view_from_world = Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)
            * Mat4::from_translation(Vec3::new(0.0, -5.0, 0.0));
        let (near, far) = (0.0, 10.0);
        let stored = (far - 4.0) / (far - near);
        let depth = (0..64)
            .map(|i| if i % 8 < 4 { stored } else { 0.0 })
            .collect();
        ShadowMap {
            size: 8,
            view_from_world,
            projection: MapProjection::Ortho(OrthoBox {
                x0: -1.0,
                x1: 1.0,
                y0: -1.0,
                y1: 1.0,
                near,
                far,
            }),
            depth,
            drawn: Drawn::all(8),
        }
    }

    /// Light 0's visibility at one point: a lone lane.
    fn one(s: &Shadows, p: Vec3, ng: Vec3, l: Vec3) -> f32 {
        s.visibility::<f32>(0, V3::from(p), &[ng], V3::from(l), 1)
    }

    fn shadows(filter: Filter) -> Shadows<'static> {
        Shadows {
            lights: std::sync::Arc::new([LightShadow::Map(map())]),
            filter,
            bias: ShadowBias::default(),
            tracer: None,
        }
    }

    #[test]
    fn a_map_shadows_what_lies_below_its_occluder() {
        let up = Vec3::Y;
        let s = shadows(Filter::Hard);
        // On the ground under the occluder, and beside it.
        assert_eq!(one(&s, Vec3::new(-0.5, 0.0, 0.1), up, up), 0.0);
        assert_eq!(one(&s, Vec3::new(0.5, 0.0, 0.1), up, up), 1.0);
        // Above the occluder's height: lit.
        assert_eq!(one(&s, Vec3::new(-0.5, 2.0, 0.1), up, up), 1.0);
        // Facing away from the light: its own shadow.
        assert_eq!(one(&s, Vec3::new(0.5, 0.0, 0.1), -up, up), 0.0);
        // Outside the map, and a light without shadows: lit.
        assert_eq!(one(&s, Vec3::new(3.0, 0.0, 0.0), up, up), 1.0);
        assert_eq!(one(&Shadows::none(), Vec3::ZERO, up, up), 1.0);
    }

    #[test]
    fn pcf_is_the_covered_fraction_of_a_three_texel_box() {
        let (up, s) = (Vec3::Y, shadows(Filter::Pcf));
        // Centered on the occluder's edge: half of the box is shadowed.
        let v = one(&s, Vec3::new(0.0, 0.0, 0.1), up, up);
        assert!((v - 0.5).abs() < 1e-5, "{v}");
        // A quarter texel (1/16 unit) into the lit side: 1/2 + 1/12 lit.
        let v = one(&s, Vec3::new(1.0 / 16.0, 0.0, 0.1), up, up);
        assert!((v - (0.5 + 1.0 / 12.0)).abs() < 1e-5, "{v}");
        // Two texels away the box sees one side only.
        assert_eq!(one(&s, Vec3::new(-0.6, 0.0, 0.1), up, up), 0.0);
        assert_eq!(one(&s, Vec3::new(0.6, 0.0, 0.1), up, up), 1.0);
    }

    /// `pcf` one texel at a time, as it was written before its four-column
    /// form.
    fn pcf_one_by_one(m: &ShadowMap, fx: f32, fy: f32, z: f32, gx: f32, gy: f32) -> f32 {
        let n = m.size as i32;
        let (bx, by) = ((fx - 1.5).floor() as i32, (fy - 1.5).floor() as i32);
        let w = |i: i32, f: f32| {
            let lo = (i as f32).max(f - 1.5);
            let hi = (i as f32 + 1.0).min(f + 1.5);
            (hi - lo).max(0.0) / 3.0
        };
        let wx = [0, 1, 2, 3].map(|k| w(bx + k, fx));
        let wy = [0, 1, 2, 3].map(|k| w(by + k, fy));
        let tx = [0, 1, 2, 3].map(|i| gx * ((bx + i) as f32 + 0.5 - fx));
        let ty = [0, 1, 2, 3].map(|j| gy * ((by + j) as f32 + 0.5 - fy));
        let cols = [0, 1, 2, 3].map(|i| (bx + i).clamp(0, n - 1) as usize);
        let mut sum = 0.0;
        for j in 0..4 {
            let base = (by + j as i32).clamp(0, n - 1) as usize * n as usize;
            let mut row = 0.0;
            for i in 0..4 {
                let stored = m.depth[base + cols[i]];
                let zr = z + tx[i] + ty[j];
                row += wx[i] * if stored <= zr { 1.0 } else { 0.0 };
            }
            sum += wy[j] * row;
        }
        sum
    }

    #[test]
    fn four_column_pcf_equals_texel_by_texel() {
        let mut x = 0x9e37_79b9u32;
        let mut rnd = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x >> 8) as f32 / (1u32 << 24) as f32
        };
        let size = 13u32;
        let mut m = map();
        m.size = size;
        m.depth = (0..size * size).map(|_| rnd()).collect();
        for round in 0..20_000 {
            // Mostly inside, often along the edges (clamped columns/rows).
            let fx = (rnd() * size as f32).min(size as f32 - 1e-3);
            let fy = if round % 4 == 0 {
                rnd() * 2.0
            } else {
                rnd() * size as f32
            };
            let fy = fy.min(size as f32 - 1e-3);
            let z = rnd();
            let (gx, gy) = ((rnd() - 0.5) * 0.2, (rnd() - 0.5) * 0.2);
            let (gx, gy) = if round % 9 == 0 {
                (0.0, -0.0)
            } else {
                (gx, gy)
            };
            let want = pcf_one_by_one(&m, fx, fy, z, gx, gy);
            let got = pcf_one(&m, fx, fy, z, gx, gy);
            assert_eq!(got.to_bits(), want.to_bits(), "{fx} {fy} {z} {gx} {gy}");
        }
    }

    /// PCF over a map whose marks leave most tiles clear (those are not
    /// read) equals PCF over the same map with every tile marked (all
    /// read), at points all over it, some in the drawn tiles, some by
    /// their edges, some on the map's border.
    #[test]
    fn pcf_skips_clear_tiles_without_changing_a_value() {
        let n = 64usize;
        let mut marked = map();
        marked.size = n as u32;
        // Depth in texels 16..37 x 16..40 (starting at a tile's corner,
        // so a footprint whose first tile is clear may reach it): tiles
        // 1 and 2 of tile rows 1 and 2.
        marked.depth = (0..n * n)
            .map(|i| {
                let (x, y) = (i % n, i / n);
                if (16..37).contains(&x) && (16..40).contains(&y) {
                    0.3 + 0.01 * ((x * 7 + y * 3) % 11) as f32
                } else {
                    0.0
                }
            })
            .collect();
        let mut drawn = Drawn::none(n as u32);
        for (ty, row) in drawn.rows_mut().enumerate() {
            if (1..3).contains(&ty) {
                Drawn::mark(row, 16, 36);
            }
        }
        assert!(!drawn.tile(0, 0) && drawn.tile(1, 1) && drawn.tile(2, 2) && !drawn.tile(3, 1));
        marked.drawn = drawn;
        let mut all = marked.clone();
        all.drawn = Drawn::all(n as u32);
        // Marks that say nothing (another map's, none) read every texel.
        let mut unknown = marked.clone();
        unknown.drawn = Drawn::default();
        let mut other = marked.clone();
        other.drawn = Drawn::none(8);
        assert!(marked.drawn.fits(n as u32) && !other.drawn.fits(n as u32));
        let mut lit = 0;
        let mut seen = std::collections::HashSet::new();
        let mut points = Vec::new();
        for k in 0..4000 {
            let fx = (k % 80) as f32 * 0.83 - 1.2;
            let fy = (k / 80) as f32 * 1.37 - 1.7;
            let (fx, fy) = (fx.clamp(0.0, 63.99), fy.clamp(0.0, 63.99));
            let z = 0.25 + 0.05 * (k % 5) as f32;
            points.push((fx, fy, z));
            let (a, b) = (
                pcf_one(&marked, fx, fy, z, 0.001, -0.002),
                pcf_one(&all, fx, fy, z, 0.001, -0.002),
            );
            assert_eq!(a.to_bits(), b.to_bits(), "at {fx} {fy}");
            for m in [&unknown, &other] {
                let c = pcf_one(m, fx, fy, z, 0.001, -0.002);
                assert_eq!(
                    c.to_bits(),
                    b.to_bits(),
                    "at {fx} {fy}, marks that do not fit"
                );
            }
            lit += (a > 0.0 && a < 1.0) as usize;
            seen.insert(a.to_bits());
        }
        // Partly shadowed lookups, so the drawn texels were compared.
        assert!(
            lit > 50 && seen.len() > 10,
            "{lit} partial, {} values",
            seen.len()
        );
        // Eight and four lanes at once, each at another point (lanes in
        // clear tiles beside lanes that read, some lanes left out): each
        // live lane is its own lookup. The points are taken out of order
        // so that a group's lanes lie far apart.
        let order: Vec<usize> = (0..points.len()).map(|i| i * 37 % points.len()).collect();
        for (g, group) in order.chunks_exact(8).enumerate() {
            let lane = |f: fn(&(f32, f32, f32)) -> f32| F8::from_fn(|k| f(&points[group[k]]));
            let at = Kernels {
                fx: lane(|p| p.0),
                fy: lane(|p| p.1),
                z: lane(|p| p.2),
                gx: F8::splat(0.001),
                gy: F8::splat(-0.002),
                inside: 0xff,
            };
            let live = [0xff, 0b0101_1010, 0b1000_0001, 0b0110_1111][g % 4];
            let got = pcf(&marked, &at, live);
            let quad = |v: F8| v.quad(0);
            let at4 = Kernels {
                fx: quad(at.fx),
                fy: quad(at.fy),
                z: quad(at.z),
                gx: quad(at.gx),
                gy: quad(at.gy),
                inside: 0xf,
            };
            let got4 = pcf(&marked, &at4, live & 0xf);
            for k in (0..8).filter(|k| live & (1 << k) != 0) {
                let (fx, fy, z) = points[group[k]];
                let want = pcf_one(&marked, fx, fy, z, 0.001, -0.002);
                assert_eq!(
                    got.lane(k).to_bits(),
                    want.to_bits(),
                    "lane {k} at {fx} {fy}"
                );
                if k < 4 {
                    assert_eq!(got4[k].to_bits(), want.to_bits(), "lane {k} of 4");
                }
            }
        }
    }

    /// The four lanes' kernels (`kernels`) cap the slopes as `f32::max`
    /// and `f32::min` do, lane by lane (a NaN takes the other operand; a
    /// zero's sign aside), and take the lanes inside the map as the
    /// one-lane test does, at NaN, infinite, negative, edge and inside
    /// coordinates and NaN, infinite and zero caps and slopes.
    #[test]
    fn four_kernels_cap_and_test_as_one_lane_does() {
        let m = map();
        let size = m.size as f32;
        let coords = [
            f32::NAN,
            f32::INFINITY,
            -f32::INFINITY,
            -0.5,
            -0.0,
            0.0,
            3.3,
            size - 1e-4,
            size,
            9.0,
        ];
        let values = [
            f32::NAN,
            f32::INFINITY,
            -f32::INFINITY,
            -2.0,
            -0.0,
            0.0,
            0.07,
            1e30,
        ];
        let caps = [f32::NAN, f32::INFINITY, 0.0, 0.01, 3.0];
        let same = |a: f32, b: f32| a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0);
        let mut i = 0usize;
        for &zpt in &caps {
            for _ in 0..200 {
                let pick =
                    |set: &[f32], k: usize| set[(i * 7 + k * 13 + i / set.len()) % set.len()];
                let lanes = |set: &[f32], s: usize| {
                    Vec4::from_array([0, 1, 2, 3].map(|k| pick(set, k + s)))
                };
                let placed = Placed {
                    before_near: 0,
                    fx: lanes(&coords, 0),
                    fy: lanes(&coords, 5),
                    z: Vec4::splat(0.5),
                    gx: lanes(&values, 2),
                    gy: lanes(&values, 7),
                    z_per_texel: Vec4::splat(zpt),
                };
                i += 1;
                let at: Kernels<Vec4> = kernels(&m, &placed);
                for k in 0..4 {
                    let cap = zpt * MAX_TAN;
                    let (gx, gy) = (placed.gx[k], placed.gy[k]);
                    let (wx, wy) = (gx.max(-cap).min(cap), gy.max(-cap).min(cap));
                    assert!(
                        same(at.gx[k], wx),
                        "gx {gx} cap {cap}: {} not {wx}",
                        at.gx[k]
                    );
                    assert!(
                        same(at.gy[k], wy),
                        "gy {gy} cap {cap}: {} not {wy}",
                        at.gy[k]
                    );
                    let (fx, fy) = (placed.fx[k], placed.fy[k]);
                    let outside = !(fx.is_finite() && fy.is_finite())
                        || fx < 0.0
                        || fy < 0.0
                        || fx >= size
                        || fy >= size;
                    assert_eq!(at.inside & (1 << k) != 0, !outside, "at {fx} {fy}");
                }
            }
        }
    }

    /// A perspective map (a spot light's, or a cube face's) of `n` x `n`
    /// texels, at 5 units up looking down -Y, 90 degrees wide, of random
    /// reverse-Z depths (some texels empty).
    fn perspective_map(n: usize, r: &mut impl FnMut() -> f32) -> ShadowMap {
        let mut m = map();
        m.size = n as u32;
        m.projection = MapProjection::Perspective {
            tan_half: 0.5,
            near: 0.5,
        };
        m.depth = (0..n * n)
            .map(|_| if r() < 0.2 { 0.0 } else { 0.1 + 0.08 * r() })
            .collect();
        m.drawn = Drawn::all(n as u32);
        m
    }

    /// Each lane of an eight- and a four-lane lookup is the lookup of that lane alone,
    /// bit for bit: in an orthographic map, a perspective map and a
    /// point light's cube whose faces hold different depths (so a lane
    /// read in another lane's face shows); both filters, two biases;
    /// points inside, beside and in front of the map, normals towards
    /// and away from the light, grazing ones, and lanes left out.
    #[test]
    fn each_lane_is_its_own_lookup() {
        let mut r = crate::testing::xorshift(0x5eed_0004);
        let n = 64usize;
        let mut m = map();
        m.size = n as u32;
        // Rough terrain of depths (some texels empty), seen from above.
        m.depth = (0..n * n)
            .map(|_| if r() < 0.2 { 0.0 } else { 0.45 + 0.2 * r() })
            .collect();
        m.drawn = Drawn::all(n as u32);
        let spot = perspective_map(n, &mut r);
        let faces = Box::new([0; 6].map(|_| perspective_map(n, &mut r)));
        let kinds = [
            LightShadow::Map(m),
            LightShadow::Map(spot),
            LightShadow::Cube {
                position: Vec3::new(0.0, 5.0, 0.0),
                faces,
            },
        ];
        let (mut shaded, mut partial) = (0, 0);
        for (filter, kind) in [Filter::Pcf, Filter::Hard]
            .into_iter()
            .flat_map(|f| kinds.iter().map(move |k| (f, k)))
        {
            for bias in [
                ShadowBias::default(),
                ShadowBias {
                    constant: 0.3,
                    slope: 2.0,
                    normal: 1.5,
                },
            ] {
                let s = Shadows {
                    lights: std::sync::Arc::new([kind.clone()]),
                    filter,
                    bias,
                    tracer: None,
                };
                for _ in 0..3000 {
                    let mut v = |s: f32| (r() * 2.0 - 1.0) * s;
                    let p: [Vec3; 8] = std::array::from_fn(|_| Vec3::new(v(1.3), v(6.0), v(1.3)));
                    let ng: [Vec3; 8] = std::array::from_fn(|_| {
                        let g = Vec3::new(v(1.0), v(1.0) + 0.3, v(1.0));
                        g.try_normalize().unwrap_or(Vec3::Y)
                    });
                    let l: [Vec3; 8] =
                        std::array::from_fn(|_| Vec3::new(v(0.3), 1.0, v(0.3)).normalize());
                    let lanes = (r() * 256.0) as u32 | 1;
                    let eight = s.visibility(
                        0,
                        V3::<F8>::from_fn(|k| p[k]),
                        &ng,
                        V3::<F8>::from_fn(|k| l[k]),
                        lanes,
                    );
                    let four = s.visibility(
                        0,
                        V3::<Vec4>::from_fn(|k| p[k]),
                        &ng,
                        V3::<Vec4>::from_fn(|k| l[k]),
                        lanes & 0xf,
                    );
                    for k in 0..8 {
                        let want = if lanes & (1 << k) != 0 {
                            one(&s, p[k], ng[k], l[k])
                        } else {
                            1.0
                        };
                        let got = eight.lane(k);
                        assert_eq!(
                            got.to_bits(),
                            want.to_bits(),
                            "lane {k}: {p:?} {ng:?} {l:?}"
                        );
                        if k < 4 {
                            assert_eq!(four[k].to_bits(), want.to_bits(), "lane {k} of four");
                        }
                        shaded += (want == 0.0) as usize;
                        partial += (want > 0.0 && want < 1.0) as usize;
                    }
                }
            }
        }
        // Shadowed and partly shadowed lanes, so the comparison means
        // something.
        assert!(
            shaded > 6000 && partial > 3000,
            "{shaded} shadowed, {partial} partial"
        );
    }

    #[test]
    fn lane_masks_hold_their_bits() {
        for bits in 0..256u32 {
            assert_eq!(lanes_in::<F8>(bits).bitmask(), bits);
            assert_eq!(lanes_in::<Vec4>(bits).bitmask(), bits & 0xf);
            assert_eq!(lanes_in::<f32>(bits).bitmask(), bits & 1);
        }
    }

    #[test]
    fn cube_faces_follow_the_largest_axis() {
        let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]
            .map(|d| cube_face(d * 2.0 + Vec3::splat(0.1)));
        assert_eq!(faces, [0, 1, 2, 3, 4, 5]);
    }
}
