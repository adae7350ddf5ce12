//! The display resolve: a frame's linear colour to 8-bit display bytes
//! (exposure, tone map, sRGB encoding), the last step of a frame.
//!
//! `resolve` turns a whole frame into an image. `Renderer::render_display`
//! does the same band by band, right after each band is shaded, while its
//! colour is still in the cache (the frame's colour is 16 bytes a pixel;
//! read back after the frame it comes from memory). Both give the same
//! bytes: they encode each pixel with one `Encoder`.

use glam::Vec4;
use rayon::prelude::*;

use super::Frame;
use crate::color::{encode_linear, encode_srgb_xyz, encode_srgb3, encode_srgb8};
use crate::scene::RenderSettings;
use crate::scene::settings::{Background, Tonemap};
use crate::shade::tonemap::{tonemap, tonemap_lanes};
use crate::simd::{F8, Lane, V3};

/// 8-bit display image: RGB, or RGBA for a transparent background.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image8 {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// 3 (RGB) or 4 (RGBA).
    pub channels: u8,
    /// The bytes, row-major from the top, `channels` per pixel.
    pub data: Vec<u8>,
}

impl Image8 {
    /// An image of no pixels (RGB), to resolve into.
    pub fn empty() -> Image8 {
        Image8 {
            width: 0,
            height: 0,
            channels: 3,
            data: Vec::new(),
        }
    }
}

/// Exposure (the frame's, `Frame::exposure`), tone map and sRGB encoding
/// (the data views are written as their values, without a transfer
/// curve). Frame colors are premultiplied by their coverage alpha (partly covered MSAA pixels, blended surfaces
/// over a transparent background); an RGBA image gets straight alpha.
pub fn resolve(frame: &Frame, s: &RenderSettings) -> Image8 {
    let mut image = Image8::empty();
    resolve_into(frame, s, &mut image);
    image
}

/// `*image = resolve(frame, s)`, reusing `image`'s memory.
pub fn resolve_into(frame: &Frame, s: &RenderSettings, image: &mut Image8) {
    let enc = Encoder::new(s, frame.exposure);
    enc.shape(frame.width, frame.height, image);
    let (w, c) = (frame.width as usize, enc.channels);
    if w == 0 {
        return;
    }
    image
        .data
        .par_chunks_mut(c * w)
        .zip(frame.color.par_chunks(w))
        .for_each(|(out, row)| enc.band(row, w, None, out));
}

/// What a band knows of its background when it is one flat colour: the
/// colour, and the columns outside which every pixel of the band holds
/// exactly that colour (`BandInputs::shade_band`).
#[derive(Debug, Clone, Copy)]
pub(super) struct PlainBackground {
    pub color: Vec4,
    /// First and one past the last column that may hold something else.
    pub columns: (usize, usize),
}

/// How a frame's pixels become display bytes, from the render settings.
#[derive(Debug, Clone, Copy)]
pub(super) struct Encoder {
    alpha: bool,
    /// 3 (RGB) or 4 (RGBA, with a transparent background).
    channels: usize,
    data_view: bool,
    tonemap: Tonemap,
    /// 2^exposure.
    scale: f32,
}

impl Encoder {
    /// The encoder of settings `s` at `exposure` stops.
    pub(super) fn new(s: &RenderSettings, exposure: f32) -> Encoder {
        let alpha = s.background == Background::Transparent;
        if s.tonemap == Tonemap::Agx {
            crate::shade::agx::prepare();
        }
        Encoder {
            alpha,
            channels: if alpha { 4 } else { 3 },
            data_view: s.shading.is_data_view(),
            tonemap: s.tonemap,
            scale: exposure.exp2(),
        }
    }

    /// Gives `image` the frame's size and this encoding's channels (its
    /// bytes are then all overwritten).
    pub(super) fn shape(&self, width: u32, height: u32, image: &mut Image8) {
        image.width = width;
        image.height = height;
        image.channels = self.channels as u8;
        image
            .data
            .resize(width as usize * height as usize * self.channels, 0);
    }

