//! Perspective-correct interpolation. Screen-space barycentrics come from the
//! edge functions (exact integers); dividing the interpolated attribute/w by
//! the interpolated 1/w gives the barycentrics in the original (unclipped)
//! triangle, which the shading stage applies to any vertex attribute.

use glam::Vec3;

use super::setup::{SUBPIXEL, Tri};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment {
    /// Barycentric coordinates in the original triangle (sum to 1).
    pub lambda: Vec3,
    /// w at the fragment: the distance along the view axis for perspective
    /// cameras (1 for orthographic).
    pub w: f32,
}

/// Interpolates at screen position (x, y) in pixels (pixel centers at +0.5).
/// Also valid outside the triangle (extrapolation), as helper pixels and
/// derivatives need.
#[inline]
pub fn at(t: &Tri, x: f64, y: f64) -> Fragment {
    let s = SUBPIXEL as f64;
    let (px, py) = (x * s, y * s);
    let fx = t.x.map(|v| v as f64);
    let fy = t.y.map(|v| v as f64);
    let edge = |a: usize, b: usize| (fx[b] - fx[a]) * (py - fy[a]) - (fy[b] - fy[a]) * (px - fx[a]);
    let inv_area = 1.0 / t.area2 as f64;
    let b = [
        edge(1, 2) * inv_area,
        edge(2, 0) * inv_area,
        edge(0, 1) * inv_area,
    ];
    let iw = [t.inv_w[0] as f64, t.inv_w[1] as f64, t.inv_w[2] as f64];
    let inv_w = b[0] * iw[0] + b[1] * iw[1] + b[2] * iw[2];
    let k = [
        b[0] * iw[0] / inv_w,
        b[1] * iw[1] / inv_w,
        b[2] * iw[2] / inv_w,
    ];
    let lam = |c: usize| {
        k[0] * t.bary[0][c] as f64 + k[1] * t.bary[1][c] as f64 + k[2] * t.bary[2][c] as f64
    };
    Fragment {
        lambda: Vec3::new(lam(0) as f32, lam(1) as f32, lam(2) as f32),
        w: (1.0 / inv_w) as f32,
    }
}

/// Interpolates at the center of pixel (px, py).
#[inline]
pub fn at_pixel(t: &Tri, px: i32, py: i32) -> Fragment {
    at(t, px as f64 + 0.5, py as f64 + 0.5)
}
