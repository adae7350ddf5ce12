//! Decoded textures and their sampling.
//!
//! Texels are kept as RGBA8 (a quarter of the memory of floats, so more of a
//! 4096² map stays in cache) and turned into linear floats per fetch: color
//! maps through a 256-entry sRGB->linear table, data maps by /255. Filtering
//! always happens on linear values. Texture coordinates here use the image's
//! convention: (0,0) is the top-left corner of the first row; loaders convert
//! (OBJ's v runs upwards, see `assets::obj`).
//!
//! Texels are stored in 4x4 blocks (one 64-byte cache line each), blocks in
//! row-major order: a bilinear footprint then touches one cache line in 9
//! cases of 16 instead of always two, and neighbouring pixels share lines in
//! both directions. Textures are cache-bound on minified models, so this is
//! worth a few shifts per fetch.

pub mod cache;
mod lanes;

use std::path::Path;

use glam::{Affine2, Vec2, Vec4};

use super::input::Input;
use crate::color::srgb_to_linear_table;
use crate::error::Error;
pub use lanes::{Chain, Placed4, Rgb4, Taps4};

/// Texture filtering, ordered from the least to the most filtering (a
/// sampler's limit lowers a scene's filter to it, never raises it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum TextureFilter {
    /// The nearest texel of level 0.
    Nearest,
    /// Four texels of level 0, blended.
    Bilinear,
    /// Mip level from the longer footprint axis, blended between levels.
    Trilinear,
    /// Up to `max_anisotropy` trilinear probes along the longer axis. The
    /// default since `softraster chart` showed trilinear off the Pareto
    /// front (docs/chart.md).
    #[default]
    Anisotropic,
}

/// What a lookup outside [0, 1] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AddressMode {
    #[default]
    /// Tiles.
    Repeat,
    /// Tiles, every other copy mirrored.
    Mirror,
    /// The edge texels extend.
    Clamp,
    /// Transparent black (`BORDER`).
    Border,
}

/// One image of a mip chain: RGBA8 in 4x4 blocks of one cache line each
/// (see the module notes).
#[derive(Debug)]
pub struct Level {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    blocks: crate::bigbuf::BigBuf<Block>,
    /// Blocks per row of blocks.
    blocks_x: u32,
}

/// A decoded image with its texel layout, colour space and the facts
/// shading asks of it (alpha, greyness); its mip chain is built on the
/// first frame that minifies it.
#[derive(Debug)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Level 0, as decoded. Levels 1.. (`chain`) are handed to the
    /// lookups by the frames that minify the texture (`Filtering::mips`).
    base: Level,
    /// Color data stored sRGB-encoded (decoded to linear on fetch).
    pub srgb: bool,
    /// Index in the scene's texture list (a frame's chains are listed
    /// under it).
    pub id: usize,
    /// Some texel has alpha below 255.
    pub has_alpha: bool,
    /// Of the texels with alpha below 255, the share that is 0 or 255-ish
    /// (a cutout rather than a gradual mask); 1 without alpha.
    pub binary_alpha: f32,
    /// Every texel has R = G = B (a height map rather than a normal map).
    pub grey: bool,
    /// Levels 1.. of the mip chain: built the first time a frame minifies
    /// the texture (`mip_chain`), or read with it from the texture cache
    /// (`--cache`). Kept with the texture, so every renderer of every scene
    /// that holds it shares one chain.
    chain: std::sync::OnceLock<Vec<Level>>,
}

/// A data texel as `[b as f32 * (1.0 / 255.0); 4]`: on x86-64 the four
/// bytes are widened and converted together (SSE2, part of the base
/// instruction set; the same IEEE operations, so the same floats).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn decode_data(t: [u8; 4]) -> Vec4 {
    use std::arch::x86_64::*;
    // SAFETY: these intrinsics need SSE2, which every x86-64 processor
    // has (it is in the target's base features); they touch no memory.
    unsafe {
        let zero = _mm_setzero_si128();
        let bytes = _mm_cvtsi32_si128(i32::from_le_bytes(t));
        let ints = _mm_unpacklo_epi16(_mm_unpacklo_epi8(bytes, zero), zero);
        Vec4::from(_mm_mul_ps(_mm_cvtepi32_ps(ints), _mm_set1_ps(1.0 / 255.0)))
    }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn decode_data(t: [u8; 4]) -> Vec4 {
    Vec4::new(t[0] as f32, t[1] as f32, t[2] as f32, t[3] as f32) * (1.0 / 255.0)
}

