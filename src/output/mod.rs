//! Frame buffers to files: the resolve to display bytes, and the writers
//! (one format per file). Every file is written to a temporary name in its
//! directory and renamed into place, so an interrupted render never leaves a
//! half-written frame under the final name.

pub mod exr;
pub mod gif;
pub mod png;
pub mod tonemap;
pub mod video;

use std::io::Write;
use std::path::Path;

use glam::Vec4;

use crate::color::{encode_linear, encode_srgb_xyz, encode_srgb3};
use crate::error::Error;
use crate::render::Frame;
use crate::scene::RenderSettings;
use crate::scene::settings::{Background, Tonemap};
use tonemap::tonemap;

/// 8-bit display image: RGB, or RGBA for a transparent background.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image8 {
    pub width: u32,
    pub height: u32,
    pub channels: u8,
    pub data: Vec<u8>,
}

/// Exposure, tone map and sRGB encoding (the data views are written as
/// their values, without a transfer curve). Frame colors are premultiplied
/// by their coverage alpha (partly covered MSAA pixels, blended surfaces
/// over a transparent background); an RGBA image gets straight alpha.
pub fn resolve(frame: &Frame, s: &RenderSettings) -> Image8 {
    let alpha = s.background == Background::Transparent;
    let channels = if alpha { 4 } else { 3 };
    let data_view = s.shading.is_data_view();
    let scale = s.exposure.exp2();
    let mut data = vec![0u8; frame.color.len() * channels];
    let pixel = |c: &Vec4| -> [u8; 4] {
        let c = if alpha && c.w > 0.0 && c.w < 1.0 {
            (c.truncate() / c.w).extend(c.w)
        } else {
            *c
        };
        let rgb = if data_view {
            [encode_linear(c.x), encode_linear(c.y), encode_linear(c.z)]
        } else if s.tonemap == Tonemap::Clamp {
            // `tonemap`'s clamp is the encoding's own: the same bytes,
            // without a trip through memory.
            encode_srgb_xyz(c * scale)
        } else {
            encode_srgb3(tonemap(c.truncate(), s.tonemap, scale))
        };
        let a = if alpha { encode_linear(c.w) } else { 255 };
        [rgb[0], rgb[1], rgb[2], a]
    };
    use rayon::prelude::*;
    let rows = data
        .par_chunks_mut(channels * frame.width as usize)
        .zip(frame.color.par_chunks(frame.width as usize));
    if alpha {
        rows.for_each(|(out, row)| resolve_row::<4>(out, row, pixel));
    } else {
        rows.for_each(|(out, row)| resolve_row::<3>(out, row, pixel));
    }
    Image8 {
        width: frame.width,
        height: frame.height,
        channels: channels as u8,
        data,
    }
}

/// One row of `resolve` into C bytes per pixel; runs of one colour (the
/// background, mostly) resolve once, and are copied four pixels at a time.
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

/// Writes `bytes` produced by `write` to `path` atomically.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), Error>,
) -> Result<(), Error> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let file = std::fs::File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush().map_err(|e| Error::io(&tmp, e))?;
        w.get_ref().sync_data().map_err(|e| Error::io(&tmp, e))?;
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
