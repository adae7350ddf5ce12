//! Colour encodings, at the ground floor: the sRGB transfer curve both
//! ways, the tables that make it cheap (256 entries to decode an sRGB byte;
//! to encode a linear value, the bytes of 64K evenly spaced values,
//! accurate to a twentieth of a code, kept as 8.7 KB of segments), and the
//! plain byte encoding of data values. Textures decode
//! with it, mip chains re-encode with it, the output resolve encodes with
//! it; tone mapping (a display decision) lives in `shade::tonemap`.

use std::sync::OnceLock;

/// The sRGB decoding curve: encoded \[0, 1\] -> linear \[0, 1\].
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB encoding curve: linear \[0, 1\] -> encoded \[0, 1\].
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

/// The encoding as first defined: the byte of each of 64K evenly spaced
/// linear values, a value taking its nearest entry. `encode_srgb` gives
/// exactly these bytes from a smaller table (`Segments`).
fn srgb_lut() -> Vec<u8> {
    (0..LUT_SIZE)
        .map(|i| {
            let v = i as f32 / (LUT_SIZE - 1) as f32;
            (linear_to_srgb(v) * 255.0 + 0.5) as u8
        })
        .collect()
}

/// The 64K-entry table's entry for v in [0, 1].
#[inline(always)]
fn lut_index(v: f32) -> u32 {
    (v * (LUT_SIZE - 1) as f32 + 0.5) as u32
}

/// The first float key: values below 2^-17 share segment 0 (they all
/// encode to 0).
const KEY_BASE: u32 = (127 - 17) << 7;
/// Segments up to that of 1.0.
const SEGMENTS: usize = ((127 << 7) - KEY_BASE + 1) as usize;

/// The 64K-entry table, as segments of the float line small enough that
/// the byte steps at most once in each: a value's segment is its exponent
/// and top 7 mantissa bits (its bits >> 16), spanning 1/128 of its
/// magnitude, where the byte changes by less than one (at most 0.88 at
/// the top). Per segment, the byte at its start in the low byte and
/// above it the first table entry (`lut_index`) of the next byte, if it
/// starts inside the segment (else beyond every entry). 8.7 KB: it stays
/// in the first-level cache where the 64 KB table did not.
struct Segments([u32; SEGMENTS]);

fn segments() -> &'static Segments {
    static TABLE: OnceLock<Box<Segments>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let lut = srgb_lut();
        let mut t = Box::new(Segments([0; SEGMENTS]));
        for (k, e) in t.0.iter_mut().enumerate() {
            let first = if k == 0 {
                0.0
            } else {
                f32::from_bits((k as u32 + KEY_BASE) << 16)
            };
            let last = f32::from_bits(((k as u32 + 1 + KEY_BASE) << 16) - 1).min(1.0);
            let (i0, i1) = (lut_index(first), lut_index(last));
            let byte = lut[i0 as usize];
            let step = (i0..=i1).find(|&i| lut[i as usize] != byte);
            if let Some(s) = step {
                assert!(lut[i1 as usize] == byte + 1, "two steps in a segment");
                *e = byte as u32 | s << 8;
            } else {
                *e = byte as u32 | (LUT_SIZE as u32) << 8;
            }
        }
        t
    })
}

impl Segments {
    /// The byte of v, which is in [0, 1] (or -0).
    #[inline(always)]
    fn encode(&self, v: f32) -> u8 {
        let key = ((v.to_bits() & 0x7fff_ffff) >> 16).saturating_sub(KEY_BASE) as usize;
        let e = self.0[key.min(SEGMENTS - 1)];
        (e as u8) + (lut_index(v) >= e >> 8) as u8
    }
}

/// Linear \[0, 1\] -> sRGB byte (clamped; NaN gives 0): the byte of the
/// nearest of 64K evenly spaced values, accurate to a twentieth of a code.
#[inline]
pub fn encode_srgb(v: f32) -> u8 {
    // NaN fails the test: 0.
    segments().encode(if v >= 0.0 { v.min(1.0) } else { 0.0 })
}

