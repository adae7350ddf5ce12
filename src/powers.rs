//! x^y four lanes at a time, for the Blinn-Phong specular power
//! max(0, n.h)^Ns: exp2(y log2 x), both halves as polynomials on SSE
//! lanes, in place of four calls of libm's `powf` per group of fragments
//! (4% of a diablo3-matched frame's instructions). One lane takes lane 0
//! of the same arithmetic (`pow_unit`), so every width gives the same
//! bits; and as plain IEEE operations, every x86-64 machine does
//! (libm picks its `powf` by the processor).
//!
//! Accuracy, for x in (0, 1.01] (the unit tests sweep it against f64): the
//! relative error is below 3e-7 (1 + |y log2 x|), so below 3e-6 wherever
//! the result is above 1e-4 (|y log2 x| < 14), far inside an 8-bit code
//! (4e-3 of the value at the dark end of sRGB). Results below 2^-126 are
//! 0.

use std::f64::consts::LN_2;

use glam::Vec4;

/// 2 / (k ln 2) for k = 1, 3, 5, 7, 9: log2(m) = sum of these times t^k,
/// t = (m - 1) / (m + 1).
const LOG2_SERIES: [f32; 5] = {
    let mut c = [0.0f32; 5];
    let mut i = 0;
    while i < 5 {
        c[i] = (2.0 / ((2 * i + 1) as f64 * LN_2)) as f32;
        i += 1;
    }
    c
};

/// ln2^k / k! for k = 0..=8: 2^f for |f| <= 1/2 (the first term left out
/// is below 3e-10).
const EXP2_SERIES: [f32; 9] = {
    let mut c = [0.0f32; 9];
    let mut term = 1.0f64;
    let mut k = 0;
    while k < 9 {
        c[k] = term as f32;
        k += 1;
        term = term * LN_2 / k as f64;
    }
    c
};

/// x^y per lane, for x > 0 (lanes at or below the smallest normal float,
/// or NaN, take it as 2^-126) and finite y >= 0, up to 2^127. y = 0
/// gives 1.
#[inline]
pub fn pow4(x: Vec4, y: f32) -> Vec4 {
    exp2_4(log2_4(x) * Vec4::splat(y))
}

/// `pow4` of one value (lane 0 of the same arithmetic).
#[inline]
pub fn pow_unit(x: f32, y: f32) -> f32 {
    pow4(Vec4::splat(x), y).x
}

/// log2 x per lane: x = 2^e m with m in [sqrt(1/2), sqrt(2)), log2 m by
/// the odd series in t = (m - 1) / (m + 1) (|t| < 0.172, the first term
/// left out below 1e-9).
#[inline(always)]
fn log2_4(x: Vec4) -> Vec4 {
    // max(NaN, MIN) is MIN on SSE (the second operand where one is NaN).
    let (m, e) = split4(x.max(Vec4::splat(f32::MIN_POSITIVE)));
    let big = m.cmpge(Vec4::splat(std::f32::consts::SQRT_2));
    let m = Vec4::select(big, m * Vec4::splat(0.5), m);
    let e = Vec4::select(big, e + Vec4::ONE, e);
    let t = (m - Vec4::ONE) / (m + Vec4::ONE);
    let s = t * t;
    let c = |k: usize| Vec4::splat(LOG2_SERIES[k]);
    let series = c(0) + s * (c(1) + s * (c(2) + s * (c(3) + s * c(4))));
    e + t * series
}

/// 2^z per lane: z = n + f with n whole and |f| <= 1/2, 2^f by its series,
/// 2^n from the exponent bits (0 below 2^-126).
#[inline(always)]
fn exp2_4(z: Vec4) -> Vec4 {
    // max(NaN, -127) is -127: a NaN exponent gives 0.
    let z = z.max(Vec4::splat(-127.0)).min(Vec4::splat(127.0));
    let n = round4(z);
    let f = z - n;
    let c = |k: usize| Vec4::splat(EXP2_SERIES[k]);
    let mut p = c(8);
    for k in (0..8).rev() {
        p = c(k) + f * p;
    }
    p * scale4(n)
}

