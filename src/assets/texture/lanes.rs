//! Four lookups of one texture at once, for shading that runs four
//! fragments side by side (`shade::lanes`): the coordinates and
//! results are held per channel with one lane per lookup (a structure of
//! arrays), and every lane is bit for bit what the one-lookup functions
//! give for it (`Chain::sample1`).
//!
//! A lookup is found in two steps. `Texture::taps4` places the four
//! footprints: per lane the level or two levels read, and in each the
//! bilinear footprint's texels (their positions in the block layout) and
//! weights. That depends only on the texture's size and mip chain, so the
//! maps of a material that share a size (diffuse, specular and normal map,
//! mostly) share it, anisotropic probes included (`Chain::place4_into`).
//! `Chain::read_placed_into` then loads, decodes and blends each map's texels.
//! A lane whose footprint leaves the image (an address mode applies) takes
//! the one-lookup path.

// Loops over the four lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Vec2, Vec4};

use super::{ALPHA_TABLE, Footprint, Level, Texture, Wrap};
use smallvec::SmallVec;

use crate::color::srgb_to_linear_table;
use crate::simd::{F8, Lane, Words8, block_steps4, lanes4, whole4};

/// Red, green and blue of four lookups, one lane each.
pub type Rgb4 = [Vec4; 3];

/// Red, green, blue and alpha of four lookups, one lane each.
pub type Rgba4 = [Vec4; 4];

/// Where four trilinear lookups fall in any texture of one size and mip
/// chain (`Texture::taps4`).
pub struct Taps4 {
    /// The chain's shape (`Chain::shape`) and the lanes' levels of detail.
    shape: (u32, u32, usize),
    lod: [f32; 4],
    u: Vec4,
    v: Vec4,
    near: Place4,
    /// Where some lane blends two levels: the farther ones (a lane that
    /// reads one level reads it again there, at weight 0: a * 1 + a * 0 =
    /// a) and the weights.
    far: Option<(Place4, Vec4)>,
}

/// Where four lookups of which some take anisotropic probes fall
/// (`Chain::place4_into`), in any texture of one size and mip chain.
pub struct ProbeTaps {
    /// Per probe: its taps, and 1 in the lanes that take it (0 in those
    /// whose probes ran out).
    probes: Vec<(Taps4, Vec4)>,
    /// Probes per lane.
    count: Vec4,
}

/// Where four lookups fall in any texture of one size and mip chain
/// (`Chain::place4_into`), for the maps that share it: one trilinear
/// probe per lane (`taps`), or anisotropic probes in some lane
/// (`probes`); neither where some lane reads the nearest texel (`sample4`
/// looks the lanes up) or nothing was placed yet.
#[derive(Default)]
pub struct Placed4 {
    taps: Option<Taps4>,
    probes: Option<ProbeTaps>,
}

/// Bilinear footprints in one level per lane.
struct Place4 {
    /// Level per lane (0: the image itself, k: mip level k).
    level: [usize; 4],
    /// Per lane: the footprint's top-left texel in the block layout, and
    /// the steps to its right and lower neighbours (`Level::footprint`);
    /// unspecified in lanes that are not inside.
    at: [u32; 4],
    dx: [u32; 4],
    dy: [u32; 4],
    /// Fractions between the texels.
    fx: Vec4,
    fy: Vec4,
    /// Lanes whose footprint lies inside the level (bit k: lane k); the
    /// others go through the address mode.
    inside: u32,
    /// Lanes whose result is used (bit k: lane k): a lone lookup reads and
    /// decodes one lane's texels, not four.
    live: u32,
}

/// A texture's levels as the four-lane lookups read them: the image and
/// the frame's mip chain (`Texture::chain`), each level's texels at hand.
pub struct Chain<'t> {
    texture: &'t Texture,
    mips: Option<&'t [Level]>,
    /// Per level (0: the image), its texels as `Level::texels`.
    texels: SmallVec<[&'t [u32]; 16]>,
}