/// Byte -> byte / 255 as `b as f32 / 255.0` (the alpha of color maps).
pub(crate) static ALPHA_TABLE: [f32; 256] = {
    let mut t = [0.0f32; 256];
    let mut i = 0;
    while i < 256 {
        t[i] = i as f32 / 255.0;
        i += 1;
    }
    t
};

/// 4x4 texels, row-major, aligned to a 64-byte cache line (so a block is
/// exactly one line).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct Block([[u8; 4]; 16]);

// SAFETY: a Block is 64 bytes of u8 (size 64, alignment 64: no padding),
// so every bit pattern is a valid Block and it has no interior pointers;
// this lets the texture cache read and write levels as bytes.
unsafe impl bytemuck::Zeroable for Block {}
// SAFETY: as above.
unsafe impl bytemuck::Pod for Block {}

/// How a material refers to a texture: the texture plus the MTL options that
/// change its lookup.
#[derive(Debug, Clone)]
pub struct TextureRef {
    /// The image.
    pub texture: std::sync::Arc<Texture>,
    /// Applied to the texture coordinates before the lookup: MTL `-s` and
    /// `-o`, glTF KHR_texture_transform.
    pub transform: Affine2,
    /// Per-texture address modes along u and v (MTL `-clamp on`, glTF
    /// sampler wrapS/wrapT), else the scene's.
    pub address: Option<Wrap>,
    /// Texture-coordinate set (0 or 1).
    pub texcoord: u8,
    /// The sampler's minification filter when it asks for no mip maps
    /// (glTF NEAREST / LINEAR): the scene's filter is lowered to it.
    pub min_limit: Option<TextureFilter>,
    /// The sampler magnifies with the nearest texel (glTF magFilter NEAREST).
    pub mag_nearest: bool,
}

/// Address modes along u and v.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Wrap(pub AddressMode, pub AddressMode);

impl From<AddressMode> for Wrap {
    fn from(m: AddressMode) -> Wrap {
        Wrap(m, m)
    }
}

/// How to filter a lookup that carries screen-space derivatives.
#[derive(Debug, Clone, Copy)]
pub struct Filtering<'a> {
    /// The scene's filter (or a sampler's lower limit).
    pub filter: TextureFilter,
    /// The largest anisotropy taken.
    pub max_anisotropy: f32,
    /// The texture's levels 1.. (empty for a 1x1 texture); None where this
    /// frame never minifies the texture: level 0 only.
    pub mips: Option<&'a [Level]>,
}

/// Texture-coordinate derivatives along screen x and y (from a 2x2 quad).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Gradients {
    /// Along screen x.
    pub dx: Vec2,
    /// Along screen y.
    pub dy: Vec2,
}

impl Gradients {
    /// No change across the quad.
    pub const ZERO: Gradients = Gradients {
        dx: Vec2::ZERO,
        dy: Vec2::ZERO,
    };

    /// The same bits as `other` (+0 and -0 differ: a footprint's axis
    /// keeps the sign).
    #[inline(always)]
    pub fn same_bits(&self, other: &Gradients) -> bool {
        let bits = |g: &Gradients| [g.dx.x, g.dx.y, g.dy.x, g.dy.y].map(f32::to_bits);
        bits(self) == bits(other)
    }
}

/// A filtered lookup's footprint in texels (`Texture::footprint`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Footprint {
    /// One trilinear probe at this level of detail.
    Lod(f32),
    /// `n` trilinear probes at `lod`, spread over `axis` (texture
    /// coordinates) centred on the lookup.
    Probes {
        /// How many probes.
        n: f32,
        /// Their level of detail.
        lod: f32,
        /// The footprint's long axis.
        axis: Vec2,
    },
    /// The nearest texel of the image (level 0): the scene's `nearest`
    /// filter, or a sampler's magnification filter NEAREST.
    Nearest,
}

/// The first bytes of a texture-cache entry (`Texture::to_cache_bytes`);
/// a new layout takes a new number.
const CACHE_MAGIC: &[u8] = b"softraster-texture-1\n";

/// Border color for `address = "border"` and NaN coordinates: transparent black.
pub const BORDER: Vec4 = Vec4::ZERO;

impl Level {
    fn new(width: u32, height: u32) -> Level {
        let blocks_x = width.div_ceil(4);
        let blocks_y = height.div_ceil(4);
        Level {
            width,
            height,
            blocks: crate::bigbuf::BigBuf::zeroed((blocks_x * blocks_y) as usize),
            blocks_x,
        }
    }

    /// From row-major texels (row 0 at the top).
    pub(crate) fn from_rows(width: u32, height: u32, rows: &[[u8; 4]]) -> Level {
        Level::from_texels(width, height, rows, |t| t)
    }