/// (mantissa in [1, 2), exponent) of each lane, a positive normal float.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn split4(x: Vec4) -> (Vec4, Vec4) {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 only (in every x86-64 target's base features); no
    // memory is touched.
    unsafe {
        let b = _mm_castps_si128(x.into());
        let e = _mm_sub_epi32(_mm_srli_epi32(b, 23), _mm_set1_epi32(127));
        let m = _mm_or_si128(
            _mm_and_si128(b, _mm_set1_epi32(0x007f_ffff)),
            _mm_set1_epi32(0x3f80_0000),
        );
        (
            Vec4::from(_mm_castsi128_ps(m)),
            Vec4::from(_mm_cvtepi32_ps(e)),
        )
    }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn split4(x: Vec4) -> (Vec4, Vec4) {
    let b = x.to_array().map(f32::to_bits);
    let m = b.map(|b| f32::from_bits(b & 0x007f_ffff | 0x3f80_0000));
    let e = b.map(|b| ((b >> 23) as i32 - 127) as f32);
    (Vec4::from_array(m), Vec4::from_array(e))
}

/// Each lane, in [-127, 127], to the nearest whole number (ties to even).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn round4(z: Vec4) -> Vec4 {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 only; the conversion rounds by MXCSR, which Rust
    // leaves at its default (to nearest, ties to even).
    unsafe { Vec4::from(_mm_cvtepi32_ps(_mm_cvtps_epi32(z.into()))) }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn round4(z: Vec4) -> Vec4 {
    Vec4::from_array(z.to_array().map(f32::round_ties_even))
}

/// 2^n per lane for whole n in [-127, 127], with 2^-127 as 0.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn scale4(n: Vec4) -> Vec4 {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 only; no memory is touched. n + 127 lies in [0, 254]:
    // a biased exponent, 0 being the float 0.
    unsafe {
        let e = _mm_add_epi32(_mm_cvttps_epi32(n.into()), _mm_set1_epi32(127));
        Vec4::from(_mm_castsi128_ps(_mm_slli_epi32(e, 23)))
    }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn scale4(n: Vec4) -> Vec4 {
    Vec4::from_array(
        n.to_array()
            .map(|n| f32::from_bits(((n as i32 + 127) as u32) << 23)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::xorshift;

    /// Against f64's powf, over x in (0, 1.01] (near 1 densely, where
    /// highlights are) and exponents from 0 to 10,000.
    #[test]
    fn pow_is_within_its_stated_error() {
        let mut rnd = xorshift(0x9e37_79b9_7f4a_7c15);
        let ys = [
            0.0, 0.25, 0.5, 1.0, 2.0, 3.7, 10.0, 32.0, 96.078_43, 250.0, 1000.0, 10000.0,
        ];
        let mut worst = 0.0f64;
        for i in 0..200_000 {
            let x = match i % 3 {
                0 => rnd() * 1.01,
                1 => 1.0 - rnd() * 0.01,
                _ => (rnd() * -30.0).exp2(),
            }
            .max(f32::MIN_POSITIVE);
            for &y in &ys {
                let got = pow_unit(x, y) as f64;
                let want = (x as f64).powf(y as f64);
                let z = (y as f64 * (x as f64).log2()).abs();
                if want > 2f64.powi(126) {
                    continue;
                }
                if want < 2f64.powi(-126) {
                    assert!(got <= 2f64.powi(-125), "{x}^{y}: {got} for {want}");
                    continue;
                }
                let rel = (got - want).abs() / want;
                worst = worst.max(rel / (1.0 + z));
                assert!(
                    rel <= 3e-7 * (1.0 + z),
                    "{x}^{y}: {got} for {want} ({rel:e})"
                );
            }
        }
        // The bound is not loose by orders of magnitude.
        assert!(worst > 3e-8, "worst {worst:e}");
    }

    #[test]
    fn edges() {
        assert_eq!(pow_unit(1.0, 32.0), 1.0);
        assert_eq!(pow_unit(0.5, 0.0), 1.0);
        assert_eq!(pow_unit(0.5, 1.0), 0.5);
        assert_eq!(pow_unit(0.5, 2.0), 0.25);
        assert_eq!(pow_unit(0.0, 8.0), 0.0);
        assert_eq!(pow_unit(f32::NAN, 8.0), 0.0);
        assert_eq!(pow_unit(1e-30, 100.0), 0.0);
        assert!((pow_unit(0.0, 0.0) - 1.0).abs() < 1e-7);
    }

    /// Four lanes give what each gives alone.
    #[test]
    fn lanes_are_independent() {
        let mut rnd = xorshift(7);
        for _ in 0..10_000 {
            let x = Vec4::new(rnd(), rnd(), rnd(), rnd() * 1.5);
            let y = rnd() * 300.0;
            let p = pow4(x, y);
            for k in 0..4 {
                assert_eq!(p[k].to_bits(), pow_unit(x[k], y).to_bits());
            }
        }
    }
}
