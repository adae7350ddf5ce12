//! Colour encodings, at the ground floor: the sRGB transfer curve both
//! ways, the tables that make it cheap (256 entries to decode an sRGB byte,
//! 64K entries to encode a linear value to a byte, accurate to a twentieth
//! of a code), and the plain byte encoding of data values. Textures decode
//! with it, mip chains re-encode with it, the output resolve encodes with
//! it; tone mapping (a display decision) lives in `output::tonemap`.

use std::sync::OnceLock;

/// The sRGB decoding curve: encoded [0,1] -> linear [0,1].
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB encoding curve: linear [0,1] -> encoded [0,1].
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// sRGB-encoded byte -> linear float.
pub fn srgb_to_linear_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = [0.0f32; 256];
        for (i, v) in t.iter_mut().enumerate() {
            *v = srgb_to_linear(i as f32 / 255.0);
        }
        t
    })
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

/// Linear [0,1] -> sRGB byte (clamped; NaN gives 0).
#[inline]
pub fn encode_srgb(v: f32) -> u8 {
    let lut = srgb_lut();
    let i = (v.clamp(0.0, 1.0) * (LUT_SIZE - 1) as f32 + 0.5) as usize;
    lut[i.min(LUT_SIZE - 1)]
}

/// `encode_srgb` of the three channels of `c`, together (the same bytes).
#[inline]
pub fn encode_srgb3(c: glam::Vec3) -> [u8; 3] {
    use glam::Vec4;
    let lut = srgb_lut();
    // max(NaN, 0) is 0, as clamp(NaN) gives index 0.
    let v = Vec4::new(c.x, c.y, c.z, 0.0).max(Vec4::ZERO).min(Vec4::ONE)
        * Vec4::splat((LUT_SIZE - 1) as f32)
        + Vec4::splat(0.5);
    let i = v.as_uvec4();
    [
        lut[(i.x as usize).min(LUT_SIZE - 1)],
        lut[(i.y as usize).min(LUT_SIZE - 1)],
        lut[(i.z as usize).min(LUT_SIZE - 1)],
    ]
}

/// [0,1] -> byte without transfer curve (data: normals, depth, alpha).
#[inline]
pub fn encode_linear(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_channels_encode_as_one() {
        let mut x = 0x1234_5678u32;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            f32::from_bits(x)
        };
        let special = [
            f32::NAN,
            -0.0,
            0.0,
            1.0,
            -1.0,
            2.0,
            f32::INFINITY,
            1e-9,
            0.5,
        ];
        for k in 0..100_000 {
            let v = if k < special.len() {
                special[k]
            } else if k % 2 == 0 {
                (next().to_bits() >> 9) as f32 / (1 << 23) as f32 * 1.2 - 0.1
            } else {
                next()
            };
            let c = glam::Vec3::new(v, 0.25, -v);
            assert_eq!(
                encode_srgb3(c),
                [encode_srgb(c.x), encode_srgb(c.y), encode_srgb(c.z)],
                "{v}"
            );
        }
    }

    #[test]
    fn srgb_tables_round_trip() {
        let lut = srgb_to_linear_table();
        assert_eq!(lut[0], 0.0);
        assert!((lut[255] - 1.0).abs() < 1e-6);
        assert!((lut[188] - 0.5029).abs() < 1e-3);
        for i in 0..=255u8 {
            let back = (linear_to_srgb(lut[i as usize]) * 255.0).round() as u8;
            assert_eq!(back, i);
        }
    }

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
        assert_eq!((encode_linear(0.5), encode_linear(2.0)), (128, 255));
    }
}
