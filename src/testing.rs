//! Helpers for the unit tests (compiled only for them).

/// A deterministic stream of floats in [0, 1) (xorshift64), for tests
/// that sweep many random configurations.
pub fn xorshift(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 24) as f32
    }
}
