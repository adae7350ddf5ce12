//! KHR_materials_anisotropy's lobe: GGX rougher along a direction t of
//! the tangent plane than across it (b = n x t), written once over the
//! lane type:
//!
//!   D   = 1 / (pi a_t a_b ((t.h/a_t)^2 + (b.h/a_b)^2 + (n.h)^2)^2)
//!   Vis = 1 / ((|n.l| + |(a_t t.l, a_b b.l, n.l)|)
//!            (|n.v| + |(a_t t.v, a_b b.v, n.v)|))      (separable Smith)
//!
//! with a_t = lerp(alpha, 1, strength^2) and a_b = alpha: at strength 0
//! the isotropic D and Vis of `pbr`.

use std::f32::consts::PI;

use super::MIN_ALPHA;
use crate::simd::{Lane, V3};

/// The anisotropic GGX lobe at the lanes' points.
#[derive(Debug, Clone, Copy)]
pub struct Aniso<L: Lane = f32> {
    /// The direction along which the lobe is rougher, unit, in tangent
    /// space (x along the tangent, y along the bitangent).
    pub dir: (L, L),
    /// 0..1.
    pub strength: L,
    /// The direction in world space, unit, and across it (n x t): set by
    /// `orient` once the shading normal is known.
    pub t: V3<L>,
    pub b: V3<L>,
    /// GGX alpha along `t` and along `b`.
    pub at: L,
    pub ab: L,
}

impl<L: Lane> Aniso<L> {
    /// A lobe of `strength` (0..1) along tangent-space direction `dir`
    /// (unit) for perceptual roughness `roughness`.
    #[inline(always)]
    pub fn new(dir: (L, L), strength: L, roughness: L) -> Aniso<L> {
        let alpha = (roughness * roughness).max(L::splat(MIN_ALPHA));
        let one = L::splat(1.0);
        let s2 = strength * strength;
        Aniso {
            dir,
            strength,
            t: V3::zero(),
            b: V3::zero(),
            at: alpha * (one - s2) + s2,
            ab: alpha,
        }
    }

    /// Places the direction in world space about unit shading normals `n`
    /// with the interpolated tangents and their bitangent signs.
    #[inline(always)]
    pub fn orient(&mut self, n: V3<L>, tangents: (V3<L>, L)) {
        let (tt, bt) = crate::shade::lanes::tangent_frame(n, tangents);
        let t = tt.scale(self.dir.0) + bt.scale(self.dir.1);
        let t = (t - n.scale(n.dot(t))).normalize_or(tt);
        self.t = t;
        self.b = n.cross(t);
    }

    /// GGX's D times the separable Smith visibility of the anisotropic
    /// lobe, for n.l = `ndl` > 0 and half vector `h`.
    #[inline(always)]
    pub fn d_vis(&self, n: V3<L>, v: V3<L>, l: V3<L>, h: V3<L>, ndl: L) -> L {
        let (at, ab) = (self.at, self.ab);
        let ndv = n.dot(v).abs().max(L::splat(1e-4));
        let d = self.d(n, h);
        let g = |c: L, w: V3<L>| {
            let (x, y) = (at * self.t.dot(w), ab * self.b.dot(w));
            c + (x * x + y * y + c * c).sqrt()
        };
        d / (g(ndl, l) * g(ndv, v))
    }

    /// GGX's D of the anisotropic lobe at half vector `h` (zero below
    /// the surface).
    #[inline(always)]
    pub fn d(&self, n: V3<L>, h: V3<L>) -> L {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let (at, ab) = (self.at, self.ab);
        let ndh = n.dot(h);
        let (x, y) = (self.t.dot(h) / at, self.b.dot(h) / ab);
        let s = x * x + y * y + ndh * ndh;
        L::select(
            ndh.cmpgt(zero),
            one / (L::splat(PI) * at * ab * s * s),
            zero,
        )
    }

