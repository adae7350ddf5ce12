//! Perspective-correct interpolation. Screen-space barycentrics come from the
//! edge functions (exact integers); dividing the interpolated attribute/w by
//! the interpolated 1/w gives the barycentrics in the original (unclipped)
//! triangle, which the shading stage applies to any vertex attribute.
//!
//! With E_k the edge function opposite vertex k (proportional to the screen
//! barycentric, the common factor cancels):
//!
//!   g_k = E_k / w_k,   lambda = sum_k g_k bary_k / sum_k g_k,   w = area2 / sum_k g_k

use glam::Vec3;

use super::setup::{Edge, Tri};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment {
    /// Barycentric coordinates in the original triangle (sum to 1).
    pub lambda: Vec3,
    /// w at the fragment: the distance along the view axis for perspective
    /// cameras (1 for orthographic).
    pub w: f32,
}

/// A triangle prepared for interpolation at many pixels (the shading loop
/// keeps one per run of pixels from the same triangle).
#[derive(Debug, Clone, Copy)]
pub struct Interpolator {
    edges: [Edge; 3],
    inv_w: [f64; 3],
    /// Rows: barycentrics of each vertex in the original triangle; None when
    /// the triangle was not clipped (identity).
    bary: Option<[[f64; 3]; 3]>,
    area2: f64,
}

impl Interpolator {
    #[inline]
    pub fn new(t: &Tri) -> Interpolator {
        let identity = t.bary == [Vec3::X, Vec3::Y, Vec3::Z];
        Interpolator {
            edges: t.edges(),
            inv_w: t.inv_w.map(f64::from),
            bary: (!identity).then(|| t.bary.map(|b| b.to_array().map(f64::from))),
            area2: t.area2 as f64,
        }
    }

    /// At the center of pixel (px, py); also valid outside the triangle
    /// (extrapolation), as neighbours for derivatives need.
    #[inline]
    pub fn at_pixel(&self, px: i32, py: i32) -> Fragment {
        let (x, y) = (px as i64, py as i64);
        let e = &self.edges;
        let g = [
            e[0].at(x, y) as f64 * self.inv_w[0],
            e[1].at(x, y) as f64 * self.inv_w[1],
            e[2].at(x, y) as f64 * self.inv_w[2],
        ];
        self.finish(g)
    }

    /// Whether the center of pixel (px, py) is inside the triangle (top-left
    /// rule).
    #[inline]
    pub fn covers_center(&self, px: i32, py: i32) -> bool {
        let (x, y) = (px as i64, py as i64);
        self.edges.iter().all(|e| e.at(x, y) + e.bias >= 0)
    }

    /// At any screen position (x, y) in pixels (pixel centers at +0.5).
    pub fn at(&self, x: f64, y: f64) -> Fragment {
        // E_k(x, y) = a (x - 1/2) + b (y - 1/2) + c, with a and b per pixel.
        let e = |k: usize| {
            let e = &self.edges[k];
            e.a as f64 * (x - 0.5) + e.b as f64 * (y - 0.5) + e.c as f64
        };
        self.finish([
            e(0) * self.inv_w[0],
            e(1) * self.inv_w[1],
            e(2) * self.inv_w[2],
        ])
    }

    #[inline]
    fn finish(&self, g: [f64; 3]) -> Fragment {
        let sum = g[0] + g[1] + g[2];
        let inv = 1.0 / sum;
        let k = [g[0] * inv, g[1] * inv, g[2] * inv];
        let lambda = match &self.bary {
            None => Vec3::new(k[0] as f32, k[1] as f32, k[2] as f32),
            Some(b) => {
                let lam = |c: usize| k[0] * b[0][c] + k[1] * b[1][c] + k[2] * b[2][c];
                Vec3::new(lam(0) as f32, lam(1) as f32, lam(2) as f32)
            }
        };
        Fragment {
            lambda,
            // sum = area2 * (1/w) interpolated, in edge-function units.
            w: (self.area2 / sum) as f32,
        }
    }
}

/// Interpolates at the center of pixel (px, py).
#[cfg(test)]
pub fn at_pixel(t: &Tri, px: i32, py: i32) -> Fragment {
    Interpolator::new(t).at_pixel(px, py)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::CullMode;
    use crate::raster::clip::ClipVertex;
    use crate::raster::setup::{Viewport, setup};
    use glam::Vec4;

    #[test]
    fn pixel_and_point_forms_agree_and_weights_sum_to_one() {
        let v = |x: f32, y: f32, w: f32, b: Vec3| ClipVertex {
            pos: Vec4::new(x * w, y * w, 0.5 * w, w),
            bary: b,
        };
        let t = setup(
            [
                v(-0.9, -0.8, 1.0, Vec3::new(0.2, 0.3, 0.5)),
                v(0.7, -0.6, 3.0, Vec3::Y),
                v(-0.2, 0.9, 7.0, Vec3::Z),
            ],
            Viewport {
                width: 32,
                height: 32,
                msaa: false,
            },
            CullMode::None,
            0,
            0,
        )
        .unwrap();
        let it = Interpolator::new(&t);
        for (px, py) in [(3, 20), (10, 10), (16, 5), (40, -3)] {
            let a = it.at_pixel(px, py);
            let b = it.at(px as f64 + 0.5, py as f64 + 0.5);
            assert!((a.lambda - b.lambda).abs().max_element() < 1e-6);
            assert!((a.w - b.w).abs() < 1e-5 * a.w.abs());
            assert!((a.lambda.element_sum() - 1.0).abs() < 1e-5);
        }
    }
}
