//! Image comparison for golden tests: per-channel absolute differences,
//! a pass/fail under a stated tolerance, and a diff image that shows where.

use super::Image8;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// A pixel differs when any channel differs by more than this (0-255).
    pub channel: u8,
    /// The images match when at most this fraction of pixels differ.
    pub fraction: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    pub max_channel_diff: u8,
    pub mean_abs_diff: f64,
    pub differing_pixels: usize,
    pub pixels: usize,
}

impl Comparison {
    pub fn passes(&self, t: Tolerance) -> bool {
        self.differing_pixels as f64 <= t.fraction * self.pixels as f64
    }
}

/// None when the sizes or channel counts differ.
pub fn compare(a: &Image8, b: &Image8, t: Tolerance) -> Option<(Comparison, Image8)> {
    if a.width != b.width || a.height != b.height || a.channels != b.channels {
        return None;
    }
    let ch = a.channels as usize;
    let mut max = 0u8;
    let mut sum = 0u64;
    let mut differing = 0;
    let mut diff = Vec::with_capacity(a.data.len() / ch * 3);
    for (pa, pb) in a.data.chunks_exact(ch).zip(b.data.chunks_exact(ch)) {
        let d = pa
            .iter()
            .zip(pb)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        sum += pa
            .iter()
            .zip(pb)
            .map(|(x, y)| x.abs_diff(*y) as u64)
            .sum::<u64>();
        max = max.max(d);
        if d > t.channel {
            differing += 1;
            diff.extend_from_slice(&[255, 0, 255]);
        } else {
            // Faint grey copy of the reference for orientation.
            let g = pa[..3.min(ch)].iter().map(|v| *v as u32).sum::<u32>() / 3.min(ch) as u32;
            let g = (g / 4) as u8 + d.saturating_mul(8);
            diff.extend_from_slice(&[g, g, g]);
        }
    }
    let pixels = (a.width * a.height) as usize;
    Some((
        Comparison {
            max_channel_diff: max,
            mean_abs_diff: sum as f64 / a.data.len().max(1) as f64,
            differing_pixels: differing,
            pixels,
        },
        Image8 {
            width: a.width,
            height: a.height,
            channels: 3,
            data: diff,
        },
    ))
}
