//! The deterministic sample patterns of `method = "sampled"`: a
//! Hammersley set turned by a hash of the shaded point, so every frame
//! and every lane width draws the same directions.

use glam::{Mat3, Vec2, Vec3};

/// Point `i` of `n` of the Hammersley set, rotated by `shift` (mod 1).
pub(crate) fn point(i: u32, n: u32, shift: Vec2) -> Vec2 {
    let p = Vec2::new(
        i as f32 / n as f32,
        i.reverse_bits() as f32 * 2.328_306_4e-10,
    ) + shift;
    p - p.floor()
}

/// Two numbers in [0, 1) from a position (the pattern's rotation).
pub(crate) fn position_hash(p: Vec3) -> Vec2 {
    let mut h = p.x.to_bits().wrapping_mul(0x9E37_79B1)
        ^ p.y.to_bits().wrapping_mul(0x85EB_CA77).rotate_left(13)
        ^ p.z.to_bits().wrapping_mul(0xC2B2_AE3D).rotate_left(7);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7FEB_352D);
    h ^= h >> 15;
    let g = h.wrapping_mul(0x846C_A68B) ^ (h >> 16);
    Vec2::new(
        (h >> 8) as f32 / (1u32 << 24) as f32,
        (g >> 8) as f32 / (1u32 << 24) as f32,
    )
}

/// An orthonormal frame whose third axis is `n`.
pub(crate) fn frame(n: Vec3) -> Mat3 {
    let t = n.any_orthonormal_vector();
    Mat3::from_cols(t, n.cross(t), n)
}
