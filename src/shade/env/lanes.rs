//! The environment's lookups for four fragments at once (the Blinn-Phong
//! lanes, `shade::lanes`): the operations of the one-direction
//! functions of the parent module in the same order on four lanes, so
//! each lane is bit for bit their answer. Texel loads and their bilinear
//! blends stay per lane; the direction arithmetic (rotation, spherical
//! harmonics, the two arc tangents of the image coordinates, the filter
//! positions) runs four-wide.

use std::f32::consts::PI;

use glam::{Mat3, Vec3, Vec3A, Vec4};

use super::{EnvLight, Equirect, level_of};
use crate::simd::V3;

/// `m * v` lane by lane, as `Mat3::mul_vec3` sums it.
#[inline(always)]
fn rotate(m: &Mat3, v: V3) -> V3 {
    let col = |c: Vec3, s: Vec4| V3::splat(c).scale(s);
    col(m.x_axis, v.x) + col(m.y_axis, v.y) + col(m.z_axis, v.z)
}

/// `super::atan2` on four lanes.
#[inline(always)]
fn atan2(y: Vec4, x: Vec4) -> Vec4 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    let a = lo / hi;
    let s = a * a;
    let mut p = Vec4::splat(super::ATAN_C[6]);
    for &c in super::ATAN_C[..6].iter().rev() {
        p = p * s + Vec4::splat(c);
    }
    let mut r = p * a;
    r = Vec4::select(
        ay.cmpgt(ax),
        Vec4::splat(std::f32::consts::FRAC_PI_2) - r,
        r,
    );
    r = Vec4::select(x.cmplt(Vec4::ZERO), Vec4::splat(PI) - r, r);
    r = Vec4::select(y.cmplt(Vec4::ZERO), -r, r);
    r = Vec4::select(hi.cmpeq(Vec4::ZERO), Vec4::ZERO, r);
    let nan = x.is_nan_mask() | y.is_nan_mask();
    Vec4::select(nan, Vec4::splat(f32::NAN), r)
}

/// `super::direction_to_uv` on four lanes: (u, v).
#[inline(always)]
fn direction_to_uv(d: V3) -> (Vec4, Vec4) {
    let horizontal = (d.x * d.x + d.z * d.z).sqrt();
    let u = Vec4::splat(0.5) + atan2(d.x, -d.z) * Vec4::splat(0.5 / PI);
    let v = atan2(horizontal, d.y) * Vec4::splat(1.0 / PI);
    let finite = d.is_finite_mask();
    (
        Vec4::select(finite, u, Vec4::splat(0.5)),
        Vec4::select(finite, v, Vec4::ZERO),
    )
}

impl Equirect {
    /// `sample_uv` at four positions.
    #[inline(always)]
    fn sample_uv4(&self, u: Vec4, v: Vec4) -> [Vec3A; 4] {
        let x = u * Vec4::splat(self.width as f32) - Vec4::splat(0.5);
        let y = (v * Vec4::splat(self.height as f32) - Vec4::splat(0.5))
            .max(Vec4::ZERO)
            .min(Vec4::splat((self.height - 1) as f32));
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        // Finite: u and v come from `direction_to_uv` (in [0, 1]) and y
        // is clamped; `as` saturates in any case.
        std::array::from_fn(|k| self.blend(x0[k] as i64, y0[k] as usize, fx[k], fy[k]))
    }
}

impl EnvLight {
    /// `to_env` on four lanes.
    #[inline(always)]
    fn to_env4(&self, d: V3) -> V3 {
        match &self.env_from_world {
            Some(m) => rotate(m, d),
            None => d,
        }
    }

    /// `irradiance` at four unit normals.
    pub fn irradiance4(&self, n: V3) -> V3 {
        let d = self.to_env4(n);
        let (x, y, z) = (d.x, d.y, d.z);
        let c = |k: f32| Vec4::splat(k);
        let basis = [
            c(0.282_095),
            c(0.488_603) * y,
            c(0.488_603) * z,
            c(0.488_603) * x,
            c(1.092_548) * x * y,
            c(1.092_548) * y * z,
            c(0.315_392) * (c(3.0) * z * z - c(1.0)),
            c(1.092_548) * x * z,
            c(0.546_274) * (x * x - y * y),
        ];
        let mut e = V3::ZERO;
        for (sh, b) in self.sh.iter().zip(basis) {
            e = e + V3::splat(*sh).scale(b);
        }
        let i = Vec4::splat(self.intensity);
        V3 {
            x: e.x.max(Vec4::ZERO) * i,
            y: e.y.max(Vec4::ZERO) * i,
            z: e.z.max(Vec4::ZERO) * i,
        }
    }

    /// `prefiltered` along four directions, for one roughness.
    pub fn prefiltered4(&self, r: V3, roughness: f32) -> V3 {
        let (u, v) = direction_to_uv(self.to_env4(r));
        let (k, f) = level_of(roughness);
        let a = self.levels[k].sample_uv4(u, v);
        let out: [Vec3; 4] = if f <= 0.0 {
            a.map(|a| Vec3::from(a * self.intensity))
        } else {
            let b = self.levels[k + 1].sample_uv4(u, v);
            std::array::from_fn(|j| Vec3::from(a[j].lerp(b[j], f) * self.intensity))
        };
        V3::from_lanes(out)
    }
}

