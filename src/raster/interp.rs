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
    /// (Inlined, so that a cache slot is written from registers, not
    /// copied from a return slot just written.)
    #[inline(always)]
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
        let [f] = self.finish(self.edges.map(|e| [e.at(x, y)]));
        f
    }

    /// At the centers of the 2x2 quad whose top-left pixel is (px, py), in
    /// reading order, with whether the triangle covers each center: what
    /// `at_pixel` and `covers_center` give at each pixel, the edge values
    /// stepped by `a` and `b` (the same integers) and the rest four lanes
    /// at a time.
    #[inline]
    pub fn at_quad(&self, px: i32, py: i32) -> ([Fragment; 4], [bool; 4]) {
        let (x, y) = (px as i64, py as i64);
        let quad = |e: &Edge| {
            let e0 = e.at(x, y);
            [e0, e0 + e.a, e0 + e.b, e0 + e.a + e.b]
        };
        // Written out, not `array::map`: that call is left out of line,
        // and this runs once per quad.
        let [e0, e1, e2] = &self.edges;
        let e = [quad(e0), quad(e1), quad(e2)];
        let covers = std::array::from_fn(|p| (0..3).all(|k| e[k][p] + self.edges[k].bias >= 0));
        (self.finish(e), covers)
    }

    /// Which of `at_quad(q0)`'s four results is pixel (px, py)'s (a pixel
    /// of that quad).
    #[inline(always)]
    pub fn quad_lane(q0: (i32, i32), px: i32, py: i32) -> usize {
        debug_assert!((0..2).contains(&(px - q0.0)) && (0..2).contains(&(py - q0.1)));
        ((px - q0.0) + 2 * (py - q0.1)) as usize
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
        let [f] = self.finish_g([0, 1, 2].map(|k| [e(k) * self.inv_w[k]]));
        f
    }

    /// From integer edge values, per lane. (Loops, not `array::map`, here
    /// and in `finish_g`: the compiler leaves `map` out of line, and these
    /// run once per quad.)
    #[inline(always)]
    fn finish<const N: usize>(&self, e: [[i64; N]; 3]) -> [Fragment; N] {
        let mut g = [[0.0; N]; 3];
        for k in 0..3 {
            for p in 0..N {
                g[k][p] = e[k][p] as f64 * self.inv_w[k];
            }
        }
        self.finish_g(g)
    }

    /// From the edge values over w (`g`), per lane: each lane computes
    /// alone what one fragment would.
    #[inline(always)]
    fn finish_g<const N: usize>(&self, g: [[f64; N]; 3]) -> [Fragment; N] {
        let mut sum = [0.0; N];
        let mut k = [[0.0; N]; 3];
        for p in 0..N {
            sum[p] = g[0][p] + g[1][p] + g[2][p];
            let inv = 1.0 / sum[p];
            for c in 0..3 {
                k[c][p] = g[c][p] * inv;
            }
        }
        let lambda = match &self.bary {
            None => k,
            Some(b) => {
                let mut l = [[0.0; N]; 3];
                for c in 0..3 {
                    for p in 0..N {
                        l[c][p] = k[0][p] * b[0][c] + k[1][p] * b[1][c] + k[2][p] * b[2][c];
                    }
                }
                l
            }
        };
        std::array::from_fn(|p| Fragment {
            lambda: Vec3::new(
                lambda[0][p] as f32,
                lambda[1][p] as f32,
                lambda[2][p] as f32,
            ),
            // sum = area2 * (1/w) interpolated, in edge-function units.
            w: (self.area2 / sum[p]) as f32,
        })
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

    /// `at_quad` steps the edge values and works four lanes at a time;
    /// each of its pixels must be bit for bit what `at_pixel` and
    /// `covers_center` give there, on clipped and unclipped triangles,
    /// inside, on the edges of and far outside them; `quad_lane` names
    /// which result is which pixel's.
    #[test]
    fn a_quad_is_its_four_pixels() {
        let mut seed = 0x2545_f491_u32;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32
        };
        let vp = Viewport {
            width: 64,
            height: 48,
            msaa: true,
        };
        let (mut tested, mut on_edge) = ([0; 2], 0);
        for i in 0..300 {
            // The first third's corners on pixel centers (w a power of
            // two), so that edges run through centers: the top-left rule.
            let snap = i < 100;
            // Unclipped (the identity) or a part of a clipped triangle.
            let b = if rnd() < 0.5 {
                Vec3::X
            } else {
                Vec3::new(0.2, 0.3, 0.5)
            };
            let mut v = |b: Vec3| {
                let (w, x, y) = if snap {
                    let center = |n: f32, r: f32| ((n * r).floor() + 0.5) / (n / 2.0) - 1.0;
                    let w = [0.5, 1.0, 2.0, 4.0][(4.0 * rnd()) as usize % 4];
                    (w, center(64.0, rnd()), center(48.0, rnd()))
                } else {
                    (0.2 + 8.0 * rnd(), 2.4 * rnd() - 1.2, 2.4 * rnd() - 1.2)
                };
                ClipVertex {
                    pos: Vec4::new(x * w, y * w, 0.5 * w, w),
                    bary: b,
                }
            };
            let corners = [v(b), v(Vec3::Y), v(Vec3::Z)];
            let Some(t) = setup(corners, vp, CullMode::None, 0, 0) else {
                continue;
            };
            let it = Interpolator::new(&t);
            tested[it.bary.is_some() as usize] += 1;
            for py in (-3..52).step_by(3) {
                for px in (-5..70).step_by(3) {
                    let (f, covered) = it.at_quad(px, py);
                    let pixels = [(px + 1, py + 1), (px, py + 1), (px + 1, py), (px, py)];
                    for (x, y) in pixels {
                        let k = Interpolator::quad_lane((px, py), x, y);
                        let one = it.at_pixel(x, y);
                        assert_eq!(
                            f[k].lambda.to_array().map(f32::to_bits),
                            one.lambda.to_array().map(f32::to_bits)
                        );
                        assert_eq!(f[k].w.to_bits(), one.w.to_bits());
                        assert_eq!(covered[k], it.covers_center(x, y), "({x}, {y})");
                        let (x, y) = (x as i64, y as i64);
                        on_edge += it.edges.iter().any(|e| e.at(x, y) + e.bias == 0) as u32;
                    }
                }
            }
        }
        assert!(tested[0] > 50 && tested[1] > 50, "{tested:?}");
        assert!(on_edge > 100, "{on_edge}");
    }
}
