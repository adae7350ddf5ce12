//! KHR_materials_sheen: the retro-reflective fuzz of cloth, a lobe added
//! over the material.
//!
//! The lobe is Zeltner, Burley and Chiang's "Practical multiple-scattering
//! sheen using linearly transformed cosines" (2022), the model Blender's
//! Cycles renders glTF sheen with: a volumetric layer of fibres whose
//! reflection is fitted per (n.v, roughness) by
//!
//!   f_sheen n.l = C R(n.v, r) D(l)
//!   D(l) = Do(M^-1 l / |M^-1 l|) |M^-1| / |M^-1 l|^3,  Do = max(z, 0) / pi
//!   M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]]  in the frame whose x axis is
//!          v projected on the surface, z the normal
//!
//! with C the sheen colour, r its roughness, R the layer's directional
//! albedo and a, b the transform, each given by the paper's closed-form
//! fits (a Gaussian in n.v for R, rational functions for a and b; the
//! ones MaterialX's `mx_microfacet_sheen` uses; Cycles reads them from
//! the tables they were fitted to). D integrates to 1 over the hemisphere,
//! so the layer reflects C R. b < 0 leans the lobe back toward the viewer
//! and toward grazing angles; rough layers (r near 1) reflect a fair share
//! even head-on (R(1, 0.8) = 0.19), smooth ones almost only at grazing
//! angles (R(1, 0.3) = 0.002, R(0.15, 0.3) = 0.33).
//!
//! The layer below is scaled by 1 - max(C) R(n.v) (and by the same at n.l
//! for a light: the smaller of the two, as the extension's albedo scaling
//! says).

use std::f32::consts::PI;

use glam::Vec3;

/// A sheen layer at one point.
#[derive(Debug, Clone, Copy)]
pub struct Sheen {
    /// Linear colour (sheenColorFactor times its texture).
    pub color: Vec3,
    /// Perceptual roughness in [0, 1].
    pub roughness: f32,
}

/// The fits' range of roughness.
const MIN_ROUGHNESS: f32 = 0.01;

impl Sheen {
    fn roughness(&self) -> f32 {
        self.roughness.clamp(MIN_ROUGHNESS, 1.0)
    }

    /// The lobe's BRDF times n.l (no colour), for unit n, v, l: R D(l).
    #[inline]
    pub fn lobe_cos(&self, n: Vec3, v: Vec3, l: Vec3) -> f32 {
        let ndl = n.dot(l);
        if ndl <= 0.0 {
            return 0.0;
        }
        let ndv = n.dot(v).abs().clamp(1e-4, 1.0);
        let r = self.roughness();
        albedo(ndv, r) * ltc(n, v, l, ndv, r)
    }

    /// The share of the light below that the layer leaves towards a
    /// viewer at n.v = `ndv`: 1 - max(C) R(n.v). Cycles layers its sheen
    /// by the view's side alone; the extension's min with the light's
    /// side darkened the sheen cloth against Cycles (0.064 -> 0.036 without
    /// it).
    #[inline]
    pub fn scaling(&self, ndv: f32) -> f32 {
        1.0 - self.color.max_element() * albedo(ndv, self.roughness)
    }
}

/// D(l), the transformed cosine, for unit n, v, l, n.v = `ndv` in (0, 1]
/// and roughness `r` in [0.01, 1].
#[inline]
fn ltc(n: Vec3, v: Vec3, l: Vec3, ndv: f32, r: f32) -> f32 {
    // The frame: x along v's part in the surface (any, head-on).
    let along = v - n * n.dot(v);
    let x = if along.length_squared() > 1e-12 {
        along.normalize()
    } else {
        n.any_orthonormal_vector()
    };
    let y = n.cross(x);
    let w = Vec3::new(l.dot(x), l.dot(y), l.dot(n));
    let (a, b) = transform(ndv, r);
    let wo = Vec3::new(a * w.x + b * w.z, a * w.y, w.z);
    let len2 = wo.length_squared();
    if len2 <= 0.0 {
        return 0.0;
    }
    let k = a / len2;
    wo.z.max(0.0) / PI * k * k
}

/// The inverse transform's a and b at n.v = `x`, roughness `y` (the
/// paper's rational fits).
#[inline]
fn transform(x: f32, y: f32) -> (f32, f32) {
    let a = (2.58126 * x + 0.813703 * y) * y / (1.0 + 0.310327 * x * x + 2.60994 * x * y);
    let b = (1.0 - x).max(0.0).sqrt() * (y - 1.0) * y * y * y
        / (0.000_025_405_3 + 1.71228 * x - 1.71506 * x * y + 1.34174 * y * y);
    (a, b)
}

