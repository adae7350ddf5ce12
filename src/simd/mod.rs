//! The wide types of the renderer's lane code (shading a group of
//! fragments at a time, `shade::lanes`, and its texture lookups): the
//! lane type `Lane` (`lane`: one f32, four as glam's `Vec4`, eight as
//! `F8`), `V3<L>` for 3-vectors as a structure of arrays, the lane widths
//! this build has (`widths`, `SOFTRASTER_LANES`), and the few four-lane
//! operations glam does not offer (lanes from scalars without a trip
//! through memory, whole numbers and bytes to and from lanes), with a
//! scalar fallback elsewhere. Every operation is the scalar one lane by
//! lane, in the same order (IEEE operations on SIMD lanes round as scalar
//! ones do, and Rust never fuses a multiply and an add), so lane code
//! gives the one-lane code's results bit for bit at every width.

// Loops over the four lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::{Vec3, Vec4};

mod lane;

pub use lane::{F8, Lane, Mask};

/// The most lanes any width has (`F8`).
pub const MAX_WIDTH: usize = 8;

/// The lane widths this build shades with: 8 where it targets AVX
/// (x86-64-v3, the default x86-64 build), else 1 and 4.
pub fn widths() -> &'static [usize] {
    if cfg!(all(target_arch = "x86_64", target_feature = "avx")) {
        &[1, 4, 8]
    } else {
        &[1, 4]
    }
}

/// The widest lane width of this build.
pub fn widest() -> usize {
    widths().iter().copied().max().unwrap_or(4)
}

/// The lane width `SOFTRASTER_LANES` asks for (1, 4 or 8, for tests and
/// bug reports), or None without it; an error names the variable and
/// the widths this build has where it asks for another.
pub fn lane_width() -> Result<Option<usize>, String> {
    let Some(v) = std::env::var_os("SOFTRASTER_LANES") else {
        return Ok(None);
    };
    let v = v.to_string_lossy();
    match v.trim().parse::<usize>() {
        Ok(w) if widths().contains(&w) => Ok(Some(w)),
        _ => {
            let w: Vec<String> = widths().iter().map(|w| w.to_string()).collect();
            let (last, rest) = w
                .split_last()
                .map_or(("4", &[][..]), |(l, r)| (l.as_str(), r));
            Err(format!(
                "SOFTRASTER_LANES={v}: expected a lane width this build and CPU support: {} or {last}",
                rest.join(", ")
            ))
        }
    }
}

/// Lanes (a, b, c, d). glam's `Vec4::new` goes through memory on SSE
/// (four scalar stores, then one wide load that waits for them); this
/// builds the vector in registers.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn lanes4(a: f32, b: f32, c: f32, d: f32) -> Vec4 {
    use std::arch::x86_64::_mm_set_ps;
    // SAFETY: SSE only (in every x86-64 target's base features); no
    // memory is touched.
    Vec4::from(unsafe { _mm_set_ps(d, c, b, a) })
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
pub fn lanes4(a: f32, b: f32, c: f32, d: f32) -> Vec4 {
    Vec4::new(a, b, c, d)
}

/// The four lanes of `v`, whole and non-negative below 2^31, as integers
/// (truncated; lanes outside that range give unspecified values).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn whole4(v: Vec4) -> [u32; 4] {
    use std::arch::x86_64::*;
    let mut out = [0u32; 4];
    // SAFETY: SSE2 only (in every x86-64 target's base features); the
    // store writes the 16 bytes of `out`.
    unsafe { _mm_storeu_si128(out.as_mut_ptr() as *mut __m128i, _mm_cvttps_epi32(v.into())) };
    out
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
pub fn whole4(v: Vec4) -> [u32; 4] {
    v.to_array().map(|x| x as u32)
}

