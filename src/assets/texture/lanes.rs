//! Four lookups of one texture at once, for shading that runs four
//! fragments side by side (`shade::lanes`): the coordinates and results
//! are held per channel with one lane per lookup (a structure of arrays),
//! and every lane is bit for bit what the one-lookup functions give for
//! it (`Texture::sample_footprint`). The arithmetic runs on all four
//! lanes together; the texel loads and sRGB decoding stay per lane, and
//! a lane whose footprint leaves the image (an address mode applies)
//! takes the one-lookup path.

// Loops over the four lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Vec2, Vec4};

use super::{Footprint, Level, Texture, Wrap};
use crate::color::srgb_to_linear_table;

/// Red, green and blue of four lookups, one lane each.
pub type Rgb4 = [Vec4; 3];

/// Bilinear footprints in one level per lane.
struct Spot4<'t> {
    levels: [&'t Level; 4],
    /// Texel coordinates of the footprints' top-left texels, whole.
    x0: Vec4,
    y0: Vec4,
    /// Fractions between the texels.
    fx: Vec4,
    fy: Vec4,
    /// Lanes whose footprint lies inside the level (bit k: lane k); the
    /// others go through the address mode.
    inside: u32,
}

impl Texture {
    /// `sample_footprint(uv_k, fps[k], mode, mips)` for the four lanes k
    /// of (`u`, `v`), red, green and blue.
    pub fn sample_footprint4(
        &self,
        u: Vec4,
        v: Vec4,
        fps: &[Footprint; 4],
        mode: Wrap,
        mips: Option<&[Level]>,
    ) -> Rgb4 {
        let mut lod = [0.0f32; 4];
        for k in 0..4 {
            match fps[k] {
                Footprint::Lod(l) => lod[k] = l,
                Footprint::Probes { .. } => return self.probes4(u, v, fps, mode, mips),
            }
        }
        self.sample_lod4(mips, u, v, lod, mode)
    }

    /// `sample_lod(mips, uv_k, mode, lod[k])` for the four lanes.
    pub fn sample_lod4(
        &self,
        mips: Option<&[Level]>,
        u: Vec4,
        v: Vec4,
        lod: [f32; 4],
        mode: Wrap,
    ) -> Rgb4 {
        let (near, far) = self.levels4(mips, lod);
        let a = self.bilinear4(&Spot4::new(near, u, v), u, v, mode);
        match far {
            None => a,
            Some((levels, f)) => {
                let b = self.bilinear4(&Spot4::new(levels, u, v), u, v, mode);
                blend(a, b, f)
            }
        }
    }

    /// The levels `sample_lod` reads per lane at level of detail `lod[k]`:
    /// the nearer one, and where some lane blends two, the farther one
    /// (a lane that reads one level reads it again there, at weight 0:
    /// a * 1 + a * 0 = a) and the weights.
    #[allow(clippy::type_complexity)]
    fn levels4<'t>(
        &'t self,
        mips: Option<&'t [Level]>,
        lod: [f32; 4],
    ) -> ([&'t Level; 4], Option<([&'t Level; 4], Vec4)>) {
        let base = &self.base;
        let mut near: [&Level; 4] = [base; 4];
        let mut far: [&Level; 4] = [base; 4];
        let mut weight = [0.0f32; 4];
        let mut two = false;
        if let Some(mips) = mips {
            let top = mips.len() as f32;
            for k in 0..4 {
                if lod[k] <= 0.0 || lod[k].is_nan() {
                    continue;
                }
                let l = lod[k].min(top);
                let i = l as u32 as f32;
                let f = l - i;
                let i = i as usize;
                near[k] = if i == 0 { base } else { &mips[i - 1] };
                far[k] = near[k];
                if f > 0.0 && i < mips.len() {
                    far[k] = &mips[i];
                    weight[k] = f;
                    two = true;
                }
            }
        }
        (near, two.then(|| (far, Vec4::from(weight))))
    }

    /// `bilinear(spot.levels[k], uv_k, mode)` for the four lanes.
    #[inline(always)]
    fn bilinear4(&self, spot: &Spot4, u: Vec4, v: Vec4, mode: Wrap) -> Rgb4 {
        // Corner j (top-left, top-right, bottom-left, bottom-right) of
        // lane k, as stored.
        let mut texels = [[0u32; 4]; 4];
        for k in 0..4 {
            if spot.inside & (1 << k) != 0 {
                let fp = spot.levels[k].footprint(spot.x0[k] as u32, spot.y0[k] as u32);
                texels[0][k] = u32::from_le_bytes(fp[0]);
                texels[1][k] = u32::from_le_bytes(fp[1]);
                texels[2][k] = u32::from_le_bytes(fp[2]);
                texels[3][k] = u32::from_le_bytes(fp[3]);
            }
        }
        let (fx, fy) = (spot.fx, spot.fy);
        let (gx, gy) = (Vec4::ONE - fx, Vec4::ONE - fy);
        let [a, b, c, d] = if self.srgb {
            let lut = srgb_to_linear_table();
            [
                decode_srgb4(lut, texels[0]),
                decode_srgb4(lut, texels[1]),
                decode_srgb4(lut, texels[2]),
                decode_srgb4(lut, texels[3]),
            ]
        } else {
            [
                decode_data4(texels[0]),
                decode_data4(texels[1]),
                decode_data4(texels[2]),
                decode_data4(texels[3]),
            ]
        };
        let mut out = [Vec4::ZERO; 3];
        for ch in 0..3 {
            let top = a[ch] * gx + b[ch] * fx;
            let bottom = c[ch] * gx + d[ch] * fx;
            out[ch] = top * gy + bottom * fy;
        }
        if spot.inside != 0b1111 {
            for k in 0..4 {
                if spot.inside & (1 << k) == 0 {
                    let r = self.bilinear_wrapped(spot.levels[k], Vec2::new(u[k], v[k]), mode);
                    out[0][k] = r.x;
                    out[1][k] = r.y;
                    out[2][k] = r.z;
                }
            }
        }
        out
    }
}

