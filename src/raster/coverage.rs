//! Coverage: which pixel centers (or, with MSAA, which samples) of a tile a
//! triangle covers, with its depth there. The visibility pass runs the depth
//! test before any shading: a tile ends with the nearest triangle id and
//! depth per pixel (per sample), and every visible fragment is shaded
//! exactly once afterwards.

use std::cell::RefCell;

use glam::{BVec4A, Vec4};

use super::bin::TileRect;
use super::setup::{Edge, SUBPIXEL, Tri};
use crate::simd::{RAMP_LIMIT, exact4, ramp4};

/// The standard Direct3D sample positions for 1, 2, 4, 8 and 16 samples:
/// offsets from the pixel center in 1/16 pixel, x right and y down (the
/// D3D11_STANDARD_MULTISAMPLE_PATTERN, which Vulkan's standard locations
/// repeat). None for other counts.
pub fn sample_pattern(samples: u32) -> Option<&'static [(i8, i8)]> {
    const P1: [(i8, i8); 1] = [(0, 0)];
    const P2: [(i8, i8); 2] = [(4, 4), (-4, -4)];
    const P4: [(i8, i8); 4] = [(-2, -6), (6, -2), (-6, 2), (2, 6)];
    const P8: [(i8, i8); 8] = [
        (1, -3),
        (-1, 3),
        (5, 1),
        (-3, -5),
        (-5, 5),
        (-7, -1),
        (3, 7),
        (7, -7),
    ];
    const P16: [(i8, i8); 16] = [
        (1, 1),
        (-1, -3),
        (-3, 2),
        (4, -1),
        (-5, -2),
        (2, 5),
        (5, 3),
        (3, -5),
        (-2, 6),
        (0, -7),
        (-4, -6),
        (-6, 4),
        (-8, 0),
        (7, -4),
        (6, 7),
        (-7, -8),
    ];
    match samples {
        1 => Some(&P1),
        2 => Some(&P2),
        4 => Some(&P4),
        8 => Some(&P8),
        16 => Some(&P16),
        _ => None,
    }
}

/// Most samples per pixel.
pub const MAX_SAMPLES: usize = 16;

/// Depth (z/w) across a triangle as a function of its biased edge values.
struct DepthPlane {
    z0: f32,
    dz1: f32,
    dz2: f32,
    bias1: i64,
    bias2: i64,
}

impl DepthPlane {
    fn new(t: &Tri, e: &[Edge; 3]) -> DepthPlane {
        let inv_area = 1.0 / t.area2 as f64;
        DepthPlane {
            z0: t.z[0],
            dz1: ((t.z[1] - t.z[0]) as f64 * inv_area) as f32,
            dz2: ((t.z[2] - t.z[0]) as f64 * inv_area) as f32,
            bias1: e[1].bias,
            bias2: e[2].bias,
        }
    }

    /// At biased edge values `w1`, `w2` (the bias is only for the fill rule).
    #[inline]
    fn at(&self, w1: i64, w2: i64) -> f32 {
        self.z0 + (w1 - self.bias1) as f32 * self.dz1 + (w2 - self.bias2) as f32 * self.dz2
    }
}

/// Walks the pixels of `rect` within `t`'s bounds, row by row, calling
/// `visit(px, py, w)` where every biased edge value `w[k]` plus `reach[k]`
/// is >= 0 (`reach` 0: the pixel center is inside). Such pixels form one
/// run per row (a convex region).
#[inline]
fn walk(
    t: &Tri,
    e: &[Edge; 3],
    rect: TileRect,
    reach: [i64; 3],
    visit: impl FnMut(i32, i32, [i64; 3]),
) {
    if t.max_x.min(rect.x1 - 1) - t.min_x.max(rect.x0) >= SPAN_WIDTH {
        walk_runs(t, e, rect, reach, visit);
    } else {
        walk_tested(t, e, rect, reach, visit);
    }
}

/// The pixel bounds of `t` within `rect` (x0, x1, y0, y1, inclusive) and
/// the biased edge values at (x0, y0); None when they do not meet.
#[inline]
fn start(t: &Tri, e: &[Edge; 3], rect: TileRect) -> Option<(i32, i32, i32, i32, [i64; 3])> {
    let x0 = t.min_x.max(rect.x0);
    let x1 = t.max_x.min(rect.x1 - 1);
    let y0 = t.min_y.max(rect.y0);
    let y1 = t.max_y.min(rect.y1 - 1);
    if x0 > x1 || y0 > y1 {
        return None;
    }
    let row = [0, 1, 2].map(|k| e[k].at(x0 as i64, y0 as i64) + e[k].bias);
    Some((x0, x1, y0, y1, row))
}