impl Texture {
    /// This texture with the mip chain `mips` (its levels 1.., or None:
    /// level 0 only), for four-lane lookups.
    pub fn chain<'t>(&'t self, mips: Option<&'t [Level]>) -> Chain<'t> {
        let mut texels: SmallVec<[&[u32]; 16]> = SmallVec::new();
        texels.push(self.base.texels());
        for l in mips.unwrap_or(&[]) {
            texels.push(l.texels());
        }
        Chain {
            texture: self,
            mips,
            texels,
        }
    }
}

impl<'t> Chain<'t> {
    /// One lookup at `uv` over `fp` in this chain (red, green, blue and
    /// alpha): the four-lane lookup with every lane the same, its first
    /// lane.
    pub fn sample1(&self, uv: Vec2, fp: Footprint, mode: Wrap) -> Vec4 {
        let (u, v) = (Vec4::splat(uv.x), Vec4::splat(uv.y));
        let c = self.sample::<4>(u, v, &[fp; 4], mode, 0b0001);
        Vec4::new(c[0].x, c[1].x, c[2].x, c[3].x)
    }

    /// The texture's size and number of levels: taps found in one chain
    /// serve every chain of the same shape.
    fn shape(&self) -> (u32, u32, usize) {
        (self.texture.width, self.texture.height, self.texels.len())
    }

    /// Four lookups in this chain, lane k at (`u`, `v`) over `fps[k]`:
    /// red, green and blue.
    pub fn sample4(&self, u: Vec4, v: Vec4, fps: &[Footprint; 4], mode: Wrap) -> Rgb4 {
        self.sample::<3>(u, v, fps, mode, 0b1111)
    }

    /// `sample4` with alpha.
    pub fn sample4_rgba(&self, u: Vec4, v: Vec4, fps: &[Footprint; 4], mode: Wrap) -> Rgba4 {
        self.sample::<4>(u, v, fps, mode, 0b1111)
    }

    /// The first `N` channels of four lookups, in the lanes `live` (the
    /// others unspecified).
    #[inline]
    fn sample<const N: usize>(
        &self,
        u: Vec4,
        v: Vec4,
        fps: &[Footprint; 4],
        mode: Wrap,
        live: u32,
    ) -> [Vec4; N] {
        let nearest = fps.iter().enumerate().fold(0, |m, (k, f)| {
            m | (u32::from(*f == Footprint::Nearest) << k)
        }) & live;
        if nearest != 0 {
            return self.with_nearest(u, v, fps, mode, (live, nearest));
        }
        match self.taps4(u, v, fps) {
            Some(taps) => self.read(&taps.only(live), mode),
            None => self.probes(u, v, fps, mode, live),
        }
    }

    /// `sample` where the lanes `nearest` (of the lanes `live`) read the
    /// nearest texel (`Texture::sample_nearest`, lane by lane).
    #[cold]
    fn with_nearest<const N: usize>(
        &self,
        u: Vec4,
        v: Vec4,
        fps: &[Footprint; 4],
        mode: Wrap,
        (live, nearest): (u32, u32),
    ) -> [Vec4; N] {
        let rest = live & !nearest;
        let mut out = [Vec4::ZERO; N];
        if rest != 0 {
            let others = fps.map(|f| match f {
                Footprint::Nearest => Footprint::Lod(0.0),
                f => f,
            });
            out = self.sample(u, v, &others, mode, rest);
        }
        for k in 0..4 {
            if nearest & (1 << k) != 0 {
                let c = self.texture.sample_nearest(Vec2::new(u[k], v[k]), mode);
                for (ch, o) in out.iter_mut().enumerate() {
                    o[k] = c[ch];
                }
            }
        }
        out
    }

