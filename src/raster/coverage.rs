//! Coverage: which pixel centers (or, with MSAA, which samples) of a tile a
//! triangle covers, with its depth there. The visibility pass runs the depth
//! test before any shading: a tile ends with the nearest triangle id and
//! depth per pixel (per sample), and every visible fragment is shaded
//! exactly once afterwards.

use super::bin::TileRect;
use super::setup::{Edge, SUBPIXEL, Tri};

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
/// run per row (a convex region), so a row ends at its first pixel past it.
#[inline]
fn walk(
    t: &Tri,
    e: &[Edge; 3],
    rect: TileRect,
    reach: [i64; 3],
    mut visit: impl FnMut(i32, i32, [i64; 3]),
) {
    let x0 = t.min_x.max(rect.x0);
    let x1 = t.max_x.min(rect.x1 - 1);
    let y0 = t.min_y.max(rect.y0);
    let y1 = t.max_y.min(rect.y1 - 1);
    if x0 > x1 || y0 > y1 {
        return;
    }
    let (x0l, y0l) = (x0 as i64, y0 as i64);
    let mut row = [0, 1, 2].map(|k| e[k].at(x0l, y0l) + e[k].bias);
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

pub const NO_TRIANGLE: u32 = u32::MAX;

/// Depth and triangle id per sample of one tile: `samples` consecutive
/// entries per pixel, pixels row-major.
pub struct Visibility {
    pub rect: TileRect,
    /// The sample offsets (one entry, (0, 0), without MSAA).
    pub pattern: &'static [(i8, i8)],
    pub depth: Vec<f32>,
    pub id: Vec<u32>,
}

impl Visibility {
    pub fn new(rect: TileRect, reverse_z: bool, pattern: &'static [(i8, i8)]) -> Visibility {
        let n = rect.width() * rect.height() * pattern.len();
        Visibility {
            rect,
            pattern,
            // Reverse-Z clears to 0 (far) and keeps greater; standard clears
            // to 1 and keeps less.
            depth: vec![if reverse_z { 0.0 } else { 1.0 }; n],
            id: vec![NO_TRIANGLE; n],
        }
    }

    pub fn samples(&self) -> usize {
        self.pattern.len()
    }

    /// Depth-tests triangle `id` into the tile. Equal depths keep the earlier
    /// triangle (submission order decides coplanar ties, deterministically).
    #[inline]
    pub fn draw<const REVERSE_Z: bool>(&mut self, t: &Tri, id: u32) {
        self.draw_if::<REVERSE_Z>(t, id, |_, _, _| true);
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
        mut keep: impl FnMut(i32, i32, (i8, i8)) -> bool,
    ) {
        let rect = self.rect;
        let stride = rect.width();
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

/// Whether depth `z` is in front of the stored depth `stored` (z outside
/// [0,1] only comes from rounding at clipped edges and never passes).
#[inline]
pub fn in_front(z: f32, stored: f32, reverse_z: bool) -> bool {
    (0.0..=1.0).contains(&z) && if reverse_z { z > stored } else { z < stored }
}
