//! The filters that read a shadow map at placed lookups: "hard" (the one
//! texel under the point) and PCF (a 3x3-texel box, area-weighted, over
//! 4x4 texels, four lookups at a time), each comparing the stored depth
//! with the receiver's plane at the texel's center.

use glam::{Mat4, Vec4};

use super::{MAX_TAN, Placed4, ShadowMap};
use crate::simd::lanes4;

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

/// Where four lookups read a map (`kernels4`): per lane, texel
/// coordinates, the receiver plane's depth there and its slopes per
/// texel, capped; the lanes inside the map (bit k: lane k).
pub(super) struct Kernels4 {
    pub fx: Vec4,
    pub fy: Vec4,
    pub z: Vec4,
    pub gx: Vec4,
    pub gy: Vec4,
    pub inside: u32,
}

/// The kernels of four lookups placed in `m` (`Shadows::place4`): the
/// plane's slopes capped at `z_per_texel` times the slope cap (`f32`'s
/// max and min: a NaN cap, from extreme geometry, caps nothing), and the
/// lanes whose point lies inside the map (the others are lit).
#[inline]
pub(super) fn kernels4(m: &ShadowMap, p: &Placed4) -> Kernels4 {
    let cap = p.z_per_texel * Vec4::splat(MAX_TAN);
    // `f32::max`, `f32::min`: a NaN lane takes the other operand (the
    // sign of a zero may differ; it only enters sums compared with <=).
    let max = |a: Vec4, b: Vec4| Vec4::select(b.is_nan_mask(), a, a.max(b));
    let min = |a: Vec4, b: Vec4| Vec4::select(b.is_nan_mask(), a, a.min(b));
    let size = Vec4::splat(m.size as f32);
    let inside = p.fx.is_finite_mask()
        & p.fy.is_finite_mask()
        & p.fx.cmpge(Vec4::ZERO)
        & p.fy.cmpge(Vec4::ZERO)
        & p.fx.cmplt(size)
        & p.fy.cmplt(size);
    Kernels4 {
        fx: p.fx,
        fy: p.fy,
        z: p.z,
        gx: min(max(p.gx, -cap), cap),
        gy: min(max(p.gy, -cap), cap),
        inside: inside.bitmask(),
    }
}

/// The PCF kernel of the lanes in `live` (bit k: lane k of `at`), four
/// at a time; the other lanes' values are unspecified. Per lane: the lit
/// fraction of a 3x3-texel box around (`fx`, `fy`), each texel compared
/// with the receiver's plane (depth `z` at the point, `gx`, `gy` per
/// texel). The box covers 4x4 texels, the outer ones in part. Each lane
/// takes the same sums in the same order as it would alone: per row the
/// products wx[i] * (0 or 1) (= wx[i] or +0) summed along the row from 0
/// in column order, then the rows weighted and summed from 0 in row order.
#[inline]
pub(super) fn pcf4(m: &ShadowMap, at: &Kernels4, live: u32) -> Vec4 {
    let n = m.size as i32;
    let sp = Vec4::splat;
    let (fx, fy, z, gx, gy) = (at.fx, at.fy, at.z, at.gx, at.gy);
    // Per lane the box's first texel column and row: [f - 1.5, f + 1.5]
    // per axis, texel i covering [i, i + 1].
    let corner: [(i32, i32); 4] =
        std::array::from_fn(|k| (floor_i32(fx[k] - 1.5), floor_i32(fy[k] - 1.5)));
    // Per row j and lane k, the 4 texels the box reads (clamped to the
    // map). Where nothing was drawn under them they are all 0: not read
    // (the same values; the reads would mostly miss the cache).
    let mut rows = [[Vec4::ZERO; 4]; 4];
    for k in (0..4).filter(|k| live & (1 << k) != 0) {
        let (bx, by) = corner[k];
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
    // The corners as floats (exact: integers far below 2^24), so column
    // i of the box is bx + i per lane.
    let bx = Vec4::from_array(corner.map(|c| c.0 as f32));
    let by = Vec4::from_array(corner.map(|c| c.1 as f32));
    let w = |i: Vec4, f: Vec4| {
        let lo = i.max(f - sp(1.5));
        let hi = (i + sp(1.0)).min(f + sp(1.5));
        (hi - lo).max(Vec4::ZERO) / sp(3.0)
    };
    let xs = [0.0, 1.0, 2.0, 3.0].map(|i| bx + sp(i));
    let wx = xs.map(|x| w(x, fx));
    // The receiver's depth at texel (i, j) is (z + tx[i]) + ty[j].
    let ztx = xs.map(|x| z + gx * ((x + sp(0.5)) - fx));
    let mut sum = Vec4::ZERO;
    for (j, row) in rows.iter().enumerate() {
        let y = by + sp(j as f32);
        let ty = gy * ((y + sp(0.5)) - fy);
        // Lane k of `stored.x_axis` is lane k's texel in column 0.
        let stored = Mat4::from_cols(row[0], row[1], row[2], row[3]).transpose();
        let term = |i: usize, s: Vec4| Vec4::select(s.cmple(ztx[i] + ty), wx[i], Vec4::ZERO);
        let along = (((Vec4::ZERO + term(0, stored.x_axis)) + term(1, stored.y_axis))
            + term(2, stored.z_axis))
            + term(3, stored.w_axis);
        sum += w(y, fy) * along;
    }
    sum
}

/// `pcf4` of one lane.
#[cfg(test)]
pub(super) fn pcf(m: &ShadowMap, fx: f32, fy: f32, z: f32, gx: f32, gy: f32) -> f32 {
    let sp = Vec4::splat;
    let at = Kernels4 {
        fx: sp(fx),
        fy: sp(fy),
        z: sp(z),
        gx: sp(gx),
        gy: sp(gy),
        inside: 1,
    };
    pcf4(m, &at, 1)[0]
}

/// `x.floor() as i32` for x in [-2^31, 2^31) (the PCF box's corner, from
/// texel coordinates inside the map), without a call to libm's `floorf`
/// (x86-64's base set has no rounding instruction).
#[inline(always)]
pub(super) fn floor_i32(x: f32) -> i32 {
    let t = x as i32;
    if t as f32 > x { t - 1 } else { t }
}