    /// Bytes per pixel.
    pub(super) fn channels(&self) -> usize {
        self.channels
    }

    /// Rows of `width` pixels (`colors`, whole rows) into `out`, `channels`
    /// bytes a pixel. With `plain`, the pixels outside its columns are
    /// its colour's bytes without being read.
    pub(super) fn band(
        &self,
        colors: &[Vec4],
        width: usize,
        plain: Option<PlainBackground>,
        out: &mut [u8],
    ) {
        if self.alpha {
            self.band_in::<4>(colors, width, plain, out);
        } else {
            self.band_in::<3>(colors, width, plain, out);
        }
    }

    /// `band` with C bytes a pixel, the encoding chosen once.
    fn band_in<const C: usize>(
        &self,
        colors: &[Vec4],
        width: usize,
        plain: Option<PlainBackground>,
        out: &mut [u8],
    ) {
        if self.data_view {
            rows::<C>(colors, width, plain, out, |c| {
                pixel::<C>(c, |c| {
                    [encode_linear(c.x), encode_linear(c.y), encode_linear(c.z)]
                })
            });
        } else if C == 3 {
            // Opaque: eight pixels at a time (`encode8`), the same bytes.
            let one = |c: &Vec4| pixel::<C>(c, |c| self.encode1(c));
            rows_with::<C>(colors, width, plain, out, one, |o, r| {
                resolve_row8(o, r, one, |p| self.encode8(p))
            });
        } else {
            rows::<C>(colors, width, plain, out, |c| {
                pixel::<C>(c, |c| self.encode1(c))
            });
        }
    }

    /// One opaque colour's bytes.
    #[inline(always)]
    fn encode1(&self, c: Vec4) -> [u8; 3] {
        if self.tonemap == Tonemap::Clamp {
            // `tonemap`'s clamp is the encoding's own: the same bytes,
            // without a trip through memory.
            encode_srgb_xyz(c * self.scale)
        } else {
            encode_srgb3(tonemap(c.truncate(), self.tonemap, self.scale))
        }
    }

    /// `encode1` of eight opaque colours at once.
    #[inline(always)]
    fn encode8(&self, p: &[Vec4]) -> [[u8; 3]; 8] {
        let c = V3 {
            x: F8::from_fn(|k| p[k].x),
            y: F8::from_fn(|k| p[k].y),
            z: F8::from_fn(|k| p[k].z),
        };
        // (The clamp of `encode_srgb` is the tone map's last step.)
        let t = tonemap_lanes(c, self.tonemap, self.scale);
        let (r, g, b) = (encode_srgb8(t.x), encode_srgb8(t.y), encode_srgb8(t.z));
        std::array::from_fn(|k| [r[k], g[k], b[k]])
    }
}

/// One pixel's bytes (the first C of them), its colour's encoded by `rgb`:
/// with alpha (C = 4), straight colour and the coverage byte.
#[inline(always)]
fn pixel<const C: usize>(c: &Vec4, rgb: impl Fn(Vec4) -> [u8; 3]) -> [u8; 4] {
    let alpha = C == 4;
    let c = if alpha && c.w > 0.0 && c.w < 1.0 {
        (c.truncate() / c.w).extend(c.w)
    } else {
        *c
    };
    let [r, g, b] = rgb(c);
    let a = if alpha { encode_linear(c.w) } else { 255 };
    [r, g, b, a]
}

/// Whole rows of `width` pixels into C bytes a pixel; with `plain`, the
/// columns outside its span get its colour's bytes directly.
#[inline(always)]
fn rows<const C: usize>(
    colors: &[Vec4],
    width: usize,
    plain: Option<PlainBackground>,
    out: &mut [u8],
    pixel: impl Fn(&Vec4) -> [u8; 4],
) {
    rows_with::<C>(colors, width, plain, out, &pixel, |o, r| {
        resolve_row::<C>(o, r, &pixel)
    });
}