/// `encode_srgb` of the three channels of `c`, together (the same bytes).
#[inline]
pub fn encode_srgb3(c: glam::Vec3) -> [u8; 3] {
    encode_srgb_xyz(glam::Vec4::new(c.x, c.y, c.z, 0.0))
}

/// `encode_srgb` of x, y and z of `c` (what `encode_srgb3` of them gives;
/// kept in a vector register, where a `Vec3` goes through memory).
#[cfg(not(target_arch = "x86_64"))]
#[inline]
pub fn encode_srgb_xyz(c: glam::Vec4) -> [u8; 3] {
    use glam::Vec4;
    let t = segments();
    // max(NaN, 0) is 0, as in `encode_srgb`.
    let v = c.max(Vec4::ZERO).min(Vec4::ONE);
    [t.encode(v.x), t.encode(v.y), t.encode(v.z)]
}

/// (On x86-64 the segment keys and table entries of the lanes are found
/// together, in SSE2: `Segments::encode`'s operations lane by lane.)
#[cfg(target_arch = "x86_64")]
#[inline]
pub fn encode_srgb_xyz(c: glam::Vec4) -> [u8; 3] {
    use glam::Vec4;
    use std::arch::x86_64::*;
    let t = segments();
    // max(NaN, 0) is 0, as in `encode_srgb`: v is in [0, 1].
    let v = c.max(Vec4::ZERO).min(Vec4::ONE);
    let (mut key, mut index) = ([0u32; 4], [0u32; 4]);
    // SAFETY: SSE2 only (in every x86-64 target's base features); the
    // stores write the 16 bytes of `key` and `index`.
    unsafe {
        let v: __m128 = v.into();
        // `Segments::encode`'s key: (|bits| >> 16) - KEY_BASE, 0 below.
        let bits = _mm_and_si128(_mm_castps_si128(v), _mm_set1_epi32(0x7fff_ffff));
        let d = _mm_sub_epi32(_mm_srli_epi32(bits, 16), _mm_set1_epi32(KEY_BASE as i32));
        let k = _mm_and_si128(d, _mm_cmpgt_epi32(d, _mm_setzero_si128()));
        // `lut_index`: v * 65535 + 0.5, truncated (in 0.5..=65535.5).
        let i = _mm_cvttps_epi32(_mm_add_ps(
            _mm_mul_ps(v, _mm_set1_ps((LUT_SIZE - 1) as f32)),
            _mm_set1_ps(0.5),
        ));
        _mm_storeu_si128(key.as_mut_ptr() as *mut __m128i, k);
        _mm_storeu_si128(index.as_mut_ptr() as *mut __m128i, i);
    }
    let byte = |j: usize| {
        let e = t.0[(key[j] as usize).min(SEGMENTS - 1)];
        (e as u8) + (index[j] >= e >> 8) as u8
    };
    [byte(0), byte(1), byte(2)]
}