    /// Where `sample4` reads at one trilinear probe per lane
    /// (`Footprint::Lod`), in this chain or any other of its shape; None
    /// where some lane takes anisotropic probes or the nearest texel.
    #[inline]
    pub fn taps4(&self, u: Vec4, v: Vec4, fps: &[Footprint; 4]) -> Option<Taps4> {
        let lod = Self::lods(fps)?;
        Some(self.lod_taps4(u, v, lod))
    }

    /// Each lane's level of detail, where every lane takes one trilinear
    /// probe.
    #[inline(always)]
    fn lods(fps: &[Footprint; 4]) -> Option<[f32; 4]> {
        let mut lod = [0.0f32; 4];
        for k in 0..4 {
            match fps[k] {
                Footprint::Lod(l) => lod[k] = l,
                Footprint::Probes { .. } | Footprint::Nearest => return None,
            }
        }
        Some(lod)
    }

    /// `*out` = where `sample4(u, v, fps, _)` reads, in this chain or any
    /// other of its shape (`read_placed_into`), written in place.
    #[inline]
    pub fn place4_into(&self, u: Vec4, v: Vec4, fps: &[Footprint; 4], out: &mut Placed4) {
        out.probes = None;
        out.taps = None;
        match Self::lods(fps) {
            Some(lod) => out.taps = Some(self.lod_taps4(u, v, lod)),
            None if fps.contains(&Footprint::Nearest) => {}
            None => {
                let most = fps.iter().map(|f| match f {
                    Footprint::Probes { n, .. } => *n as usize,
                    _ => 1,
                });
                let mut probes = Vec::with_capacity(most.max().unwrap_or(1));
                let count = self.each_probe(u, v, fps, 0b1111, |t, live| probes.push((t, live)));
                out.probes = Some(ProbeTaps { probes, count });
            }
        }
    }

    /// What `sample4` gives at the lookups `placed` places (found in a
    /// chain of this shape), in this texture, written into `out`; false
    /// (and `out` as it was) where they are not placed. (Into place: a
    /// caller's copy of a returned result would load wide over the
    /// lookup's narrow stores, and wait on them.)
    #[inline]
    pub fn read_placed_into(&self, placed: &Placed4, mode: Wrap, out: &mut Rgb4) -> bool {
        match placed {
            Placed4 { taps: Some(t), .. } => self.read_into::<3>(t, mode, out),
            Placed4 {
                probes: Some(p), ..
            } => *out = self.read_probes::<3>(p, mode),
            _ => return false,
        }
        true
    }

    /// The taps of `sample_lod(mips, uv_k, mode, lod[k])` per lane: the
    /// level `lod[k]` selects, and the next one where it blends two.
    #[inline(always)]
    fn lod_taps4(&self, u: Vec4, v: Vec4, lod: [f32; 4]) -> Taps4 {
        let mut near = [0usize; 4];
        let mut far = [0usize; 4];
        let mut weight = [0.0f32; 4];
        let mut two = false;
        // The lanes of a quad of one triangle share one level of detail:
        // then the first lane's choice is every lane's.
        let lod_bits = lod.map(f32::to_bits);
        let lanes = if lod_bits.iter().all(|&b| b == lod_bits[0]) {
            1
        } else {
            4
        };
        if let Some(mips) = self.mips {
            let top = mips.len() as f32;
            for k in 0..lanes {
                if lod[k] <= 0.0 || lod[k].is_nan() {
                    continue;
                }
                let l = lod[k].min(top);
                let i = l as u32 as f32;
                let f = l - i;
                let i = i as usize;
                near[k] = i;
                far[k] = i;
                if f > 0.0 && i < mips.len() {
                    far[k] = i + 1;
                    weight[k] = f;
                    two = true;
                }
            }
            if lanes == 1 {
                near = [near[0]; 4];
                far = [far[0]; 4];
                weight = [weight[0]; 4];
            }
        }
        let level = |i: usize| self.level(i);
        Taps4 {
            shape: self.shape(),
            lod,
            u,
            v,
            near: Place4::new(near, near.map(level), u, v),
            far: two.then(|| {
                let w = lanes4(weight[0], weight[1], weight[2], weight[3]);
                (Place4::new(far, far.map(level), u, v), w)
            }),
        }
    }