/// `rows`, each row's span resolved by `row` (bytes, colours).
#[inline(always)]
fn rows_with<const C: usize>(
    colors: &[Vec4],
    width: usize,
    plain: Option<PlainBackground>,
    out: &mut [u8],
    pixel: impl Fn(&Vec4) -> [u8; 4],
    row: impl Fn(&mut [u8], &[Vec4]),
) {
    let (lo, hi) = plain.map_or((0, width), |p| {
        let hi = p.columns.1.min(width);
        (p.columns.0.min(hi), hi)
    });
    // The background's bytes for 64 pixels, copied a run at a time.
    const RUN: usize = 64;
    let bg = plain.map(|p| {
        let px = pixel(&p.color);
        let mut run = [0u8; RUN * 4];
        for k in 0..RUN {
            run[k * C..k * C + C].copy_from_slice(&px[..C]);
        }
        run
    });
    let fill = |bytes: &mut [u8], run: &[u8; RUN * 4]| {
        for part in bytes.chunks_mut(RUN * C) {
            part.copy_from_slice(&run[..part.len()]);
        }
    };
    for (colors, bytes) in colors.chunks(width).zip(out.chunks_mut(width * C)) {
        if let Some(run) = &bg {
            fill(&mut bytes[..lo * C], run);
            fill(&mut bytes[hi * C..], run);
        }
        row(&mut bytes[lo * C..hi * C], &colors[lo..hi]);
    }
}

/// One row of opaque pixels into 3 bytes each, eight at a time
/// (`eight`), a group of eight that repeats the pixel before it copied;
/// the last few one by one (`pixel`).
#[inline]
fn resolve_row8(
    out: &mut [u8],
    row: &[Vec4],
    pixel: impl Fn(&Vec4) -> [u8; 4],
    eight: impl Fn(&[Vec4]) -> [[u8; 3]; 8],
) {
    let n = row.len();
    let mut x = 0;
    while x + 8 <= n {
        let p = &row[x..x + 8];
        if x > 0 && p.iter().all(|c| *c == row[x - 1]) {
            let (done, rest) = out.split_at_mut(x * 3);
            let last = &done[x * 3 - 3..];
            for o in rest[..24].chunks_exact_mut(3) {
                o.copy_from_slice(last);
            }
        } else {
            let bytes = eight(p);
            for (o, b) in out[x * 3..x * 3 + 24].chunks_exact_mut(3).zip(bytes) {
                o.copy_from_slice(&b);
            }
        }
        x += 8;
    }
    resolve_row::<3>(&mut out[x * 3..], &row[x..], pixel);
}

/// One row into C bytes per pixel; runs of one colour (the background,
/// mostly) resolve once, and are copied four pixels at a time.
#[inline]
fn resolve_row<const C: usize>(out: &mut [u8], row: &[Vec4], pixel: impl Fn(&Vec4) -> [u8; 4]) {
    let Some(first) = row.first() else {
        return;
    };
    let mut last = (*first, pixel(first));
    // `last`'s bytes for four pixels (the first 4 C of them).
    let repeat = |px: [u8; 4]| -> [u8; 16] {
        let mut r = [0u8; 16];
        for k in 0..4 {
            r[k * C..k * C + C].copy_from_slice(&px[..C]);
        }
        r
    };
    let mut four = repeat(last.1);
    let mut x = 0;
    let n = row.len();
    while x + 4 <= n {
        let p = &row[x..x + 4];
        let l = last.0;
        if p[0] == l && p[1] == l && p[2] == l && p[3] == l {
            out[x * C..x * C + 4 * C].copy_from_slice(&four[..4 * C]);
            x += 4;
            continue;
        }
        for c in p {
            if *c != last.0 {
                last = (*c, pixel(c));
                four = repeat(last.1);
            }
            out[x * C..x * C + C].copy_from_slice(&last.1[..C]);
            x += 1;
        }
    }
    for c in &row[x..] {
        if *c != last.0 {
            last = (*c, pixel(c));
        }
        out[x * C..x * C + C].copy_from_slice(&last.1[..C]);
        x += 1;
    }
}