    /// From row-major texels of any kind, each stored as `rgba` of it.
    #[inline(always)]
    fn from_texels<T: Copy>(
        width: u32,
        height: u32,
        rows: &[T],
        rgba: impl Fn(T) -> [u8; 4],
    ) -> Level {
        let mut l = Level::new(width, height);
        let blocks_x = l.blocks_x as usize;
        for (y, row) in rows.chunks_exact(width as usize).enumerate() {
            // Row y is row y % 4 of its blocks: four texels in each.
            let (first, r) = ((y / 4) * blocks_x, 4 * (y % 4));
            for (block, texels) in l.blocks[first..].iter_mut().zip(row.chunks(4)) {
                for (o, &t) in block.0[r..r + texels.len()].iter_mut().zip(texels) {
                    *o = rgba(t);
                }
            }
        }
        l
    }

    /// Position of texel (x, y) in the block layout.
    #[inline(always)]
    fn index(&self, x: u32, y: u32) -> usize {
        ((((y >> 2) * self.blocks_x + (x >> 2)) << 4) | ((y & 3) << 2) | (x & 3)) as usize
    }

    /// Row `y`'s texels, left to right, each through `f` into `out`
    /// (`width` values).
    #[inline(always)]
    pub(crate) fn read_row<T>(&self, y: u32, out: &mut [T], f: impl Fn([u8; 4]) -> T) {
        let (first, r) = ((y / 4 * self.blocks_x) as usize, 4 * (y % 4) as usize);
        let blocks = &self.blocks[first..first + self.blocks_x as usize];
        let out = &mut out[..self.width as usize];
        for (o, b) in out.chunks_mut(4).zip(blocks) {
            for (o, &t) in o.iter_mut().zip(&b.0[r..r + 4]) {
                *o = f(t);
            }
        }
    }

    #[inline]
    /// The RGBA8 texel at (x, y).
    pub fn texel(&self, x: u32, y: u32) -> [u8; 4] {
        let i = self.index(x, y);
        self.blocks[i >> 4].0[i & 15]
    }
}

impl Level {
    /// The texels in the block layout, each RGBA8 as a little-endian u32.
    #[inline(always)]
    fn texels(&self) -> &[u32] {
        bytemuck::cast_slice(&self.blocks)
    }
}

impl Texture {
    /// Decodes PNG, TGA (RLE, either origin), JPEG, BMP, TIFF, Radiance
    /// HDR, DDS or KTX2 by content, read through `input` (a regular file,
    /// at most its cap; the sandbox).
    pub fn load(path: &Path, srgb: bool, input: &Input) -> Result<Texture, Error> {
        let bytes = input.read(path, None, None)?;
        Texture::from_bytes(&bytes, path, srgb, input)
    }