/// Where four bilinear footprints find their texels in levels laid out in
/// 4x4 blocks (the steps `Level::footprint` takes, per lane): for the top-left texels
/// (`x`, `y`) of levels `blocks_x` blocks wide, the first texel's position
/// and the steps to its right and lower neighbours. u32 arithmetic, as
/// `Level::index` has it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn block_steps4(x: [u32; 4], y: [u32; 4], blocks_x: [u32; 4]) -> [[u32; 4]; 3] {
    use std::arch::x86_64::*;
    let mut out = [[0u32; 4]; 3];
    // SAFETY: SSE2 only (in every x86-64 target's base features); the
    // loads and stores touch the 16 bytes of the arrays named.
    unsafe {
        let load = |a: &[u32; 4]| _mm_loadu_si128(a.as_ptr() as *const __m128i);
        let (x, y, bx) = (load(&x), load(&y), load(&blocks_x));
        let three = _mm_set1_epi32(3);
        let (xl, yl) = (_mm_and_si128(x, three), _mm_and_si128(y, three));
        // (y >> 2) * blocks_x, the low 32 bits, lanes 0 and 2 then 1 and 3.
        let by = _mm_srli_epi32(y, 2);
        let even = _mm_mul_epu32(by, bx);
        let odd = _mm_mul_epu32(_mm_srli_epi64(by, 32), _mm_srli_epi64(bx, 32));
        let rows = _mm_unpacklo_epi32(
            _mm_shuffle_epi32(even, 0b00_00_10_00),
            _mm_shuffle_epi32(odd, 0b00_00_10_00),
        );
        let block = _mm_add_epi32(rows, _mm_srli_epi32(x, 2));
        let at = _mm_or_si128(
            _mm_or_si128(_mm_slli_epi32(block, 4), _mm_slli_epi32(yl, 2)),
            xl,
        );
        // dx: 13 at a block's last column, else 1; dy: blocks_x * 16 - 12
        // at its last row, else 4.
        let last_x = _mm_cmpeq_epi32(xl, three);
        let last_y = _mm_cmpeq_epi32(yl, three);
        let dx = _mm_add_epi32(_mm_set1_epi32(1), _mm_and_si128(last_x, _mm_set1_epi32(12)));
        let down = _mm_sub_epi32(_mm_slli_epi32(bx, 4), _mm_set1_epi32(16));
        let dy = _mm_add_epi32(_mm_set1_epi32(4), _mm_and_si128(last_y, down));
        for (o, v) in out.iter_mut().zip([at, dx, dy]) {
            _mm_storeu_si128(o.as_mut_ptr() as *mut __m128i, v);
        }
    }
    out
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
pub fn block_steps4(x: [u32; 4], y: [u32; 4], blocks_x: [u32; 4]) -> [[u32; 4]; 3] {
    let mut out = [[0u32; 4]; 3];
    for k in 0..4 {
        let (x, y, bx) = (x[k], y[k], blocks_x[k]);
        out[0][k] =
            (((y >> 2).wrapping_mul(bx).wrapping_add(x >> 2)) << 4) | ((y & 3) << 2) | (x & 3);
        out[1][k] = if x & 3 == 3 { 13 } else { 1 };
        out[2][k] = if y & 3 == 3 {
            bx.wrapping_mul(16).wrapping_sub(12)
        } else {
            4
        };
    }
    out
}

/// Eight words (stored RGBA8 texels), `lo` in lanes 0-3 and `hi` in
/// lanes 4-7, held in one AVX2 register where the build has it: their
/// bytes are taken out channel by channel without going through memory
/// again.
#[derive(Clone, Copy)]
pub struct Words8 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    v: std::arch::x86_64::__m256i,
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    v: ([u32; 4], [u32; 4]),
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
impl Words8 {
    #[inline(always)]
    pub fn new(lo: [u32; 4], hi: [u32; 4]) -> Words8 {
        use std::arch::x86_64::*;
        // SAFETY: AVX2 is enabled for the build (the cfg above); no
        // memory is touched.
        let v = unsafe {
            _mm256_set_m128i(
                _mm_set_epi32(hi[3] as i32, hi[2] as i32, hi[1] as i32, hi[0] as i32),
                _mm_set_epi32(lo[3] as i32, lo[2] as i32, lo[1] as i32, lo[0] as i32),
            )
        };
        Words8 { v }
    }

