//! The filters that read a shadow map at placed lookups: "hard" (the one
//! texel under the point) and PCF (a 3x3-texel box, area-weighted, over
//! 4x4 texels, one lookup per lane of any width), each comparing the
//! stored depth with the receiver's plane at the texel's center.

use glam::{Mat4, Vec4};

use super::{MAX_TAN, Placed, ShadowMap};
use crate::simd::{Lane, Mask, lanes4};

/// Most lanes of a lookup (`simd::F8`).
const MAX_LANES: usize = 8;

/// The "hard" filter: the one texel under (`fx`, `fy`), lit when its
/// stored depth is not nearer (greater) than the receiver's plane at its
/// center.
#[inline]
pub(super) fn hard(m: &ShadowMap, (fx, fy): (f32, f32), z: f32, (gx, gy): (f32, f32)) -> f32 {
    let n = m.size as i32;
    let (ix, iy) = (fx as i32, fy as i32);
    let (cx, cy) = (ix.clamp(0, n - 1), iy.clamp(0, n - 1));
    let stored = m.depth[(cy * n + cx) as usize];
    let zr = z + gx * (ix as f32 + 0.5 - fx) + gy * (iy as f32 + 0.5 - fy);
    if stored <= zr { 1.0 } else { 0.0 }
}

/// Where lookups read a map (`kernels`), one per lane of `L`: texel
/// coordinates, the receiver plane's depth there and its slopes per
/// texel, capped; the lanes inside the map (bit k: lane k).
pub(super) struct Kernels<L: Lane> {
    pub fx: L,
    pub fy: L,
    pub z: L,
    pub gx: L,
    pub gy: L,
    pub inside: u32,
}

/// The kernels of the lookups placed in `m` (`Shadows::place`): the
/// plane's slopes capped at `z_per_texel` times the slope cap (`f32`'s
/// max and min: a NaN cap, from extreme geometry, caps nothing), and the
/// lanes whose point lies inside the map (the others are lit).
#[inline(always)]
pub(super) fn kernels<L: Lane>(m: &ShadowMap, p: &Placed<L>) -> Kernels<L> {
    let cap = p.z_per_texel * L::splat(MAX_TAN);
    // `f32::max`, `f32::min`: a NaN lane takes the other operand (the
    // sign of a zero may differ; it only enters sums compared with <=).
    let max = |a: L, b: L| L::select(b.is_nan(), a, a.max(b));
    let min = |a: L, b: L| L::select(b.is_nan(), a, a.min(b));
    let size = L::splat(m.size as f32);
    let zero = L::splat(0.0);
    let inside = p.fx.is_finite()
        & p.fy.is_finite()
        & p.fx.cmpge(zero)
        & p.fy.cmpge(zero)
        & p.fx.cmplt(size)
        & p.fy.cmplt(size);
    Kernels {
        fx: p.fx,
        fy: p.fy,
        z: p.z,
        gx: min(max(p.gx, -cap), cap),
        gy: min(max(p.gy, -cap), cap),
        inside: inside.bitmask(),
    }
}