/// R(n.v, roughness): the layer's directional albedo for C = 1 (the
/// paper's Gaussian fit in n.v, its mean, width and offset rational in
/// the roughness), in [0, 1].
pub fn albedo(ndv: f32, roughness: f32) -> f32 {
    let x = ndv.abs().clamp(0.0, 1.0);
    let y = roughness.clamp(MIN_ROUGHNESS, 1.0);
    let s = y * (0.020_660_7 + 1.58491 * y) / (0.037_942_4 + y * (1.32227 + y));
    let m = y * (-0.193_854 + y * (-1.14885 + y * (1.7932 - 0.95943 * y * y))) / (0.046391 + y);
    let o =
        y * (0.000_654_023 + (-0.020_781_8 + 0.119_681 * y) * y) / (1.26264 + y * (-1.92021 + y));
    let z = (x - m) / s;
    ((-0.5 * z * z).exp() / (s * (2.0 * PI).sqrt()) + o).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lobe's directional albedo by quadrature (`m` x `m` points over
    /// (cos theta, phi), midpoint rule).
    fn integrate(ndv: f32, roughness: f32, m: usize) -> f32 {
        let s = Sheen {
            color: Vec3::ONE,
            roughness,
        };
        let v = Vec3::new((1.0 - ndv * ndv).max(0.0).sqrt(), 0.0, ndv);
        let mut sum = 0.0f64;
        for i in 0..m {
            let mu = (i as f32 + 0.5) / m as f32;
            let r = (1.0 - mu * mu).sqrt();
            for j in 0..m {
                let phi = (j as f32 + 0.5) / m as f32 * 2.0 * PI;
                let l = Vec3::new(r * phi.cos(), r * phi.sin(), mu);
                sum += f64::from(s.lobe_cos(Vec3::Z, v, l));
            }
        }
        (sum * 2.0 * std::f64::consts::PI / (m * m) as f64) as f32
    }

    #[test]
    fn the_transformed_cosine_integrates_to_the_albedo() {
        // D integrates to 1 over the hemisphere, so the lobe reflects R.
        for r in [0.1, 0.3, 0.5, 0.8, 1.0] {
            for ndv in [1.0, 0.7, 0.4, 0.15] {
                let quad = integrate(ndv, r, 400);
                let want = albedo(ndv, r);
                assert!(
                    (quad - want).abs() <= 0.01 * want + 1e-5,
                    "r {r}, n.v {ndv}: {quad} against {want}"
                );
            }
        }
    }

    #[test]
    fn rough_layers_reflect_head_on_and_smooth_ones_at_grazing_angles() {
        // The fits' values (Zeltner et al. 2022), to the digits shown.
        for (ndv, r, want) in [
            (1.0, 0.8, 0.1853),
            (1.0, 0.5, 0.0249),
            (1.0, 0.3, 0.0020),
            (0.15, 0.3, 0.3314),
            (0.4, 0.5, 0.2213),
        ] {
            let got = albedo(ndv, r);
            assert!((got - want).abs() < 1e-4, "n.v {ndv}, r {r}: {got}");
        }
        for r in [0.0, 0.2, 0.6, 1.0] {
            for ndv in [0.0, 0.3, 1.0] {
                assert!((0.0..=1.0).contains(&albedo(ndv, r)));
            }
        }
    }

    #[test]
    fn the_lobe_leans_back_toward_the_viewer() {
        // Seen at 60 degrees, light from the viewer's side outweighs light
        // from the mirror direction (0.232 against 0.184 before R), light
        // from the normal gives less than either (a fibre layer shines at
        // grazing angles), and light from below is none.
        let s = Sheen {
            color: Vec3::ONE,
            roughness: 0.5,
        };
        let v = Vec3::new(0.866, 0.0, 0.5);
        let mirror = Vec3::new(-0.866, 0.0, 0.5);
        let retro = s.lobe_cos(Vec3::Z, v, v);
        let mirrored = s.lobe_cos(Vec3::Z, v, mirror);
        assert!(retro > 1.2 * mirrored, "{retro} {mirrored}");
        assert!(s.lobe_cos(Vec3::Z, v, Vec3::Z) < 0.5 * mirrored);
        assert_eq!(s.lobe_cos(Vec3::Z, v, -Vec3::Z), 0.0);
        // Head on the frame is arbitrary and the lobe symmetric about n.
        let a = s.lobe_cos(Vec3::Z, Vec3::Z, Vec3::new(0.6, 0.0, 0.8));
        let b = s.lobe_cos(Vec3::Z, Vec3::Z, Vec3::new(0.0, -0.6, 0.8));
        assert!((a - b).abs() < 1e-6 * a.max(1.0), "{a} {b}");
    }
}