    /// The normal the environment's reflection is taken about: the normal
    /// of the plane through `b` that faces `v`, blended back to `n` by
    /// (1 - strength (1 - roughness))^4 (the extension's sample viewer).
    #[inline(always)]
    pub fn bent_normal(&self, n: V3<L>, v: V3<L>, roughness: L) -> V3<L> {
        let one = L::splat(1.0);
        let across = self.b.cross(v);
        let facing = across.cross(self.b);
        let bend = one - self.strength * (one - roughness);
        let k = (bend * bend) * (bend * bend);
        (facing.scale(one - k) + n.scale(k)).normalize_or(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shade::pbr::d_vis;
    use crate::testing::xorshift;
    use glam::Vec3;

    /// A lobe of `strength` at `angle` (radians from the tangent +x)
    /// about +z, oriented.
    fn lobe(angle: f32, strength: f32, roughness: f32) -> Aniso {
        let mut a = Aniso::new((angle.cos(), angle.sin()), strength, roughness);
        a.orient(V3::from(Vec3::Z), (V3::from(Vec3::X), 1.0));
        a
    }

    fn unit(mut next: impl FnMut() -> f32) -> Vec3 {
        let d = Vec3::new(next() - 0.5, next() - 0.5, next());
        d.normalize()
    }

    #[test]
    fn at_strength_zero_the_lobe_is_the_isotropic_one() {
        let mut next = xorshift(7);
        for _ in 0..200 {
            let (v, l) = (unit(&mut next), unit(&mut next));
            let angle = next() * 6.0;
            let rough = 0.05 + 0.9 * next();
            let a = lobe(angle, 0.0, rough);
            let n = V3::from(Vec3::Z);
            let h = V3::from((v + l).normalize());
            let alpha = (rough * rough).max(MIN_ALPHA);
            let iso = d_vis(n, v.into(), h, l.z, alpha * alpha);
            let aniso = a.d_vis(n, v.into(), l.into(), h, l.z);
            assert!((aniso - iso).abs() <= 1e-4 * iso.max(1.0), "{aniso} {iso}");
        }
    }

    /// D (n.h) integrates to 1 over the hemisphere of half vectors,
    /// whatever the direction and strength.
    #[test]
    fn the_distribution_is_normalized_at_every_direction() {
        for (angle, strength) in [(0.0f32, 0.8f32), (0.785, 0.8), (1.571, 0.8), (2.0, 0.5)] {
            let a = lobe(angle, strength, 0.5);
            let n = V3::from(Vec3::Z);
            let (nt, np) = (600, 600);
            let mut sum = 0.0f64;
            for i in 0..nt {
                let theta = (i as f32 + 0.5) / nt as f32 * std::f32::consts::FRAC_PI_2;
                for j in 0..np {
                    let phi = (j as f32 + 0.5) / np as f32 * std::f32::consts::TAU;
                    let h = Vec3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    );
                    let d = a.d(n, h.into());
                    let domega = theta.sin()
                        * (std::f32::consts::FRAC_PI_2 / nt as f32)
                        * (std::f32::consts::TAU / np as f32);
                    sum += (d * h.z * domega) as f64;
                }
            }
            assert!((sum - 1.0).abs() < 0.01, "{angle} {strength}: {sum}");
        }
    }

    /// The lobe turned by a quarter turn is the lobe of the turned
    /// directions; d_vis stays finite and positive.
    #[test]
    fn turning_the_direction_turns_the_lobe() {
        let mut next = xorshift(11);
        let turn = |d: Vec3| Vec3::new(-d.y, d.x, d.z);
        for angle in [0.0f32, 0.785, 1.2] {
            let (a, b) = (lobe(angle, 0.8, 0.35), lobe(angle + 1.570_796_4, 0.8, 0.35));
            for _ in 0..100 {
                let (v, l) = (unit(&mut next), unit(&mut next));
                let n = V3::from(Vec3::Z);
                let h = (v + l).normalize();
                let x = a.d_vis(n, v.into(), l.into(), h.into(), l.z);
                let (tv, tl) = (turn(v), turn(l));
                let y = b.d_vis(n, tv.into(), tl.into(), turn(h).into(), tl.z);
                assert!(x.is_finite() && x > 0.0, "{x}");
                assert!((x - y).abs() <= 1e-3 * x.max(1.0), "{angle}: {x} {y}");
            }
        }
    }
}
