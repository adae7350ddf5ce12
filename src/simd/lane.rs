//! The lane types shading is written over: one `f32` (a lone fragment),
//! four (`Vec4`: SSE on x86-64, NEON on aarch64) or eight (`F8`: AVX on
//! x86-64-v3 builds, two fours elsewhere). Code generic over `Lane` runs
//! the same IEEE operations in the same order at every width, so each
//! lane of a wide call is bit for bit the one-lane answer: Rust never
//! fuses a multiply and an add, and the SIMD instructions round as the
//! scalar ones do. The one place widths may differ is `min` and `max`
//! of a NaN or of two zeros of opposite sign (`f32::min` returns the
//! other operand, `minps` the second): code that can meet those there
//! selects them away first.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use glam::{BVec4A, Vec4};

/// A mask of lanes (a compare's result).
pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    /// Whether any lane is set.
    fn any(self) -> bool;
    /// Whether every lane is set.
    fn all(self) -> bool;
    /// Bit k: lane k.
    fn bitmask(self) -> u32;
}

/// `WIDTH` f32 lanes and the operations shading uses, each the scalar
/// operation lane by lane.
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: Mask;
    const WIDTH: usize;
    /// Groups of four lanes (`quad`): the texture and shadow lookups work
    /// four lanes at a time.
    const QUADS: usize;
    fn splat(x: f32) -> Self;
    /// Lane k is `f(k)`.
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self;
    /// Lane `k` (< WIDTH).
    fn lane(self, k: usize) -> f32;
    fn min(self, o: Self) -> Self;
    fn max(self, o: Self) -> Self;
    fn abs(self) -> Self;
    /// `f32::signum`: 1 or -1 by the sign bit (zeros too), NaN for NaN.
    fn signum(self) -> Self;
    fn sqrt(self) -> Self;
    /// `f32::floor`, but for the sign of a zero (glam's four-lane floor
    /// gives +0 for -0): use it where that sign is lost anyway (an
    /// index, a fraction `x - floor(x)`).
    fn floor(self) -> Self;
    fn cmpeq(self, o: Self) -> Self::Mask;
    fn cmplt(self, o: Self) -> Self::Mask;
    fn cmple(self, o: Self) -> Self::Mask;
    fn cmpgt(self, o: Self) -> Self::Mask;
    fn cmpge(self, o: Self) -> Self::Mask;
    fn is_nan(self) -> Self::Mask;
    fn is_finite(self) -> Self::Mask;
    /// Lane by lane: `a` where `m`, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Each lane, a positive normal float 2^e m, as (m in [1, 2), e): its
    /// bits taken apart (`powers`).
    fn split_exponent(self) -> (Self, Self);
    /// Each lane, whole or not, in [-2^22, 2^22], to the nearest whole
    /// number, ties to even; a zero is +0.
    fn round_even(self) -> Self;
    /// 2^n per lane for whole n in [-127, 127], with 2^-127 as 0: n put
    /// in the exponent bits.
    fn exp2_whole(self) -> Self;
    /// Lanes 4q .. 4q + 4 (q < QUADS); one lane repeats in all four.
    #[inline(always)]
    fn quad(self, q: usize) -> Vec4 {
        if Self::WIDTH == 1 {
            return Vec4::splat(self.lane(0));
        }
        super::lanes4(
            self.lane(4 * q),
            self.lane(4 * q + 1),
            self.lane(4 * q + 2),
            self.lane(4 * q + 3),
        )
    }
    /// Lanes from their quads (`f(q)` for quad q; one lane takes the
    /// first quad's first lane).
    #[inline(always)]
    fn from_quads(mut f: impl FnMut(usize) -> Vec4) -> Self {
        let mut q = [Vec4::ZERO; 2];
        for (k, o) in q.iter_mut().take(Self::QUADS).enumerate() {
            *o = f(k);
        }
        Self::from_fn(|k| q[k / 4][k % 4])
    }
    /// `f` of each lane (library calls: powers, trigonometry).
    #[inline(always)]
    fn map(self, mut f: impl FnMut(f32) -> f32) -> Self {
        Self::from_fn(|k| f(self.lane(k)))
    }
}

