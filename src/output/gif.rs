//! Animated GIF from a sequence of PNG frames: one palette for the whole
//! sequence (so a color does not flicker between palette entries from
//! frame to frame), infinitely looping, with optional dithering.
//!
//! Two passes over the files, so memory stays at a few frames whatever the
//! sequence length: the first trains a NeuQuant palette (color_quant, MIT)
//! on pixels from every frame, the second maps each frame to it and
//! encodes (gif crate, MIT/Apache). Frames with any alpha below 128 make
//! one palette entry, after the colors, transparent.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::write_atomic;
use crate::error::Error;
use crate::scene::settings::GifDither;

/// How `assemble` writes a GIF.
#[derive(Debug, Clone, Copy)]
pub struct GifOptions {
    /// Per frame; GIF stores centiseconds, so this is rounded to 10 ms.
    pub delay_ms: u32,
    /// How colours between palette entries are approximated.
    pub dither: GifDither,
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct GifInfo {
    /// Frames written.
    pub frames: usize,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Palette entries (256 at most, including a transparent one).
    pub colors: usize,
    /// Whether one palette entry is transparent.
    pub transparent: bool,
}

/// Pixels the palette is trained on, at most (spread over all frames).
const TRAINING_PIXELS: usize = 1 << 21;
/// Frames decoded and mapped at once in the second pass.
const BATCH: usize = 8;

fn read_rgba(path: &Path) -> Result<image::RgbaImage, Error> {
    Ok(super::png::read_any(path)?.to_rgba8())
}

/// Assembles `frames` (PNG files, in order) into `out`.
pub fn assemble(frames: &[PathBuf], out: &Path, opts: GifOptions) -> Result<GifInfo, Error> {
    let first = frames
        .first()
        .ok_or_else(|| Error::Argument("a GIF needs at least one frame".into()))?;
    let (width, height) = image::image_dimensions(first).map_err(|e| match e {
        image::ImageError::IoError(io) => Error::io(first, io),
        other => Error::asset(first, None, format!("cannot read the frame: {other}")),
    })?;
    if width > u16::MAX as u32 || height > u16::MAX as u32 {
        return Err(Error::asset(
            first,
            None,
            format!("{width}x{height} is larger than a GIF can hold (65535 per side)"),
        ));
    }
    // Pass 1: training pixels from every frame (a regular stride), and
    // whether any frame is transparent.
    let per_frame = (TRAINING_PIXELS / frames.len()).max(1);
    let samples: Vec<(Vec<u8>, bool)> = frames
        .par_iter()
        .map(|p| {
            let img = read_rgba(p)?;
            if img.dimensions() != (width, height) {
                return Err(Error::asset(
                    p,
                    None,
                    format!(
                        "frame is {}x{}, the first frame ({}) is {width}x{height}",
                        img.width(),
                        img.height(),
                        first.display()
                    ),
                ));
            }
            let px = img.as_raw();
            let n = px.len() / 4;
            let stride = n.div_ceil(per_frame).max(1);
            let mut out = Vec::with_capacity(n / stride * 4 + 4);
            let mut transparent = false;
            for i in 0..n {
                let p = &px[i * 4..i * 4 + 4];
                if p[3] < 128 {
                    transparent = true;
                } else if i % stride == 0 {
                    out.extend_from_slice(&[p[0], p[1], p[2], 255]);
                }
            }
            Ok((out, transparent))
        })
        .collect::<Result<_, Error>>()?;
    let transparent = samples.iter().any(|s| s.1);
    let mut training: Vec<u8> = samples.into_iter().flat_map(|s| s.0).collect();
    if training.is_empty() {
        training.extend_from_slice(&[0, 0, 0, 255]);
    }
    let colors = if transparent { 255 } else { 256 };
    let mut palette = Palette::train(&training, colors);
    // The transparent entry follows the colors (at most 255 of them).
    palette.transparent = transparent.then_some((palette.rgb.len() / 3) as u8);

    // Pass 2: map and encode, a batch of frames at a time.
    let delay = (opts.delay_ms as f64 / 10.0)
        .round()
        .clamp(1.0, u16::MAX as f64) as u16;
    let mut global = palette.rgb.clone();
    if transparent {
        global.extend_from_slice(&[0, 0, 0]);
    }
    write_atomic(out, |w| {
        let enc_err = |e: gif::EncodingError| match e {
            gif::EncodingError::Io(io) => Error::io(out, io),
            other => Error::Encode {
                path: out.to_path_buf(),
                message: other.to_string(),
            },
        };
        let mut enc =
            gif::Encoder::new(w, width as u16, height as u16, &global).map_err(enc_err)?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(enc_err)?;
        for batch in frames.chunks(BATCH) {
            let mapped: Vec<Vec<u8>> = batch
                .par_iter()
                .map(|p| {
                    let img = read_rgba(p)?;
                    Ok(palette.map(img.as_raw(), width as usize, opts.dither))
                })
                .collect::<Result<_, Error>>()?;
            for indices in mapped {
                let mut f = gif::Frame {
                    width: width as u16,
                    height: height as u16,
                    buffer: std::borrow::Cow::Owned(indices),
                    delay,
                    ..Default::default()
                };
                if let Some(t) = palette.transparent {
                    f.transparent = Some(t);
                    f.dispose = gif::DisposalMethod::Background;
                }
                enc.write_frame(&f).map_err(enc_err)?;
            }
        }
        Ok(())
    })?;
    Ok(GifInfo {
        frames: frames.len(),
        width,
        height,
        colors: global.len() / 3,
        transparent,
    })
}

/// A trained palette and an exact nearest-color search (squared RGB
/// distance) over it.
struct Palette {
    rgb: Vec<u8>,
    /// The index pixels with alpha below 128 get, if any.
    transparent: Option<u8>,
}

impl Palette {
    fn train(rgba: &[u8], colors: usize) -> Palette {
        // Few colors: use them as they are (NeuQuant would blur them).
        let mut distinct = std::collections::BTreeSet::new();
        for p in rgba.chunks_exact(4) {
            distinct.insert([p[0], p[1], p[2]]);
            if distinct.len() > colors {
                break;
            }
        }
        let rgb = if distinct.len() <= colors {
            distinct.into_iter().flatten().collect()
        } else {
            color_quant::NeuQuant::new(10, colors, rgba).color_map_rgb()
        };
        Palette {
            rgb,
            transparent: None,
        }
    }