impl Texture {
    /// `sample_footprint` of four lanes of which some take anisotropic
    /// probes: the probes' sum over their count per lane, a lane with
    /// fewer probes adding nothing after its last (x + 0 = x); a `Lod`
    /// lane is one probe at the point itself ((0 + x) / 1 = x).
    fn probes4(
        &self,
        u: Vec4,
        v: Vec4,
        fps: &[Footprint; 4],
        mode: Wrap,
        mips: Option<&[Level]>,
    ) -> Rgb4 {
        let mut n = [1u32; 4];
        let mut nf = [1.0f32; 4];
        let mut lod = [0.0f32; 4];
        let mut axis = [Vec2::ZERO; 4];
        for k in 0..4 {
            match fps[k] {
                Footprint::Lod(l) => lod[k] = l,
                Footprint::Probes {
                    n: pn,
                    lod: l,
                    axis: a,
                } => {
                    n[k] = pn as u32;
                    nf[k] = pn;
                    lod[k] = l;
                    axis[k] = a;
                }
            }
        }
        let probes = n.iter().copied().max().unwrap_or(1);
        let mut sum = [Vec4::ZERO; 3];
        for p in 0..probes {
            let (mut pu, mut pv) = (u, v);
            let mut live = [0.0f32; 4];
            for k in 0..4 {
                if p < n[k] {
                    live[k] = 1.0;
                    if let Footprint::Probes { .. } = fps[k] {
                        let t = (p as f32 + 0.5) / nf[k] - 0.5;
                        let at = Vec2::new(u[k], v[k]) + axis[k] * t;
                        pu[k] = at.x;
                        pv[k] = at.y;
                    }
                }
            }
            let r = self.sample_lod4(mips, pu, pv, lod, mode);
            let live = Vec4::from(live).cmpgt(Vec4::ZERO);
            for c in 0..3 {
                sum[c] += Vec4::select(live, r[c], Vec4::ZERO);
            }
        }
        let nf = Vec4::from(nf);
        [sum[0] / nf, sum[1] / nf, sum[2] / nf]
    }
}

