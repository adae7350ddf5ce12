//! From linear radiance to display values: exposure and a tone map (clamp,
//! Reinhard, ACES); the sRGB encoding that follows is `color::encode_srgb`.

use glam::Vec3;

use crate::scene::settings::Tonemap;

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

#[cfg(test)]
mod tests {
    use super::*;

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