    /// Level `i` (0: the image).
    #[inline(always)]
    fn level(&self, i: usize) -> &'t Level {
        level_of(&self.texture.base, self.mips, i)
    }

    /// The lookups `taps` describe, in this texture: the first `N`
    /// channels (taps found in a chain of another shape are found again
    /// here).
    #[inline(always)]
    fn read<const N: usize>(&self, taps: &Taps4, mode: Wrap) -> [Vec4; N] {
        let mut out = [Vec4::ZERO; N];
        self.read_into(taps, mode, &mut out);
        out
    }

    /// `read` into `out`, each channel stored alone: a caller that reads
    /// them one by one does not wait on a wide copy of narrow stores.
    #[inline]
    fn read_into<const N: usize>(&self, taps: &Taps4, mode: Wrap, out: &mut [Vec4; N]) {
        if taps.shape != self.shape() {
            // Taps of another shape: found again here.
            let again = self.lod_taps4(taps.u, taps.v, taps.lod);
            return self.read_into(&again.only(taps.near.live), mode, out);
        }
        let a = self.bilinear4(&taps.near, taps.u, taps.v, mode);
        *out = match &taps.far {
            None => a,
            Some((far, f)) => blend(a, self.bilinear4(far, taps.u, taps.v, mode), *f),
        };
    }

    /// `prefetch` of the lookups `placed` places.
    #[inline]
    pub fn prefetch_placed(&self, placed: &Placed4) {
        if let Some(t) = &placed.taps {
            self.prefetch(t);
        }
        if let Some(p) = &placed.probes {
            p.probes.iter().for_each(|(t, _)| self.prefetch(t));
        }
    }

    /// Asks for the cache lines `read` of `taps` will load, so that the
    /// misses of several maps overlap instead of coming one map after the
    /// other. A hint only: what `read` returns does not change.
    #[inline]
    pub fn prefetch(&self, taps: &Taps4) {
        if taps.shape != self.shape() {
            return;
        }
        self.prefetch_place(&taps.near);
        if let Some((far, _)) = &taps.far {
            self.prefetch_place(far);
        }
    }

    /// The line of each inside lane's top-left texel (the whole footprint
    /// lies in it unless it crosses a block's edge).
    #[inline(always)]
    fn prefetch_place(&self, place: &Place4) {
        // The slice once, not the small vector's inline-or-heap check per
        // lane.
        let texels = self.texels.as_slice();
        for k in 0..4 {
            if place.inside & (1 << k) != 0 {
                prefetch_texel(texels[place.level[k]], place.at[k] as usize);
            }
        }
    }

    /// Bilinear lookups at (`u`, `v`) for the four lanes, each in its
    /// level of `place`: the first `N` channels. The four texels are
    /// decoded, then blended along x and then along y, a (1 - f) + b f.
    #[inline(always)]
    fn bilinear4<const N: usize>(&self, place: &Place4, u: Vec4, v: Vec4, mode: Wrap) -> [Vec4; N] {
        let read = place.inside & place.live;
        let (left, right) = self.corners(place, read);
        let (fx, fy) = (place.fx, place.fy);
        let (gx, gy) = (Vec4::ONE - fx, Vec4::ONE - fy);
        // The corners go in pairs, eight lanes at once: top-left with
        // bottom-left, top-right with bottom-right, so that one blend
        // along x gives the top row's values in lanes 0-3 and the bottom
        // row's in lanes 4-7.
        let (gx2, fx2) = (F8::from_quads(|_| gx), F8::from_quads(|_| fx));
        let mut out = [Vec4::ZERO; N];
        // Channel by channel: its four corners decoded
        // (`Texture::decode`), then blended, a (1 - f) + b f.
        for (ch, o) in out.iter_mut().enumerate() {
            let shift = 8 * ch as u32;
            let (left, right) = if self.texture.srgb {
                // Color through the sRGB table, alpha as it is stored.
                let lut = if ch < 3 {
                    srgb_to_linear_table()
                } else {
                    &ALPHA_TABLE
                };
                (left.lookup(lut, shift), right.lookup(lut, shift))
            } else {
                let unit = F8::splat(1.0 / 255.0);
                (left.bytes(shift) * unit, right.bytes(shift) * unit)
            };
            let rows = left * gx2 + right * fx2;
            *o = rows.quad(0) * gy + rows.quad(1) * fy;
        }
        let wrapped = place.live & !place.inside;
        if wrapped != 0 {
            for k in 0..4 {
                if wrapped & (1 << k) != 0 {
                    let level = self.level(place.level[k]);
                    let uv = Vec2::new(u[k], v[k]);
                    let r = self.texture.bilinear_wrapped(level, uv, mode);
                    for (c, o) in out.iter_mut().enumerate() {
                        o[k] = r[c];
                    }
                }
            }
        }
        out
    }

    /// The four lanes' bilinear footprints in `place`, as stored: the
    /// left texels (top in lanes 0-3, bottom in lanes 4-7) and the right
    /// ones; 0 in the lanes not in `read` (bit k: lane k), which read
    /// nothing.
    #[inline(always)]
    fn corners(&self, place: &Place4, read: u32) -> (Words8, Words8) {
        let right = std::array::from_fn(|k| place.at[k].wrapping_add(place.dx[k]));
        let first = read.trailing_zeros() as usize;
        let level = place.level.get(first).map_or(0, |&l| l);
        let one_level = (0..4).all(|k| read & (1 << k) == 0 || place.level[k] == level);
        let t = self.texels[level];
        if read != 0 && one_level && t.len() <= i32::MAX as usize {
            // SAFETY: an inside lane's footprint has x0 + 1 < width and
            // y0 + 1 < height in its level (`Place4::new`, for a level of
            // this size: `read` checks the shape), so its four texels, the
            // last at at + dx + dy, lie in the level's blocks
            // (`Level::footprint`'s steps); the read lanes are all in
            // level `level`, whose length fits an i32.
            return unsafe {
                (
                    Words8::gather_pair(t, place.at, place.dy, read),
                    Words8::gather_pair(t, right, place.dy, read),
                )
            };
        }
        // Corner j (top-left, top-right, bottom-left, bottom-right) of
        // lane k, as stored.
        let mut texels = [[0u32; 4]; 4];
        for k in 0..4 {
            if read & (1 << k) != 0 {
                let t = self.texels[place.level[k]];
                let (i, dx, dy) = (
                    place.at[k] as usize,
                    place.dx[k] as usize,
                    place.dy[k] as usize,
                );
                debug_assert!(i + dx + dy < t.len());
                // SAFETY: as above, lane by lane in its own level.
                unsafe {
                    texels[0][k] = u32::from_le(*t.get_unchecked(i));
                    texels[1][k] = u32::from_le(*t.get_unchecked(i + dx));
                    texels[2][k] = u32::from_le(*t.get_unchecked(i + dy));
                    texels[3][k] = u32::from_le(*t.get_unchecked(i + dx + dy));
                }
            }
        }
        (
            Words8::new(texels[0], texels[2]),
            Words8::new(texels[1], texels[3]),
        )
    }

    /// Four lanes of which some take anisotropic probes (`each_probe`):
    /// per lane, the sum of its probes over their count.
    fn probes<const N: usize>(
        &self,
        u: Vec4,
        v: Vec4,
        fps: &[Footprint; 4],
        mode: Wrap,
        used: u32,
    ) -> [Vec4; N] {
        let mut sum = [Vec4::ZERO; N];
        let count = self.each_probe(u, v, fps, used, |taps, live| {
            self.add_probe(&mut sum, &taps, live, mode);
        });
        sum.map(|s| s / count)
    }

    /// The probes `taps` place (found in a chain of this shape), read in
    /// this texture as `probes` reads them.
    fn read_probes<const N: usize>(&self, taps: &ProbeTaps, mode: Wrap) -> [Vec4; N] {
        let mut sum = [Vec4::ZERO; N];
        for (probe, live) in &taps.probes {
            self.add_probe(&mut sum, probe, *live, mode);
        }
        sum.map(|s| s / taps.count)
    }

    /// One probe's lookups added to `sum` in the lanes `live` (1) that
    /// take it; a lane with fewer probes adds nothing after its last (x +
    /// 0 = x).
    #[inline(always)]
    fn add_probe<const N: usize>(&self, sum: &mut [Vec4; N], taps: &Taps4, live: Vec4, mode: Wrap) {
        let r: [Vec4; N] = self.read(taps, mode);
        let live = live.cmpgt(Vec4::ZERO);
        for c in 0..N {
            sum[c] += Vec4::select(live, r[c], Vec4::ZERO);
        }
    }

    /// Where four lanes of which some take anisotropic probes read: per
    /// lane, `n` trilinear probes spread along the footprint's longer
    /// axis (at (k + 1/2) / n - 1/2 of it); a `Lod` lane is one probe at
    /// the point itself. Each probe's taps (only the lanes `used` read)
    /// and 1 in the lanes that take it go to `f`, in order; returns the
    /// probes per lane.
    #[inline(always)]
    fn each_probe(
        &self,
        u: Vec4,
        v: Vec4,
        fps: &[Footprint; 4],
        used: u32,
        mut f: impl FnMut(Taps4, Vec4),
    ) -> Vec4 {
        let mut n = [1u32; 4];
        let mut nf = [1.0f32; 4];
        let mut lod = [0.0f32; 4];
        let mut axis = [Vec2::ZERO; 4];
        for k in 0..4 {
            match fps[k] {
                Footprint::Lod(l) => lod[k] = l,
                // (`sample` looks these up before the probes.)
                Footprint::Nearest => {}
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
        let count = n.iter().copied().max().unwrap_or(1);
        for p in 0..count {
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
            f(self.lod_taps4(pu, pv, lod).only(used), Vec4::from(live));
        }
        Vec4::from(nf)
    }
}

/// Level `i` of a chain: the image itself for 0, else mip level i (the
/// image where the chain has no such level: taps found in a texture of
/// the same size and chain never ask for one).
#[inline(always)]
fn level_of<'a>(base: &'a Level, mips: Option<&'a [Level]>, i: usize) -> &'a Level {
    match (i, mips) {
        (0, _) | (_, None) => base,
        (i, Some(m)) => m.get(i - 1).unwrap_or(base),
    }
}

impl Taps4 {
    /// These taps with only the lanes `live` read.
    #[inline(always)]
    fn only(mut self, live: u32) -> Taps4 {
        self.near.live = live;
        if let Some((far, _)) = &mut self.far {
            far.live = live;
        }
        self
    }
}

impl Place4 {
    /// As `bilinear` places a lookup at `uv` in a level: x = u w - 1/2,
    /// y = v h - 1/2, inside where both footprint texels exist; and where
    /// `Level::footprint` finds the texels.
    #[inline(always)]
    fn new(level: [usize; 4], levels: [&Level; 4], u: Vec4, v: Vec4) -> Place4 {
        if std::ptr::eq(levels[0], levels[1])
            && std::ptr::eq(levels[0], levels[2])
            && std::ptr::eq(levels[0], levels[3])
        {
            // One level for the four lanes (a quad's shared footprint):
            // its size splat, the same values the lanes would gather.
            let l = levels[0];
            let (w, h) = (Vec4::splat(l.width as f32), Vec4::splat(l.height as f32));
            return Place4::within(level, levels, w, h, u, v);
        }
        let w = lanes4(
            levels[0].width as f32,
            levels[1].width as f32,
            levels[2].width as f32,
            levels[3].width as f32,
        );
        let h = lanes4(
            levels[0].height as f32,
            levels[1].height as f32,
            levels[2].height as f32,
            levels[3].height as f32,
        );
        Place4::within(level, levels, w, h, u, v)
    }

    /// `new`, given the levels' widths `w` and heights `h` per lane.
    #[inline(always)]
    fn within(
        level: [usize; 4],
        levels: [&Level; 4],
        w: Vec4,
        h: Vec4,
        u: Vec4,
        v: Vec4,
    ) -> Place4 {
        let x = u * w - Vec4::splat(0.5);
        let y = v * h - Vec4::splat(0.5);
        let inside = (x.cmpge(Vec4::ZERO)
            & y.cmpge(Vec4::ZERO)
            & x.cmplt(w - Vec4::ONE)
            & y.cmplt(h - Vec4::ONE))
        .bitmask();
        let (x0, y0) = (x.trunc(), y.trunc());
        let (xi, yi) = (whole4(x0), whole4(y0));
        // `Level::footprint`'s steps for every lane at once (the lanes that
        // are not inside get values no read uses).
        let [at, dx, dy] = block_steps4(xi, yi, levels.map(|l| l.blocks_x));
        Place4 {
            level,
            at,
            dx,
            dy,
            fx: x - x0,
            fy: y - y0,
            inside,
            live: 0b1111,
        }
    }
}

/// A prefetch of texel `i` of `t` into every cache level (no effect on
/// what is read, and none off x86-64).
#[inline(always)]
fn prefetch_texel(t: &[u32], i: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // A prefetch never faults, and `i` is an inside lane's texel
        // (`Place4::new`), so the address lies in the slice anyway.
        let p = t.as_ptr().wrapping_add(i);
        // SAFETY: `_mm_prefetch` only hints the cache; it reads nothing
        // the program sees, and SSE is part of x86-64's base set.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p as *const i8) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (t, i);
}

/// a (1 - f) + b f per channel, as `Vec4::lerp`.
#[inline(always)]
fn blend<const N: usize>(a: [Vec4; N], b: [Vec4; N], f: Vec4) -> [Vec4; N] {
    let g = Vec4::ONE - f;
    std::array::from_fn(|c| a[c] * g + b[c] * f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::mip::build_chain;
    use crate::assets::texture::{AddressMode, Filtering, Gradients, TextureFilter};

    fn noise(w: u32, h: u32, srgb: bool) -> Texture {
        let mut s = 0x9e37_79b9u32;
        let texels: Vec<[u8; 4]> = (0..w * h)
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
        Texture::from_rgba8(w, h, &texels, srgb)
    }

    /// Bilinear filtering as the GL specification states it, texel by
    /// texel: inside the image the four texels around `uv` blended along
    /// x, then y; across an edge the address mode's general path.
    fn bilinear(t: &Texture, l: &Level, uv: Vec2, mode: Wrap) -> Vec4 {
        let x = uv.x * l.width as f32 - 0.5;
        let y = uv.y * l.height as f32 - 0.5;
        if !(x >= 0.0 && y >= 0.0 && x < (l.width - 1) as f32 && y < (l.height - 1) as f32) {
            return t.bilinear_wrapped(l, uv, mode);
        }
        let (x0, y0) = (x as u32, y as u32);
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let at = |dx: u32, dy: u32| t.decode(l.texel(x0 + dx, y0 + dy));
        let top = at(0, 0).lerp(at(1, 0), fx);
        let bottom = at(0, 1).lerp(at(1, 1), fx);
        top.lerp(bottom, fy)
    }

    /// Trilinear filtering: level floor(lod), blended with the next by
    /// lod's fraction; level 0 for lod <= 0 or without a chain.
    fn trilinear(t: &Texture, mips: Option<&[Level]>, uv: Vec2, mode: Wrap, lod: f32) -> Vec4 {
        let Some(mips) = mips.filter(|_| lod > 0.0) else {
            return bilinear(t, &t.base, uv, mode);
        };
        let lod = lod.min(mips.len() as f32);
        let i = lod.floor() as usize;
        let f = lod - i as f32;
        let level = |k: usize| if k == 0 { &t.base } else { &mips[k - 1] };
        let a = bilinear(t, level(i), uv, mode);
        if f <= 0.0 || i + 1 > mips.len() {
            return a;
        }
        a.lerp(bilinear(t, level(i + 1), uv, mode), f)
    }

    /// A footprint's lookup: one trilinear probe, or the mean of `n`
    /// spread along its axis.
    fn reference(t: &Texture, mips: Option<&[Level]>, uv: Vec2, fp: Footprint, mode: Wrap) -> Vec4 {
        match fp {
            Footprint::Lod(lod) => trilinear(t, mips, uv, mode, lod),
            Footprint::Probes { n, lod, axis } => {
                let mut sum = Vec4::ZERO;
                for k in 0..n as u32 {
                    let s = (k as f32 + 0.5) / n - 0.5;
                    sum += trilinear(t, mips, uv + axis * s, mode, lod);
                }
                sum / n
            }
            Footprint::Nearest => t.sample_nearest(uv, mode),
        }
    }

    /// Every lane, and every lone lookup, equals the texel-by-texel
    /// reference bit for bit in all four channels: inside the image,
    /// across its edges (address modes), between levels, with
    /// anisotropic probes of different counts per lane and with some
    /// lanes reading the nearest texel.
    #[test]
    fn lanes_equal_texel_by_texel_filtering() {
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
                            if round % 7 == 6 {
                                // Coordinates from the wild: the unchecked
                                // loads must never see them as inside.
                                const ODD: [f32; 8] = [
                                    f32::NAN,
                                    f32::INFINITY,
                                    f32::NEG_INFINITY,
                                    -1e30,
                                    3e9,
                                    -0.0,
                                    1.0,
                                    -1e-39,
                                ];
                                uv[k].x = ODD[(round / 7 + k) % ODD.len()];
                                if k % 2 == 1 {
                                    uv[k].y = ODD[(round / 7 + 3 * k) % ODD.len()];
                                }
                            }
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
                        if round % 4 == 1 {
                            // A quad of one triangle: one footprint.
                            fps = [fps[0]; 4];
                        }
                        if round % 6 == 5 {
                            // A sampler magnifying with the nearest
                            // texel: some lanes, or all.
                            for f in &mut fps {
                                if rnd() < 0.6 {
                                    *f = Footprint::Nearest;
                                }
                            }
                        }
                        let mips = if round % 5 == 4 {
                            None
                        } else {
                            Some(&chain[..])
                        };
                        let mode = Wrap::from(mode);
                        let lanes = t.chain(mips);
                        let u = Vec4::from(uv.map(|p| p.x));
                        let v = Vec4::from(uv.map(|p| p.y));
                        let got = lanes.sample4_rgba(u, v, &fps, mode);
                        let rgb = lanes.sample4(u, v, &fps, mode);
                        for k in 0..4 {
                            let want = reference(&t, mips, uv[k], fps[k], mode);
                            let one = lanes.sample1(uv[k], fps[k], mode);
                            for c in 0..4 {
                                let why = format!("lane {k} channel {c}: {:?} {:?}", uv[k], fps[k]);
                                assert_eq!(got[c][k].to_bits(), want[c].to_bits(), "{why}");
                                assert_eq!(one[c].to_bits(), want[c].to_bits(), "{why}");
                                if c < 3 {
                                    assert_eq!(rgb[c][k].to_bits(), want[c].to_bits(), "{why}");
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}
