//! Triangle setup: clip space -> viewport in 17.15 fixed point, culling, and
//! the edge functions with the top-left fill rule.
//!
//! Screen space has its origin at the top-left corner and y down; pixel
//! centers sit at +0.5. After setup every triangle has positive signed area
//! in this space (vertices swapped if needed), so a pixel center is inside
//! when all three edge functions are >= 0, and the top-left rule turns that
//! into > 0 for edges that are neither top nor left: a pixel center on an
//! edge shared by two triangles belongs to exactly one of them.

use glam::Vec3;

use super::CullMode;
use super::clip::ClipVertex;

/// 1/32768 pixel. Coordinates stay within 2^14 pixels of the viewport center
/// (guard band), so each edge-function product stays below 2^60: no
/// overflow in i64, and vertex snapping moves depth by ~1e-7 relative rather
/// than the 1e-4 that 8 bits give at grazing angles.
pub const SUBPIXEL_BITS: u32 = 15;
pub const SUBPIXEL: i64 = 1 << SUBPIXEL_BITS;
const HALF: i64 = SUBPIXEL / 2;

/// A triangle ready to rasterize.
#[derive(Debug, Clone, Copy)]
pub struct Tri {
    /// Fixed-point screen coordinates (1/2^15 pixel), positive-area order.
    pub x: [i32; 3],
    pub y: [i32; 3],
    /// Inclusive pixel bounds, clamped to the viewport.
    pub min_x: i32,
    pub min_y: i32,
    pub max_x: i32,
    pub max_y: i32,
    /// Depth (z/w) at the vertices.
    pub z: [f32; 3],
    /// 1/w at the vertices (w = distance along the view axis in perspective).
    pub inv_w: [f32; 3],
    /// Barycentric coordinates of each vertex in the original triangle.
    pub bary: [Vec3; 3],
    /// Twice the signed area in fixed-point units (> 0).
    pub area2: i64,
    /// Which draw (model and material) and which of its triangles.
    pub draw: u32,
    pub prim: u32,
    /// Counter-clockwise as seen by the camera.
    pub front: bool,
}

/// An edge function E(px, py) = a*px + b*py + c, evaluated at the center of
/// pixel (px, py); `bias` is 0 for top-left edges and -1 otherwise.
#[derive(Debug, Clone, Copy)]
pub struct Edge {
    pub a: i64,
    pub b: i64,
    pub c: i64,
    pub bias: i64,
}

impl Edge {
    /// Edge from (ax, ay) to (bx, by).
    #[inline]
    fn new(ax: i64, ay: i64, bx: i64, by: i64) -> Edge {
        let dx = bx - ax;
        let dy = by - ay;
        // E(p) = dx * (p.y - ay) - dy * (p.x - ax), p = SUBPIXEL * (pixel + 1/2).
        let a = -dy * SUBPIXEL;
        let b = dx * SUBPIXEL;
        let c = dx * (HALF - ay) - dy * (HALF - ax);
        let top_left = (dy == 0 && dx > 0) || dy < 0;
        Edge {
            a,
            b,
            c,
            bias: if top_left { 0 } else { -1 },
        }
    }

    #[inline]
    pub fn at(&self, px: i64, py: i64) -> i64 {
        self.a * px + self.b * py + self.c
    }
}

impl Tri {
    /// Edge k is opposite vertex k; E_k / area2 is the barycentric weight of
    /// vertex k.
    #[inline]
    pub fn edges(&self) -> [Edge; 3] {
        let (x, y) = (self.x.map(i64::from), self.y.map(i64::from));
        [
            Edge::new(x[1], y[1], x[2], y[2]),
            Edge::new(x[2], y[2], x[0], y[0]),
            Edge::new(x[0], y[0], x[1], y[1]),
        ]
    }
}

#[derive(Debug, Clone, Copy)]
pub struct Viewport {
    pub width: u32,
    pub height: u32,
    /// Multisampling: samples lie up to half a pixel from the pixel center,
    /// so a triangle's pixel bounds reach half a pixel further.
    pub msaa: bool,
}

