//! Blender 5's AgX view transform (view "AgX", look "None", display
//! "sRGB"), as Blender's colour configuration applies it:
//!
//! 1. the linear Rec.709 colour is taken to linear E-Gamut (through CIE XYZ,
//!    the matrices of Blender's `config.ocio`);
//! 2. each channel is encoded log2 over [-12.47393, 12.5260688117] stops
//!    (0.18 times 2^-10 to 2^+15) and clamped to [0, 1];
//! 3. the 57³ formation table `AgX_Base_sRGB.cube` is read with
//!    tetrahedral interpolation;
//! 4. its output, encoded for a Rec.1886 display (power 2.4), is decoded
//!    here to display-linear values; the sRGB encoding that follows in
//!    the display is the one Blender's sRGB display applies.
//!
//! softraster does not ship Blender's table: it computes the same table
//! once, from the formula of the script that generated the file
//! (Eary Chow's AgX_LUT_Gen, `AgXBasesRGB.py` with `AgXBaseRec2020.py`
//! at the parameters the file's header names: rotate [3, -1, -2], inset
//! [0.4, 0.22, 0.13], outset [0.4, 0.22, 0.04], 40% of the hue shift
//! kept). Each node, from the E-Gamut log2 value it stands for:
//!
//! - to linear Rec.2020; negative values lifted with the luminance kept
//!   (the "lower guard rail");
//! - the inset matrix; the hue noted;
//! - each channel log2-encoded over [-10, +6.5] stops around 0.18 and put
//!   through Jed Smith's tunable sigmoid (pivot at middle grey, slope 2.4,
//!   toe and shoulder powers 1.5), then raised to 2.4;
//! - the hue set to 60% of the noted one plus 40% of the new one (HSV);
//! - the outset matrix; to linear Rec.709 and its own lower guard rail;
//! - encoded with power 1/2.4 and clamped to [0, 1].
//!
//! Over all 185,193 nodes this formula gives Blender's file to 1.7e-6
//! (the file's seven printed digits); `benches/tone_curves.py` compares
//! whole frames with Blender's own output.

use std::sync::OnceLock;

use glam::{DMat3, DVec3, Mat3, Vec3};

/// Nodes per side of the formation table.
const SIZE: usize = 57;

/// The view's log2 allocation of E-Gamut, in stops: 0.18 times 2^-10 and
/// 2^+15.
const ALLOCATION: (f32, f32) = (-12.473_93, 12.526_069);

/// A row-major 3x3 matrix as glam's (column-major) one.
const fn rows(m: [[f64; 3]; 3]) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(m[0][0], m[1][0], m[2][0]),
        DVec3::new(m[0][1], m[1][1], m[2][1]),
        DVec3::new(m[0][2], m[1][2], m[2][2]),
    )
}

/// CIE XYZ (D65) to linear Rec.709, as Blender's `config.ocio` writes it.
const CONFIG_XYZ_TO_REC709: DMat3 = rows([
    [3.240_969_9, -1.537_383_2, -0.498_610_8],
    [-0.969_243_6, 1.875_967_5, 0.041_555_1],
    [0.055_630_1, -0.203_977, 1.056_971_5],
]);

/// CIE XYZ (D65) to linear E-Gamut, as Blender's `config.ocio` writes it.
const CONFIG_XYZ_TO_EGAMUT: DMat3 = rows([
    [1.525_052_8, -0.315_913_5, -0.122_658_3],
    [-0.509_152_6, 1.333_327_4, 0.138_284_4],
    [0.095_715_3, 0.050_897_4, 0.787_955_8],
]);