    /// The words of `t` at `at[k]` (lanes 0-3) and `at[k] + step[k]`
    /// (lanes 4-7) for the lanes k whose bit is set in `live`, 0 in the
    /// others (which read nothing): two masked gathers.
    ///
    /// # Safety
    /// For every live lane, `at[k] + step[k] < t.len()`, and `t.len()`
    /// fits an `i32` (the gathers' indices).
    #[inline(always)]
    pub unsafe fn gather_pair(t: &[u32], at: [u32; 4], step: [u32; 4], live: u32) -> Words8 {
        use std::arch::x86_64::*;
        debug_assert!(t.len() <= i32::MAX as usize);
        // SAFETY: AVX2 is enabled for the build; the live lanes' indices
        // lie in `t` (the caller's contract), and a masked gather reads
        // nothing at the lanes its mask clears.
        let v = unsafe {
            let lo = _mm_loadu_si128(at.as_ptr().cast());
            let hi = _mm_add_epi32(lo, _mm_loadu_si128(step.as_ptr().cast()));
            let idx = _mm256_set_m128i(hi, lo);
            let bits = _mm256_set_epi32(8, 4, 2, 1, 8, 4, 2, 1);
            let mask =
                _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(live as i32), bits), bits);
            _mm256_mask_i32gather_epi32::<4>(_mm256_setzero_si256(), t.as_ptr().cast(), idx, mask)
        };
        Words8 { v }
    }

    /// Byte `shift / 8` of each word, 0..=255.
    #[inline(always)]
    fn byte(self, shift: u32) -> std::arch::x86_64::__m256i {
        use std::arch::x86_64::*;
        // SAFETY: as in `new`.
        unsafe {
            _mm256_and_si256(
                _mm256_srl_epi32(self.v, _mm_cvtsi32_si128(shift as i32)),
                _mm256_set1_epi32(0xff),
            )
        }
    }

    /// Byte `shift / 8` of each word as `byte as f32`.
    #[inline(always)]
    pub fn bytes(self, shift: u32) -> F8 {
        // SAFETY: as in `new`.
        F8::from(unsafe { std::arch::x86_64::_mm256_cvtepi32_ps(self.byte(shift)) })
    }

    /// `table[b]` for byte `shift / 8` of each word: one gather.
    #[inline(always)]
    pub fn lookup(self, table: &[f32; 256], shift: u32) -> F8 {
        // SAFETY: as in `new`; every index is masked to 0..=255, inside
        // the table's 256 entries.
        F8::from(unsafe {
            std::arch::x86_64::_mm256_i32gather_ps::<4>(table.as_ptr(), self.byte(shift))
        })
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
impl Words8 {
    #[inline(always)]
    pub fn new(lo: [u32; 4], hi: [u32; 4]) -> Words8 {
        Words8 { v: (lo, hi) }
    }

    /// The words of `t` at `at[k]` (lanes 0-3) and `at[k] + step[k]`
    /// (lanes 4-7) for the lanes k whose bit is set in `live`, 0 in the
    /// others (which read nothing).
    ///
    /// # Safety
    /// For every live lane, `at[k] + step[k] < t.len()`.
    #[inline(always)]
    pub unsafe fn gather_pair(t: &[u32], at: [u32; 4], step: [u32; 4], live: u32) -> Words8 {
        let (mut lo, mut hi) = ([0u32; 4], [0u32; 4]);
        for k in 0..4 {
            if live & (1 << k) != 0 {
                let i = at[k] as usize;
                debug_assert!(i + (step[k] as usize) < t.len());
                // SAFETY: the caller's contract.
                unsafe {
                    lo[k] = u32::from_le(*t.get_unchecked(i));
                    hi[k] = u32::from_le(*t.get_unchecked(i + step[k] as usize));
                }
            }
        }
        Words8 { v: (lo, hi) }
    }

    /// Byte `shift / 8` of each word as `byte as f32`.
    #[inline(always)]
    pub fn bytes(self, shift: u32) -> F8 {
        let at = |t: [u32; 4], k: usize| ((t[k] >> shift) & 0xff) as f32;
        F8::from_quads(|q| {
            let t = if q == 0 { self.v.0 } else { self.v.1 };
            lanes4(at(t, 0), at(t, 1), at(t, 2), at(t, 3))
        })
    }

    /// `table[b]` for byte `shift / 8` of each word.
    #[inline(always)]
    pub fn lookup(self, table: &[f32; 256], shift: u32) -> F8 {
        let at = |t: [u32; 4], k: usize| table[((t[k] >> shift) & 0xff) as usize];
        F8::from_quads(|q| {
            let t = if q == 0 { self.v.0 } else { self.v.1 };
            lanes4(at(t, 0), at(t, 1), at(t, 2), at(t, 3))
        })
    }
}

/// Whole numbers below which `exact4` and `ramp4` hold (2^51).
pub const RAMP_LIMIT: i64 = 1 << 51;

/// `v[k] as f32`, lane by lane (rounded once, to nearest), for values of
/// magnitude below `RAMP_LIMIT`: each becomes an f64 exactly (its bits
/// added to those of 2^52 + 2^51, which is then taken away), then one f32
/// rounding.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn exact4(v: [i64; 4]) -> Vec4 {
    use std::arch::x86_64::*;
    const MAGIC: f64 = 6_755_399_441_055_744.0; // 2^52 + 2^51
    debug_assert!(v.iter().all(|v| v.abs() < RAMP_LIMIT));
    // SAFETY: SSE2 only (in every x86-64 target's base features); no
    // memory is touched.
    unsafe {
        let m = _mm_set1_pd(MAGIC);
        let mi = _mm_castpd_si128(m);
        let exact = |a: i64, b: i64| {
            let v = _mm_add_epi64(_mm_set_epi64x(b, a), mi);
            _mm_cvtpd_ps(_mm_sub_pd(_mm_castsi128_pd(v), m))
        };
        let lo = exact(v[0], v[1]);
        let hi = exact(v[2], v[3]);
        Vec4::from(_mm_movelh_ps(lo, hi))
    }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
pub fn exact4(v: [i64; 4]) -> Vec4 {
    Vec4::new(v[0] as f32, v[1] as f32, v[2] as f32, v[3] as f32)
}

/// `[s, s + step, s + 2 step, s + 3 step]`, each as `v as f32` gives it
/// (`exact4`: magnitudes below `RAMP_LIMIT`).
#[inline(always)]
pub fn ramp4(s: i64, step: i64) -> Vec4 {
    exact4([s, s + step, s + 2 * step, s + 3 * step])
}

/// 3-vectors, one per lane of `L` (four by default), as a structure of
/// arrays: each operation is `Vec3`'s, lane by lane, in its order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct V3<L = Vec4> {
    pub x: L,
    pub y: L,
    pub z: L,
}

