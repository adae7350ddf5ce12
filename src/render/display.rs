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
    pub width: u32,
    pub height: u32,
    pub channels: u8,
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

/// Exposure, tone map and sRGB encoding (the data views are written as
/// their values, without a transfer curve). Frame colors are premultiplied
/// by their coverage alpha (partly covered MSAA pixels, blended surfaces
/// over a transparent background); an RGBA image gets straight alpha.
pub fn resolve(frame: &Frame, s: &RenderSettings) -> Image8 {
    let mut image = Image8::empty();
    resolve_into(frame, s, &mut image);
    image
}

/// `*image = resolve(frame, s)`, reusing `image`'s memory.
pub fn resolve_into(frame: &Frame, s: &RenderSettings, image: &mut Image8) {
    let enc = Encoder::new(s);
    enc.shape(frame.width, frame.height, image);
    let (w, c) = (frame.width as usize, enc.channels);
    if w == 0 {
        return;
    }
    image
        .data
        .par_chunks_mut(c * w)
        .zip(frame.color.par_chunks(w))
        .for_each(|(out, row)| enc.rows(row, w, out));
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
    pub(super) fn new(s: &RenderSettings) -> Encoder {
        let alpha = s.background == Background::Transparent;
        Encoder {
            alpha,
            channels: if alpha { 4 } else { 3 },
            data_view: s.shading.is_data_view(),
            tonemap: s.tonemap,
            scale: s.exposure.exp2(),
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

    /// One pixel's bytes (the first `channels` of them).
    #[inline]
    fn pixel(&self, c: &Vec4) -> [u8; 4] {
        let c = if self.alpha && c.w > 0.0 && c.w < 1.0 {
            (c.truncate() / c.w).extend(c.w)
        } else {
            *c
        };
        let rgb = if self.data_view {
            [encode_linear(c.x), encode_linear(c.y), encode_linear(c.z)]
        } else if self.tonemap == Tonemap::Clamp {
            // `tonemap`'s clamp is the encoding's own: the same bytes,
            // without a trip through memory.
            encode_srgb_xyz(c * self.scale)
        } else {
            encode_srgb3(tonemap(c.truncate(), self.tonemap, self.scale))
        };
        let a = if self.alpha { encode_linear(c.w) } else { 255 };
        [rgb[0], rgb[1], rgb[2], a]
    }

    /// Rows of `width` pixels (`colors`, whole rows) into `out`, `channels`
    /// bytes a pixel.
    pub(super) fn rows(&self, colors: &[Vec4], width: usize, out: &mut [u8]) {
        let c = self.channels;
        for (row, bytes) in colors.chunks(width).zip(out.chunks_mut(width * c)) {
            if self.alpha {
                resolve_row::<4>(bytes, row, |p| self.pixel(p));
            } else {
                resolve_row::<3>(bytes, row, |p| self.pixel(p));
            }
        }
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
