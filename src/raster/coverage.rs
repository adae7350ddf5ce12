//! Coverage: which pixel centers of a tile a triangle covers, with its depth
//! there. The visibility pass runs the depth test before any shading: a tile
//! ends with the nearest triangle id and depth per pixel, and every visible
//! pixel is shaded exactly once afterwards.

use super::bin::TileRect;
use super::setup::Tri;

/// Calls `visit(px, py, z)` for every pixel center inside `rect` covered by
/// `t` (top-left rule), row by row.
#[inline]
pub fn raster_triangle<F: FnMut(i32, i32, f32)>(t: &Tri, rect: TileRect, mut visit: F) {
    let x0 = t.min_x.max(rect.x0);
    let x1 = t.max_x.min(rect.x1 - 1);
    let y0 = t.min_y.max(rect.y0);
    let y1 = t.max_y.min(rect.y1 - 1);
    if x0 > x1 || y0 > y1 {
        return;
    }
    let e = t.edges();
    let inv_area = 1.0 / t.area2 as f64;
    let dz1 = ((t.z[1] - t.z[0]) as f64 * inv_area) as f32;
    let dz2 = ((t.z[2] - t.z[0]) as f64 * inv_area) as f32;
    let z0 = t.z[0];
    let (x0l, y0l) = (x0 as i64, y0 as i64);
    let mut row = [
        e[0].at(x0l, y0l) + e[0].bias,
        e[1].at(x0l, y0l) + e[1].bias,
        e[2].at(x0l, y0l) + e[2].bias,
    ];
    for py in y0..=y1 {
        let mut w = row;
        let mut inside_seen = false;
        for px in x0..=x1 {
            if (w[0] | w[1] | w[2]) >= 0 {
                inside_seen = true;
                // Unbiased weights for depth: bias is only for the rule.
                let e1 = (w[1] - e[1].bias) as f32;
                let e2 = (w[2] - e[2].bias) as f32;
                visit(px, py, z0 + e1 * dz1 + e2 * dz2);
            } else if inside_seen {
                // Convex: once out again, the rest of the row is outside.
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

pub const NO_TRIANGLE: u32 = u32::MAX;

/// Depth and triangle id per pixel of one tile.
pub struct Visibility {
    pub rect: TileRect,
    pub depth: Vec<f32>,
    pub id: Vec<u32>,
}

impl Visibility {
    pub fn new(rect: TileRect, reverse_z: bool) -> Visibility {
        let n = rect.width() * rect.height();
        Visibility {
            rect,
            // Reverse-Z clears to 0 (far) and keeps greater; standard clears
            // to 1 and keeps less.
            depth: vec![if reverse_z { 0.0 } else { 1.0 }; n],
            id: vec![NO_TRIANGLE; n],
        }
    }

    /// Depth-tests triangle `id` into the tile. Equal depths keep the earlier
    /// triangle (submission order decides coplanar ties, deterministically).
    #[inline]
    pub fn draw<const REVERSE_Z: bool>(&mut self, t: &Tri, id: u32) {
        self.draw_if::<REVERSE_Z>(t, id, |_, _| true);
    }

    /// As `draw`, for pixels that also pass `keep(px, py)` (the alpha test
    /// of cutout materials), asked only where the depth test passes.
    #[inline]
    pub fn draw_if<const REVERSE_Z: bool>(
        &mut self,
        t: &Tri,
        id: u32,
        mut keep: impl FnMut(i32, i32) -> bool,
    ) {
        let rect = self.rect;
        let stride = rect.width();
        let (depth, ids) = (&mut self.depth, &mut self.id);
        raster_triangle(t, rect, |px, py, z| {
            let i = (py - rect.y0) as usize * stride + (px - rect.x0) as usize;
            if in_front(z, depth[i], REVERSE_Z) && keep(px, py) {
                depth[i] = z;
                ids[i] = id;
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