impl Viewport {
    /// Guard band: clip-space multiples of the half-viewport that keep every
    /// fixed-point coordinate below 2^14 pixels from the center (so edge
    /// function products fit easily in i64).
    pub fn guard_band(&self) -> (f32, f32) {
        let limit = 16384.0;
        (
            limit / (self.width as f32 * 0.5),
            limit / (self.height as f32 * 0.5),
        )
    }
}

/// A vertex projected to the viewport and snapped, as `setup` does it to
/// each corner: per vertex once (`project`), shared by the triangles
/// around it.
#[derive(Debug, Clone, Copy, Default)]
pub struct Projected {
    /// Fixed-point screen coordinates (1/2^15 pixel).
    pub x: i32,
    pub y: i32,
    /// z/w and 1/w.
    pub z: f32,
    pub inv_w: f32,
    /// Within the snapping limit (1.25 times the guard band; false for a
    /// NaN): a triangle with a corner that is not is dropped.
    pub ok: bool,
}

/// Projects and snaps clip-space position `p` to viewport `vp`.
#[inline]
pub fn project(p: glam::Vec4, vp: Viewport) -> Projected {
    let (w, h) = (vp.width as f64, vp.height as f64);
    let iw = 1.0 / p.w as f64;
    let sx = (p.x as f64 * iw * 0.5 + 0.5) * w;
    let sy = (0.5 - p.y as f64 * iw * 0.5) * h;
    // Clipping keeps vertices inside the guard band (2^14 pixels from
    // the center); one beyond 1.25 times that (or not finite) comes
    // from a numerical breakdown on extreme input and is dropped. With
    // |dx|, |dy| <= 2.5 * 2^14 pixels = 2^(15.33 + SUBPIXEL_BITS) fixed
    // point, area2 <= 2 * 2^60.7 < 2^63: no i64 overflow below.
    const LIMIT: f64 = 1.25 * 16384.0;
    let inside = |d: f64| d.abs() <= LIMIT; // false for NaN
    if !(inside(sx - w * 0.5) && inside(sy - h * 0.5)) {
        return Projected::default();
    }
    Projected {
        x: (sx * SUBPIXEL as f64).round() as i32,
        y: (sy * SUBPIXEL as f64).round() as i32,
        z: (p.z as f64 * iw) as f32,
        inv_w: iw as f32,
        ok: true,
    }
}

/// Projects, snaps, culls and orders one (clipped) triangle. None when it is
/// culled, has zero area after snapping, or covers no pixel center.
pub fn setup(
    v: [ClipVertex; 3],
    vp: Viewport,
    cull: CullMode,
    draw: u32,
    prim: u32,
) -> Option<Tri> {
    let p = v.map(|v| project(v.pos, vp));
    setup_projected(p, v.map(|v| v.bary), vp, cull, draw, prim)
}