/// The generator's matrices.
const EGAMUT_TO_XYZ: DMat3 = rows([
    [0.705_396_850_1, 0.164_041_328_3, 0.081_017_748_65],
    [0.280_130_724_1, 0.820_206_641_5, -0.100_337_365_6],
    [-0.103_781_511_6, -0.072_907_257_03, 1.265_746_519],
]);
const XYZ_TO_REC2020: DMat3 = rows([
    [
        1.716_663_427_795_880_5,
        -0.355_673_319_730_139_9,
        -0.253_368_087_890_247_8,
    ],
    [
        -0.666_673_836_198_886_9,
        1.616_455_739_824_698_1,
        0.015_768_297_096_133_7,
    ],
    [
        0.017_642_481_784_977_2,
        -0.042_776_976_382_753_2,
        0.942_243_281_018_430_8,
    ],
]);
const REC2020_TO_XYZ: DMat3 = rows([
    [
        0.636_953_506_785_074,
        0.144_619_184_669_233_1,
        0.168_855_853_922_873_4,
    ],
    [
        0.262_698_338_956_556,
        0.678_008_765_772_816_5,
        0.059_292_895_227_627_3,
    ],
    [0.0, 0.028_073_135_847_557, 1.060_827_234_950_570_7],
]);
const XYZ_TO_REC709: DMat3 = rows([
    [
        3.241_003_232_976_358_7,
        -1.537_398_969_488_785_5,
        -0.498_615_881_996_362_9,
    ],
    [
        -0.969_224_252_202_516_4,
        1.875_929_983_695_176,
        0.041_554_226_340_084_7,
    ],
    [
        0.055_639_419_851_975_5,
        -0.204_011_206_123_909_9,
        1.057_148_977_187_533_3,
    ],
]);
/// Sobotka's inset, rotate [3, -1, -2] and inset [0.4, 0.22, 0.13].
const INSET: DMat3 = rows([
    [
        0.856_627_153_315_983,
        0.095_121_240_538_158_8,
        0.048_251_606_145_858_3,
    ],
    [
        0.137_318_972_929_847,
        0.761_241_990_602_591,
        0.101_439_036_467_562,
    ],
    [
        0.111_898_212_999_95,
        0.076_799_418_603_190_3,
        0.811_302_368_396_859,
    ],
]);
/// The matrix whose inverse is the outset: rotate [0, 0, 0] and inset
/// [0.4, 0.22, 0.04].
const OUTSET_INVERSE: DMat3 = rows([
    [
        0.899_796_955_911_611,
        0.087_199_619_202_835_1,
        0.013_003_424_885_555,
    ],
    [
        0.111_420_988_957_48,
        0.875_575_586_156_966,
        0.013_003_424_885_554_8,
    ],
    [
        0.111_420_988_957_48,
        0.087_199_619_202_834_9,
        0.801_379_391_839_686,
    ],
]);
/// Rec.2020 luminance weights the guard rails use (CIE 2015 observer,
/// 6504 K black body: the generator's values when Blender's file was
/// made).
const LUMA_2020: DVec3 = DVec3::new(
    0.265_818_037_025_044_9,
    0.598_469_860_453_65,
    0.135_712_102_521_305_2,
);

/// The formation table, red fastest, as the `.cube` file orders it.
struct Formation {
    nodes: Vec<Vec3>,
    /// Linear Rec.709 to linear E-Gamut.
    to_egamut: Mat3,
}

/// Builds the formation table now if it is not built yet (about 0.1 s of
/// one core), so that frames do not wait for it.
pub fn prepare() {
    formation();
}

/// The formation table, built on first use, its slices of blue over
/// plain threads of their own (not rayon's: a worker waiting for the
/// table could never run a job the table's build gave the pool).
fn formation() -> &'static Formation {
    static TABLE: OnceLock<Formation> = OnceLock::new();
    TABLE.get_or_init(|| {
        let slice = SIZE * SIZE;
        let mut nodes = vec![Vec3::ZERO; slice * SIZE];
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let per_thread = SIZE.div_ceil(threads.clamp(1, SIZE)) * slice;
        std::thread::scope(|scope| {
            for (chunk, part) in nodes.chunks_mut(per_thread).enumerate() {
                scope.spawn(move || {
                    let first = chunk * per_thread;
                    for (i, n) in part.iter_mut().enumerate() {
                        let i = first + i;
                        let at = DVec3::new(
                            (i % SIZE) as f64,
                            (i / SIZE % SIZE) as f64,
                            (i / slice) as f64,
                        );
                        *n = node(at / (SIZE - 1) as f64).as_vec3();
                    }
                });
            }
        });
        Formation {
            nodes,
            to_egamut: (CONFIG_XYZ_TO_EGAMUT * CONFIG_XYZ_TO_REC709.inverse()).as_mat3(),
        }
    })
}