impl<'t> Spot4<'t> {
    /// As `bilinear` places a lookup at `uv` in a level: x = u w - 1/2,
    /// y = v h - 1/2, inside where both footprint texels exist.
    #[inline(always)]
    fn new(levels: [&'t Level; 4], u: Vec4, v: Vec4) -> Spot4<'t> {
        let w = Vec4::new(
            levels[0].width as f32,
            levels[1].width as f32,
            levels[2].width as f32,
            levels[3].width as f32,
        );
        let h = Vec4::new(
            levels[0].height as f32,
            levels[1].height as f32,
            levels[2].height as f32,
            levels[3].height as f32,
        );
        let x = u * w - Vec4::splat(0.5);
        let y = v * h - Vec4::splat(0.5);
        let inside = (x.cmpge(Vec4::ZERO)
            & y.cmpge(Vec4::ZERO)
            & x.cmplt(w - Vec4::ONE)
            & y.cmplt(h - Vec4::ONE))
        .bitmask();
        let (x0, y0) = (x.trunc(), y.trunc());
        Spot4 {
            levels,
            x0,
            y0,
            fx: x - x0,
            fy: y - y0,
            inside,
        }
    }
}

/// a (1 - f) + b f per channel, as `Vec4::lerp`.
#[inline(always)]
fn blend(a: Rgb4, b: Rgb4, f: Vec4) -> Rgb4 {
    let g = Vec4::ONE - f;
    [
        a[0] * g + b[0] * f,
        a[1] * g + b[1] * f,
        a[2] * g + b[2] * f,
    ]
}

/// Red, green and blue of four stored sRGB texels (one per lane), linear:
/// the decoding table's values.
#[inline(always)]
fn decode_srgb4(lut: &[f32; 256], t: [u32; 4]) -> Rgb4 {
    let at = |k: usize, shift: u32| lut[((t[k] >> shift) & 0xff) as usize];
    [
        Vec4::new(at(0, 0), at(1, 0), at(2, 0), at(3, 0)),
        Vec4::new(at(0, 8), at(1, 8), at(2, 8), at(3, 8)),
        Vec4::new(at(0, 16), at(1, 16), at(2, 16), at(3, 16)),
    ]
}

/// Red, green and blue of four stored data texels (one per lane), as
/// `byte as f32 * (1.0 / 255.0)`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn decode_data4(t: [u32; 4]) -> Rgb4 {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 only (in every x86-64 target's base features); the
    // one memory access reads the four u32 of `t`, a 16-byte array.
    unsafe {
        let v = _mm_loadu_si128(t.as_ptr() as *const __m128i);
        let mask = _mm_set1_epi32(0xff);
        let k = _mm_set1_ps(1.0 / 255.0);
        let ch = |c: __m128i| Vec4::from(_mm_mul_ps(_mm_cvtepi32_ps(_mm_and_si128(c, mask)), k));
        [ch(v), ch(_mm_srli_epi32(v, 8)), ch(_mm_srli_epi32(v, 16))]
    }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn decode_data4(t: [u32; 4]) -> Rgb4 {
    let ch = |s: u32| {
        Vec4::new(
            ((t[0] >> s) & 0xff) as f32,
            ((t[1] >> s) & 0xff) as f32,
            ((t[2] >> s) & 0xff) as f32,
            ((t[3] >> s) & 0xff) as f32,
        ) * Vec4::splat(1.0 / 255.0)
    };
    [ch(0), ch(8), ch(16)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::mip::build_chain;
    use crate::assets::texture::{AddressMode, Filtering, Gradients, TextureFilter};

    fn noise(w: u32, h: u32, srgb: bool) -> Texture {
        let mut s = 0x9e37_79b9u32;
        let texels = (0..w * h)
            .map(|_| {
                let mut b = [0u8; 4];
                for c in &mut b {
                    s ^= s << 13;
                    s ^= s >> 17;
                    s ^= s << 5;
                    *c = (s >> 24) as u8;
                }
                b
            })
            .collect();
        Texture::from_rgba8(w, h, texels, srgb)
    }

    /// Every lane equals the one-lookup function's answer bit for bit,
    /// inside the image, across its edges (address modes), between
    /// levels and with anisotropic probes of different counts per lane.
    #[test]
    fn four_lanes_equal_four_single_lookups() {
        for srgb in [false, true] {
            let t = noise(37, 20, srgb);
            let chain = build_chain(&t);
            let mut s = 7u32;
            let mut rnd = || {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (s >> 8) as f32 / (1u32 << 24) as f32
            };
            for mode in [AddressMode::Repeat, AddressMode::Clamp, AddressMode::Border] {
                for filter in [TextureFilter::Trilinear, TextureFilter::Anisotropic] {
                    for round in 0..200 {
                        let mut uv = [Vec2::ZERO; 4];
                        let mut fps = [Footprint::Lod(0.0); 4];
                        for k in 0..4 {
                            // Mostly inside, some lanes across an edge.
                            let spread = if round % 3 == 0 { 1.6 } else { 1.0 };
                            uv[k] = Vec2::new(rnd() * spread - 0.3 * (spread - 1.0), rnd());
                            let g = Gradients {
                                dx: Vec2::new(rnd() - 0.5, rnd() - 0.5) * (0.3 * rnd()),
                                dy: Vec2::new(rnd() - 0.5, rnd() - 0.5) * (0.05 * rnd()),
                            };
                            let f = Filtering {
                                filter,
                                max_anisotropy: 8.0,
                                mips: Some(&chain),
                            };
                            fps[k] = t.footprint(g, &f);
                        }
                        let mips = if round % 5 == 4 {
                            None
                        } else {
                            Some(&chain[..])
                        };
                        let u = Vec4::from(uv.map(|p| p.x));
                        let v = Vec4::from(uv.map(|p| p.y));
                        let got = t.sample_footprint4(u, v, &fps, mode.into(), mips);
                        for k in 0..4 {
                            let want = t.sample_footprint(uv[k], fps[k], mode.into(), mips);
                            for c in 0..3 {
                                assert_eq!(
                                    got[c][k].to_bits(),
                                    want[c].to_bits(),
                                    "lane {k} channel {c}: {:?} {:?} {mode:?} {filter:?}",
                                    uv[k],
                                    fps[k]
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}