    /// Decodes an image held in memory (a file's bytes, a glTF image in a
    /// buffer or a data URI); `name` stands for it in errors. The size
    /// it will take (the decode, its RGBA expansion, the block layout and
    /// the mip chain) is read from the header and checked against the
    /// memory budget before anything is decoded.
    pub fn from_bytes(
        bytes: &[u8],
        name: &Path,
        srgb: bool,
        input: &Input,
    ) -> Result<Texture, Error> {
        let refuse = |m: String| Error::asset(name, None, m);
        type Decode = fn(&[u8]) -> Result<super::dds::Decoded, String>;
        let special: Option<(Option<u64>, Decode)> = if super::dds::is_dds(bytes) {
            Some((super::dds::decode_bytes(bytes), super::dds::decode))
        } else if super::ktx2::is_ktx2(bytes) {
            Some((super::ktx2::decode_bytes(bytes), super::ktx2::decode))
        } else {
            None
        };
        if let Some((need, decode)) = special {
            if let Some(need) = need {
                // The decode (its RGBA8 texels and any inflated level),
                // then the level and its chain: at most three times that.
                input.check_file(name, "texture", need.saturating_mul(3))?;
            }
            let d = decode(bytes).map_err(|e| refuse(format!("cannot decode texture: {e}")))?;
            let t = Texture::from_rgba8(d.width, d.height, &d.texels, srgb);
            input.keep(t.kept_bytes());
            return Ok(t);
        }
        // The image crate guesses by content, then by the name's extension
        // (TGA has no magic number).
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| refuse(format!("cannot read texture: {e}")))?;
        if reader.format().is_none() {
            reader.set_format(
                image::ImageFormat::from_path(name)
                    .map_err(|e| refuse(format!("cannot read texture: {e}")))?,
            );
        }
        let t = Texture::decode_image(reader, name, srgb, input)?;
        input.keep(t.kept_bytes());
        Ok(t)
    }

    /// The bytes this texture keeps for the render: its level 0 in blocks
    /// and (once built) its mip chain, a third more.
    fn kept_bytes(&self) -> u64 {
        self.width as u64 * self.height as u64 * 4 * 4 / 3
    }

    fn decode_image<R: std::io::BufRead + std::io::Seek>(
        reader: image::ImageReader<R>,
        path: &Path,
        srgb: bool,
        input: &Input,
    ) -> Result<Texture, Error> {
        let img = decode_within(reader, input, path, "texture", 4 + 4 + 4 * 4 / 3)?;
        let (width, height) = (img.width(), img.height());
        if width == 0 || height == 0 {
            return Err(Error::asset(path, None, "texture has no pixels"));
        }
        let texels: Vec<[u8; 4]> = if matches!(
            img,
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
        ) {
            // Linear float images (Radiance HDR, float TIFF): colour maps
            // are stored sRGB-encoded like every 8-bit colour map, data
            // maps linearly; values above 1 clip.
            let encode = if srgb {
                crate::color::encode_srgb
            } else {
                crate::color::encode_linear
            };
            img.to_rgba32f()
                .pixels()
                .map(|p| {
                    let [r, g, b, a] = p.0;
                    [
                        encode(r),
                        encode(g),
                        encode(b),
                        crate::color::encode_linear(a),
                    ]
                })
                .collect()
        } else {
            // 8-bit images: their texels read in place (one copy fewer of
            // a map in fresh memory, which the first touch makes costly).
            let n = width as usize * height as usize;
            if let image::DynamicImage::ImageRgb8(rgb) = &img {
                let texels = bytemuck::cast_slice(&rgb.as_raw()[..n * 3]);
                return Ok(Texture::from_rgb8(width, height, texels, srgb));
            }
            let rgba = img.into_rgba8();
            let texels = bytemuck::cast_slice(&rgba.as_raw()[..n * 4]);
            return Ok(Texture::from_rgba8(width, height, texels, srgb));
        };
        Ok(Texture::from_rgba8(width, height, &texels, srgb))
    }

    /// From row-major texels (row 0 at the top); width and height > 0.
    pub fn from_rgba8(width: u32, height: u32, texels: &[[u8; 4]], srgb: bool) -> Texture {
        Texture::from_texels(width, height, texels, srgb, |t| t)
    }

    /// `from_rgba8` of opaque texels given as RGB.
    pub fn from_rgb8(width: u32, height: u32, texels: &[[u8; 3]], srgb: bool) -> Texture {
        Texture::from_texels(width, height, texels, srgb, |[r, g, b]| [r, g, b, 255])
    }

    /// From row-major texels of any kind, each `rgba` of it.
    #[inline(always)]
    fn from_texels<T: Copy>(
        width: u32,
        height: u32,
        texels: &[T],
        srgb: bool,
        rgba: impl Fn(T) -> [u8; 4] + Copy,
    ) -> Texture {
        assert_eq!(texels.len(), (width as usize) * (height as usize));
        assert!(width > 0 && height > 0);
        let grey = texels.iter().all(|&t| {
            let t = rgba(t);
            t[0] == t[1] && t[1] == t[2]
        });
        let partial = texels.iter().filter(|&&t| rgba(t)[3] < 255).count();
        let hard = texels.iter().filter(|&&t| rgba(t)[3] < 8).count();
        Texture {
            width,
            height,
            base: Level::from_texels(width, height, texels, rgba),
            srgb,
            id: 0,
            has_alpha: partial > 0,
            binary_alpha: if partial == 0 {
                1.0
            } else {
                hard as f32 / partial as f32
            },
            grey,
            chain: Default::default(),
        }
    }

    /// With levels 1.. already built (`chain`), as the texture cache
    /// reads them.
    pub fn with_cached_chain(self, chain: Vec<Level>) -> Texture {
        let _ = self.chain.set(chain);
        self
    }

    /// Levels 1.. of the mip chain (empty for a 1x1 texture): the chain
    /// this texture holds, else made by `build` (`mip::build_chain`) now
    /// and kept.
    pub fn mip_chain(&self, build: impl FnOnce(&Texture) -> Vec<Level>) -> &[Level] {
        self.chain.get_or_init(|| build(self))
    }

    /// Whether the texture holds its mip chain yet.
    pub fn has_mip_chain(&self) -> bool {
        self.chain.get().is_some()
    }

    /// The texture and its levels 1.. (`chain`) as a texture-cache entry:
    /// a header, then each level's size and blocks as stored.
    pub fn to_cache_bytes(&self, chain: &[Level]) -> Vec<u8> {
        let mut out = Vec::with_capacity(
            CACHE_MAGIC.len()
                + 32
                + std::iter::once(&self.base)
                    .chain(chain)
                    .map(|l| 8 + l.blocks.len() * 64)
                    .sum::<usize>(),
        );
        out.extend_from_slice(CACHE_MAGIC);
        out.extend_from_slice(&self.width.to_le_bytes());
        out.extend_from_slice(&self.height.to_le_bytes());
        out.extend_from_slice(&[self.srgb as u8, self.has_alpha as u8, self.grey as u8, 0]);
        out.extend_from_slice(&self.binary_alpha.to_le_bytes());
        out.extend_from_slice(&(1 + chain.len() as u32).to_le_bytes());
        for l in std::iter::once(&self.base).chain(chain) {
            out.extend_from_slice(&l.width.to_le_bytes());
            out.extend_from_slice(&l.height.to_le_bytes());
            out.extend_from_slice(bytemuck::cast_slice(&l.blocks));
        }
        out
    }

    /// A texture-cache entry back (`to_cache_bytes`) from `r`, which
    /// holds `len` bytes: the chain kept for `take_cached_chain`. None for
    /// anything that is not a whole, valid entry of a `srgb` texture
    /// (checked against `len` before any level is allocated).
    pub fn from_cache_reader(r: &mut impl std::io::Read, len: u64, srgb: bool) -> Option<Texture> {
        let mut head = [0u8; 21 + 24];
        debug_assert_eq!(CACHE_MAGIC.len(), 21);
        r.read_exact(&mut head).ok()?;
        let rest = head.strip_prefix(CACHE_MAGIC)?;
        let u32_at =
            |i: usize| u32::from_le_bytes([rest[i], rest[i + 1], rest[i + 2], rest[i + 3]]);
        let (width, height) = (u32_at(0), u32_at(4));
        let flags = &rest[8..12];
        let binary_alpha = f32::from_bits(u32_at(12));
        let count = u32_at(16);
        // rest[20..24]: the first level's width, read with its height.
        if flags[0] != srgb as u8 || flags[1] > 1 || flags[2] > 1 || width == 0 || height == 0 {
            return None;
        }
        // The levels' sizes follow from the base's: check the length first.
        let mut sizes = Vec::new();
        let (mut w, mut h) = (width, height);
        let mut total: u64 = head.len() as u64 - 4;
        for k in 0..count {
            if k > 0 {
                if (w, h) == (1, 1) {
                    return None;
                }
                (w, h) = ((w / 2).max(1), (h / 2).max(1));
            }
            let bytes = (w.div_ceil(4) as u64)
                .checked_mul(h.div_ceil(4) as u64)?
                .checked_mul(64)?;
            total = total.checked_add(bytes)?.checked_add(8)?;
            sizes.push((w, h));
        }
        if count == 0 || total != len || (count > 1 && (w, h) != (1, 1)) {
            return None;
        }
        let mut levels = Vec::with_capacity(sizes.len());
        for (k, &(w, h)) in sizes.iter().enumerate() {
            let mut size = [0u8; 8];
            if k == 0 {
                size[..4].copy_from_slice(&rest[20..24]);
                r.read_exact(&mut size[4..]).ok()?;
            } else {
                r.read_exact(&mut size).ok()?;
            }
            let lw = u32::from_le_bytes([size[0], size[1], size[2], size[3]]);
            let lh = u32::from_le_bytes([size[4], size[5], size[6], size[7]]);
            if (lw, lh) != (w, h) {
                return None;
            }
            let mut l = Level::new(w, h);
            r.read_exact(bytemuck::cast_slice_mut(&mut l.blocks)).ok()?;
            levels.push(l);
        }
        let mut levels = levels.into_iter();
        let base = levels.next()?;
        let chain: Vec<Level> = levels.collect();
        Some(Texture {
            width,
            height,
            base,
            srgb,
            id: 0,
            has_alpha: flags[1] == 1,
            binary_alpha,
            grey: flags[2] == 1,
            chain: chain.into(),
        })
    }

    /// `from_cache_reader` of an entry held in memory.
    pub fn from_cache_bytes(mut bytes: &[u8], srgb: bool) -> Option<Texture> {
        let len = bytes.len() as u64;
        Texture::from_cache_reader(&mut bytes, len, srgb)
    }

    /// Level 0.
    pub fn base(&self) -> &Level {
        &self.base
    }

    #[inline]
    fn fetch(&self, l: &Level, x: i64, y: i64) -> Vec4 {
        self.decode(l.texel(x as u32, y as u32))
    }

    /// Nearest-texel lookup at texture coordinates `uv` (top-left origin).
    pub fn sample_nearest(&self, uv: Vec2, mode: impl Into<Wrap>) -> Vec4 {
        let mode = mode.into();
        if !uv.is_finite() {
            return BORDER;
        }
        let l = &self.base;
        let x = (uv.x as f64 * l.width as f64).floor();
        let y = (uv.y as f64 * l.height as f64).floor();
        match (address(x, l.width, mode.0), address(y, l.height, mode.1)) {
            (Some(x), Some(y)) => self.fetch(l, x, y),
            _ => BORDER,
        }
    }

    /// Bilinear lookup in level 0.
    #[inline]
    pub fn sample_bilinear(&self, uv: Vec2, mode: impl Into<Wrap>) -> Vec4 {
        self.chain(None)
            .sample1(uv, Footprint::Lod(0.0), mode.into())
    }

    /// Filtered lookup with screen-space derivatives: nearest and bilinear
    /// read level 0; trilinear picks the level from the longer footprint
    /// axis; anisotropic takes up to `max_anisotropy` trilinear probes
    /// spread along the longer axis, at the level of the shorter one.
    pub fn sample_grad(&self, uv: Vec2, g: Gradients, mode: impl Into<Wrap>, f: Filtering) -> Vec4 {
        let mode = mode.into();
        match f.filter {
            TextureFilter::Nearest => self.sample_nearest(uv, mode),
            TextureFilter::Bilinear => self.sample_bilinear(uv, mode),
            _ if f.mips.is_none() => self.sample_bilinear(uv, mode),
            _ => self.chain(f.mips).sample1(uv, self.footprint(g, &f), mode),
        }
    }

    /// What trilinear or anisotropic filtering (`f.filter`) derives from
    /// the derivatives `g` and this texture's size: the same for every
    /// texture of that size looked up with those derivatives, so a
    /// material's maps share it.
    pub fn footprint(&self, g: Gradients, f: &Filtering) -> Footprint {
        Texture::footprint_of_size(self.width, self.height, g, f)
    }

    /// `footprint` of any texture of `width` x `height` texels.
    pub fn footprint_of_size(width: u32, height: u32, g: Gradients, f: &Filtering) -> Footprint {
        let size = Vec2::new(width as f32, height as f32);
        let (ax, ay) = (g.dx * size, g.dy * size);
        let (lx, ly) = (ax.length(), ay.length());
        if f.filter != TextureFilter::Anisotropic {
            return Footprint::Lod(lod_of(lx.max(ly)));
        }
        let (major, minor, axis) = if lx >= ly {
            (lx, ly, g.dx)
        } else {
            (ly, lx, g.dy)
        };
        let ratio = if minor > 0.0 {
            major / minor
        } else {
            f32::INFINITY
        };
        let n = ratio.min(f.max_anisotropy).ceil().max(1.0);
        if !n.is_finite() || n <= 1.0 {
            return Footprint::Lod(lod_of(major));
        }
        // n probes cover the major axis; each filters major / n.
        Footprint::Probes {
            n,
            lod: lod_of(major / n),
            axis,
        }
    }

    /// Linear RGBA stored as a texel: `decode`'s inverse, to the nearest
    /// byte (sRGB color by `encode_srgb`, data and alpha by
    /// `encode_linear`).
    #[inline]
    pub(crate) fn encode(&self, c: Vec4) -> [u8; 4] {
        use crate::color::encode_linear;
        let a = encode_linear(c.w);
        if self.srgb {
            let [r, g, b] = crate::color::encode_srgb_xyz(c);
            [r, g, b, a]
        } else {
            [
                encode_linear(c.x),
                encode_linear(c.y),
                encode_linear(c.z),
                a,
            ]
        }
    }

    /// A stored texel as linear RGBA: sRGB color decoded by table, data
    /// /255.
    #[inline(always)]
    pub(crate) fn decode(&self, t: [u8; 4]) -> Vec4 {
        self.decoder()(t)
    }

    /// `decode` with its table found once, for many texels.
    #[inline(always)]
    pub(crate) fn decoder(&self) -> impl Fn([u8; 4]) -> Vec4 + use<> {
        let lut = self.srgb.then(srgb_to_linear_table);
        move |t| match lut {
            None => decode_data(t),
            Some(lut) => Vec4::new(
                lut[t[0] as usize],
                lut[t[1] as usize],
                lut[t[2] as usize],
                ALPHA_TABLE[t[3] as usize],
            ),
        }
    }

    /// The general case: any finite coordinate, through the address mode.
    fn bilinear_wrapped(&self, l: &Level, uv: Vec2, mode: Wrap) -> Vec4 {
        if !uv.is_finite() {
            return BORDER;
        }
        // f64 keeps the fraction exact for coordinates far from the origin.
        let x = uv.x as f64 * l.width as f64 - 0.5;
        let y = uv.y as f64 * l.height as f64 - 0.5;
        let x0 = x.floor();
        let y0 = y.floor();
        let fx = (x - x0) as f32;
        let fy = (y - y0) as f32;
        let xs = [
            address(x0, l.width, mode.0),
            address(x0 + 1.0, l.width, mode.0),
        ];
        let ys = [
            address(y0, l.height, mode.1),
            address(y0 + 1.0, l.height, mode.1),
        ];
        let get = |xi: Option<i64>, yi: Option<i64>| match (xi, yi) {
            (Some(x), Some(y)) => self.fetch(l, x, y),
            _ => BORDER,
        };
        let top = get(xs[0], ys[0]).lerp(get(xs[1], ys[0]), fx);
        let bottom = get(xs[0], ys[1]).lerp(get(xs[1], ys[1]), fx);
        top.lerp(bottom, fy)
    }
}