/// Blender's AgX view of the linear Rec.709 colour `c`: display-linear
/// values in [0, 1] (the table's output decoded with power 2.4).
pub fn agx(c: Vec3) -> Vec3 {
    let table = formation();
    let e = table.to_egamut * c;
    let (low, high) = ALLOCATION;
    let at = e.to_array().map(|v| {
        // OCIO's log takes at least the smallest normal float.
        let x = (v.max(f32::MIN_POSITIVE).log2() - low) / (high - low);
        x.clamp(0.0, 1.0) * (SIZE - 1) as f32
    });
    tetrahedral(&table.nodes, at).map(|v| v.max(0.0).powf(2.4))
}

/// The table read at node coordinates `at` (each in [0, SIZE - 1]), by
/// tetrahedral interpolation as OCIO's CPU path does it.
fn tetrahedral(nodes: &[Vec3], at: [f32; 3]) -> Vec3 {
    let low = at.map(|x| (x.floor() as usize).min(SIZE - 1));
    let high = low.map(|i| (i + 1).min(SIZE - 1));
    let (fr, fg, fb) = (
        at[0] - low[0] as f32,
        at[1] - low[1] as f32,
        at[2] - low[2] as f32,
    );
    let pick = |axis: usize, up: bool| if up { high[axis] } else { low[axis] };
    let c = |r, g, b| nodes[pick(0, r) + SIZE * (pick(1, g) + SIZE * pick(2, b))];
    let c000 = c(false, false, false);
    let c111 = c(true, true, true);
    if fr > fg {
        if fg > fb {
            c000 * (1.0 - fr)
                + c(true, false, false) * (fr - fg)
                + c(true, true, false) * (fg - fb)
                + c111 * fb
        } else if fr > fb {
            c000 * (1.0 - fr)
                + c(true, false, false) * (fr - fb)
                + c(true, false, true) * (fb - fg)
                + c111 * fg
        } else {
            c000 * (1.0 - fb)
                + c(false, false, true) * (fb - fr)
                + c(true, false, true) * (fr - fg)
                + c111 * fg
        }
    } else if fb > fg {
        c000 * (1.0 - fb)
            + c(false, false, true) * (fb - fg)
            + c(false, true, true) * (fg - fr)
            + c111 * fr
    } else if fb > fr {
        c000 * (1.0 - fg)
            + c(false, true, false) * (fg - fb)
            + c(false, true, true) * (fb - fr)
            + c111 * fr
    } else {
        c000 * (1.0 - fg)
            + c(false, true, false) * (fg - fr)
            + c(true, true, false) * (fr - fb)
            + c111 * fb
    }
}

/// The table's node at `at` (each in [0, 1], E-Gamut log2 over [-10, +15]
/// stops around 0.18): the generator's formula, in double precision. A
/// NaN is written as 0, as the generator writes its file.
fn node(at: DVec3) -> DVec3 {
    let linear = (at * 25.0 - 10.0).map(f64::exp2) * 0.18;
    let c = guard_rec2020(XYZ_TO_REC2020 * (EGAMUT_TO_XYZ * linear));
    let c = INSET * c;
    let before = hsv(c);
    let formed = c
        .map(|v| (v / 0.18).log2().mul_add(1.0 / 16.5, 10.0 / 16.5))
        .map(sigmoid)
        .map(|v| if v >= 0.0 { v.powf(2.4) } else { 0.0 });
    let mut after = hsv(formed);
    after.x = (1.0 - 0.4) * before.x + 0.4 * after.x;
    let c = OUTSET_INVERSE.inverse() * from_hsv(after);
    let c = guard_rec709(XYZ_TO_REC709 * (REC2020_TO_XYZ * c));
    c.map(|v| {
        let v = if v >= 0.0 { v.powf(1.0 / 2.4) } else { 0.0 };
        if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) }
    })
}

