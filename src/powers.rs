//! x^y at any lane width, for the Blinn-Phong specular power
//! max(0, n.h)^Ns: exp2(y log2 x), both halves as polynomials over the
//! lanes (`Lane`: eight on AVX2, four on SSE and NEON, one), in place of a
//! call of libm's `powf` per fragment (4% of a diablo3-matched frame's
//! instructions). Every width runs the same IEEE operations, so every
//! width gives the same bits; and every x86-64 machine does (libm picks
//! its `powf` by the processor).
//!
//! Accuracy, for x in (0, 1.01] (the unit tests sweep it against f64): the
//! relative error is below 3e-7 (1 + |y log2 x|), so below 3e-6 wherever
//! the result is above 1e-4 (|y log2 x| < 14), far inside an 8-bit code
//! (4e-3 of the value at the dark end of sRGB). Results below 2^-126 are
//! 0.

use std::f64::consts::LN_2;

use crate::simd::Lane;

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
/// gives 1. The same operations at every lane width (`Lane`), so each
/// lane is bit for bit the one-lane answer.
#[inline(always)]
pub fn pow<L: Lane>(x: L, y: L) -> L {
    exp2(log2(x) * y)
}

/// `pow` of one value.
#[cfg(test)]
fn pow_unit(x: f32, y: f32) -> f32 {
    pow(x, y)
}

/// log2 x per lane: x = 2^e m with m in [sqrt(1/2), sqrt(2)), log2 m by
/// the odd series in t = (m - 1) / (m + 1) (|t| < 0.172, the first term
/// left out below 1e-9).
#[inline(always)]
fn log2<L: Lane>(x: L) -> L {
    // max(NaN, MIN) is MIN at every width (`f32::max`, and SSE's second
    // operand where one is NaN).
    let (m, e) = x.max(L::splat(f32::MIN_POSITIVE)).split_exponent();
    let big = m.cmpge(L::splat(std::f32::consts::SQRT_2));
    let m = L::select(big, m * L::splat(0.5), m);
    let e = L::select(big, e + L::splat(1.0), e);
    let one = L::splat(1.0);
    let t = (m - one) / (m + one);
    let s = t * t;
    let c = |k: usize| L::splat(LOG2_SERIES[k]);
    let series = c(0) + s * (c(1) + s * (c(2) + s * (c(3) + s * c(4))));
    e + t * series
}

/// 2^z per lane: z = n + f with n whole and |f| <= 1/2, 2^f by its series,
/// 2^n from the exponent bits (0 below 2^-126).
#[inline(always)]
fn exp2<L: Lane>(z: L) -> L {
    // max(NaN, -127) is -127: a NaN exponent gives 0.
    let z = z.max(L::splat(-127.0)).min(L::splat(127.0));
    let n = z.round_even();
    let f = z - n;
    let c = |k: usize| L::splat(EXP2_SERIES[k]);
    let mut p = c(8);
    for k in (0..8).rev() {
        p = c(k) + f * p;
    }
    p * n.exp2_whole()
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

    /// Four and eight lanes give what each gives alone.
    #[test]
    fn lanes_are_independent() {
        use crate::simd::F8;
        use glam::Vec4;
        let mut rnd = xorshift(7);
        for _ in 0..10_000 {
            let x: [f32; 8] = std::array::from_fn(|k| rnd() * if k % 4 == 3 { 1.5 } else { 1.0 });
            let y: [f32; 8] = std::array::from_fn(|k| if k < 4 { 40.0 } else { rnd() * 300.0 });
            let p4 = pow(Vec4::from_slice(&x[..4]), Vec4::from_slice(&y[..4]));
            let p8 = pow(F8::from_fn(|k| x[k]), F8::from_fn(|k| y[k]));
            for k in 0..8 {
                let one = pow_unit(x[k], y[k]).to_bits();
                assert_eq!(p8.lane(k).to_bits(), one);
                if k < 4 {
                    assert_eq!(p4[k].to_bits(), one);
                }
            }
        }
    }
}
