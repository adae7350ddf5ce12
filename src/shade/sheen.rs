//! KHR_materials_sheen: the retro-reflective fuzz of cloth, a lobe added
//! over the material.
//!
//!   f_sheen = C D(n.h) V(n.l, n.v)
//!   D = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi)        (Charlie, Estevez and
//!                                                    Kulla 2017), a = r^2
//!   V = 1 / (4 (n.l + n.v - n.l n.v))               (Neubelt and Pettineo)
//!
//! with C the sheen colour and r its roughness. The layer below is scaled
//! by 1 - max(C) E(n.v) (and by the same at n.l for a light: the smaller
//! of the two, as the extension's albedo scaling says), with E(n.v, r) the
//! lobe's directional albedo for C = 1, integrated once into a table.

use std::f32::consts::PI;
use std::sync::OnceLock;

use glam::Vec3;

/// A sheen layer at one point.
#[derive(Debug, Clone, Copy)]
pub struct Sheen {
    /// Linear colour (sheenColorFactor times its texture).
    pub color: Vec3,
    /// Perceptual roughness in [0, 1].
    pub roughness: f32,
}

/// Smallest alpha: the lobe's exponent 1/a stays finite.
const MIN_ALPHA: f32 = 1e-3;

/// Table side (n.v by roughness).
const SIZE: usize = 16;

impl Sheen {
    fn alpha(&self) -> f32 {
        (self.roughness * self.roughness).max(MIN_ALPHA)
    }

    /// The lobe's BRDF times n.l (no colour), for unit n, v, l.
    #[inline]
    pub fn lobe_cos(&self, n: Vec3, v: Vec3, l: Vec3) -> f32 {
        let ndl = n.dot(l);
        if ndl <= 0.0 {
            return 0.0;
        }
        let ndv = n.dot(v).abs().max(1e-4);
        let h = (l + v).normalize_or_zero();
        lobe(self.alpha(), n.dot(h), ndl, ndv) * ndl
    }

    /// The share of the light below that the layer leaves, towards `v`
    /// (and from `l` for a light): 1 - max(C) E.
    #[inline]
    pub fn scaling(&self, ndv: f32, ndl: Option<f32>) -> f32 {
        let m = self.color.max_element();
        let at = |c: f32| 1.0 - m * albedo(c, self.roughness);
        match ndl {
            Some(ndl) => at(ndv).min(at(ndl)),
            None => at(ndv),
        }
    }
}

/// D V for the given cosines (n.h, n.l, n.v) and alpha.
#[inline]
fn lobe(a: f32, ndh: f32, ndl: f32, ndv: f32) -> f32 {
    let inv = 1.0 / a;
    let sin2 = (1.0 - ndh * ndh).max(0.0);
    let d = (2.0 + inv) * sin2.powf(0.5 * inv) / (2.0 * PI);
    let v = 1.0 / (4.0 * (ndl + ndv - ndl * ndv)).max(1e-4);
    d * v
}

/// E(n.v, roughness): the lobe's directional albedo (C = 1), from the table
/// (bilinear).
pub fn albedo(ndv: f32, roughness: f32) -> f32 {
    let t = table();
    let x = ndv.abs().clamp(0.0, 1.0) * (SIZE - 1) as f32;
    let y = roughness.clamp(0.0, 1.0) * (SIZE - 1) as f32;
    let (x0, y0) = ((x as usize).min(SIZE - 2), (y as usize).min(SIZE - 2));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |i: usize, j: usize| t[j * SIZE + i];
    let top = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * fx;
    let bottom = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * fx;
    top + (bottom - top) * fy
}

/// The albedo table, integrated on first use by a midpoint rule over the
/// hemisphere (cos theta, phi), 64 x 64 points per entry.
fn table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..SIZE * SIZE)
            .map(|i| {
                let (ix, iy) = (i % SIZE, i / SIZE);
                let ndv = (ix as f32 / (SIZE - 1) as f32).max(1e-3);
                let roughness = iy as f32 / (SIZE - 1) as f32;
                integrate(ndv, roughness, 64)
            })
            .collect()
    })
}

/// The lobe's directional albedo by quadrature (`m` x `m` points).
fn integrate(ndv: f32, roughness: f32, m: usize) -> f32 {
    let s = Sheen {
        color: Vec3::ONE,
        roughness,
    };
    let n = Vec3::Z;
    let v = Vec3::new((1.0 - ndv * ndv).max(0.0).sqrt(), 0.0, ndv);
    let mut sum = 0.0f64;
    for i in 0..m {
        let mu = (i as f32 + 0.5) / m as f32;
        let r = (1.0 - mu * mu).sqrt();
        for j in 0..m {
            let phi = (j as f32 + 0.5) / m as f32 * 2.0 * PI;
            let l = Vec3::new(r * phi.cos(), r * phi.sin(), mu);
            sum += s.lobe_cos(n, v, l) as f64;
        }
    }
    (sum * 2.0 * PI as f64 / (m * m) as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_head_on_albedo_at_roughness_half_is_the_value_the_render_test_expects() {
        // `tests/it/gltf.rs` (KHR_materials_sheen) checks a rendered cube
        // face against this number.
        assert!((albedo(1.0, 0.5) - 0.031_526_58).abs() < 1e-7);
    }

    #[test]
    fn albedo_is_bounded_and_grows_towards_grazing_views() {
        for r in [0.1, 0.3, 0.6, 1.0] {
            let head_on = albedo(1.0, r);
            let grazing = albedo(0.1, r);
            assert!(head_on > 0.0 && head_on < 1.0, "{r}: {head_on}");
            assert!(grazing > head_on, "{r}: {grazing} <= {head_on}");
            assert!(grazing <= 1.0, "{r}: {grazing}");
            // The table agrees with a finer quadrature between its entries.
            for ndv in [0.23, 0.71] {
                let fine = integrate(ndv, r, 160);
                assert!((albedo(ndv, r) - fine).abs() < 0.02, "{r} {ndv}: {fine}");
            }
        }
    }
}