/// Level of detail for a footprint of `texels` texels per pixel. NaN (from
/// degenerate derivatives) reads level 0.
#[inline]
fn lod_of(texels: f32) -> f32 {
    let l = texels.log2();
    if l.is_nan() { 0.0 } else { l.max(0.0) }
}

/// Maps an integer texel coordinate (given as a whole f64) into the texture,
/// or None for a border texel. Works for any finite input (no loops).
#[inline]
fn address(c: f64, size: u32, mode: AddressMode) -> Option<i64> {
    let n = size as i64;
    // Saturating conversion: huge coordinates stay huge, never wrap around.
    let i = c as i64;
    Some(match mode {
        AddressMode::Repeat => i.rem_euclid(n),
        AddressMode::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m >= n { 2 * n - 1 - m } else { m }
        }
        AddressMode::Clamp => i.clamp(0, n - 1),
        AddressMode::Border => {
            if i < 0 || i >= n {
                return None;
            }
            i
        }
    })
}

impl TextureRef {
    /// No transform and no sampler limits: a lookup is the texture's own
    /// (`Texture::sample_grad`), and its footprint can be shared.
    #[inline]
    pub fn is_plain(&self) -> bool {
        self.transform == Affine2::IDENTITY && self.min_limit.is_none() && !self.mag_nearest
    }

