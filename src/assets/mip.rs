//! Mip chains: each level half the size of the one above (rounded down, at
//! least 1), down to 1x1, for any size including non-powers of two.
//!
//! Filtering happens in linear space (sRGB maps decoded first) with an
//! area-weighted box: each texel of the smaller level averages the texels of
//! the larger level under its footprint, with fractional weights at the
//! edges of the footprint when a size is odd, so no texel is dropped and
//! none counts twice. Levels are kept as RGBA8 (re-encoded to sRGB for color
//! maps) in the same block layout as level 0. Alpha is averaged like the
//! other channels (straight, not premultiplied).

use glam::Vec4;
use rayon::prelude::*;

use super::texture::{Level, Texture};

/// Levels 1.. of `t` (empty for a 1x1 texture), built from level 0.
/// `Texture::mip_chain(build_chain)` keeps them with the texture.
pub fn build_chain(t: &Texture) -> Vec<Level> {
    chain_with(t, true)
}

/// `build_chain`: where `fast`, the first exact halvings strip by strip
/// (`strips`) and later even sizes by `halve`; else every level by `area`
/// (the same values: the test compares them).
fn chain_with(t: &Texture, fast: bool) -> Vec<Level> {
    let mut levels = Vec::new();
    let base = t.base();
    // Level 0 decoded on the fly; later levels from the floats kept.
    let (mut w, mut h) = (t.width, t.height);
    let mut prev: Option<Vec<Vec4>> = None;
    let k = if fast { halvings(w, h) } else { 0 };
    if k > 0 {
        let last;
        (levels, last) = strips(t, k);
        prev = Some(last);
        (w, h) = (w >> k, h >> k);
    }
    while w > 1 || h > 1 {
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let src = Source {
            texture: t,
            base,
            prev: prev.as_deref(),
            width: w,
        };
        let mut next = vec![Vec4::ZERO; (nw * nh) as usize];
        if fast && w == 2 * nw && h == 2 * nh {
            halve(&src, &mut next, nw);
        } else {
            area(&src, &mut next, (w, h), (nw, nh));
        }
        let bytes: Vec<[u8; 4]> = next.par_iter().map(|&c| t.encode(c)).collect();
        levels.push(Level::from_rows(nw, nh, &bytes));
        prev = Some(next);
        (w, h) = (nw, nh);
    }
    levels
}

/// The most levels made strip by strip (`strips`): 32 rows of level 0 a
/// strip.
const STRIP_LEVELS: u32 = 5;

/// How many of the first levels halve both sides exactly (at most
/// `STRIP_LEVELS`).
fn halvings(w: u32, h: u32) -> u32 {
    (0..STRIP_LEVELS)
        .take_while(|&k| w.is_multiple_of(2 << k) && h.is_multiple_of(2 << k))
        .count() as u32
}

/// A strip's rows of levels 1..=k (`strips`), encoded, and of level k as
/// floats.
type Strip = (Vec<Vec<[u8; 4]>>, Vec<Vec4>);

/// Levels 1..=`k` of `t`, which halve exactly (`halvings`), made strip by
/// strip: each strip of 2^k rows of level 0 is decoded and halved `k`
/// times in a thread's scratch rows, so no level is held as floats whole
/// (a 4096² map's level 1 would be 64 MB of them, fresh memory the first
/// touch makes slow); the values are `halve`'s. Also the floats of level
/// `k`, which the smaller levels are made from.
fn strips(t: &Texture, k: u32) -> (Vec<Level>, Vec<Vec4>) {
    let (w, rows) = (t.width as usize, 1usize << k);
    let decode = t.decoder();
    let per_strip: Vec<Strip> = (0..t.height as usize / rows)
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new()),
            |(a, b): &mut (Vec<Vec4>, Vec<Vec4>), strip| {
                a.resize(w * rows, Vec4::ZERO);
                for (r, row) in a.chunks_exact_mut(w).enumerate() {
                    t.base().read_row((strip * rows + r) as u32, row, &decode);
                }
                let mut bytes = Vec::with_capacity(k as usize);
                for j in 1..=k {
                    let (sw, nw) = (w >> (j - 1), w >> j);
                    b.resize(nw * (rows >> j), Vec4::ZERO);
                    let pairs = a.chunks_exact(2 * sw);
                    for (out, pair) in b.chunks_exact_mut(nw).zip(pairs) {
                        let (top, bottom) = pair.split_at(sw);
                        halve_rows(top, bottom, out);
                    }
                    bytes.push(b.iter().map(|&c| t.encode(c)).collect());
                    std::mem::swap(a, b);
                }
                (bytes, a.clone())
            },
        )
        .collect();
    let levels = (1..=k)
        .map(|j| {
            let mut texels = Vec::new();
            for (bytes, _) in &per_strip {
                texels.extend_from_slice(&bytes[j as usize - 1]);
            }
            Level::from_rows(t.width >> j, t.height >> j, &texels)
        })
        .collect();
    let mut last = Vec::new();
    for (_, floats) in &per_strip {
        last.extend_from_slice(floats);
    }
    (levels, last)
}

/// One row of a halved level from the two rows under it: each texel the
/// mean of the 2x2 under it, added in `area`'s order with its weights
/// (1/2 x 1/2), so the same values.
#[inline(always)]
fn halve_rows(top: &[Vec4], bottom: &[Vec4], out: &mut [Vec4]) {
    let pairs = top.chunks_exact(2).zip(bottom.chunks_exact(2));
    for (o, (t, b)) in out.iter_mut().zip(pairs) {
        let mut acc = Vec4::ZERO;
        acc += t[0] * 0.25;
        acc += t[1] * 0.25;
        acc += b[0] * 0.25;
        acc += b[1] * 0.25;
        *o = acc;
    }
}