/// `encode_srgb` of eight values each in \[0, 1\] (or -0), as
/// `Segments::encode` finds them, eight at once: the segments by one
/// gather (AVX2 builds), the bytes packed.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline]
pub fn encode_srgb8(v: crate::simd::F8) -> [u8; 8] {
    use std::arch::x86_64::*;
    let t = segments();
    let mut out = [0u32; 8];
    // SAFETY: AVX2 is enabled for the build (the cfg above); the gather's
    // indices are clamped to the table's SEGMENTS entries, and the store
    // writes the 32 bytes of `out`.
    unsafe {
        let v: __m256 = v.into();
        // `Segments::encode`'s key: (|bits| >> 16) - KEY_BASE, 0 below,
        // at most the last segment.
        let bits = _mm256_and_si256(_mm256_castps_si256(v), _mm256_set1_epi32(0x7fff_ffff));
        let d = _mm256_sub_epi32(
            _mm256_srli_epi32(bits, 16),
            _mm256_set1_epi32(KEY_BASE as i32),
        );
        let k = _mm256_and_si256(d, _mm256_cmpgt_epi32(d, _mm256_setzero_si256()));
        let k = _mm256_min_epi32(k, _mm256_set1_epi32(SEGMENTS as i32 - 1));
        let e = _mm256_i32gather_epi32::<4>(t.0.as_ptr() as *const i32, k);
        // `lut_index`: v * 65535 + 0.5, truncated (in 0.5..=65535.5).
        let i = _mm256_cvttps_epi32(_mm256_add_ps(
            _mm256_mul_ps(v, _mm256_set1_ps((LUT_SIZE - 1) as f32)),
            _mm256_set1_ps(0.5),
        ));
        // The byte, one more where i >= the next byte's first entry: a
        // compare of "the step lies beyond i" is -1, else 0.
        let step = _mm256_srli_epi32(e, 8);
        let byte = _mm256_add_epi32(
            _mm256_and_si256(e, _mm256_set1_epi32(0xff)),
            _mm256_add_epi32(_mm256_set1_epi32(1), _mm256_cmpgt_epi32(step, i)),
        );
        _mm256_storeu_si256(out.as_mut_ptr() as *mut __m256i, byte);
    }
    out.map(|b| b as u8)
}

/// `encode_srgb` of eight values each in \[0, 1\] (or -0).
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
#[inline]
pub fn encode_srgb8(v: crate::simd::F8) -> [u8; 8] {
    use crate::simd::Lane;
    let t = segments();
    std::array::from_fn(|k| t.encode(v.lane(k)))
}

/// \[0, 1\] -> byte without transfer curve (data: normals, depth, alpha).
#[inline]
pub fn encode_linear(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eight at once (`encode_srgb8`) gives `encode_srgb`'s bytes: every
    /// 97th float of [0, 1] and the values where the bytes step, each
    /// with its neighbouring floats, in every lane.
    #[test]
    fn eight_at_once_are_the_bytes_of_one_at_a_time() {
        use crate::simd::{F8, Lane};
        let mut values: Vec<f32> = (0..=1.0f32.to_bits())
            .step_by(97)
            .map(f32::from_bits)
            .collect();
        for b in 0..256 {
            let v = srgb_to_linear(b as f32 / 255.0);
            for d in [-1i32, 0, 1] {
                values.push(f32::from_bits((v.to_bits() as i32 + d).max(0) as u32).min(1.0));
            }
        }
        values.extend([-0.0, 0.0, 1.0]);
        for chunk in values.chunks(8) {
            let lanes = F8::from_fn(|k| chunk[k % chunk.len()]);
            let got = encode_srgb8(lanes);
            for k in 0..8 {
                let v = chunk[k % chunk.len()];
                assert_eq!(got[k], encode_srgb(v), "{v} in lane {k}");
            }
        }
    }

    /// The segment table gives the 64K-entry table's byte for every
    /// float in [0, 1] (each one of the 1.07 billion, and -0).
    #[test]
    fn segments_equal_the_full_table() {
        let lut = srgb_lut();
        let want = |v: f32| lut[lut_index(v) as usize];
        assert_eq!(encode_srgb(-0.0), 0);
        assert_eq!(encode_srgb(1.0), 255);
        let top = 1.0f32.to_bits();
        let chunks = 64u32;
        let bad: u32 = std::thread::scope(|sc| {
            let jobs: Vec<_> = (0..chunks)
                .map(|c| {
                    let want = &want;
                    sc.spawn(move || {
                        let (a, b) = (top / chunks * c, (top / chunks * (c + 1)).min(top));
                        let b = if c + 1 == chunks { top + 1 } else { b };
                        (a..b)
                            .filter(|&bits| {
                                let v = f32::from_bits(bits);
                                encode_srgb(v) != want(v)
                            })
                            .count() as u32
                    })
                })
                .collect();
            jobs.into_iter().map(|j| j.join().unwrap_or(u32::MAX)).sum()
        });
        assert_eq!(bad, 0);
    }

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
            let w = if k % 3 == 0 { next() } else { 0.25 };
            let c = glam::Vec3::new(v, w, -v);
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
