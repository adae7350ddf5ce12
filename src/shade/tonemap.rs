//! From linear radiance to display bytes: exposure, tone map (clamp,
//! Reinhard, ACES), sRGB encoding through a 64K-entry table (accurate to a
//! twentieth of a code, and a table lookup instead of a `powf` per channel).

use std::sync::OnceLock;

use glam::Vec3;

use crate::assets::texture::linear_to_srgb;
use crate::scene::desc::Tonemap;

#[inline]
pub fn tonemap(c: Vec3, op: Tonemap, exposure_scale: f32) -> Vec3 {
    let c = c * exposure_scale;
    match op {
        Tonemap::Clamp => c,
        Tonemap::Reinhard => c / (Vec3::ONE + c),
        Tonemap::Aces => {
            // Narkowicz's fit of the ACES filmic curve.
            let (a, b, cc, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
            (c * (c * a + b)) / (c * (c * cc + d) + e)
        }
    }
    .clamp(Vec3::ZERO, Vec3::ONE)
}

const LUT_SIZE: usize = 1 << 16;

fn srgb_lut() -> &'static [u8] {
    static LUT: OnceLock<Vec<u8>> = OnceLock::new();
    LUT.get_or_init(|| {
        (0..LUT_SIZE)
            .map(|i| {
                let v = i as f32 / (LUT_SIZE - 1) as f32;
                (linear_to_srgb(v) * 255.0 + 0.5) as u8
            })
            .collect()
    })
}

/// Linear [0,1] -> sRGB byte.
#[inline]
pub fn encode_srgb(v: f32) -> u8 {
    let lut = srgb_lut();
    let i = (v.clamp(0.0, 1.0) * (LUT_SIZE - 1) as f32 + 0.5) as usize;
    lut[i.min(LUT_SIZE - 1)]
}

/// [0,1] -> byte without transfer curve (for data views: normals, depth).
#[inline]
pub fn encode_linear(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encoding_matches_the_formula() {
        for i in 0..=1000 {
            let v = i as f32 / 1000.0;
            let exact = linear_to_srgb(v) * 255.0;
            let got = encode_srgb(v) as f32;
            assert!((got - exact).abs() <= 0.55, "{v}: {got} vs {exact}");
        }
        assert_eq!(encode_srgb(-1.0), 0);
        assert_eq!(encode_srgb(f32::NAN), 0);
        assert_eq!(encode_srgb(7.0), 255);
    }

    #[test]
    fn tone_maps_are_monotonic_and_bounded() {
        for op in [Tonemap::Clamp, Tonemap::Reinhard, Tonemap::Aces] {
            let mut last = -1.0;
            for i in 0..100 {
                let v = tonemap(Vec3::splat(i as f32 * 0.1), op, 1.0).x;
                assert!((0.0..=1.0).contains(&v) && v >= last);
                last = v;
            }
        }
        assert!((tonemap(Vec3::ONE, Tonemap::Reinhard, 1.0).x - 0.5).abs() < 1e-6);
    }
}