    /// A plain reference to `texture`: no transform, the scene's address
    /// mode, coordinate set 0.
    pub fn new(texture: std::sync::Arc<Texture>) -> TextureRef {
        TextureRef {
            texture,
            transform: Affine2::IDENTITY,
            address: None,
            texcoord: 0,
            min_limit: None,
            mag_nearest: false,
        }
    }

    /// Filtered lookup with derivatives (the transform applies to them),
    /// with the sampler's filter limits.
    #[inline]
    pub fn sample_grad(
        &self,
        uv: Vec2,
        g: Gradients,
        default_mode: AddressMode,
        mut f: Filtering,
    ) -> Vec4 {
        let uv = self.transform.transform_point2(uv);
        let m = self.transform.matrix2;
        let g = Gradients {
            dx: m * g.dx,
            dy: m * g.dy,
        };
        let mode = self.address.unwrap_or(default_mode.into());
        if self.mag_nearest || self.min_limit.is_some() {
            let t = &self.texture;
            let size = Vec2::new(t.width as f32, t.height as f32);
            let texels = (g.dx * size).length().max((g.dy * size).length());
            if texels <= 1.0 {
                if self.mag_nearest {
                    return t.sample_nearest(uv, mode);
                }
            } else if let Some(limit) = self.min_limit
                && limit < f.filter
            {
                f.filter = limit;
            }
        }
        self.texture.sample_grad(uv, g, mode, f)
    }
}