/// The PCF kernel of the lanes in `live` (bit k: lane k of `at`); the
/// other lanes' values are unspecified. Per lane: the lit fraction of a
/// 3x3-texel box around (`fx`, `fy`), each texel compared with the
/// receiver's plane (depth `z` at the point, `gx`, `gy` per texel). The
/// box covers 4x4 texels, the outer ones in part. Each lane takes the
/// same sums in the same order at every width: per row the products
/// wx[i] * (0 or 1) (= wx[i] or +0) summed along the row from 0 in column
/// order, then the rows weighted and summed from 0 in row order.
#[inline(always)]
pub(super) fn pcf<L: Lane>(m: &ShadowMap, at: &Kernels<L>, live: u32) -> L {
    let sp = L::splat;
    let (fx, fy, z, gx, gy) = (at.fx, at.fy, at.z, at.gx, at.gy);
    // Per lane the box's first texel column and row: [f - 1.5, f + 1.5]
    // per axis, texel i covering [i, i + 1] (whole numbers, exact as
    // floats: far below 2^24).
    let (bx, by) = ((fx - sp(1.5)).floor(), (fy - sp(1.5)).floor());
    let rows = box_rows::<L>(m, (bx, by), live);
    let w = |i: L, f: L| {
        let lo = i.max(f - sp(1.5));
        let hi = (i + sp(1.0)).min(f + sp(1.5));
        (hi - lo).max(sp(0.0)) / sp(3.0)
    };
    let xs = [0.0, 1.0, 2.0, 3.0].map(|i| bx + sp(i));
    let wx = xs.map(|x| w(x, fx));
    // The receiver's depth at texel (i, j) is (z + tx[i]) + ty[j].
    let ztx = xs.map(|x| z + gx * ((x + sp(0.5)) - fx));
    let mut sum = sp(0.0);
    for (j, row) in rows.iter().enumerate() {
        let y = by + sp(j as f32);
        let ty = gy * ((y + sp(0.5)) - fy);
        // Lane k of `stored[i]` is lane k's texel in column i: each four
        // lanes' rows turned into columns.
        let mut t = [Mat4::ZERO; 2];
        for (q, t) in t.iter_mut().enumerate().take(L::QUADS) {
            *t = Mat4::from_cols(row[4 * q], row[4 * q + 1], row[4 * q + 2], row[4 * q + 3])
                .transpose();
        }
        let stored = [0, 1, 2, 3].map(|i| L::from_quads(|q| t[q].col(i)));
        let term = |i: usize| L::select(stored[i].cmple(ztx[i] + ty), wx[i], sp(0.0));
        let along = (((sp(0.0) + term(0)) + term(1)) + term(2)) + term(3);
        sum = sum + w(y, fy) * along;
    }
    sum
}

/// Per row j of the PCF boxes whose first texels are (`bx`, `by`) and
/// lane k in `live`, the 4 texels the box reads (clamped to the map);
/// 0 elsewhere. Where nothing was drawn under a box, its texels are all
/// 0: not read (the same values; the reads would mostly miss the cache).
#[inline(always)]
fn box_rows<L: Lane>(m: &ShadowMap, (bx, by): (L, L), live: u32) -> [[Vec4; MAX_LANES]; 4] {
    let n = m.size as i32;
    let mut rows = [[Vec4::ZERO; MAX_LANES]; 4];
    for k in (0..L::WIDTH).filter(|k| live & (1 << k) != 0) {
        let (bx, by) = (bx.lane(k) as i32, by.lane(k) as i32);
        let cols = [0, 1, 2, 3].map(|i| (bx + i).clamp(0, n - 1) as usize);
        let (r0, r3) = (
            by.clamp(0, n - 1) as usize,
            (by + 3).clamp(0, n - 1) as usize,
        );
        if m.drawn.clear_box(cols[0], cols[3], r0, r3) {
            continue;
        }
        let inside = bx >= 0 && bx + 3 < n;
        for (j, row) in rows.iter_mut().enumerate() {
            let base = (by + j as i32).clamp(0, n - 1) as usize * n as usize;
            row[k] = if inside {
                let first = base + bx as usize;
                Vec4::from_slice(&m.depth[first..first + 4])
            } else {
                let d = |i: usize| m.depth[base + cols[i]];
                lanes4(d(0), d(1), d(2), d(3))
            };
        }
    }
    rows
}

/// `pcf` of one lane.
#[cfg(test)]
pub(super) fn pcf_one(m: &ShadowMap, fx: f32, fy: f32, z: f32, gx: f32, gy: f32) -> f32 {
    let at = Kernels {
        fx,
        fy,
        z,
        gx,
        gy,
        inside: 1,
    };
    pcf::<f32>(m, &at, 1)
}