/// `walk` testing every pixel; a row ends at its first pixel past the run.
#[inline]
fn walk_tested(
    t: &Tri,
    e: &[Edge; 3],
    rect: TileRect,
    reach: [i64; 3],
    mut visit: impl FnMut(i32, i32, [i64; 3]),
) {
    let Some((x0, x1, y0, y1, mut row)) = start(t, e, rect) else {
        return;
    };
    for py in y0..=y1 {
        let mut w = row;
        let mut inside_seen = false;
        for px in x0..=x1 {
            if (w[0] + reach[0]) | (w[1] + reach[1]) | (w[2] + reach[2]) >= 0 {
                inside_seen = true;
                visit(px, py, w);
            } else if inside_seen {
                break;
            }
            w[0] += e[0].a;
            w[1] += e[1].a;
            w[2] += e[2].a;
        }
        row[0] += e[0].b;
        row[1] += e[1].b;
        row[2] += e[2].b;
    }
}

/// `walk` for wide triangles: each row's run comes from the edge
/// equations (three divisions) instead of a test per pixel; the same
/// pixels, in the same order, with the same edge values.
#[inline]
fn walk_runs(
    t: &Tri,
    e: &[Edge; 3],
    rect: TileRect,
    reach: [i64; 3],
    mut visit: impl FnMut(i32, i32, [i64; 3]),
) {
    let Some((x0, x1, y0, y1, mut row)) = start(t, e, rect) else {
        return;
    };
    let x0l = x0 as i64;
    for py in y0..=y1 {
        if let Some((lo, hi)) = span(e, row, reach, x0l, x1 as i64) {
            let d = lo - x0l;
            let mut w = [0, 1, 2].map(|k| row[k] + e[k].a * d);
            for px in lo as i32..=hi as i32 {
                visit(px, py, w);
                w[0] += e[0].a;
                w[1] += e[1].a;
                w[2] += e[2].a;
            }
        }
        row[0] += e[0].b;
        row[1] += e[1].b;
        row[2] += e[2].b;
    }
}

/// Bounding-box width (pixels) from which `walk` computes runs per row.
const SPAN_WIDTH: i32 = 8;