/// `setup` of a triangle whose corners are already projected, with their
/// barycentrics `bary` in the original triangle.
pub fn setup_projected(
    p: [Projected; 3],
    mut bary: [Vec3; 3],
    vp: Viewport,
    cull: CullMode,
    draw: u32,
    prim: u32,
) -> Option<Tri> {
    if !(p[0].ok && p[1].ok && p[2].ok) {
        return None;
    }
    let mut x = p.map(|p| p.x);
    let mut y = p.map(|p| p.y);
    let mut z = p.map(|p| p.z);
    let mut inv_w = p.map(|p| p.inv_w);
    let area2 = (x[1] as i64 - x[0] as i64) * (y[2] as i64 - y[0] as i64)
        - (y[1] as i64 - y[0] as i64) * (x[2] as i64 - x[0] as i64);
    if area2 == 0 {
        return None;
    }
    // With y down, a counter-clockwise (front) triangle has negative area.
    let front = area2 < 0;
    match cull {
        CullMode::Back if !front => return None,
        CullMode::Front if front => return None,
        _ => {}
    }
    if area2 < 0 {
        x.swap(1, 2);
        y.swap(1, 2);
        z.swap(1, 2);
        inv_w.swap(1, 2);
        bary.swap(1, 2);
    }
    let (lo_x, hi_x) = (*x.iter().min()? as i64, *x.iter().max()? as i64);
    let (lo_y, hi_y) = (*y.iter().min()? as i64, *y.iter().max()? as i64);
    // Pixel p is a candidate when lo <= SUBPIXEL p + HALF + o <= hi for
    // a sample offset o: 0, or within half a pixel with MSAA.
    let reach = if vp.msaa { HALF } else { 0 };
    let range = |lo: i64, hi: i64, size: u32| {
        (
            (lo - HALF - reach + SUBPIXEL - 1)
                .div_euclid(SUBPIXEL)
                .max(0),
            (hi - HALF + reach)
                .div_euclid(SUBPIXEL)
                .min(size as i64 - 1),
        )
    };
    let (min_x, max_x) = range(lo_x, hi_x, vp.width);
    let (min_y, max_y) = range(lo_y, hi_y, vp.height);
    if min_x > max_x || min_y > max_y {
        return None;
    }
    Some(Tri {
        x,
        y,
        min_x: min_x as i32,
        min_y: min_y as i32,
        max_x: max_x as i32,
        max_y: max_y as i32,
        z,
        inv_w,
        bary,
        area2: area2.abs(),
        draw,
        prim,
        front,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    fn cv(x: f32, y: f32) -> ClipVertex {
        ClipVertex {
            pos: Vec4::new(x, y, 0.5, 1.0),
            bary: Vec3::ZERO,
        }
    }

    #[test]
    fn counter_clockwise_is_front_and_back_faces_cull() {
        let vp = Viewport {
            width: 8,
            height: 8,
            msaa: false,
        };
        let ccw = [cv(-1.0, -1.0), cv(1.0, -1.0), cv(-1.0, 1.0)];
        let t = setup(ccw, vp, CullMode::Back, 0, 0).unwrap();
        assert!(t.front);
        let cw = [ccw[0], ccw[2], ccw[1]];
        assert!(setup(cw, vp, CullMode::Back, 0, 0).is_none());
        assert!(setup(cw, vp, CullMode::None, 0, 0).is_some_and(|t| !t.front));
        assert!(setup(ccw, vp, CullMode::Front, 0, 0).is_none());
    }

    #[test]
    fn a_corner_beyond_the_snapping_limit_drops_the_triangle() {
        let vp = Viewport {
            width: 8,
            height: 8,
            msaa: false,
        };
        // 1e6 half-viewports out: far beyond 1.25 times the guard band.
        let far = cv(1e6, 0.0);
        assert!(!project(far.pos, vp).ok);
        assert!(!project(Vec4::new(f32::NAN, 0.0, 0.5, 1.0), vp).ok);
        for k in 0..3 {
            let mut t = [cv(-1.0, -1.0), cv(1.0, -1.0), cv(-1.0, 1.0)];
            assert!(setup(t, vp, CullMode::None, 0, 0).is_some());
            t[k] = far;
            assert!(setup(t, vp, CullMode::None, 0, 0).is_none(), "corner {k}");
        }
    }

    #[test]
    fn edge_functions_give_barycentrics() {
        let vp = Viewport {
            width: 8,
            height: 8,
            msaa: false,
        };
        let t = setup(
            [cv(-1.0, -1.0), cv(1.0, -1.0), cv(-1.0, 1.0)],
            vp,
            CullMode::None,
            0,
            0,
        )
        .unwrap();
        let e = t.edges();
        for (px, py) in [(0, 7), (3, 3), (1, 5)] {
            let s: i64 = e.iter().map(|e| e.at(px, py)).sum();
            assert_eq!(s, t.area2, "weights sum to one at ({px},{py})");
        }
    }
}