impl<L: Lane> V3<L> {
    #[inline(always)]
    pub fn zero() -> V3<L> {
        V3::splat(Vec3::ZERO)
    }

    #[inline(always)]
    pub fn splat(v: Vec3) -> V3<L> {
        V3 {
            x: L::splat(v.x),
            y: L::splat(v.y),
            z: L::splat(v.z),
        }
    }

    /// Lane k is `f(k)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> Vec3) -> V3<L> {
        let mut v = [Vec3::ZERO; 8];
        for (k, o) in v.iter_mut().take(L::WIDTH).enumerate() {
            *o = f(k);
        }
        V3 {
            x: L::from_fn(|k| v[k].x),
            y: L::from_fn(|k| v[k].y),
            z: L::from_fn(|k| v[k].z),
        }
    }

    #[inline(always)]
    pub fn lane(&self, k: usize) -> Vec3 {
        Vec3::new(self.x.lane(k), self.y.lane(k), self.z.lane(k))
    }

    /// `Vec3::dot`: (x x') + (y y') + (z z').
    #[inline(always)]
    pub fn dot(self, o: V3<L>) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// `Vec3::cross`.
    #[inline(always)]
    pub fn cross(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// Each lane's vector times that lane's scalar (`Vec3 * f32`).
    #[inline(always)]
    pub fn scale(self, s: L) -> V3<L> {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Lane by lane: `a` where `m`, else `b`.
    #[inline(always)]
    pub fn select(m: L::Mask, a: V3<L>, b: V3<L>) -> V3<L> {
        V3 {
            x: L::select(m, a.x, b.x),
            y: L::select(m, a.y, b.y),
            z: L::select(m, a.z, b.z),
        }
    }

    /// `Vec3::min` per lane.
    #[inline(always)]
    pub fn min(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x.min(o.x),
            y: self.y.min(o.y),
            z: self.z.min(o.z),
        }
    }

    /// `Vec3::max` with a scalar per lane's components.
    #[inline(always)]
    pub fn max(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x.max(o.x),
            y: self.y.max(o.y),
            z: self.z.max(o.z),
        }
    }

    /// `Vec3::length_recip`: 1 / sqrt(dot).
    #[inline(always)]
    pub fn length_recip(self) -> L {
        L::splat(1.0) / self.dot(self).sqrt()
    }

    /// `Vec3::try_normalize` per lane: the unit vector and the lanes where
    /// it exists (the reciprocal length is finite and positive).
    #[inline(always)]
    pub fn try_normalize(self) -> (V3<L>, L::Mask) {
        let rcp = self.length_recip();
        let ok = rcp.is_finite() & rcp.cmpgt(L::splat(0.0));
        (self.scale(rcp), ok)
    }

    /// `Vec3::normalize_or`.
    #[inline(always)]
    pub fn normalize_or(self, fallback: V3<L>) -> V3<L> {
        let (n, ok) = self.try_normalize();
        V3::select(ok, n, fallback)
    }

    /// The lanes where all three components are finite.
    #[inline(always)]
    pub fn is_finite_mask(self) -> L::Mask {
        self.x.is_finite() & self.y.is_finite() & self.z.is_finite()
    }
}