    fn nearest(&self, c: [i32; 3]) -> u8 {
        let mut best = (i32::MAX, 0usize);
        for (i, p) in self.rgb.chunks_exact(3).enumerate() {
            let d = [0, 1, 2].map(|k| c[k] - p[k] as i32);
            let d = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if d < best.0 {
                best = (d, i);
            }
        }
        best.1 as u8
    }

    /// Palette indices of one RGBA frame (the transparent index where
    /// alpha < 128, when the palette has one).
    fn map(&self, rgba: &[u8], width: usize, dither: GifDither) -> Vec<u8> {
        let n = rgba.len() / 4;
        let mut out = vec![0u8; n];
        let mut cache: HashMap<[u8; 3], u8> = HashMap::new();
        let mut lookup = |c: [i32; 3]| {
            let key = c.map(|v| v.clamp(0, 255) as u8);
            *cache
                .entry(key)
                .or_insert_with(|| self.nearest(key.map(i32::from)))
        };
        let transparent_index = self.transparent;
        match dither {
            GifDither::None | GifDither::Ordered => {
                for i in 0..n {
                    let p = &rgba[i * 4..i * 4 + 4];
                    if p[3] < 128
                        && let Some(t) = transparent_index
                    {
                        out[i] = t;
                        continue;
                    }
                    let mut c = [p[0] as i32, p[1] as i32, p[2] as i32];
                    if dither == GifDither::Ordered {
                        let (x, y) = (i % width, i / width);
                        // Bayer threshold in (-0.5, 0.5), times a step of
                        // about one palette spacing.
                        let t = (BAYER8[y % 8][x % 8] as i32 * 2 - 63) * 12 / 64;
                        c = c.map(|v| v + t);
                    }
                    out[i] = lookup(c);
                }
            }
            GifDither::FloydSteinberg => {
                let height = n / width.max(1);
                let mut err = vec![[0i32; 3]; 2 * (width + 2)];
                for y in 0..height {
                    let (cur, next) = err.split_at_mut(width + 2);
                    next.fill([0; 3]);
                    for x in 0..width {
                        let i = y * width + x;
                        let p = &rgba[i * 4..i * 4 + 4];
                        if p[3] < 128
                            && let Some(t) = transparent_index
                        {
                            out[i] = t;
                            continue;
                        }
                        // Errors in 1/16 units.
                        let e = cur[x + 1];
                        let c = [0, 1, 2].map(|k| p[k] as i32 + e[k] / 16);
                        let idx = lookup(c);
                        out[i] = idx;
                        let q = &self.rgb[idx as usize * 3..idx as usize * 3 + 3];
                        for k in 0..3 {
                            let d = c[k].clamp(0, 255) - q[k] as i32;
                            cur[x + 2][k] += d * 7;
                            next[x][k] += d * 3;
                            next[x + 1][k] += d * 5;
                            next[x + 2][k] += d;
                        }
                    }
                    err.copy_within(width + 2.., 0);
                }
            }
        }
        out
    }
}

const BAYER8: [[u8; 8]; 8] = [
    [0, 32, 8, 40, 2, 34, 10, 42],
    [48, 16, 56, 24, 50, 18, 58, 26],
    [12, 44, 4, 36, 14, 46, 6, 38],
    [60, 28, 52, 20, 62, 30, 54, 22],
    [3, 35, 11, 43, 1, 33, 9, 41],
    [51, 19, 59, 27, 49, 17, 57, 25],
    [15, 47, 7, 39, 13, 45, 5, 37],
    [63, 31, 55, 23, 61, 29, 53, 21],
];

/// A decoded GIF, for tests and checks.
#[derive(Debug)]
pub struct DecodedGif {
    /// Logical screen width.
    pub width: u16,
    /// Logical screen height.
    pub height: u16,
    /// The global palette, RGB bytes.
    pub global_palette: Option<Vec<u8>>,
    /// Whether the animation loops forever (NETSCAPE2.0).
    pub repeat_infinite: bool,
    /// Per frame: delay in centiseconds, whether it has a local palette.
    pub frames: Vec<(u16, bool)>,
}

/// Reads the GIF at `path`: its screen, palette, loop and frames.
pub fn decode(path: &Path) -> Result<DecodedGif, Error> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let bad = |e: gif::DecodingError| Error::asset(path, None, e.to_string());
    let mut dec = opts.read_info(file).map_err(bad)?;
    let mut frames = Vec::new();
    while let Some(f) = dec.read_next_frame().map_err(bad)? {
        frames.push((f.delay, f.palette.is_some()));
    }
    Ok(DecodedGif {
        width: dec.width(),
        height: dec.height(),
        global_palette: dec.global_palette().map(|p| p.to_vec()),
        repeat_infinite: dec.repeat() == gif::Repeat::Infinite,
        frames,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn few_colors_are_kept_exactly_and_dithering_stays_in_range() {
        let mut rgba = Vec::new();
        for i in 0..64u32 {
            let v = (i * 4) as u8;
            rgba.extend_from_slice(&[v, 255 - v, 0, 255]);
        }
        let p = Palette::train(&rgba, 256);
        assert_eq!(p.rgb.len(), 64 * 3);
        for d in [
            GifDither::None,
            GifDither::Ordered,
            GifDither::FloydSteinberg,
        ] {
            let idx = p.map(&rgba, 8, d);
            assert_eq!(idx.len(), 64);
            // Every index names a palette entry (64 here, none transparent).
            assert!(idx.iter().all(|&k| (k as usize) < 64), "{d:?}: {idx:?}");
            if d == GifDither::None {
                for (i, &k) in idx.iter().enumerate() {
                    assert_eq!(
                        &p.rgb[k as usize * 3..k as usize * 3 + 3],
                        &rgba[i * 4..i * 4 + 3]
                    );
                }
            }
        }
    }

    #[test]
    fn transparent_pixels_decode_transparent_with_few_colors() {
        // Two frames of three colors with a transparent left half: the
        // transparent entry must follow the three colors, inside the
        // palette the encoder writes.
        let dir = std::env::temp_dir().join(format!("softraster-gif-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let colors = [[200u8, 30, 30], [30, 200, 30], [30, 30, 200]];
        let frames: Vec<PathBuf> = (0..2)
            .map(|f| {
                let img = image::RgbaImage::from_fn(8, 4, |x, y| {
                    if x < 4 {
                        image::Rgba([0, 0, 0, 0])
                    } else {
                        let c = colors[(x as usize + y as usize + f) % 3];
                        image::Rgba([c[0], c[1], c[2], 255])
                    }
                });
                let p = dir.join(format!("f{f}.png"));
                img.save(&p).unwrap();
                p
            })
            .collect();
        let out = dir.join("t.gif");
        let opts = GifOptions {
            delay_ms: 40,
            dither: GifDither::None,
        };
        let info = assemble(&frames, &out, opts).unwrap();
        assert!(info.transparent);
        assert_eq!(info.colors, 4);
        let mut o = gif::DecodeOptions::new();
        o.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = o.read_info(std::fs::File::open(&out).unwrap()).unwrap();
        let entries = dec.global_palette().unwrap().len() / 3;
        let mut n = 0;
        while let Some(f) = dec.read_next_frame().unwrap() {
            // The transparent index names an entry of the palette written.
            let t = f.transparent.unwrap() as usize;
            assert!(t < entries, "transparent index {t} of {entries} entries");
            for y in 0..4usize {
                for x in 0..8usize {
                    let p = &f.buffer[(y * 8 + x) * 4..(y * 8 + x) * 4 + 4];
                    if x < 4 {
                        assert_eq!(p[3], 0, "frame {n} ({x},{y}) should be transparent");
                    } else {
                        let c = colors[(x + y + n) % 3];
                        assert_eq!(p, &[c[0], c[1], c[2], 255][..], "frame {n} ({x},{y})");
                    }
                }
            }
            n += 1;
        }
        assert_eq!(n, 2);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