impl Mask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
    #[inline(always)]
    fn bitmask(self) -> u32 {
        self as u32
    }
}

impl Lane for f32 {
    type Mask = bool;
    const WIDTH: usize = 1;
    const QUADS: usize = 1;
    #[inline(always)]
    fn splat(x: f32) -> f32 {
        x
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> f32 {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _: usize) -> f32 {
        self
    }
    #[inline(always)]
    fn min(self, o: f32) -> f32 {
        f32::min(self, o)
    }
    #[inline(always)]
    fn max(self, o: f32) -> f32 {
        f32::max(self, o)
    }
    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    #[inline(always)]
    fn signum(self) -> f32 {
        f32::signum(self)
    }
    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn floor(self) -> f32 {
        f32::floor(self)
    }
    #[inline(always)]
    fn cmpeq(self, o: f32) -> bool {
        self == o
    }
    #[inline(always)]
    fn cmplt(self, o: f32) -> bool {
        self < o
    }
    #[inline(always)]
    fn cmple(self, o: f32) -> bool {
        self <= o
    }
    #[inline(always)]
    fn cmpgt(self, o: f32) -> bool {
        self > o
    }
    #[inline(always)]
    fn cmpge(self, o: f32) -> bool {
        self >= o
    }
    #[inline(always)]
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn select(m: bool, a: f32, b: f32) -> f32 {
        if m { a } else { b }
    }
    #[inline(always)]
    fn split_exponent(self) -> (f32, f32) {
        let b = self.to_bits();
        let m = f32::from_bits(b & 0x007f_ffff | 0x3f80_0000);
        (m, ((b >> 23) as i32 - 127) as f32)
    }
    #[inline(always)]
    fn round_even(self) -> f32 {
        // + 0: a zero is +0, as the SIMD conversions give it.
        self.round_ties_even() + 0.0
    }
    #[inline(always)]
    fn exp2_whole(self) -> f32 {
        f32::from_bits(((self as i32 + 127) as u32) << 23)
    }
}

impl Mask for BVec4A {
    #[inline(always)]
    fn any(self) -> bool {
        BVec4A::any(self)
    }
    #[inline(always)]
    fn all(self) -> bool {
        BVec4A::all(self)
    }
    #[inline(always)]
    fn bitmask(self) -> u32 {
        BVec4A::bitmask(self)
    }
}

impl Lane for Vec4 {
    type Mask = BVec4A;
    const WIDTH: usize = 4;
    const QUADS: usize = 1;
    #[inline(always)]
    fn splat(x: f32) -> Vec4 {
        Vec4::splat(x)
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> Vec4 {
        super::lanes4(f(0), f(1), f(2), f(3))
    }
    #[inline(always)]
    fn lane(self, k: usize) -> f32 {
        self[k]
    }
    #[inline(always)]
    fn min(self, o: Vec4) -> Vec4 {
        Vec4::min(self, o)
    }
    #[inline(always)]
    fn max(self, o: Vec4) -> Vec4 {
        Vec4::max(self, o)
    }
    #[inline(always)]
    fn abs(self) -> Vec4 {
        Vec4::abs(self)
    }
    #[inline(always)]
    fn signum(self) -> Vec4 {
        Vec4::signum(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Vec4 {
        Vec4::sqrt(self)
    }
    #[inline(always)]
    fn floor(self) -> Vec4 {
        Vec4::floor(self)
    }
    #[inline(always)]
    fn cmpeq(self, o: Vec4) -> BVec4A {
        Vec4::cmpeq(self, o)
    }
    #[inline(always)]
    fn cmplt(self, o: Vec4) -> BVec4A {
        Vec4::cmplt(self, o)
    }
    #[inline(always)]
    fn cmple(self, o: Vec4) -> BVec4A {
        Vec4::cmple(self, o)
    }
    #[inline(always)]
    fn cmpgt(self, o: Vec4) -> BVec4A {
        Vec4::cmpgt(self, o)
    }
    #[inline(always)]
    fn cmpge(self, o: Vec4) -> BVec4A {
        Vec4::cmpge(self, o)
    }
    #[inline(always)]
    fn quad(self, _: usize) -> Vec4 {
        self
    }
    #[inline(always)]
    fn from_quads(mut f: impl FnMut(usize) -> Vec4) -> Vec4 {
        f(0)
    }
    #[inline(always)]
    fn is_nan(self) -> BVec4A {
        Vec4::is_nan_mask(self)
    }
    #[inline(always)]
    fn is_finite(self) -> BVec4A {
        Vec4::is_finite_mask(self)
    }
    #[inline(always)]
    fn select(m: BVec4A, a: Vec4, b: Vec4) -> Vec4 {
        Vec4::select(m, a, b)
    }
    #[inline(always)]
    fn split_exponent(self) -> (Vec4, Vec4) {
        bits4::split_exponent(self)
    }
    #[inline(always)]
    fn round_even(self) -> Vec4 {
        bits4::round_even(self)
    }
    #[inline(always)]
    fn exp2_whole(self) -> Vec4 {
        bits4::exp2_whole(self)
    }
}

/// The bit-level steps of four lanes (`Lane::split_exponent`,
/// `round_even`, `exp2_whole`): SSE2 integer instructions on x86-64, the
/// scalar steps lane by lane elsewhere.
mod bits4 {
    use glam::Vec4;

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn split_exponent(x: Vec4) -> (Vec4, Vec4) {
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

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn round_even(z: Vec4) -> Vec4 {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 only; the conversion rounds by MXCSR, which Rust
        // leaves at its default (to nearest, ties to even).
        unsafe { Vec4::from(_mm_cvtepi32_ps(_mm_cvtps_epi32(z.into()))) }
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn exp2_whole(n: Vec4) -> Vec4 {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 only; no memory is touched. n + 127 lies in [0,
        // 254]: a biased exponent, 0 being the float 0.
        unsafe {
            let e = _mm_add_epi32(_mm_cvttps_epi32(n.into()), _mm_set1_epi32(127));
            Vec4::from(_mm_castsi128_ps(_mm_slli_epi32(e, 23)))
        }
    }

    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    pub fn split_exponent(x: Vec4) -> (Vec4, Vec4) {
        use super::Lane;
        let s = x.to_array().map(f32::split_exponent);
        (
            Vec4::from_array(s.map(|s| s.0)),
            Vec4::from_array(s.map(|s| s.1)),
        )
    }

    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    pub fn round_even(z: Vec4) -> Vec4 {
        use super::Lane;
        Vec4::from_array(z.to_array().map(f32::round_even))
    }

    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    pub fn exp2_whole(n: Vec4) -> Vec4 {
        use super::Lane;
        Vec4::from_array(n.to_array().map(f32::exp2_whole))
    }
}

pub use f8::F8;

/// Eight lanes as one AVX register (x86-64 builds with AVX: the
/// x86-64-v3 default).
#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
mod f8 {
    use std::arch::x86_64::*;
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

    use super::{Lane, Mask};

    /// Eight f32 lanes.
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub struct F8(__m256);

    /// Eight lanes' mask: all ones or all zeros per lane.
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub struct M8(__m256);

    // SAFETY (every block below): AVX is enabled for the whole build
    // (`target_feature = "avx"` gates this module; the blocks with AVX2
    // intrinsics are gated by `target_feature = "avx2"`); the intrinsics touch
    // no memory but the arrays named.
    macro_rules! op {
        ($tr:ident, $f:ident, $ty:ident, $intr:ident) => {
            impl $tr for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $f(self, o: $ty) -> $ty {
                    $ty(unsafe { $intr(self.0, o.0) })
                }
            }
        };
    }
    op!(Add, add, F8, _mm256_add_ps);
    op!(Sub, sub, F8, _mm256_sub_ps);
    op!(Mul, mul, F8, _mm256_mul_ps);
    op!(Div, div, F8, _mm256_div_ps);
    op!(BitAnd, bitand, M8, _mm256_and_ps);
    op!(BitOr, bitor, M8, _mm256_or_ps);

    impl Neg for F8 {
        type Output = F8;
        #[inline(always)]
        fn neg(self) -> F8 {
            // The sign bit flipped, as scalar negation does (NaN too).
            F8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
        }
    }

    impl Not for M8 {
        type Output = M8;
        #[inline(always)]
        fn not(self) -> M8 {
            M8(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
        }
    }

    impl Mask for M8 {
        #[inline(always)]
        fn any(self) -> bool {
            self.bitmask() != 0
        }
        #[inline(always)]
        fn all(self) -> bool {
            self.bitmask() == 0xff
        }
        #[inline(always)]
        fn bitmask(self) -> u32 {
            unsafe { _mm256_movemask_ps(self.0) as u32 }
        }
    }

    impl From<F8> for __m256 {
        #[inline(always)]
        fn from(v: F8) -> __m256 {
            v.0
        }
    }

    impl From<__m256> for F8 {
        #[inline(always)]
        fn from(v: __m256) -> F8 {
            F8(v)
        }
    }

    impl Lane for F8 {
        type Mask = M8;
        const WIDTH: usize = 8;
        const QUADS: usize = 2;
        #[inline(always)]
        fn splat(x: f32) -> F8 {
            F8(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        fn quad(self, q: usize) -> glam::Vec4 {
            glam::Vec4::from(unsafe {
                if q == 0 {
                    _mm256_castps256_ps128(self.0)
                } else {
                    _mm256_extractf128_ps(self.0, 1)
                }
            })
        }
        #[inline(always)]
        fn from_quads(mut f: impl FnMut(usize) -> glam::Vec4) -> F8 {
            let (lo, hi) = (f(0), f(1));
            F8(unsafe { _mm256_set_m128(hi.into(), lo.into()) })
        }
        #[inline(always)]
        fn from_fn(mut f: impl FnMut(usize) -> f32) -> F8 {
            let v: [f32; 8] = std::array::from_fn(&mut f);
            F8(unsafe { _mm256_setr_ps(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]) })
        }
        #[inline(always)]
        fn lane(self, k: usize) -> f32 {
            let mut out = [0.0f32; 8];
            unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
            out[k]
        }
        #[inline(always)]
        fn min(self, o: F8) -> F8 {
            F8(unsafe { _mm256_min_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn max(self, o: F8) -> F8 {
            F8(unsafe { _mm256_max_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn abs(self) -> F8 {
            F8(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
        }
        #[inline(always)]
        fn signum(self) -> F8 {
            // The sign bit on 1.0; NaN stays.
            let one = unsafe {
                _mm256_or_ps(
                    _mm256_and_ps(self.0, _mm256_set1_ps(-0.0)),
                    _mm256_set1_ps(1.0),
                )
            };
            F8::select(self.is_nan(), self, F8(one))
        }
        #[inline(always)]
        fn sqrt(self) -> F8 {
            F8(unsafe { _mm256_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn floor(self) -> F8 {
            F8(unsafe { _mm256_round_ps(self.0, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC) })
        }
        #[inline(always)]
        fn cmpeq(self, o: F8) -> M8 {
            M8(unsafe { _mm256_cmp_ps(self.0, o.0, _CMP_EQ_OQ) })
        }
        #[inline(always)]
        fn cmplt(self, o: F8) -> M8 {
            M8(unsafe { _mm256_cmp_ps(self.0, o.0, _CMP_LT_OQ) })
        }
        #[inline(always)]
        fn cmple(self, o: F8) -> M8 {
            M8(unsafe { _mm256_cmp_ps(self.0, o.0, _CMP_LE_OQ) })
        }
        #[inline(always)]
        fn cmpgt(self, o: F8) -> M8 {
            M8(unsafe { _mm256_cmp_ps(self.0, o.0, _CMP_GT_OQ) })
        }
        #[inline(always)]
        fn cmpge(self, o: F8) -> M8 {
            M8(unsafe { _mm256_cmp_ps(self.0, o.0, _CMP_GE_OQ) })
        }
        #[inline(always)]
        fn is_nan(self) -> M8 {
            M8(unsafe { _mm256_cmp_ps(self.0, self.0, _CMP_UNORD_Q) })
        }
        #[inline(always)]
        fn is_finite(self) -> M8 {
            // |x| < infinity: false for both infinities and NaN.
            M8(unsafe {
                _mm256_cmp_ps(
                    _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0),
                    _mm256_set1_ps(f32::INFINITY),
                    _CMP_LT_OQ,
                )
            })
        }
        #[inline(always)]
        fn select(m: M8, a: F8, b: F8) -> F8 {
            F8(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
        }
        #[cfg(target_feature = "avx2")]
        #[inline(always)]
        fn split_exponent(self) -> (F8, F8) {
            // (Integer AVX2 as `bits4`'s SSE2.)
            unsafe {
                let b = _mm256_castps_si256(self.0);
                let e = _mm256_sub_epi32(_mm256_srli_epi32(b, 23), _mm256_set1_epi32(127));
                let m = _mm256_or_si256(
                    _mm256_and_si256(b, _mm256_set1_epi32(0x007f_ffff)),
                    _mm256_set1_epi32(0x3f80_0000),
                );
                (F8(_mm256_castsi256_ps(m)), F8(_mm256_cvtepi32_ps(e)))
            }
        }
        #[cfg(target_feature = "avx2")]
        #[inline(always)]
        fn round_even(self) -> F8 {
            // The conversion rounds by MXCSR, which Rust leaves at its
            // default (to nearest, ties to even).
            F8(unsafe { _mm256_cvtepi32_ps(_mm256_cvtps_epi32(self.0)) })
        }
        #[cfg(target_feature = "avx2")]
        #[inline(always)]
        fn exp2_whole(self) -> F8 {
            // n + 127 lies in [0, 254]: a biased exponent, 0 being the
            // float 0.
            unsafe {
                let e = _mm256_add_epi32(_mm256_cvttps_epi32(self.0), _mm256_set1_epi32(127));
                F8(_mm256_castsi256_ps(_mm256_slli_epi32(e, 23)))
            }
        }
        #[cfg(not(target_feature = "avx2"))]
        #[inline(always)]
        fn split_exponent(self) -> (F8, F8) {
            let (lo, hi) = (self.quad(0).split_exponent(), self.quad(1).split_exponent());
            (
                F8::from_quads(|q| [lo.0, hi.0][q]),
                F8::from_quads(|q| [lo.1, hi.1][q]),
            )
        }
        #[cfg(not(target_feature = "avx2"))]
        #[inline(always)]
        fn round_even(self) -> F8 {
            F8::from_quads(|q| self.quad(q).round_even())
        }
        #[cfg(not(target_feature = "avx2"))]
        #[inline(always)]
        fn exp2_whole(self) -> F8 {
            F8::from_quads(|q| self.quad(q).exp2_whole())
        }
    }
}

/// Eight lanes as two fours (builds without AVX).
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
mod f8 {
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

    use glam::{BVec4A, Vec4};

    use super::{Lane, Mask};

    /// Eight f32 lanes.
    #[derive(Clone, Copy, Debug)]
    pub struct F8(Vec4, Vec4);

    /// Eight lanes' mask.
    #[derive(Clone, Copy, Debug)]
    pub struct M8(BVec4A, BVec4A);

    macro_rules! op {
        ($tr:ident, $f:ident, $ty:ident) => {
            impl $tr for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $f(self, o: $ty) -> $ty {
                    $ty(self.0.$f(o.0), self.1.$f(o.1))
                }
            }
        };
    }
    op!(Add, add, F8);
    op!(Sub, sub, F8);
    op!(Mul, mul, F8);
    op!(Div, div, F8);
    op!(BitAnd, bitand, M8);
    op!(BitOr, bitor, M8);

    impl Neg for F8 {
        type Output = F8;
        #[inline(always)]
        fn neg(self) -> F8 {
            F8(-self.0, -self.1)
        }
    }

    impl Not for M8 {
        type Output = M8;
        #[inline(always)]
        fn not(self) -> M8 {
            M8(!self.0, !self.1)
        }
    }

    impl Mask for M8 {
        #[inline(always)]
        fn any(self) -> bool {
            self.0.any() || self.1.any()
        }
        #[inline(always)]
        fn all(self) -> bool {
            self.0.all() && self.1.all()
        }
        #[inline(always)]
        fn bitmask(self) -> u32 {
            self.0.bitmask() | (self.1.bitmask() << 4)
        }
    }

    macro_rules! two {
        ($f:ident) => {
            #[inline(always)]
            fn $f(self) -> F8 {
                F8(Lane::$f(self.0), Lane::$f(self.1))
            }
        };
    }
    macro_rules! cmp {
        ($f:ident) => {
            #[inline(always)]
            fn $f(self, o: F8) -> M8 {
                M8(Lane::$f(self.0, o.0), Lane::$f(self.1, o.1))
            }
        };
    }

    impl Lane for F8 {
        type Mask = M8;
        const WIDTH: usize = 8;
        const QUADS: usize = 2;
        #[inline(always)]
        fn splat(x: f32) -> F8 {
            F8(Vec4::splat(x), Vec4::splat(x))
        }
        #[inline(always)]
        fn quad(self, q: usize) -> Vec4 {
            if q == 0 { self.0 } else { self.1 }
        }
        #[inline(always)]
        fn from_quads(mut f: impl FnMut(usize) -> Vec4) -> F8 {
            let lo = f(0);
            F8(lo, f(1))
        }
        #[inline(always)]
        fn from_fn(mut f: impl FnMut(usize) -> f32) -> F8 {
            let lo = <Vec4 as Lane>::from_fn(&mut f);
            F8(lo, <Vec4 as Lane>::from_fn(|k| f(k + 4)))
        }
        #[inline(always)]
        fn lane(self, k: usize) -> f32 {
            if k < 4 { self.0[k] } else { self.1[k - 4] }
        }
        #[inline(always)]
        fn min(self, o: F8) -> F8 {
            F8(self.0.min(o.0), self.1.min(o.1))
        }
        #[inline(always)]
        fn max(self, o: F8) -> F8 {
            F8(self.0.max(o.0), self.1.max(o.1))
        }
        two!(abs);
        two!(signum);
        two!(sqrt);
        two!(floor);
        cmp!(cmpeq);
        cmp!(cmplt);
        cmp!(cmple);
        cmp!(cmpgt);
        cmp!(cmpge);
        #[inline(always)]
        fn is_nan(self) -> M8 {
            M8(Lane::is_nan(self.0), Lane::is_nan(self.1))
        }
        #[inline(always)]
        fn is_finite(self) -> M8 {
            M8(Lane::is_finite(self.0), Lane::is_finite(self.1))
        }
        #[inline(always)]
        fn select(m: M8, a: F8, b: F8) -> F8 {
            F8(Vec4::select(m.0, a.0, b.0), Vec4::select(m.1, a.1, b.1))
        }
        #[inline(always)]
        fn split_exponent(self) -> (F8, F8) {
            let (lo, hi) = (self.0.split_exponent(), self.1.split_exponent());
            (F8(lo.0, hi.0), F8(lo.1, hi.1))
        }
        two!(round_even);
        two!(exp2_whole);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values of every kind: ordinary, signed zeros, tiny, huge, infinite
    /// and NaN.
    fn values() -> Vec<f32> {
        let mut rnd = crate::testing::xorshift(0x5eed_1a4e);
        let mut v = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -2.5,
            1e-40,
            -1e-40,
            3.4e38,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        v.extend((0..500).map(|_| (rnd() - 0.5) * 1000.0));
        v
    }

    /// Every operation at `L`'s width equals the scalar one lane by lane.
    fn check<L: Lane>() {
        let v = values();
        let bits = |x: f32| x.to_bits();
        let n = v.len();
        for start in 0..n {
            let a = L::from_fn(|k| v[(start + k) % n]);
            let b = L::from_fn(|k| v[(start * 7 + k * 3 + 1) % n]);
            for k in 0..L::WIDTH {
                let (x, y) = (v[(start + k) % n], v[(start * 7 + k * 3 + 1) % n]);
                assert_eq!(bits((a + b).lane(k)), bits(x + y));
                assert_eq!(bits((a - b).lane(k)), bits(x - y));
                assert_eq!(bits((a * b).lane(k)), bits(x * y));
                let (q, want) = ((a / b).lane(k), x / y);
                assert!(bits(q) == bits(want) || (q.is_nan() && want.is_nan()));
                assert_eq!(bits((-a).lane(k)), bits(-x));
                assert_eq!(bits(a.abs().lane(k)), bits(x.abs()));
                let (sg, want) = (a.signum().lane(k), x.signum());
                assert!(bits(sg) == bits(want) || (sg.is_nan() && want.is_nan()));
                let (s, want) = (a.sqrt().lane(k), x.sqrt());
                assert!(bits(s) == bits(want) || (s.is_nan() && want.is_nan()));
                let (f, want) = (a.floor().lane(k), x.floor());
                assert!(f == want || (f.is_nan() && want.is_nan()), "floor {x}");
                // (NaN, and zeros of opposite sign: see the module's note.)
                if !(x.is_nan() || y.is_nan() || x == 0.0 && y == 0.0) {
                    assert_eq!(bits(a.min(b).lane(k)), bits(x.min(y)), "{x} {y}");
                    assert_eq!(bits(a.max(b).lane(k)), bits(x.max(y)), "{x} {y}");
                }
                let set = |m: L::Mask| m.bitmask() >> k & 1 == 1;
                assert_eq!(set(a.cmpeq(b)), x == y);
                assert_eq!(set(a.cmplt(b)), x < y);
                assert_eq!(set(a.cmpgt(b)), x > y);
                assert_eq!(set(a.cmple(b)), x <= y);
                assert_eq!(set(a.cmpge(b)), x >= y);
                let q = a.quad(k / 4)[k % 4];
                assert_eq!(bits(q), bits(x));
                let back = L::from_quads(|q| a.quad(q));
                assert_eq!(bits(back.lane(k)), bits(x));
                assert_eq!(set(a.is_nan()), x.is_nan());
                assert_eq!(set(a.is_finite()), x.is_finite());
                assert_eq!(
                    set(!a.cmplt(b)),
                    x.partial_cmp(&y) != Some(std::cmp::Ordering::Less)
                );
                assert_eq!(set(a.cmplt(b) & b.is_finite()), x < y && y.is_finite());
                assert_eq!(set(a.cmplt(b) | a.is_nan()), x < y || x.is_nan());
                let pick = L::select(a.cmplt(b), a, b).lane(k);
                assert_eq!(bits(pick), bits(if x < y { x } else { y }));
                assert_eq!(bits(a.map(|x| x * 3.0 + 1.0).lane(k)), bits(x * 3.0 + 1.0));
            }
            // The bit-level steps, over their domains.
            let pos = L::from_fn(|k| v[(start + k) % n].abs().max(f32::MIN_POSITIVE));
            let w = |k: usize| v[(start + k) % n] * 0.25;
            let whole = L::from_fn(|k| {
                if w(k).is_nan() {
                    0.5
                } else {
                    w(k).clamp(-127.0, 127.0)
                }
            });
            let (m, e) = pos.split_exponent();
            for k in 0..L::WIDTH {
                let (x, w) = (pos.lane(k), whole.lane(k));
                let (mx, ex) = x.split_exponent();
                assert_eq!((bits(m.lane(k)), bits(e.lane(k))), (bits(mx), bits(ex)));
                assert_eq!(mx * ex.exp2(), x, "{x} = {mx} 2^{ex}");
                assert_eq!(
                    bits(whole.round_even().lane(k)),
                    bits(w.round_ties_even() + 0.0)
                );
                let r = w.round_ties_even();
                let want = if r == -127.0 { 0.0 } else { r.exp2() };
                assert_eq!(r.round_even().exp2_whole(), want);
                assert_eq!(bits(whole.round_even().exp2_whole().lane(k)), bits(want));
            }
            let m = a.cmplt(b);
            assert_eq!(m.any(), m.bitmask() != 0);
            assert_eq!(m.all(), m.bitmask() == (1u32 << L::WIDTH) - 1);
        }
    }

    #[test]
    fn every_width_is_the_scalar_operations_bit_for_bit() {
        check::<f32>();
        check::<Vec4>();
        check::<F8>();
    }
}