impl EnvLight {
    /// `prefiltered_phong` along four directions.
    pub fn prefiltered_phong4(&self, r: V3, roughness: f32) -> V3 {
        match self.phong_level(roughness) {
            Some(level) => {
                let t = level.sample4(self.to_env4(r));
                V3::from_lanes(t.map(|t| Vec3::from(t * self.intensity)))
            }
            None => self.prefiltered4(r, roughness),
        }
    }
}

/// `super::dominant_direction` on four lanes, each with its roughness.
#[inline(always)]
pub fn dominant_direction4(n: V3, r: V3, roughness: Vec4) -> V3 {
    let a = roughness * roughness;
    let f = (Vec4::ONE - a) * ((Vec4::ONE - a).sqrt() + a);
    // `Vec3::lerp`: n (1 - f) + r f.
    let l = n.scale(Vec4::ONE - f) + r.scale(f);
    l.normalize_or(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::environment::EnvImage;
    use glam::Vec2;

    /// Directions of every kind: random, on the axes and the poles, signed
    /// zeros, tiny, huge, infinite and NaN components.
    fn directions() -> Vec<Vec3> {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut out: Vec<Vec3> = (0..20_000)
            .map(|_| Vec3::new(next(), next(), next()))
            .collect();
        let odd = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            1e-30,
            -3e-39,
            3e38,
            f32::INFINITY,
            f32::NAN,
        ];
        for &x in &odd {
            for &y in &odd {
                for &z in &odd {
                    out.push(Vec3::new(x, y, z));
                }
            }
        }
        out
    }

    fn same(a: Vec3, b: Vec3) -> bool {
        a.to_array()
            .iter()
            .zip(b.to_array())
            .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
    }

    fn studio() -> EnvImage {
        // Varied radiance: a bright patch, a gradient, a dark floor.
        let (w, h) = (64u32, 32u32);
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
                let patch = if (0.3..0.4).contains(&x) && y < 0.3 {
                    20.0
                } else {
                    0.0
                };
                Vec3::new(0.2 + x + patch, 1.0 - y, 0.5 * x * y + patch * 0.5)
            })
            .collect();
        EnvImage {
            width: w,
            height: h,
            texels,
        }
    }

    #[test]
    fn four_lanes_are_the_one_direction_functions_bit_for_bit() {
        // Turned, and not (the unturned one skips the rotation).
        for turn in [33.0, 0.0] {
            compare_lanes(turn);
        }
    }

    fn compare_lanes(turn: f32) {
        let phong = [0.15, 0.55, 0.75];
        let env = EnvLight::with_size(&studio(), 1.7, turn, 16).with_phong_roughness(phong);
        let dirs = directions();
        for (i, q) in dirs.chunks_exact(4).enumerate() {
            let d = V3::from_lanes([q[0], q[1], q[2], q[3]]);
            for k in 0..4 {
                let (u, v) = direction_to_uv(d);
                let uv = super::super::direction_to_uv(q[k]);
                let want = Vec2::new(u[k], v[k]);
                assert!(
                    same(uv.extend(0.0), want.extend(0.0)),
                    "uv of {:?}: {uv:?} against {want:?}",
                    q[k]
                );
            }
            let unit = d.normalize_or(V3::splat(Vec3::Y));
            let irr = env.irradiance4(unit);
            let roughness = (i % 13) as f32 / 12.0;
            let pre = env.prefiltered4(unit, roughness);
            let n = V3::from_lanes([q[1], q[2], q[3], q[0]]).normalize_or(V3::splat(Vec3::Z));
            let dom = dominant_direction4(n, unit, Vec4::splat(roughness));
            let ph = phong[i % 3];
            let pre_phong = env.prefiltered_phong4(unit, ph);
            for k in 0..4 {
                let (nk, dk) = (n.lane(k), unit.lane(k));
                assert!(
                    same(irr.lane(k), env.irradiance(dk)),
                    "irradiance at {dk:?}"
                );
                assert!(
                    same(pre.lane(k), env.prefiltered(dk, roughness)),
                    "prefiltered at {dk:?}, roughness {roughness}"
                );
                assert!(same(pre_phong.lane(k), env.prefiltered_phong(dk, ph)));
                assert!(same(
                    dom.lane(k),
                    super::super::dominant_direction(nk, dk, roughness)
                ));
            }
        }
    }

    #[test]
    fn a_phong_level_reads_as_the_two_levels_it_blends() {
        let env = EnvLight::with_size(&studio(), 1.0, 0.0, 128).with_phong_roughness([0.55, 0.15]);
        assert!(env.phong_level(0.55).is_some() && env.phong_level(0.3).is_none());
        // The octahedral map resamples the blended levels: the same light
        // to within a small part of its range (the test sky has a patch 20
        // times brighter than the rest, blurred by the lobe).
        for rough in [0.55, 0.15] {
            let (mut sum, mut worst, mut n) = (0.0f32, 0.0f32, 0);
            let mut top = 0.0f32;
            for d in directions().into_iter().take(5000) {
                let Some(d) = d.try_normalize() else { continue };
                let (a, b) = (env.prefiltered_phong(d, rough), env.prefiltered(d, rough));
                let e = (a - b).abs().max_element();
                sum += e;
                worst = worst.max(e);
                top = top.max(b.max_element());
                n += 1;
            }
            let mean = sum / n as f32;
            assert!(
                mean < 0.01 * top && worst < 0.1 * top,
                "roughness {rough}: mean {mean}, worst {worst}, top {top}"
            );
        }
    }
}
