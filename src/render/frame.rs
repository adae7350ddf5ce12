//! The frame buffers a render fills, and the supersampling resolve that
//! turns a frame rendered `k` times larger per axis into the output size.

use super::display::PlainBackground;
use glam::{Vec3, Vec4};
use rayon::prelude::*;

/// A rendered frame in linear space, before tone mapping.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB and coverage alpha per pixel, row-major from the top.
    /// For the data views (normals, depth, wireframe) RGB is already the
    /// display value.
    pub color: Vec<Vec4>,
    /// Distance along the view axis at the pixel center; +inf where nothing
    /// was drawn.
    pub depth: Vec<f32>,
    /// Ambient occlusion at the pixel center (1: unoccluded, and where
    /// nothing was drawn); empty unless the scene selects an AO method.
    pub ao: Vec<f32>,
    /// The surface data passes (normal, albedo, position, ids) of the
    /// nearest fragment per pixel; empty unless the scene writes one.
    pub aov: Vec<AovPixel>,
    /// Stops the display transform applies (`display::resolve`): the
    /// exposure of the shot rendered into the frame.
    pub exposure: f32,
}

/// What the data passes record of a pixel's nearest fragment: the one its
/// depth comes from. Background (and the ground shadow catcher): zeros.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AovPixel {
    /// World-space unit shading normal (normal maps applied), facing the
    /// camera.
    pub normal: Vec3,
    /// The material's base colour after textures, linear (Kd, or glTF's
    /// base colour, times vertex colours).
    pub albedo: Vec3,
    /// World-space position.
    pub position: Vec3,
    /// 1 + the model's index; 0: none.
    pub object: u32,
    /// 1 + the material's index in the scene (models' materials in order);
    /// 0: none.
    pub material: u32,
}

/// Frames rendered one after another into one buffer that only the
/// renderer writes (`Renderer::render_next`; `frame` reads it). Per band
/// of rows it remembers the plain background the last frame left (its
/// colour and the columns outside which the band holds only that colour
/// at infinite depth), so that the next frame fills only the columns that
/// changed instead of the whole band again.
pub struct FrameSequence {
    frame: Frame,
    /// Per band of the last frame, where known.
    known: Vec<Option<PlainBackground>>,
}

impl Default for FrameSequence {
    fn default() -> FrameSequence {
        FrameSequence::new()
    }
}

impl FrameSequence {
    /// An empty sequence: its first frame fills the whole buffer.
    pub fn new() -> FrameSequence {
        FrameSequence {
            frame: Frame::new(0, 0),
            known: Vec::new(),
        }
    }

    /// The last frame rendered.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// The buffer and what is known of it, for the renderer.
    pub(super) fn parts(&mut self) -> (&mut Frame, &mut Vec<Option<PlainBackground>>) {
        (&mut self.frame, &mut self.known)
    }
}

impl AovPixel {
    /// A pixel no surface covers.
    pub const EMPTY: AovPixel = AovPixel {
        normal: Vec3::ZERO,
        albedo: Vec3::ZERO,
        position: Vec3::ZERO,
        object: 0,
        material: 0,
    };
}

impl Frame {
    /// A frame of `width` x `height` background pixels (a renderer resizes
    /// it to the scene's output size).
    pub fn new(width: u32, height: u32) -> Frame {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            color: vec![Vec4::ZERO; n],
            depth: vec![f32::INFINITY; n],
            ao: Vec::new(),
            aov: Vec::new(),
            exposure: 0.0,
        }
    }

    pub(super) fn resize(&mut self, width: u32, height: u32) {
        let n = width as usize * height as usize;
        self.width = width;
        self.height = height;
        self.color.resize(n, Vec4::ZERO);
        self.depth.resize(n, f32::INFINITY);
    }
}

/// Box filter of `k` x `k` blocks: the mean color (linear, before tone
/// mapping) and AO, the nearest depth.
pub(super) fn downsample(big: &Frame, k: u32, out: &mut Frame) {
    let (w, h) = (big.width / k, big.height / k);
    out.resize(w, h);
    let k = k as usize;
    let bw = big.width as usize;
    let inv = 1.0 / (k * k) as f32;
    let has_ao = !big.ao.is_empty();
    if has_ao {
        out.ao.resize(w as usize * h as usize, 1.0);
    } else {
        out.ao.clear();
    }
    let w = w as usize;
    out.color
        .par_chunks_mut(w)
        .zip(out.depth.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (color, depth))| {
            for x in 0..w {
                let mut c = Vec4::ZERO;
                let mut d = f32::INFINITY;
                for sy in 0..k {
                    let row = (y * k + sy) * bw + x * k;
                    for sx in 0..k {
                        c += big.color[row + sx];
                        d = d.min(big.depth[row + sx]);
                    }
                }
                color[x] = c * inv;
                depth[x] = d;
            }
        });
    if big.aov.is_empty() {
        out.aov.clear();
    } else {
        // The data of the block's nearest pixel (no blending).
        out.aov.resize(w * h as usize, AovPixel::EMPTY);
        out.aov.par_chunks_mut(w).enumerate().for_each(|(y, aov)| {
            for (x, a) in aov.iter_mut().enumerate() {
                let mut best = (f32::INFINITY, AovPixel::EMPTY);
                for sy in 0..k {
                    let row = (y * k + sy) * bw + x * k;
                    for sx in 0..k {
                        if big.depth[row + sx] < best.0 {
                            best = (big.depth[row + sx], big.aov[row + sx]);
                        }
                    }
                }
                *a = best.1;
            }
        });
    }
    if has_ao {
        out.ao.par_chunks_mut(w).enumerate().for_each(|(y, ao)| {
            for (x, a) in ao.iter_mut().enumerate() {
                let mut sum = 0.0;
                for sy in 0..k {
                    let row = (y * k + sy) * bw + x * k;
                    sum += big.ao[row..row + k].iter().sum::<f32>();
                }
                *a = sum * inv;
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn downsample_averages_color_and_ao_and_keeps_the_nearest_depth() {
        let mut big = Frame::new(4, 2);
        for (i, c) in big.color.iter_mut().enumerate() {
            *c = Vec4::splat(i as f32);
        }
        big.depth = vec![5.0, 4.0, f32::INFINITY, 9.0, 3.0, 6.0, 8.0, 7.0];
        big.ao = vec![1.0, 0.0, 0.5, 0.5, 1.0, 1.0, 0.0, 0.0];
        let mut out = Frame::new(0, 0);
        downsample(&big, 2, &mut out);
        assert_eq!((out.width, out.height), (2, 1));
        // Block 0 holds pixels 0, 1, 4, 5; block 1 holds 2, 3, 6, 7.
        assert_eq!(out.color, vec![Vec4::splat(2.5), Vec4::splat(4.5)]);
        assert_eq!(out.depth, vec![3.0, 7.0]);
        assert_eq!(out.ao, vec![0.75, 0.25]);
    }
}
