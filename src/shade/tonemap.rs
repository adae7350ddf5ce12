//! From linear radiance to display values: exposure and a tone map (clamp,
//! Reinhard, ACES as Narkowicz and as Hill fit it, Khronos PBR Neutral,
//! Blender's AgX); the sRGB encoding that follows is `color::encode_srgb`.

use glam::{Mat3, Vec3};

use crate::scene::settings::Tonemap;
use crate::simd::{Lane, V3};

/// Linear radiance `c` scaled by `exposure_scale` (2^stops) and mapped by
/// `op` to display-linear values (in [0, 1] for every map but `clamp`,
/// which the sRGB encoding clamps): `tonemap_lanes` of one lane.
#[inline]
pub fn tonemap(c: Vec3, op: Tonemap, exposure_scale: f32) -> Vec3 {
    tonemap_lanes::<f32>(c.into(), op, exposure_scale).into()
}

/// `tonemap` of every lane of `c`, each lane's operations those of
/// `Vec3`'s, in their order.
#[inline(always)]
pub fn tonemap_lanes<L: Lane>(c: V3<L>, op: Tonemap, exposure_scale: f32) -> V3<L> {
    let c = c.scale(L::splat(exposure_scale));
    let mapped = match op {
        Tonemap::Clamp => c,
        Tonemap::Reinhard => c.over(c.plus(1.0)),
        Tonemap::Aces => {
            // Narkowicz's fit of the ACES filmic curve.
            let (a, b, cc, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
            (c * c.times(a).plus(b)).over((c * c.times(cc).plus(d)).plus(e))
        }
        Tonemap::AcesHill => aces_hill(c),
        Tonemap::PbrNeutral => pbr_neutral(c),
        Tonemap::Agx => agx(c),
    };
    // `Vec3::clamp(0, 1)`: max, then min.
    mapped.max(V3::splat(Vec3::ZERO)).min(V3::splat(Vec3::ONE))
}

/// `Vec3`'s arithmetic with a scalar, lane by lane.
trait Scalars {
    /// `v + s`.
    fn plus(self, s: f32) -> Self;
    /// `v * s`.
    fn times(self, s: f32) -> Self;
    /// `v / w`, component by component.
    fn over(self, w: Self) -> Self;
    /// `m * v` as glam's `Mat3::mul_vec3` sums it.
    fn by(self, m: Mat3) -> Self;
}

impl<L: Lane> Scalars for V3<L> {
    #[inline(always)]
    fn plus(self, s: f32) -> V3<L> {
        self + V3::splat(Vec3::splat(s))
    }
    #[inline(always)]
    fn times(self, s: f32) -> V3<L> {
        self.scale(L::splat(s))
    }
    #[inline(always)]
    fn over(self, w: V3<L>) -> V3<L> {
        V3 {
            x: self.x / w.x,
            y: self.y / w.y,
            z: self.z / w.z,
        }
    }
    #[inline(always)]
    fn by(self, m: Mat3) -> V3<L> {
        V3::splat(m.x_axis).scale(self.x)
            + V3::splat(m.y_axis).scale(self.y)
            + V3::splat(m.z_axis).scale(self.z)
    }
}

/// three.js's `ACESFilmicToneMapping` (tonemapping_pars_fragment.glsl):
/// the radiance scaled by 1/0.6 ("a brighter viewing environment"), taken
/// from sRGB primaries to ACES AP1 with the RRT's saturation, through
/// Stephen Hill's rational fit of the RRT and ODT, and back to sRGB with
/// the ODT's saturation.
#[inline(always)]
fn aces_hill<L: Lane>(c: V3<L>) -> V3<L> {
    // By column, as the GLSL source writes them.
    let input = Mat3::from_cols(
        Vec3::new(0.597_19, 0.076_00, 0.028_40),
        Vec3::new(0.354_58, 0.908_34, 0.133_83),
        Vec3::new(0.048_23, 0.015_66, 0.837_77),
    );
    let output = Mat3::from_cols(
        Vec3::new(1.604_75, -0.102_08, -0.003_27),
        Vec3::new(-0.531_08, 1.108_13, -0.072_76),
        Vec3::new(-0.073_67, -0.006_05, 1.076_02),
    );
    let v = (c / L::splat(0.6)).by(input);
    let a = (v * v.plus(0.024_578_6)).plus(-0.000_090_537);
    let b = (v * v.times(0.983_729).plus(0.432_951)).plus(0.238_081);
    a.over(b).by(output)
}

/// min(x, min(y, z)) as `Vec3::min_element` takes it (`a < b ? a : b`).
#[inline(always)]
fn min_element<L: Lane>(c: V3<L>) -> L {
    let min = |a: L, b: L| L::select(a.cmplt(b), a, b);
    min(c.x, min(c.y, c.z))
}

/// max(x, max(y, z)) as `Vec3::max_element` takes it (`a > b ? a : b`).
#[inline(always)]
fn max_element<L: Lane>(c: V3<L>) -> L {
    let max = |a: L, b: L| L::select(a.cmpgt(b), a, b);
    max(c.x, max(c.y, c.z))
}

/// Khronos PBR Neutral (2024): identity below 0.76, then a soft compression
/// of the peak toward 1 that keeps hue, desaturating only what it
/// compresses; a base colour under white light of 1 shows as itself.
#[inline(always)]
fn pbr_neutral<L: Lane>(c: V3<L>) -> V3<L> {
    const START: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let one = L::splat(1.0);
    let x = min_element(c);
    let offset = L::select(
        x.cmplt(L::splat(0.08)),
        x - L::splat(6.25) * x * x,
        L::splat(0.04),
    );
    let c = c - V3 {
        x: offset,
        y: offset,
        z: offset,
    };
    let peak = max_element(c);
    let d = 1.0 - START;
    let new_peak = one - L::splat(d * d) / (peak + L::splat(d) - L::splat(START));
    let squeezed = c.scale(new_peak / peak);
    let g = one - one / (L::splat(DESATURATION) * (peak - new_peak) + one);
    // `Vec3::lerp`: a (1 - g) + b g.
    let peaks = V3 {
        x: new_peak,
        y: new_peak,
        z: new_peak,
    };
    let compressed = squeezed.scale(one - g) + peaks.scale(g);
    V3::select(peak.cmplt(L::splat(START)), c, compressed)
}

/// `agx::agx` of each lane (the formation table is read lane by lane).
#[inline(always)]
fn agx<L: Lane>(c: V3<L>) -> V3<L> {
    const MAX: usize = 16;
    debug_assert!(L::WIDTH <= MAX);
    let mapped: [Vec3; MAX] = std::array::from_fn(|k| {
        if k < L::WIDTH {
            super::agx::agx(Vec3::new(c.x.lane(k), c.y.lane(k), c.z.lane(k)))
        } else {
            Vec3::ZERO
        }
    });
    V3 {
        x: L::from_fn(|k| mapped[k].x),
        y: L::from_fn(|k| mapped[k].y),
        z: L::from_fn(|k| mapped[k].z),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every tone map.
    const ALL: [Tonemap; 6] = [
        Tonemap::Clamp,
        Tonemap::Reinhard,
        Tonemap::Aces,
        Tonemap::AcesHill,
        Tonemap::PbrNeutral,
        Tonemap::Agx,
    ];

    #[test]
    fn tone_maps_are_monotonic_and_bounded() {
        for op in ALL {
            let mut last = -1.0;
            for i in 0..100 {
                let v = tonemap(Vec3::splat(i as f32 * 0.1), op, 1.0).x;
                assert!((0.0..=1.0).contains(&v) && v >= last);
                last = v;
            }
        }
        assert!((tonemap(Vec3::ONE, Tonemap::Reinhard, 1.0).x - 0.5).abs() < 1e-6);
    }

    /// Eight lanes (`tonemap_lanes`, as the display encodes) give each
    /// lane's one-lane value bit for bit, for every map, over darks,
    /// highlights, saturated colours, zeros, infinities and NaN.
    #[test]
    fn eight_lanes_are_one_lane_bit_for_bit() {
        use crate::simd::{F8, Lane, V3};
        let mut colors = Vec::new();
        let levels = [
            0.0, 1e-6, 0.003, 0.05, 0.079, 0.081, 0.2, 0.75, 0.77, 1.0, 3.0, 40.0,
        ];
        for (i, &r) in levels.iter().enumerate() {
            for (j, &g) in levels.iter().enumerate() {
                colors.push(Vec3::new(r, g, levels[(i * 5 + j * 7) % levels.len()]));
            }
        }
        colors.extend([
            Vec3::new(f32::INFINITY, 0.5, 0.0),
            Vec3::new(f32::NAN, 0.2, 0.3),
            Vec3::new(-0.5, 0.3, 0.9),
        ]);
        for op in ALL {
            for chunk in colors.chunks(8) {
                let at = |k: usize| chunk[k % chunk.len()];
                let c = V3 {
                    x: F8::from_fn(|k| at(k).x),
                    y: F8::from_fn(|k| at(k).y),
                    z: F8::from_fn(|k| at(k).z),
                };
                let t = tonemap_lanes(c, op, 1.5);
                for k in 0..8 {
                    let want = tonemap(at(k), op, 1.5);
                    let got = Vec3::new(t.x.lane(k), t.y.lane(k), t.z.lane(k));
                    assert_eq!(
                        got.to_array().map(f32::to_bits),
                        want.to_array().map(f32::to_bits),
                        "{op:?} {:?}",
                        at(k)
                    );
                }
            }
        }
    }

    #[test]
    fn pbr_neutral_keeps_colours_below_its_knee_and_agx_is_neutral_on_grey() {
        // Between 0.08 and 0.76 PBR Neutral only subtracts its 0.04 offset.
        let c = Vec3::new(0.5, 0.3, 0.2);
        let t = tonemap(c, Tonemap::PbrNeutral, 1.0);
        assert!(
            (t - (c - Vec3::splat(0.04))).abs().max_element() < 1e-6,
            "{t}"
        );
        // Bright colours approach but never pass 1.
        let t = tonemap(Vec3::new(50.0, 10.0, 1.0), Tonemap::PbrNeutral, 1.0);
        assert!(t.max_element() <= 1.0 && t.x > t.y && t.y > t.z, "{t}");
        // AgX maps greys to greys, middle grey near the middle.
        for v in [0.01f32, 0.18, 1.0, 10.0] {
            let t = tonemap(Vec3::splat(v), Tonemap::Agx, 1.0);
            assert!(
                (t.x - t.y).abs() < 2e-3 && (t.y - t.z).abs() < 2e-3,
                "{v}: {t}"
            );
        }
        let mid = tonemap(Vec3::splat(0.18), Tonemap::Agx, 1.0).x;
        assert!(mid > 0.1 && mid < 0.35, "{mid}");
    }

    /// `op` of each input against the values its source gives, to 1e-5.
    fn matches_source(op: Tonemap, cases: &[([f32; 3], [f32; 3])]) {
        for (input, want) in cases {
            let got = tonemap(Vec3::from(*input), op, 1.0);
            assert!(
                (got - Vec3::from(*want)).abs().max_element() < 1e-5,
                "{op:?} {input:?}: {got} against {want:?}"
            );
        }
    }

    #[test]
    fn aces_hill_is_threejs_aces_filmic() {
        // three.js src/renderers/shaders/ShaderChunk/
        // tonemapping_pars_fragment.glsl.js, `ACESFilmicToneMapping` at
        // toneMappingExposure 1 (the input times 1/0.6, ACESInputMat,
        // RRTAndODTFit, ACESOutputMat, saturate), evaluated in double
        // precision from the source's constants.
        matches_source(
            Tonemap::AcesHill,
            &[
                ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
                ([0.18, 0.18, 0.18], [0.213_105, 0.213_105, 0.213_103]),
                ([0.5, 0.5, 0.5], [0.557_586, 0.557_586, 0.557_581]),
                ([1.0, 1.0, 1.0], [0.763_397, 0.763_397, 0.763_390]),
                ([4.0, 4.0, 4.0], [0.952_237, 0.952_237, 0.952_227]),
                ([16.0, 16.0, 16.0], [1.0, 1.0, 1.0]),
                ([1.0, 0.0, 0.0], [0.957_333, 0.005_324, 0.007_158]),
                ([0.0, 1.0, 0.0], [0.293_359, 0.774_607, 0.099_434]),
                ([0.0, 0.0, 1.0], [0.0, 0.0, 0.772_830]),
                ([0.8, 0.2, 0.05], [0.781_403, 0.274_796, 0.064_413]),
            ],
        );
    }

    #[test]
    fn aces_is_narkowiczs_fit() {
        // Krzysztof Narkowicz, "ACES Filmic Tone Mapping Curve" (2016):
        // x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), per channel, clamped.
        let grey = |x: f32, y: f32| ([x; 3], [y; 3]);
        matches_source(
            Tonemap::Aces,
            &[
                grey(0.0, 0.0),
                grey(0.18, 0.266_899),
                grey(0.5, 0.616_307),
                grey(1.0, 0.803_797),
                grey(4.0, 0.973_417),
                grey(16.0, 1.0),
            ],
        );
    }

    #[test]
    fn pbr_neutral_is_the_khronos_specification() {
        // KhronosGroup/ToneMapping, PBR_Neutral/README.md, "PBR Neutral
        // Specification" (F90 = 0.04, Ks = 0.76, Kd = 0.15), evaluated in
        // double precision.
        matches_source(
            Tonemap::PbrNeutral,
            &[
                ([0.18, 0.18, 0.18], [0.14, 0.14, 0.14]),
                ([0.5, 0.3, 0.2], [0.46, 0.26, 0.16]),
                ([1.0, 1.0, 1.0], [0.869_091, 0.869_091, 0.869_091]),
                ([4.0, 4.0, 4.0], [0.983_256, 0.983_256, 0.983_256]),
                ([1.0, 0.0, 0.0], [0.88, 0.015_560, 0.015_560]),
                ([0.8, 0.2, 0.05], [0.765_496, 0.165_609, 0.015_637]),
                ([5.0, 1.0, 0.2], [0.987_027, 0.488_270, 0.388_518]),
            ],
        );
    }
}
