//! Binning: which triangles touch which screen tile. Tiles are rendered
//! independently (one thread each, owning its pixels); each tile's list keeps
//! submission order, which makes the result independent of scheduling.
//!
//! The renderer uses full-width tiles (bands of `BAND_ROWS` rows): a band is
//! a contiguous slice of the frame, so each thread writes its pixels straight
//! into the frame buffer with no copy, and a band's depth and id buffers
//! (700 x 16 x 8 bytes) stay in the core's L2 cache.

use super::setup::Tri;

/// Rows per band in the renderer's grid.
pub const BAND_ROWS: u32 = 16;

#[derive(Debug, Clone, Copy)]
pub struct TileGrid {
    pub width: u32,
    pub height: u32,
    pub tile_w: u32,
    pub tile_h: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileRect {
    pub x0: i32,
    pub y0: i32,
    /// Exclusive.
    pub x1: i32,
    pub y1: i32,
}

impl TileRect {
    pub fn width(&self) -> usize {
        (self.x1 - self.x0) as usize
    }
    pub fn height(&self) -> usize {
        (self.y1 - self.y0) as usize
    }
}

impl TileGrid {
    /// Tiles of `tile_w` x `tile_h` pixels (both > 0) covering the frame.
    pub fn new(width: u32, height: u32, tile_w: u32, tile_h: u32) -> TileGrid {
        TileGrid {
            width,
            height,
            tile_w,
            tile_h,
            tiles_x: width.div_ceil(tile_w),
            tiles_y: height.div_ceil(tile_h),
        }
    }

    /// Full-width bands of `BAND_ROWS` rows.
    pub fn bands(width: u32, height: u32) -> TileGrid {
        TileGrid::new(width, height, width.max(1), BAND_ROWS)
    }

    pub fn count(&self) -> usize {
        (self.tiles_x * self.tiles_y) as usize
    }

    pub fn rect(&self, index: usize) -> TileRect {
        let tx = (index as u32 % self.tiles_x) as i32;
        let ty = (index as u32 / self.tiles_x) as i32;
        let (tw, th) = (self.tile_w as i32, self.tile_h as i32);
        TileRect {
            x0: tx * tw,
            y0: ty * th,
            x1: ((tx + 1) * tw).min(self.width as i32),
            y1: ((ty + 1) * th).min(self.height as i32),
        }
    }
}

/// Per tile, the indices (into `tris`) of the triangles that may cover one of
/// its pixels, in order.
/// `msaa`: the triangles were set up for multisampling (coverage reaches
/// half a pixel past the pixel centers).
pub fn bin(tris: &[Tri], grid: &TileGrid, msaa: bool) -> Vec<Vec<u32>> {
    let mut bins = vec![Vec::new(); grid.count()];
    for (i, t) in tris.iter().enumerate() {
        let (tw, th) = (grid.tile_w as i32, grid.tile_h as i32);
        let (tx0, tx1) = (t.min_x / tw, t.max_x / tw);
        let (ty0, ty1) = (t.min_y / th, t.max_y / th);
        let single = tx0 == tx1 && ty0 == ty1;
        let edges = t.edges();
        for ty in ty0..=ty1 {
            for tx in tx0..=tx1 {
                let index = (ty as u32 * grid.tiles_x + tx as u32) as usize;
                if !single && !touches(&edges, grid.rect(index), msaa) {
                    continue;
                }
                bins[index].push(i as u32);
            }
        }
    }
    bins
}

/// False when one edge function is negative at every pixel center of the
/// tile (checked at the corner where it is largest), or with `msaa` at
/// every point within half a pixel of one.
fn touches(edges: &[super::setup::Edge; 3], r: TileRect, msaa: bool) -> bool {
    edges.iter().all(|e| {
        let px = if e.a > 0 { r.x1 - 1 } else { r.x0 } as i64;
        let py = if e.b > 0 { r.y1 - 1 } else { r.y0 } as i64;
        let reach = if msaa { (e.a.abs() + e.b.abs()) / 2 } else { 0 };
        e.at(px, py) + e.bias + reach >= 0
    })
}