/// Jed Smith's tunable sigmoid at AgX's settings: through (x0, y0) =
/// (10 / 16.5, 0.18^(1/2.4)) with slope 2.4, a toe toward (0, 0) and a
/// shoulder toward (1, 1), each of power 1.5.
fn sigmoid(x: f64) -> f64 {
    const SLOPE: f64 = 2.4;
    const POWER: f64 = 1.5;
    let x0 = 10.0 / 16.5;
    let y0 = 0.18f64.powf(1.0 / 2.4);
    // The scale that takes the curve from the pivot through the limit
    // `dx` and `dy` away.
    let scale = |dx: f64, dy: f64| {
        ((SLOPE * dx).powf(-POWER) * ((SLOPE * dx / dy).powf(POWER) - 1.0)).powf(-1.0 / POWER)
    };
    let curve = |s: f64| {
        let t = SLOPE * (x - x0) / s;
        s * (t / (1.0 + t.powf(POWER)).powf(1.0 / POWER)) + y0
    };
    if x < x0 {
        curve(-scale(x0, y0))
    } else if x <= x0 {
        SLOPE * x + (y0 - SLOPE * x0)
    } else {
        curve(scale(1.0 - x0, 1.0 - y0))
    }
}

/// Rec.2020's lower guard rail: lifts negative channels by a common offset
/// and scales the result back to the luminance the colour had, each
/// luminance counting its opponent colour's.
fn guard_rec2020(rgb: DVec3) -> DVec3 {
    let opponent = |c: DVec3| {
        let inverse = DVec3::splat(c.max_element()) - c;
        inverse.max_element() - inverse.dot(LUMA_2020) + c.dot(LUMA_2020)
    };
    let wanted = opponent(rgb);
    let lifted = rgb + (-rgb.min_element()).max(0.0);
    let got = opponent(lifted);
    let ratio = if got > wanted { wanted / got } else { 1.0 };
    lifted * ratio
}

/// Rec.709's lower guard rail: as Rec.2020's, luminances measured in
/// Rec.2020, the opponent's share blended away as Y^0.08 nears 1 (a
/// negative luminance gives NaN there, and then no scaling).
fn guard_rec709(rgb: DVec3) -> DVec3 {
    let to_2020 = XYZ_TO_REC2020 * XYZ_TO_REC709.inverse();
    let luma = |c: DVec3| (to_2020 * c).dot(LUMA_2020);
    let blended = |c: DVec3| {
        let y = luma(c);
        let inverse = DVec3::splat(c.max_element()) - c;
        let opponent = inverse.max_element() - luma(inverse) + y;
        let t = y.powf(0.08).clamp(0.0, 1.0);
        (1.0 - t) * opponent + t * y
    };
    let wanted = blended(rgb);
    let lifted = rgb + (-rgb.min_element()).max(0.0);
    let got = blended(lifted);
    let ratio = if got > wanted {
        wanted / got.max(1e-100)
    } else {
        1.0
    };
    lifted * ratio
}

/// Hue, saturation and value, hue in [0, 1] (0 for greys), the largest
/// channel deciding the hue's sextant with blue before green before red.
fn hsv(c: DVec3) -> DVec3 {
    let max = c.max_element();
    let delta = max - c.min_element();
    let s = if max == 0.0 { 0.0 } else { delta / max };
    if delta == 0.0 {
        return DVec3::new(0.0, s, max);
    }
    let d = (DVec3::splat(max) - c) / 6.0 / delta + 0.5;
    let mut h = if max == c.z {
        2.0 / 3.0 + d.y - d.x
    } else if max == c.y {
        1.0 / 3.0 + d.x - d.z
    } else {
        d.z - d.y
    };
    if h < 0.0 {
        h += 1.0;
    }
    if h > 1.0 {
        h -= 1.0;
    }
    DVec3::new(h, s, max)
}

