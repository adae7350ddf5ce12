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
use crate::color::{encode_linear, encode_srgb_xyz, encode_srgb3};
use crate::scene::RenderSettings;
use crate::scene::settings::{Background, Tonemap};
use crate::shade::tonemap::tonemap;

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
        let scale = self.scale;
        if self.data_view {
            rows::<C>(colors, width, plain, out, |c| {
                pixel::<C>(c, |c| {
                    [encode_linear(c.x), encode_linear(c.y), encode_linear(c.z)]
                })
            });
        } else if self.tonemap == Tonemap::Clamp {
            // `tonemap`'s clamp is the encoding's own: the same bytes,
            // without a trip through memory.
            rows::<C>(colors, width, plain, out, |c| {
                pixel::<C>(c, |c| encode_srgb_xyz(c * scale))
            });
        } else {
            let op = self.tonemap;
            rows::<C>(colors, width, plain, out, |c| {
                pixel::<C>(c, |c| encode_srgb3(tonemap(c.truncate(), op, scale)))
            });
        }
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
    for (row, bytes) in colors.chunks(width).zip(out.chunks_mut(width * C)) {
        if let Some(run) = &bg {
            fill(&mut bytes[..lo * C], run);
            fill(&mut bytes[hi * C..], run);
        }
        resolve_row::<C>(&mut bytes[lo * C..hi * C], &row[lo..hi], &pixel);
    }
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
