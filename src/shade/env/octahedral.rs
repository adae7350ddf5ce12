//! Square octahedral maps of directions (+Y at the centre, -Y folded into
//! the corners): the Blinn-Phong materials' levels (`EnvLight::
//! with_phong_roughness`). A lookup is a few sums and one division where
//! the lat-long image needs two arc tangents and a square root; the levels
//! are smooth (roughness 0.1 and up), so resampling them into this layout
//! costs no visible detail. One direction and four (`simd::V3`) by the same
//! operations, lane by lane.

use glam::{Vec2, Vec3, Vec3A};

use crate::simd::{Lane, V3};

/// A `size` x `size` octahedral map, stored with a border of one texel
/// that repeats the texels across each edge (the map's edges fold onto
/// themselves mirrored), so bilinear lookups need no case at the edges.
#[derive(Debug, Clone)]
pub(super) struct Octahedral {
    size: usize,
    /// (size + 2)^2 texels, row by row, the border included.
    texels: Vec<Vec3A>,
}

/// The fold of the lower hemisphere: (1 - |b|) sign(a), per coordinate.
#[inline(always)]
fn fold<L: Lane>(a: L, b: L) -> L {
    (L::splat(1.0) - b.abs()) * a.signum()
}

/// Map coordinates in [0, 1]^2 of each lane's direction `d` (any
/// length): (u, v); zero or non-finite directions read the centre (+Y).
#[inline(always)]
pub(super) fn encode<L: Lane>(d: V3<L>) -> (L, L) {
    let s = d.x.abs() + d.y.abs() + d.z.abs();
    let ok = s.cmpgt(L::splat(0.0)) & s.is_finite();
    let (px, pz) = (d.x / s, d.z / s);
    let below = d.y.cmplt(L::splat(0.0));
    let (px, pz) = (
        L::select(below, fold(px, pz), px),
        L::select(below, fold(pz, px), pz),
    );
    let half = L::splat(0.5);
    (
        L::select(ok, px * half + half, half),
        L::select(ok, pz * half + half, half),
    )
}

/// The unit direction at map coordinates `uv` (the inverse of `encode`).
pub(super) fn decode(uv: Vec2) -> Vec3 {
    let (mut px, mut pz) = (uv.x * 2.0 - 1.0, uv.y * 2.0 - 1.0);
    let y = 1.0 - px.abs() - pz.abs();
    if y < 0.0 {
        (px, pz) = (fold(px, pz), fold(pz, px));
    }
    Vec3::new(px, y, pz).normalize_or(Vec3::Y)
}

impl Octahedral {
    /// A map whose texel centres hold `f` of their directions.
    pub fn from_fn(size: usize, f: impl Fn(Vec3) -> Vec3A) -> Octahedral {
        let n = size.max(2);
        let inner: Vec<Vec3A> = (0..n * n)
            .map(|i| {
                let uv = Vec2::new(
                    ((i % n) as f32 + 0.5) / n as f32,
                    ((i / n) as f32 + 0.5) / n as f32,
                );
                f(decode(uv))
            })
            .collect();
        // Across an edge the map continues mirrored: the texel beyond
        // (x, -1) is (n-1-x, 0), beyond (-1, y) is (0, n-1-y), and the
        // corners meet the opposite corners.
        let last = n as i64 - 1;
        let texels = (0..(n + 2) * (n + 2))
            .map(|i| {
                let (mut x, mut y) = ((i % (n + 2)) as i64 - 1, (i / (n + 2)) as i64 - 1);
                if x < 0 || x > last {
                    x = x.clamp(0, last);
                    y = last - y;
                }
                if y < 0 || y > last {
                    y = y.clamp(0, last);
                    x = last - x;
                }
                inner[(y.clamp(0, last) * n as i64 + x.clamp(0, last)) as usize]
            })
            .collect();
        Octahedral { size: n, texels }
    }

    /// Bilinear lookup at map coordinates (u, v), clamped to the edges.
    #[inline(always)]
    pub(super) fn at(&self, u: f32, v: f32) -> Vec3A {
        let n = self.size;
        // In the bordered grid: texel k of the map is at k + 1, and u in
        // [0, 1] gives x in [0.5, n + 0.5].
        let hi = n as f32;
        let x = (u * n as f32 + 0.5).clamp(0.0, hi);
        let y = (v * n as f32 + 0.5).clamp(0.0, hi);
        // x, y >= 0 (a NaN clamps to NaN and converts to 0): truncation
        // is floor, and x0 + 1, y0 + 1 <= n + 1 stay inside.
        let (x0, y0) = (x as usize, y as usize);
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let (x1, y1) = (x0 + 1, y0 + 1);
        let stride = n + 2;
        let t = |x: usize, y: usize| self.texels[y * stride + x];
        let top = t(x0, y0).lerp(t(x1, y0), fx);
        let bottom = t(x0, y1).lerp(t(x1, y1), fx);
        top.lerp(bottom, fy)
    }

    /// The map along direction `d`.
    #[cfg(test)]
    pub fn sample(&self, d: Vec3) -> Vec3A {
        let (u, v) = encode(V3::<f32>::from(d));
        self.at(u, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::F8;
    use glam::Vec4;

    #[test]
    fn directions_round_trip_and_every_width_encodes_as_one() {
        let mut unit = crate::testing::xorshift(0x2545_f491_4f6c_dd1d);
        let mut next = || unit() * 2.0 - 1.0;
        let mut dirs: Vec<Vec3> = (0..40_000)
            .map(|_| Vec3::new(next(), next(), next()))
            .collect();
        let odd = [0.0, -0.0, 1.0, -1.0, 1e-30, 3e38, f32::INFINITY, f32::NAN];
        for x in odd {
            for y in odd {
                for z in odd {
                    dirs.push(Vec3::new(x, y, z));
                }
            }
        }
        for q in dirs.chunks_exact(8) {
            let (u8, v8) = encode(V3::<F8>::from_fn(|k| q[k]));
            let (u4, v4) = encode(V3::<Vec4>::from_fn(|k| q[k + 4]));
            for k in 0..8 {
                let (u, v) = encode(V3::<f32>::from(q[k]));
                let bits = (u.to_bits(), v.to_bits());
                assert_eq!(bits, (u8.lane(k).to_bits(), v8.lane(k).to_bits()));
                if k >= 4 {
                    assert_eq!(bits, (u4[k - 4].to_bits(), v4[k - 4].to_bits()));
                }
                assert!((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v));
                if let Some(d) = q[k].try_normalize() {
                    let back = decode(Vec2::new(u, v));
                    assert!(back.dot(d) > 1.0 - 1e-5, "{d} -> {u} {v} -> {back}");
                }
            }
        }
    }

    #[test]
    fn a_smooth_function_reads_back_through_the_map() {
        // A smooth field of directions, as a prefiltered level is.
        let f = |d: Vec3| Vec3A::new(1.0 + d.x, 2.0 + d.y * d.z, 1.5 - 0.5 * d.z);
        let map = Octahedral::from_fn(64, f);
        let mut worst = 0.0f32;
        for i in 0..2000 {
            let t = i as f32 * 0.618;
            let d = Vec3::new(t.sin() * (t * 0.37).cos(), (t * 1.3).cos(), t.cos()).normalize();
            worst = worst.max((map.sample(d) - f(d)).abs().max_element());
        }
        // The layout is creased along the equator (the diamond's edges),
        // where bilinear weights are off by up to half a texel: the field
        // changes by up to 1.4 per radian, a texel spans 0.035 radians.
        assert!(worst < 0.03, "{worst}");
    }
}