/// Decodes an image whose size, taken from its header, fits the memory
/// budget: the decoder's own buffer plus `per_texel` bytes a texel for
/// what is made from it (an RGBA copy, a level, a chain). The image
/// library's allocation limit is the budget too.
/// `path` names the image in errors.
pub fn decode_within<R: std::io::BufRead + std::io::Seek>(
    mut reader: image::ImageReader<R>,
    input: &Input,
    path: &Path,
    what: &str,
    per_texel: u64,
) -> Result<image::DynamicImage, Error> {
    let bad = |e: image::ImageError| Error::asset(path, None, format!("cannot decode {what}: {e}"));
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(input.budget());
    reader.limits(limits);
    let decoder = reader.into_decoder().map_err(bad)?;
    let (w, h) = image::ImageDecoder::dimensions(&decoder);
    let decoded = image::ImageDecoder::total_bytes(&decoder);
    let made = (w as u64 * h as u64).saturating_mul(per_texel);
    input.check_file(
        path,
        &format!("{what} ({w}x{h})"),
        decoded.saturating_add(made),
    )?;
    image::DynamicImage::from_decoder(decoder).map_err(bad)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Texture {
        // 2x2: white, black / black, white (linear data)
        Texture::from_rgba8(
            2,
            2,
            &[[255; 4], [0, 0, 0, 255], [0, 0, 0, 255], [255; 4]],
            false,
        )
    }

    /// RGB texels are stored as the same texels with alpha 255, in every
    /// block, partial ones included.
    #[test]
    fn rgb_is_rgba_made_opaque() {
        for (w, h) in [(5, 3), (8, 4), (1, 1)] {
            let rgb: Vec<[u8; 3]> = (0..w * h)
                .map(|i| [(i * 37) as u8, (i * 11) as u8, (255 - i) as u8])
                .collect();
            let rgba: Vec<[u8; 4]> = rgb.iter().map(|&[r, g, b]| [r, g, b, 255]).collect();
            let (a, b) = (
                Texture::from_rgb8(w, h, &rgb, true),
                Texture::from_rgba8(w, h, &rgba, true),
            );
            assert_eq!(a.base.texels(), b.base.texels(), "{w}x{h}");
            assert_eq!((a.grey, a.has_alpha), (b.grey, b.has_alpha));
            assert!(!a.has_alpha && a.binary_alpha == 1.0);
        }
        let grey = Texture::from_rgb8(2, 1, &[[7, 7, 7], [9, 9, 9]], false);
        assert!(grey.grey);
    }

    #[test]
    fn bilinear_hits_texel_centers_and_blends_between() {
        let t = checker();
        let c = t.sample_bilinear(Vec2::new(0.25, 0.25), AddressMode::Repeat);
        assert!((c.x - 1.0).abs() < 1e-6);
        let mid = t.sample_bilinear(Vec2::new(0.5, 0.25), AddressMode::Clamp);
        assert!((mid.x - 0.5).abs() < 1e-6);
        // The fast path and the general path agree inside the image.
        let big = Texture::from_rgba8(
            3,
            3,
            &(0..9u8)
                .map(|i| [i * 20, i, 255 - i, 255])
                .collect::<Vec<_>>(),
            true,
        );
        for uv in [
            Vec2::new(0.4, 0.6),
            Vec2::new(0.5, 0.5),
            Vec2::new(0.21, 0.7),
        ] {
            let a = big.sample_bilinear(uv, AddressMode::Repeat);
            let b = big.bilinear_wrapped(&big.base, uv, AddressMode::Repeat.into());
            assert!((a - b).abs().max_element() < 1e-5, "{a} {b}");
        }
    }

    #[test]
    fn address_modes_handle_any_finite_coordinate() {
        let t = checker();
        for mode in [
            AddressMode::Repeat,
            AddressMode::Mirror,
            AddressMode::Clamp,
            AddressMode::Border,
        ] {
            for u in [1e9f32, -1e9, 3.75, -0.25, f32::MAX, f32::MIN, 1e30] {
                let c = t.sample_bilinear(Vec2::new(u, 0.3), mode);
                assert!(c.is_finite(), "{mode:?} {u}");
                let c = t.sample_nearest(Vec2::new(u, u), mode);
                assert!(c.is_finite(), "{mode:?} {u}");
            }
            assert_eq!(t.sample_bilinear(Vec2::new(f32::NAN, 0.5), mode), BORDER);
            assert_eq!(
                t.sample_nearest(Vec2::new(0.5, f32::INFINITY), mode),
                BORDER
            );
        }
        // repeat wraps, mirror reflects, clamp holds the edge, border is black
        assert_eq!(address(2.0, 2, AddressMode::Repeat), Some(0));
        assert_eq!(address(-1.0, 2, AddressMode::Repeat), Some(1));
        assert_eq!(address(2.0, 2, AddressMode::Mirror), Some(1));
        assert_eq!(address(-1.0, 2, AddressMode::Mirror), Some(0));
        assert_eq!(address(5.0, 2, AddressMode::Clamp), Some(1));
        assert_eq!(address(2.0, 2, AddressMode::Border), None);
    }
}
