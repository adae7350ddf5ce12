//! Emissive surfaces as lights, for `[environment] method = "sampled"`:
//! the frame's emissive triangles, drawn in proportion to the power they
//! emit (luminance times area), each a two-sided Lambertian emitter of
//! one radiance. A path tracer lights a scene with them (a Cornell box's
//! ceiling lamp lights the box); the prefiltered default, like the GPU
//! viewers, shows them without letting them light anything.

use glam::{Vec2, Vec3};

/// One emissive triangle, placed in the world.
#[derive(Debug, Clone, Copy)]
struct Emitter {
    a: Vec3,
    ab: Vec3,
    ac: Vec3,
    /// Unit normal (the emission is two-sided: its sign does not matter).
    normal: Vec3,
    area: f32,
    radiance: Vec3,
}

/// The emissive triangles of one frame.
#[derive(Debug, Clone, Default)]
pub struct Emitters {
    tris: Vec<Emitter>,
    /// Per triangle: the cumulative power of the triangles up to and
    /// including it.
    cdf: Vec<f32>,
    total: f32,
}

/// A point drawn on an emitter: where, its unit normal, its radiance and
/// the density of drawing it per unit area.
#[derive(Debug, Clone, Copy)]
pub struct EmitterPoint {
    pub at: Vec3,
    pub normal: Vec3,
    pub radiance: Vec3,
    pub pdf_area: f32,
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl Emitters {
    /// From world-space triangles and their emitted radiance (linear RGB);
    /// triangles without area or without light are left out.
    pub fn new(triangles: impl IntoIterator<Item = ([Vec3; 3], Vec3)>) -> Emitters {
        let mut out = Emitters::default();
        for ([a, b, c], radiance) in triangles {
            let (ab, ac) = (b - a, c - a);
            let cross = ab.cross(ac);
            let area = 0.5 * cross.length();
            let power = luminance(radiance.max(Vec3::ZERO)) * area;
            if !(power > 0.0 && power.is_finite()) {
                continue;
            }
            out.total += power;
            out.cdf.push(out.total);
            out.tris.push(Emitter {
                a,
                ab,
                ac,
                normal: cross / (2.0 * area),
                area,
                radiance: radiance.max(Vec3::ZERO),
            });
        }
        out
    }

    /// The point `xi` (uniform in [0, 1)^2) selects: a triangle by its
    /// share of the power (xi.x), then a point uniform over its area (the
    /// rest of xi.x within the triangle's share, and xi.y). None without
    /// emitters.
    pub fn sample(&self, xi: Vec2) -> Option<EmitterPoint> {
        let t = xi.x * self.total;
        let i = self
            .cdf
            .partition_point(|&c| c <= t)
            .min(self.tris.len().checked_sub(1)?);
        let e = &self.tris[i];
        let before = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let share = self.cdf[i] - before;
        let u = ((t - before) / share).clamp(0.0, 1.0);
        // Uniform over the triangle: sqrt(u) along a to the far edge.
        let s = u.sqrt();
        let at = e.a + e.ab * (s * (1.0 - xi.y)) + e.ac * (s * xi.y);
        Some(EmitterPoint {
            at,
            normal: e.normal,
            radiance: e.radiance,
            pdf_area: share / self.total / e.area,
        })
    }
}

/// The light point `q` sends towards `p` as the lobe `f_cos` takes it:
/// f cos L cos_q / (d^2 pdf_area), where `visible(l, d)` (the unit
/// direction and the distance to `q`); zero where it is hidden.
pub fn from_emitter(
    q: &EmitterPoint,
    p: Vec3,
    f_cos: &impl Fn(Vec3) -> Vec3,
    visible: impl Fn(Vec3, f32) -> bool,
) -> Vec3 {
    let to = q.at - p;
    let d2 = to.length_squared();
    if d2 <= 0.0 || !d2.is_finite() {
        return Vec3::ZERO;
    }
    let d = d2.sqrt();
    let l = to / d;
    let cos_q = q.normal.dot(l).abs();
    let fc = f_cos(l);
    if cos_q <= 0.0 || fc == Vec3::ZERO || !visible(l, d) {
        return Vec3::ZERO;
    }
    fc * q.radiance * (cos_q / (d2 * q.pdf_area))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_are_drawn_by_power_and_points_cover_them() {
        // Two triangles of one unit square: the first twice as bright.
        let quad = [
            ([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::splat(2.0)),
            ([Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y], Vec3::ONE),
            // Without area or without light: left out.
            ([Vec3::ZERO, Vec3::X, Vec3::X * 2.0], Vec3::ONE),
            ([Vec3::ZERO, Vec3::Z, Vec3::Y], Vec3::ZERO),
        ];
        let e = Emitters::new(quad);
        assert_eq!(e.tris.len(), 2);
        let n = 64;
        let mut first = 0;
        for i in 0..n {
            for j in 0..n {
                let xi = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let p = e.sample(xi).unwrap();
                assert!(p.at.z.abs() < 1e-6 && p.at.x >= -1e-6 && p.at.y >= -1e-6);
                assert!(p.at.x <= 1.0 + 1e-6 && p.at.y <= 1.0 + 1e-6);
                assert_eq!(p.normal.z.abs(), 1.0);
                if p.radiance.x == 2.0 {
                    first += 1;
                    assert!(p.at.x + p.at.y <= 1.0 + 1e-5);
                    // Density: its share (2/3) over its area (1/2).
                    assert!((p.pdf_area - 4.0 / 3.0).abs() < 1e-5);
                }
            }
        }
        // xi.x below 2/3: 43 of the 64 columns.
        assert_eq!(first, 43 * n);
        assert!(Emitters::new([]).sample(Vec2::ZERO).is_none());
    }
}