impl V3 {
    pub const ZERO: V3 = V3 {
        x: Vec4::ZERO,
        y: Vec4::ZERO,
        z: Vec4::ZERO,
    };

    #[inline(always)]
    pub fn from_lanes(v: [Vec3; 4]) -> V3 {
        V3 {
            x: lanes4(v[0].x, v[1].x, v[2].x, v[3].x),
            y: lanes4(v[0].y, v[1].y, v[2].y, v[3].y),
            z: lanes4(v[0].z, v[1].z, v[2].z, v[3].z),
        }
    }
}

impl From<Vec3> for V3<f32> {
    #[inline(always)]
    fn from(v: Vec3) -> V3<f32> {
        V3 {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

impl From<V3<f32>> for Vec3 {
    #[inline(always)]
    fn from(v: V3<f32>) -> Vec3 {
        Vec3::new(v.x, v.y, v.z)
    }
}

/// Component-wise sum.
impl<L: Lane> Add for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn add(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

/// Component-wise difference.
impl<L: Lane> Sub for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn sub(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

/// Component-wise product (`Vec3 * Vec3`).
impl<L: Lane> Mul for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn mul(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }
}

/// Each lane's vector over that lane's scalar (`Vec3 / f32`).
impl<L: Lane> Div<L> for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn div(self, s: L) -> V3<L> {
        V3 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }
}

impl<L: Lane> Neg for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn neg(self) -> V3<L> {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

/// `f32::clamp(x, 0.0, 1.0)` per lane (signed zeros and NaN included).
#[inline(always)]
pub fn clamp01<L: Lane>(x: L) -> L {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let x = L::select(x.cmplt(zero), zero, x);
    L::select(x.cmpgt(one), one, x)
}

/// `a x + b y + c z` lane by lane, in that order (barycentric weights
/// (x, y, z) of a triangle's corners, as `Vec3 * f32` sums).
#[inline(always)]
pub fn lerp3<L: Lane>(a: V3<L>, b: V3<L>, c: V3<L>, l: V3<L>) -> V3<L> {
    a.scale(l.x) + b.scale(l.y) + c.scale(l.z)
}

#[cfg(test)]
mod tests {
    /// `Words8::gather_pair` reads the live lanes' two words and nothing
    /// else: the dead lanes' indices lie far outside the slice (a read
    /// there would fault or give garbage), and they come back 0.
    #[test]
    fn a_gathered_pair_reads_only_the_live_lanes() {
        let t: Vec<u32> = (0..64u32).map(|i| i.wrapping_mul(0x9e37_79b9)).collect();
        let far = u32::MAX / 8;
        for live in 0..16u32 {
            let at: [u32; 4] = std::array::from_fn(|k| {
                if live & (1 << k) != 0 {
                    [3, 9, 17, 40][k]
                } else {
                    far
                }
            });
            let step = [4, 13, 1, 20];
            // SAFETY: every live lane's at + step lies in `t` (at most 60).
            let w = unsafe { Words8::gather_pair(&t, at, step, live) };
            let bytes = w.bytes(0);
            for k in 0..4 {
                let on = live & (1 << k) != 0;
                let (lo, hi) = if on {
                    (t[at[k] as usize], t[(at[k] + step[k]) as usize])
                } else {
                    (0, 0)
                };
                assert_eq!(
                    bytes.quad(0)[k],
                    (lo & 0xff) as f32,
                    "live {live:04b} lane {k}"
                );
                assert_eq!(
                    bytes.quad(1)[k],
                    (hi & 0xff) as f32,
                    "live {live:04b} lane {k}"
                );
            }
            let high = w.bytes(24);
            for k in (0..4).filter(|k| live & (1 << k) != 0) {
                assert_eq!(high.quad(0)[k], (t[at[k] as usize] >> 24) as f32);
                assert_eq!(
                    high.quad(1)[k],
                    (t[(at[k] + step[k]) as usize] >> 24) as f32
                );
            }
        }
    }

    /// The SSE2 block steps equal the scalar formula (`Level::index`
    /// and `footprint`) over positions and widths up to 2^14
    /// blocks, at every remainder mod 4.
    #[test]
    fn block_steps_equal_the_scalar_formula() {
        let mut rnd = crate::testing::xorshift(0x1234_5678);
        // Whole numbers below 2^24.
        let mut next = || (rnd() * (1u32 << 24) as f32) as u32;
        for _ in 0..20_000 {
            let bx: [u32; 4] = std::array::from_fn(|_| 1 + next() % (1 << 14));
            let x: [u32; 4] = std::array::from_fn(|k| next() % (bx[k] * 4));
            let y: [u32; 4] = std::array::from_fn(|_| next() % (1 << 16));
            let [at, dx, dy] = super::block_steps4(x, y, bx);
            for k in 0..4 {
                let (x, y, b) = (x[k], y[k], bx[k]);
                let want_at = ((((y >> 2) * b + (x >> 2)) << 4) | ((y & 3) << 2) | (x & 3)) as u64;
                assert_eq!(at[k] as u64, want_at, "{x} {y} {b}");
                assert_eq!(dx[k], if x & 3 == 3 { 13 } else { 1 });
                assert_eq!(
                    dy[k] as u64,
                    if y & 3 == 3 { b as u64 * 16 - 12 } else { 4 }
                );
            }
        }
    }

    use super::*;

    #[test]
    fn clamp01_is_f32_clamp() {
        for x in [-1.0f32, -0.0, 0.0, 0.3, 1.0, 1.5, f32::INFINITY, f32::NAN] {
            let got = clamp01(Vec4::splat(x)).x;
            let want = x.clamp(0.0, 1.0);
            assert!(got.to_bits() == want.to_bits(), "{x}: {got} {want}");
        }
    }

    #[test]
    fn ramps_round_as_one_conversion() {
        let mut x = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for round in 0..200_000 {
            // Every magnitude up to the limit, and around powers of two
            // where f32 rounding ties.
            let bits = 1 + round % 50;
            let s = (next() >> (64 - bits)) as i64 * if round % 2 == 0 { 1 } else { -1 };
            let s = if round % 5 == 0 {
                (1i64 << (round % 49)) + (round as i64 % 3) - 1
            } else {
                s
            };
            let step = (next() >> (64 - (1 + round % 40))) as i64 - (1i64 << (round % 40)) / 2;
            if [s, s + 3 * step].iter().any(|v| v.abs() >= RAMP_LIMIT) {
                continue;
            }
            let got = ramp4(s, step);
            for k in 0..4 {
                let want = (s + k as i64 * step) as f32;
                assert_eq!(got[k].to_bits(), want.to_bits(), "{s} {step} {k}");
            }
        }
    }

    #[test]
    fn lanes_and_bytes_are_the_scalar_values() {
        assert_eq!(
            lanes4(1.0, -2.0, f32::NAN, 4.0).to_array()[..2],
            [1.0, -2.0]
        );
        assert!(lanes4(1.0, -2.0, f32::NAN, 4.0).z.is_nan());
        assert_eq!(
            whole4(Vec4::new(0.0, 1.0, 7.0, 16_777_215.0)),
            [0, 1, 7, 16_777_215]
        );
        let t = [0x0403_0201, 0xff00_80fe, 0, u32::MAX];
        let squares: [f32; 256] = std::array::from_fn(|i| (i * i) as f32);
        for shift in [0, 8, 16, 24] {
            let w = Words8::new(t, [t[3], t[2], t[1], t[0]]);
            let (bytes, table) = (w.bytes(shift), w.lookup(&squares, shift));
            for k in 0..4 {
                let b = ((t[k] >> shift) & 0xff) as f32;
                for lane in [k, 7 - k] {
                    assert_eq!(bytes.lane(lane).to_bits(), b.to_bits());
                    assert_eq!(table.lane(lane), b * b);
                }
            }
        }
    }

    #[test]
    fn lanes_are_bit_for_bit_the_scalar_operations() {
        let mut s = 12345u32;
        let mut r = || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) as f32 / (1u32 << 23) as f32 - 1.0
        };
        for _ in 0..500 {
            let a = [0; 4].map(|_| Vec3::new(r(), r(), r()));
            let b = [0; 4].map(|_| Vec3::new(r(), r(), r()) * 3.0);
            let (va, vb) = (V3::from_lanes(a), V3::from_lanes(b));
            let zero = V3::from_lanes([a[0], Vec3::ZERO, a[2], Vec3::ZERO]);
            let n = zero.normalize_or(V3::splat(Vec3::Y));
            for k in 0..4 {
                assert_eq!(va.dot(vb)[k].to_bits(), a[k].dot(b[k]).to_bits());
                assert_eq!(va.cross(vb).lane(k), a[k].cross(b[k]));
                assert_eq!(va.normalize_or(vb).lane(k), a[k].normalize_or(b[k]));
                assert_eq!(
                    n.lane(k),
                    zero.lane(k).normalize_or(Vec3::Y),
                    "zero vectors fall back"
                );
                let l = Vec3::new(r(), r(), r());
                let vl = V3::splat(l);
                assert_eq!(
                    lerp3(va, vb, va, vl).lane(k),
                    a[k] * l.x + b[k] * l.y + a[k] * l.z
                );
            }
        }
    }
}