/// The pixels x0..=x1 of a row where every `w[k] + reach[k] >= 0`, with
/// `row[k]` the biased edge values at x0 (each grows by `e[k].a` a pixel):
/// None when there are none.
#[inline]
fn span(e: &[Edge; 3], row: [i64; 3], reach: [i64; 3], x0: i64, x1: i64) -> Option<(i64, i64)> {
    let (mut lo, mut hi) = (x0, x1);
    for k in 0..3 {
        let v = row[k] + reach[k];
        let a = e[k].a;
        if a > 0 {
            // v + a d >= 0 from d = ceil(-v / a) on.
            if v < 0 {
                lo = lo.max(x0 + (-v + a - 1) / a);
            }
        } else if a < 0 {
            // v + a d >= 0 up to d = floor(v / -a).
            if v < 0 {
                return None;
            }
            hi = hi.min(x0 + v / -a);
        } else if v < 0 {
            return None;
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Calls `visit(px, py, mask, z)` for every pixel of `rect` where `t`
/// covers at least one sample of `pattern` (top-left rule at each sample):
/// bit s of `mask` is set when sample s is covered, and `z[s]` is the
/// depth there. `t` must come from a multisampling setup (its pixel bounds
/// reach half a pixel further).
#[inline]
pub fn raster_samples<F: FnMut(i32, i32, u32, &[f32; MAX_SAMPLES])>(
    t: &Tri,
    rect: TileRect,
    pattern: &[(i8, i8)],
    mut visit: F,
) {
    let n = pattern.len().min(MAX_SAMPLES);
    let e = t.edges();
    // Edge-function offsets of each sample from the pixel center: exact,
    // as a and b are multiples of SUBPIXEL (a 1/16 pixel step is a/16).
    debug_assert!(e.iter().all(|e| e.a % SUBPIXEL == 0 && e.b % SUBPIXEL == 0));
    let mut off = [[0i64; MAX_SAMPLES]; 3];
    let mut reach = [i64::MIN; 3];
    for k in 0..3 {
        for (s, &(ox, oy)) in pattern.iter().take(n).enumerate() {
            let o = (e[k].a * ox as i64 + e[k].b * oy as i64) / 16;
            off[k][s] = o;
            reach[k] = reach[k].max(o);
        }
    }
    let plane = DepthPlane::new(t, &e);
    let mut z = [0f32; MAX_SAMPLES];
    // Pixels where some sample may be inside every edge.
    walk(t, &e, rect, reach, |px, py, w| {
        let mut mask = 0u32;
        for s in 0..n {
            let (a, b, c) = (w[0] + off[0][s], w[1] + off[1][s], w[2] + off[2][s]);
            if (a | b | c) >= 0 {
                mask |= 1 << s;
                z[s] = plane.at(b, c);
            }
        }
        if mask != 0 {
            visit(px, py, mask, &z);
        }
    });
}

/// `raster_samples` for patterns of `G` groups of four samples (4, 8 or 16
/// samples), four side by side: `visit(px, py, g, mask, z)` for each group `g` of four
/// (samples 4g..4g + 4) that covers some sample, with their depths as
/// lanes (bit for bit `raster_samples`' where the mask has them; the others
/// unspecified).
#[inline]
pub fn raster_samples4<const G: usize, F: FnMut(i32, i32, usize, u32, Vec4)>(
    t: &Tri,
    rect: TileRect,
    pattern: &[(i8, i8)],
    mut visit: F,
) {
    let groups = G;
    debug_assert_eq!(groups * 4, pattern.len(), "{G} groups of four samples");
    let e = t.edges();
    debug_assert!(e.iter().all(|e| e.a % SUBPIXEL == 0 && e.b % SUBPIXEL == 0));
    // Per group and edge, the samples' edge-function offsets from the
    // pixel center.
    let mut off = [[[0i64; 4]; 3]; G];
    for (g, o) in off.iter_mut().enumerate().take(groups) {
        for (k, ok) in o.iter_mut().enumerate() {
            for (s, v) in ok.iter_mut().enumerate() {
                let (ox, oy) = pattern[4 * g + s];
                *v = (e[k].a * ox as i64 + e[k].b * oy as i64) / 16;
            }
        }
    }
    let reach: [i64; 3] =
        std::array::from_fn(|k| off[..groups].iter().flat_map(|o| o[k]).max().unwrap_or(0));
    let plane = DepthPlane::new(t, &e);
    let (z0, dz1, dz2) = (
        Vec4::splat(plane.z0),
        Vec4::splat(plane.dz1),
        Vec4::splat(plane.dz2),
    );
    // Below it, a pixel center's edge values plus a sample's offset (at
    // most half a pixel's step) less the bias stay within `RAMP_LIMIT`.
    const CENTER_LIMIT: i64 = RAMP_LIMIT / 2;
    let (b1, b2) = (plane.bias1, plane.bias2);
    let small = off[..groups]
        .iter()
        .flatten()
        .flatten()
        .chain(&[b1, b2])
        .all(|v| v.abs() < CENTER_LIMIT);
    walk(t, &e, rect, reach, |px, py, w| {
        let exact = small && w[1].abs() < CENTER_LIMIT && w[2].abs() < CENTER_LIMIT;
        for (g, off) in off.iter().enumerate().take(groups) {
            let at = |k: usize| off[k].map(|o| w[k] + o);
            let (a, b, c) = (at(0), at(1), at(2));
            let mut mask = 0u32;
            for s in 0..4 {
                mask |= (((a[s] | b[s] | c[s]) >= 0) as u32) << s;
            }
            if mask == 0 {
                continue;
            }
            let z = if exact {
                // `plane.at`, lane by lane, in its order.
                z0 + exact4(b.map(|v| v - b1)) * dz1 + exact4(c.map(|v| v - b2)) * dz2
            } else {
                Vec4::from_array(std::array::from_fn(|s| plane.at(b[s], c[s])))
            };
            visit(px, py, g, mask, z);
        }
    });
}

/// Calls `visit(px, py, z)` for every pixel center inside `rect` covered by
/// `t` (top-left rule), row by row.
#[inline]
pub fn raster_triangle<F: FnMut(i32, i32, f32)>(t: &Tri, rect: TileRect, mut visit: F) {
    let e = t.edges();
    let plane = DepthPlane::new(t, &e);
    walk(t, &e, rect, [0; 3], |px, py, w| {
        visit(px, py, plane.at(w[1], w[2]))
    });
}

/// `raster_triangle` into a reverse-Z depth map `d` (rows of `stride`
/// texels from `rect`'s top-left) that keeps the greatest depth up to 1
/// (`z <= 1 && z > d`): the same texels and depths, four texels of a run
/// at a time where its edge values allow (`simd::ramp4`).
pub fn raster_depth_max(t: &Tri, rect: TileRect, d: &mut [f32], stride: usize) {
    let e = t.edges();
    let plane = DepthPlane::new(t, &e);
    // Written either way, a select and not a branch: the processor
    // mispredicts a branch along every overlap.
    let keep = |d: &mut f32, z: f32| {
        let m = 0u32.wrapping_sub((z <= 1.0 && z > *d) as u32);
        *d = f32::from_bits(z.to_bits() & m | d.to_bits() & !m);
    };
    let at = |px: i32, py: i32| (py - rect.y0) as usize * stride + (px - rect.x0) as usize;
    if t.max_x.min(rect.x1 - 1) - t.min_x.max(rect.x0) < SPAN_WIDTH {
        walk_tested(t, &e, rect, [0; 3], |px, py, w| {
            keep(&mut d[at(px, py)], plane.at(w[1], w[2]))
        });
        return;
    }
    let Some((x0, x1, y0, y1, mut row)) = start(t, &e, rect) else {
        return;
    };
    let (x0l, a1, a2) = (x0 as i64, e[1].a, e[2].a);
    let (z0, dz1, dz2) = (
        Vec4::splat(plane.z0),
        Vec4::splat(plane.dz1),
        Vec4::splat(plane.dz2),
    );
    for py in y0..=y1 {
        if let Some((lo, hi)) = span(&e, row, [0; 3], x0l, x1 as i64) {
            let n = (hi - lo + 1) as usize;
            // Biased edge values at the run's first texel (`walk_runs`).
            let w1 = row[1] + a1 * (lo - x0l);
            let w2 = row[2] + a2 * (lo - x0l);
            let line = &mut d[at(lo as i32, py)..][..n];
            let last = n as i64 - 1;
            let (u1, u2) = (w1 - plane.bias1, w2 - plane.bias2);
            let fits = [u1, u1 + a1 * last, u2, u2 + a2 * last]
                .iter()
                .all(|v| v.abs() < RAMP_LIMIT);
            let mut k = 0;
            if fits {
                while k + 4 <= n {
                    let (k1, k2) = (u1 + a1 * k as i64, u2 + a2 * k as i64);
                    // `plane.at`: z0 + t1 * dz1 + t2 * dz2, lane by lane.
                    let z = z0 + ramp4(k1, a1) * dz1 + ramp4(k2, a2) * dz2;
                    let old = Vec4::from_slice(&line[k..k + 4]);
                    let m = z.cmple(Vec4::ONE) & z.cmpgt(old);
                    Vec4::select(m, z, old).write_to_slice(&mut line[k..k + 4]);
                    k += 4;
                }
            }
            for (j, dk) in line.iter_mut().enumerate().skip(k) {
                let j = j as i64;
                keep(dk, plane.at(w1 + a1 * j, w2 + a2 * j));
            }
        }
        row[0] += e[0].b;
        row[1] += e[1].b;
        row[2] += e[2].b;
    }
}

/// The depth test of `in_front` for triangle `id` over every sample of
/// `rect` it covers, `G` groups of four samples per pixel
/// (`raster_samples4`), four side by side, into a tile's `(depth, ids)`.
#[inline]
fn test_groups<const REVERSE_Z: bool, const G: usize>(
    t: &Tri,
    rect: TileRect,
    pattern: &[(i8, i8)],
    id: u32,
    (depth, ids): (&mut [f32], &mut [u32]),
) {
    let stride = rect.width();
    raster_samples4::<G, _>(t, rect, pattern, |px, py, g, mask, z| {
        let pixel = (py - rect.y0) as usize * stride + (px - rect.x0) as usize;
        let base = pixel * 4 * G + 4 * g;
        let old = Vec4::from_slice(&depth[base..base + 4]);
        let front = if REVERSE_Z {
            z.cmpgt(old)
        } else {
            z.cmplt(old)
        };
        let pass = (z.cmpge(Vec4::ZERO) & z.cmple(Vec4::ONE) & front).bitmask() & mask;
        if pass == 0 {
            return;
        }
        // The four samples written at once: a blend of bits (no float
        // arithmetic; the ids pass through as bit patterns).
        let m = BVec4A::new(pass & 1 != 0, pass & 2 != 0, pass & 4 != 0, pass & 8 != 0);
        Vec4::select(m, z, old).write_to_slice(&mut depth[base..base + 4]);
        let slot = &mut ids[base..base + 4];
        let old_ids = Vec4::from_array([slot[0], slot[1], slot[2], slot[3]].map(f32::from_bits));
        let new = Vec4::select(m, Vec4::splat(f32::from_bits(id)), old_ids);
        slot.copy_from_slice(&new.to_array().map(f32::to_bits));
    });
}

pub const NO_TRIANGLE: u32 = u32::MAX;

/// Depth and triangle id per sample of one tile: `samples` consecutive
/// entries per pixel, pixels row-major.
///
/// The buffers are reused: a dropped tile clears the columns it drew into
/// and leaves its buffers to the next tile of its thread, so a tile costs
/// no allocation and no clear of the columns no triangle reaches.
pub struct Visibility {
    pub rect: TileRect,
    /// The sample offsets (one entry, (0, 0), without MSAA).
    pub pattern: &'static [(i8, i8)],
    depth: Vec<f32>,
    id: Vec<u32>,
    /// The columns (from `rect.x0`, end exclusive) drawn into so far:
    /// every sample outside them is clear.
    drawn: (usize, usize),
    /// The depth a clear sample holds.
    clear: f32,
}

/// A dropped tile's cleared buffers: depth, ids and the clear depth.
type Spare = (Vec<f32>, Vec<u32>, f32);

thread_local! {
    static SPARE: RefCell<Vec<Spare>> = const { RefCell::new(Vec::new()) };
}

/// At most this many spare buffer pairs per thread.
const SPARES: usize = 2;

impl Visibility {
    pub fn new(rect: TileRect, reverse_z: bool, pattern: &'static [(i8, i8)]) -> Visibility {
        let n = rect.width() * rect.height() * pattern.len();
        // Reverse-Z clears to 0 (far) and keeps greater; standard clears
        // to 1 and keeps less.
        let clear = if reverse_z { 0.0 } else { 1.0 };
        let spare = SPARE.with(|s| {
            let mut s = s.try_borrow_mut().ok()?;
            let k = s
                .iter()
                .position(|e| e.0.len() == n && e.1.len() == n && e.2 == clear)?;
            Some(s.swap_remove(k))
        });
        let (depth, id) = match spare {
            Some((depth, id, _)) => (depth, id),
            None => (vec![clear; n], vec![NO_TRIANGLE; n]),
        };
        Visibility {
            rect,
            pattern,
            depth,
            id,
            drawn: (usize::MAX, 0),
            clear,
        }
    }

    /// A tile with the given samples (for tests of what reads tiles).
    #[cfg(test)]
    pub fn from_parts(
        rect: TileRect,
        pattern: &'static [(i8, i8)],
        depth: Vec<f32>,
        id: Vec<u32>,
    ) -> Visibility {
        let n = rect.width() * rect.height() * pattern.len();
        assert!(depth.len() == n && id.len() == n);
        Visibility {
            rect,
            pattern,
            depth,
            id,
            drawn: (0, rect.width()),
            clear: 1.0,
        }
    }

    /// Depth per sample (the clear depth where nothing was drawn).
    #[inline(always)]
    pub fn depth(&self) -> &[f32] {
        &self.depth
    }

    /// Triangle id per sample (`NO_TRIANGLE` where nothing was drawn).
    #[inline(always)]
    pub fn id(&self) -> &[u32] {
        &self.id
    }

    /// The columns (from `rect.x0`, end exclusive) where some sample may
    /// hold a triangle; outside them every sample is clear. Empty (0, 0)
    /// when nothing was drawn.
    #[inline]
    pub fn drawn_columns(&self) -> (usize, usize) {
        if self.drawn.0 < self.drawn.1 {
            self.drawn
        } else {
            (0, 0)
        }
    }

    pub fn samples(&self) -> usize {
        self.pattern.len()
    }

    /// Depth-tests triangle `id` into the tile. Equal depths keep the earlier
    /// triangle (submission order decides coplanar ties, deterministically).
    #[inline]
    pub fn draw<const REVERSE_Z: bool>(&mut self, t: &Tri, id: u32) {
        self.tested::<REVERSE_Z, true>(t, id, |_, _, _| true);
    }

    /// As `draw`, for samples that also pass `keep(px, py, offset)` (the
    /// alpha test of cutout materials, at the sample: `offset` from the
    /// pixel center in 1/16 pixel, (0, 0) without MSAA), asked only where
    /// the depth test passes. With MSAA, cutout edges are thereby resolved
    /// by coverage like triangle edges.
    #[inline]
    pub fn draw_if<const REVERSE_Z: bool>(
        &mut self,
        t: &Tri,
        id: u32,
        keep: impl FnMut(i32, i32, (i8, i8)) -> bool,
    ) {
        self.tested::<REVERSE_Z, false>(t, id, keep);
    }

    /// `draw_if`; `TESTS_ALL`: `keep` passes every sample (`draw`), which
    /// lets four samples be tested side by side.
    #[inline]
    fn tested<const REVERSE_Z: bool, const TESTS_ALL: bool>(
        &mut self,
        t: &Tri,
        id: u32,
        mut keep: impl FnMut(i32, i32, (i8, i8)) -> bool,
    ) {
        let rect = self.rect;
        let stride = rect.width();
        // The raster visits only the triangle's pixel bounds in the tile.
        let (a, b) = (t.min_x.max(rect.x0), t.max_x.min(rect.x1 - 1));
        if a > b {
            return;
        }
        let (a, b) = ((a - rect.x0) as usize, (b - rect.x0) as usize + 1);
        self.drawn = (self.drawn.0.min(a), self.drawn.1.max(b));
        let (depth, ids) = (&mut self.depth, &mut self.id);
        let n = self.pattern.len();
        if n == 1 {
            raster_triangle(t, rect, |px, py, z| {
                let i = (py - rect.y0) as usize * stride + (px - rect.x0) as usize;
                if in_front(z, depth[i], REVERSE_Z) && keep(px, py, (0, 0)) {
                    depth[i] = z;
                    ids[i] = id;
                }
            });
            return;
        }
        let pattern = self.pattern;
        if TESTS_ALL {
            // Four samples side by side.
            let buffers = (&mut depth[..], &mut ids[..]);
            match n {
                4 => return test_groups::<REVERSE_Z, 1>(t, rect, pattern, id, buffers),
                8 => return test_groups::<REVERSE_Z, 2>(t, rect, pattern, id, buffers),
                16 => return test_groups::<REVERSE_Z, 4>(t, rect, pattern, id, buffers),
                _ => {}
            }
        }
        raster_samples(t, rect, pattern, |px, py, mask, z| {
            let base = ((py - rect.y0) as usize * stride + (px - rect.x0) as usize) * n;
            for (s, &zs) in z.iter().enumerate().take(n) {
                let i = base + s;
                if mask & (1 << s) != 0
                    && in_front(zs, depth[i], REVERSE_Z)
                    && keep(px, py, pattern[s])
                {
                    depth[i] = zs;
                    ids[i] = id;
                }
            }
        });
    }
}

impl Drop for Visibility {
    /// Clears the columns drawn into and leaves the buffers to the next
    /// tile of this thread.
    fn drop(&mut self) {
        let (lo, hi) = self.drawn_columns();
        let n = self.pattern.len();
        let stride = self.rect.width() * n;
        if lo < hi && stride > 0 {
            for (d, i) in self
                .depth
                .chunks_exact_mut(stride)
                .zip(self.id.chunks_exact_mut(stride))
            {
                d[lo * n..hi * n].fill(self.clear);
                i[lo * n..hi * n].fill(NO_TRIANGLE);
            }
        }
        let entry = (
            std::mem::take(&mut self.depth),
            std::mem::take(&mut self.id),
            self.clear,
        );
        SPARE.with(|s| {
            if let Ok(mut s) = s.try_borrow_mut()
                && s.len() < SPARES
            {
                s.push(entry);
            }
        });
    }
}

/// Whether depth `z` is in front of the stored depth `stored` (z outside
/// \[0, 1\] only comes from rounding at clipped edges and never passes).
#[inline]
pub fn in_front(z: f32, stored: f32, reverse_z: bool) -> bool {
    (0.0..=1.0).contains(&z) && if reverse_z { z > stored } else { z < stored }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::CullMode;
    use crate::raster::clip::ClipVertex;
    use crate::raster::setup::{Viewport, setup};
    use glam::{Vec3, Vec4};

    /// A viewport of `size` (multisampled or not) and the tile
    /// `[x0, y0, x1, y1]` of it.
    fn frame_and_tile(
        size: (u32, u32),
        msaa: bool,
        [x0, y0, x1, y1]: [i32; 4],
    ) -> (Viewport, TileRect) {
        let vp = Viewport {
            width: size.0,
            height: size.1,
            msaa,
        };
        (vp, TileRect { x0, y0, x1, y1 })
    }

    #[test]
    fn runs_visit_the_pixels_that_tests_visit() {
        // Pseudo-random triangles of every size and slope, whole and cut
        // by the tile, with and without MSAA reach.
        let mut rnd = crate::testing::xorshift(0x2545_f491);
        let (vp, rect) = frame_and_tile((128, 96), true, [16, 8, 112, 80]);
        let mut checked = 0;
        for i in 0..3000 {
            let scale = [0.05f32, 0.3, 1.5][i % 3];
            let (cx, cy) = (rnd() * 2.0 - 1.0, rnd() * 2.0 - 1.0);
            let v = |dx: f32, dy: f32| ClipVertex {
                pos: Vec4::new(cx + dx * scale, cy + dy * scale, 0.5, 1.0),
                bary: Vec3::ZERO,
            };
            let p = [(); 3].map(|_| (rnd() - 0.5, rnd() - 0.5));
            let Some(t) = setup(
                [v(p[0].0, p[0].1), v(p[1].0, p[1].1), v(p[2].0, p[2].1)],
                vp,
                CullMode::None,
                0,
                0,
            ) else {
                continue;
            };
            let e = t.edges();
            for reach in [[0i64; 3], [e[0].a.abs(), e[1].b.abs(), 3]] {
                let (mut a, mut b) = (Vec::new(), Vec::new());
                walk_tested(&t, &e, rect, reach, |x, y, w| a.push((x, y, w)));
                walk_runs(&t, &e, rect, reach, |x, y, w| b.push((x, y, w)));
                assert_eq!(a, b, "triangle {i}");
                checked += a.len();
            }
        }
        assert!(checked > 100_000, "{checked}");
    }

    /// A reused tile is a fresh one: drawing random triangles into tiles
    /// taken one after the other on one thread (whose buffers come back
    /// cleared only in the columns drawn) gives what fresh buffers give,
    /// and nothing is drawn outside `drawn_columns`.
    #[test]
    fn reused_tiles_equal_fresh_ones() {
        let mut rnd = crate::testing::xorshift(0x51_7cc1_b727_220a);
        const FOUR: &[(i8, i8)] = &[(-2, -6), (6, -2), (-6, 2), (2, 6)];
        for (round, pattern) in [&[(0i8, 0i8)][..], FOUR]
            .iter()
            .cycle()
            .take(40)
            .enumerate()
        {
            let (vp, rect) = frame_and_tile((96, 64), pattern.len() > 1, [0, 16, 96, 32]);
            let reverse = round % 3 == 0;
            let mut tris = Vec::new();
            for _ in 0..(round % 5) {
                let (cx, cy) = (rnd() * 2.0 - 1.0, rnd() - 0.5);
                let s = 0.05 + rnd() * 0.4;
                let p = [(); 3].map(|_| (rnd() - 0.5, rnd() - 0.5, rnd()));
                let v = |(dx, dy, z): (f32, f32, f32)| ClipVertex {
                    pos: Vec4::new(cx + dx * s, cy + dy * s, z, 1.0),
                    bary: Vec3::ZERO,
                };
                let v3 = [v(p[0]), v(p[1]), v(p[2])];
                tris.extend(setup(v3, vp, CullMode::None, 0, 0));
            }
            let draw = |vis: &mut Visibility| {
                for (i, t) in tris.iter().enumerate() {
                    if reverse {
                        vis.draw::<true>(t, i as u32);
                    } else {
                        vis.draw::<false>(t, i as u32);
                    }
                }
            };
            let mut reused = Visibility::new(rect, reverse, pattern);
            draw(&mut reused);
            let n = rect.width() * rect.height() * pattern.len();
            let clear = if reverse { 0.0 } else { 1.0 };
            let mut fresh = Visibility {
                rect,
                pattern,
                depth: vec![clear; n],
                id: vec![NO_TRIANGLE; n],
                drawn: (usize::MAX, 0),
                clear,
            };
            draw(&mut fresh);
            assert_eq!(reused.id(), fresh.id(), "round {round}");
            let bits = |d: &[f32]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(reused.depth()), bits(fresh.depth()), "round {round}");
            let (lo, hi) = reused.drawn_columns();
            let k = pattern.len();
            for (i, &id) in reused.id().iter().enumerate() {
                let x = i / k % rect.width();
                assert!(id == NO_TRIANGLE || (lo..hi).contains(&x), "round {round}");
            }
        }
    }

    /// Four samples side by side (`draw` at 4, 8 and 16 samples) test depth as
    /// one sample at a time does (`draw_if` passing every sample): the same
    /// ids and depth bits, over triangles crossing the near and far depths,
    /// overlapping each other, and drawn twice.
    #[test]
    fn four_samples_at_once_equal_one_at_a_time() {
        let mut rnd = crate::testing::xorshift(0x2f0b_39c1_77e4_d015);
        let (vp, rect) = frame_and_tile((96, 64), true, [0, 16, 96, 32]);
        let mut covered = 0;
        for round in 0..180 {
            let reverse = round % 2 == 0;
            let pattern = sample_pattern([4, 8, 16][round % 3]).unwrap_or(&[]);
            let mut tris = Vec::new();
            for _ in 0..(1 + round % 7) {
                let (cx, cy) = (rnd() * 2.0 - 1.0, rnd() - 0.5);
                let s = [0.02, 0.2, 1.0][round / 3 % 3] * (0.5 + rnd());
                let p = [(); 3].map(|_| (rnd() - 0.5, rnd() - 0.5, rnd() * 1.4 - 0.2));
                let v = |(dx, dy, z): (f32, f32, f32)| ClipVertex {
                    pos: Vec4::new(cx + dx * s, cy + dy * s, z, 1.0),
                    bary: Vec3::ZERO,
                };
                tris.extend(setup([v(p[0]), v(p[1]), v(p[2])], vp, CullMode::None, 0, 0));
            }
            // Coplanar twins: equal depths keep the earlier triangle.
            if let Some(t) = tris.first() {
                tris.push(*t);
            }
            let (mut four, mut one) = (
                Visibility::new(rect, reverse, pattern),
                Visibility::new(rect, reverse, pattern),
            );
            for (i, t) in tris.iter().enumerate() {
                if reverse {
                    four.draw::<true>(t, i as u32);
                    one.draw_if::<true>(t, i as u32, |_, _, _| true);
                } else {
                    four.draw::<false>(t, i as u32);
                    one.draw_if::<false>(t, i as u32, |_, _, _| true);
                }
            }
            assert_eq!(four.id(), one.id(), "round {round}");
            let bits = |d: &[f32]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(four.depth()), bits(one.depth()), "round {round}");
            covered += four.id().iter().filter(|&&id| id != NO_TRIANGLE).count();
        }
        assert!(covered > 40_000, "{covered}");
    }

    #[test]
    fn depth_max_runs_equal_texel_by_texel() {
        // Triangles of every size, some crossing the near and far
        // depths, into a map seeded with depths.
        let mut rnd = crate::testing::xorshift(0x9e37_79b9_7f4a_7c15);
        let (vp, rect) = frame_and_tile((300, 200), false, [20, 10, 280, 150]);
        let stride = rect.width();
        let start: Vec<f32> = (0..stride * rect.height()).map(|_| rnd() * 0.5).collect();
        let (mut a, mut b) = (start.clone(), start);
        let mut drawn = 0;
        for i in 0..4000 {
            let scale = [0.02f32, 0.2, 1.0, 6.0][i % 4];
            let (cx, cy) = (rnd() * 2.0 - 1.0, rnd() * 2.0 - 1.0);
            let p = [(); 3].map(|_| (rnd() - 0.5, rnd() - 0.5, rnd() * 1.4 - 0.2));
            let v = |(dx, dy, z): (f32, f32, f32)| ClipVertex {
                pos: Vec4::new(cx + dx * scale, cy + dy * scale, z, 1.0),
                bary: Vec3::ZERO,
            };
            let Some(t) = setup([v(p[0]), v(p[1]), v(p[2])], vp, CullMode::None, 0, 0) else {
                continue;
            };
            raster_triangle(&t, rect, |px, py, z| {
                let k = (py - rect.y0) as usize * stride + (px - rect.x0) as usize;
                if z <= 1.0 && z > a[k] {
                    a[k] = z;
                }
                drawn += 1;
            });
            raster_depth_max(&t, rect, &mut b, stride);
            for (k, (x, y)) in a.iter().zip(&b).enumerate() {
                assert_eq!(x.to_bits(), y.to_bits(), "triangle {i}, texel {k}");
            }
        }
        assert!(drawn > 1_000_000, "{drawn}");
    }
}