/// The level a mip level is filtered from: level 0 (`base`, decoded
/// texel by texel) or the floats of the level above (`prev`), `width`
/// texels a row.
struct Source<'a> {
    texture: &'a Texture,
    base: &'a Level,
    prev: Option<&'a [Vec4]>,
    width: u32,
}

impl Source<'_> {
    #[inline(always)]
    fn at(&self, x: u32, y: u32) -> Vec4 {
        match self.prev {
            Some(p) => p[(y * self.width + x) as usize],
            None => self.texture.decode(self.base.texel(x, y)),
        }
    }

    /// Row `y`, `self.width` texels: the floats kept, or level 0's texels
    /// decoded into `buf`.
    #[inline(always)]
    fn row<'b>(&'b self, y: u32, buf: &'b mut Vec<Vec4>) -> &'b [Vec4] {
        let w = self.width as usize;
        match self.prev {
            Some(p) => &p[y as usize * w..][..w],
            None => {
                buf.resize(w, Vec4::ZERO);
                self.base.read_row(y, buf, self.texture.decoder());
                buf
            }
        }
    }
}

/// A level of even width and height halved (`next`, `nw` texels a row;
/// `halve_rows`).
fn halve(src: &Source, next: &mut [Vec4], nw: u32) {
    next.par_chunks_mut(nw as usize).enumerate().for_each_init(
        || (Vec::new(), Vec::new()),
        |(a, b), (y, row)| {
            let sy = 2 * y as u32;
            halve_rows(src.row(sy, a), src.row(sy + 1, b), row);
        },
    );
}

/// A level of size `(w, h)` filtered into `next` of size `(nw, nh)` by the
/// area-weighted box (`weights` along each axis).
fn area(src: &Source, next: &mut [Vec4], (w, h): (u32, u32), (nw, nh): (u32, u32)) {
    let wx = weights(w, nw);
    let wy = weights(h, nh);
    next.par_chunks_mut(nw as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let mut acc = Vec4::ZERO;
                for &(sy, fy) in &wy[y] {
                    for &(sx, fx) in &wx[x] {
                        acc += src.at(sx, sy) * (fx * fy);
                    }
                }
                *out = acc;
            }
        });
}

/// For each of the `dst` texels along one axis, the `src` texels under its
/// footprint and their weights (summing to 1).
fn weights(src: u32, dst: u32) -> Vec<Vec<(u32, f32)>> {
    let step = src as f64 / dst as f64;
    (0..dst)
        .map(|i| {
            let (a, b) = (i as f64 * step, (i + 1) as f64 * step);
            let mut v = Vec::new();
            let mut k = a.floor() as u32;
            while (k as f64) < b && k < src {
                let lo = (k as f64).max(a);
                let hi = ((k + 1) as f64).min(b);
                if hi > lo {
                    v.push((k, ((hi - lo) / step) as f32));
                }
                k += 1;
            }
            v
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_cover_every_source_texel_once() {
        for (s, d) in [(8, 4), (5, 2), (7, 3), (1, 1), (3, 1)] {
            let w = weights(s, d);
            let mut per_src = vec![0.0f32; s as usize];
            for taps in &w {
                let sum: f32 = taps.iter().map(|t| t.1).sum();
                assert!((sum - 1.0).abs() < 1e-6, "{s}->{d}");
                for &(k, f) in taps {
                    per_src[k as usize] += f;
                }
            }
            // Each source texel contributes the same total weight.
            for v in per_src {
                assert!((v - d as f32 / s as f32).abs() < 1e-5, "{s}->{d}");
            }
        }
    }

    /// Halving even levels gives the area-weighted box's bytes, for color
    /// and data maps, square or not, with odd sizes further down.
    #[test]
    fn halving_is_the_area_box() {
        for (w, h, srgb) in [
            (64, 16, true),
            (64, 16, false),
            (256, 128, true),
            (96, 192, false),
            (12, 20, true),
            (6, 10, true),
            (8, 8, false),
        ] {
            // Scrambled texels: every byte value turns up.
            let texels: Vec<[u8; 4]> = (0..w * h)
                .map(|i: u32| (i.wrapping_mul(2_654_435_761) ^ (i << 7)).to_le_bytes())
                .collect();
            let t = Texture::from_rgba8(w, h, &texels, srgb);
            let (fast, slow) = (chain_with(&t, true), chain_with(&t, false));
            assert_eq!(fast.len(), slow.len());
            for (a, b) in fast.iter().zip(&slow) {
                assert_eq!((a.width, a.height), (b.width, b.height));
                for y in 0..a.height {
                    for x in 0..a.width {
                        assert_eq!(a.texel(x, y), b.texel(x, y), "{w}x{h} {x},{y}");
                    }
                }
            }
        }
    }

    #[test]
    fn chain_of_a_non_power_of_two_keeps_the_mean_in_linear_space() {
        // 5x3 sRGB texture: half black, half white columns.
        let texels: Vec<[u8; 4]> = (0..15)
            .map(|i| if i % 5 < 2 { [0, 0, 0, 255] } else { [255; 4] })
            .collect();
        let t = Texture::from_rgba8(5, 3, &texels, true);
        let chain = build_chain(&t);
        let sizes: Vec<_> = chain.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, vec![(2, 1), (1, 1)]);
        // 3/5 white in linear: the 1x1 level is linear 0.6, sRGB ~203.
        let top = chain[1].texel(0, 0);
        let lin = crate::color::srgb_to_linear_table()[top[0] as usize];
        assert!((lin - 0.6).abs() < 0.01, "{top:?} {lin}");
    }
}