/// `hsv`'s inverse.
fn from_hsv(c: DVec3) -> DVec3 {
    let (h, s, v) = (c.x * 6.0, c.y, c.z);
    let h = if h == 6.0 { 0.0 } else { h };
    let i = h.floor();
    let f = h - i;
    let (j, k, l) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    match i.clamp(0.0, 5.0) as u8 {
        0 => DVec3::new(v, l, j),
        1 => DVec3::new(k, v, j),
        2 => DVec3::new(j, v, l),
        3 => DVec3::new(j, k, v),
        4 => DVec3::new(l, j, v),
        _ => DVec3::new(v, j, k),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::linear_to_srgb;

    /// Nodes of Blender 5.0.1's `datafiles/colormanagement/luts/
    /// AgX_Base_sRGB.cube` (red, green, blue node indices; the file's
    /// values, as printed), against the generator's formula.
    #[test]
    fn the_formula_gives_blenders_formation_table() {
        let nodes = [
            ([5, 5, 5], [0.0273026, 0.0273025, 0.0273062]),
            ([20, 20, 20], [0.3470131, 0.3470117, 0.3470397]),
            ([28, 28, 28], [0.7853074, 0.7853064, 0.7853274]),
            ([24, 10, 8], [0.7072685, 0.0979469, 0.0]),
            ([10, 24, 16], [0.0, 0.6068474, 0.3445333]),
            ([16, 12, 26], [0.0811849, 0.2395303, 0.705358]),
            ([26, 22, 18], [0.8281592, 0.4394838, 0.0]),
            ([22, 0, 0], [0.5478776, 0.0210939, 0.0]),
            ([0, 22, 0], [0.0, 0.4849367, 0.2473379]),
            ([0, 0, 22], [0.0, 0.1506471, 0.3907202]),
            ([30, 2, 30], [0.9464023, 0.5916331, 0.8872583]),
        ];
        for (at, want) in nodes {
            let got = node(DVec3::from_array(at.map(|i: u32| f64::from(i) / 56.0)));
            let err = (got - DVec3::from_array(want)).abs().max_element();
            assert!(err < 2e-6, "node {at:?}: {got} against {want:?}");
        }
    }

    /// The sRGB display values (in 1/255) Blender 5.0.1 gives linear
    /// Rec.709 colours under its "AgX" view, look "None", exposure 0:
    /// `benches/tone_curves.py`'s image, saved by Blender as a 16-bit PNG
    /// and read back, rounded to 0.1. A grey ramp one stop apart, the
    /// primaries and secondaries from 0.05 to 16, three colours.
    #[test]
    fn agx_is_blenders_view_within_a_third_of_a_code() {
        let cases: [([f32; 3], [f32; 3]); 51] = [
            ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
            ([0.0009765625, 0.0009765625, 0.0009765625], [0.8, 0.8, 0.8]),
            ([0.001953125, 0.001953125, 0.001953125], [2.5, 2.5, 2.5]),
            ([0.00390625, 0.00390625, 0.00390625], [6.4, 6.4, 6.4]),
            ([0.0078125, 0.0078125, 0.0078125], [14.7, 14.7, 14.7]),
            ([0.015625, 0.015625, 0.015625], [26.6, 26.6, 26.6]),
            ([0.03125, 0.03125, 0.03125], [43.1, 43.1, 43.1]),
            ([0.0625, 0.0625, 0.0625], [66.1, 66.1, 66.1]),
            ([0.125, 0.125, 0.125], [97.8, 97.8, 97.9]),
            ([0.25, 0.25, 0.25], [135.7, 135.7, 135.7]),
            ([0.5, 0.5, 0.5], [169.6, 169.6, 169.6]),
            ([1.0, 1.0, 1.0], [196.6, 196.6, 196.6]),
            ([2.0, 2.0, 2.0], [217.2, 217.2, 217.2]),
            ([4.0, 4.0, 4.0], [233.0, 233.0, 233.0]),
            ([8.0, 8.0, 8.0], [245.2, 245.2, 245.2]),
            ([16.0, 16.0, 16.0], [254.6, 254.6, 254.6]),
            ([32.0, 32.0, 32.0], [255.0, 255.0, 255.0]),
            ([64.0, 64.0, 64.0], [255.0, 255.0, 255.0]),
            ([0.05, 0.0, 0.0], [51.8, 0.9, 0.0]),
            ([0.18, 0.0, 0.0], [109.1, 3.9, 0.0]),
            ([1.0, 0.0, 0.0], [218.8, 57.1, 32.9]),
            ([4.0, 0.0, 0.0], [254.6, 148.3, 134.8]),
            ([16.0, 0.0, 0.0], [255.0, 205.6, 198.4]),
            ([0.0, 0.05, 0.0], [6.1, 53.1, 0.0]),
            ([0.0, 0.18, 0.0], [23.3, 110.2, 0.0]),
            ([0.0, 1.0, 0.0], [110.3, 197.0, 81.2]),
            ([0.0, 4.0, 0.0], [183.1, 234.4, 168.3]),
            ([0.0, 16.0, 0.0], [225.5, 255.0, 217.4]),
            ([0.0, 0.0, 0.05], [0.0, 11.9, 53.1]),
            ([0.0, 0.0, 0.18], [0.0, 34.2, 110.9]),
            ([0.0, 0.0, 1.0], [20.2, 86.1, 209.5]),
            ([0.0, 0.0, 4.0], [132.3, 157.9, 247.6]),
            ([0.0, 0.0, 16.0], [196.3, 209.9, 255.0]),
            ([0.05, 0.05, 0.0], [58.1, 54.7, 0.0]),
            ([0.18, 0.18, 0.0], [118.3, 112.2, 0.0]),
            ([1.0, 1.0, 0.0], [199.4, 192.9, 108.1]),
            ([4.0, 4.0, 0.0], [235.2, 231.0, 183.9]),
            ([16.0, 16.0, 0.0], [254.7, 253.2, 226.2]),
            ([0.0, 0.05, 0.05], [2.5, 56.9, 57.6]),
            ([0.0, 0.18, 0.18], [14.8, 116.5, 117.6]),
            ([0.0, 1.0, 1.0], [134.1, 197.4, 198.0]),
            ([0.0, 4.0, 4.0], [198.7, 233.8, 234.0]),
            ([0.0, 16.0, 16.0], [234.6, 254.1, 254.2]),
            ([0.05, 0.0, 0.05], [54.6, 7.6, 57.0]),
            ([0.18, 0.0, 0.18], [113.4, 28.0, 117.2]),
            ([1.0, 0.0, 1.0], [201.6, 116.7, 201.8]),
            ([4.0, 0.0, 4.0], [237.6, 186.7, 237.3]),
            ([16.0, 0.0, 16.0], [254.3, 227.6, 255.0]),
            ([0.8, 0.2, 0.05], [199.6, 122.6, 76.6]),
            ([0.1, 0.5, 0.9], [122.6, 170.4, 196.3]),
            ([0.3, 0.02, 0.6], [138.7, 81.4, 184.0]),
        ];
        for (linear, want) in cases {
            let got = agx(Vec3::from(linear)).map(|v| linear_to_srgb(v) * 255.0);
            let err = (got - Vec3::from(want)).abs().max_element();
            assert!(err < 0.3, "{linear:?}: {got} against Blender's {want:?}");
        }
    }

    /// Tetrahedral interpolation gives back a linear function of the
    /// coordinates exactly, at nodes, inside cells (in each of the six
    /// orderings of the fractions) and at the top edge.
    #[test]
    fn tetrahedral_interpolation_is_exact_on_linear_tables() {
        let f = |r: f32, g: f32, b: f32| Vec3::new(r + 2.0 * g, 3.0 * b - r, 0.5 * g + b);
        let nodes: Vec<Vec3> = (0..SIZE * SIZE * SIZE)
            .map(|i| {
                f(
                    (i % SIZE) as f32,
                    (i / SIZE % SIZE) as f32,
                    (i / (SIZE * SIZE)) as f32,
                )
            })
            .collect();
        let points = [
            [0.0, 0.0, 0.0],
            [56.0, 56.0, 56.0],
            [3.7, 2.2, 1.1],
            [3.7, 1.1, 2.2],
            [2.2, 1.1, 3.7],
            [1.1, 2.2, 3.7],
            [2.2, 3.7, 1.1],
            [1.1, 3.7, 2.2],
            [55.5, 0.25, 56.0],
            [10.0, 20.5, 30.25],
        ];
        for at in points {
            let got = tetrahedral(&nodes, at);
            let want = f(at[0], at[1], at[2]);
            assert!(
                (got - want).abs().max_element() < 1e-3,
                "{at:?}: {got} against {want}"
            );
        }
    }

    #[test]
    fn out_of_range_input_stays_in_range() {
        for c in [
            Vec3::ZERO,
            Vec3::new(-1.0, 0.5, 2.0),
            Vec3::splat(1e9),
            Vec3::new(f32::NAN, 0.2, f32::INFINITY),
        ] {
            let t = agx(c);
            assert!(
                t.cmpge(Vec3::ZERO).all() && t.cmple(Vec3::ONE).all(),
                "{c}: {t}"
            );
        }
    }
}
