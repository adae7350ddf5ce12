//! `--cache DIR`: decoded textures kept between runs. An entry holds level
//! 0 and the whole mip chain in the renderer's block layout
//! (`Texture::to_cache_bytes`), so a warm load reads blocks instead of
//! decoding an image and filtering its levels.
//!
//! Entries are keyed by a BLAKE3 hash of the image's bytes (the file's
//! content, not its name or date), the sRGB flag and this program's
//! version: an edited image, or another softraster, misses. Entries are
//! written to a temporary name and renamed, so a reader never sees half an
//! entry and runs sharing a directory (a farm) do not clash. A damaged or
//! foreign entry is a miss and is rewritten. The cache is opt-in: without
//! it every load (and every load figure in the docs) is cold.

use std::path::{Path, PathBuf};

use super::Texture;
use crate::error::Error;

/// A cache directory.
#[derive(Debug, Clone)]
pub struct TextureCache {
    dir: PathBuf,
}

/// How a texture was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lookup {
    /// Read from the cache.
    Hit,
    /// Decoded; the entry was written (or, with a warning, could not be).
    Miss,
}

impl TextureCache {
    /// The cache in `dir`, created if missing.
    pub fn new(dir: &Path) -> Result<TextureCache, Error> {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::asset(dir, None, format!("cannot create the texture cache: {e}"))
        })?;
        Ok(TextureCache {
            dir: dir.to_path_buf(),
        })
    }

    /// Where the entry for an image with these bytes lives.
    pub fn entry_path(&self, bytes: &[u8], srgb: bool) -> PathBuf {
        let mut h = blake3::Hasher::new();
        h.update(b"softraster texture cache\0");
        h.update(env!("CARGO_PKG_VERSION").as_bytes());
        h.update(&[0, srgb as u8]);
        h.update(bytes);
        let hex = h.finalize().to_hex();
        self.dir.join(format!("{}.srtex", &hex[..32]))
    }

    /// The texture for an image whose bytes are `bytes`: the cache's entry
    /// when it has a valid one, otherwise `decode()`'s texture with its mip
    /// chain built now and written as an entry. A warning (an entry that
    /// could not be written) comes back with it.
    pub fn load(
        &self,
        bytes: &[u8],
        srgb: bool,
        decode: impl FnOnce() -> Result<Texture, Error>,
    ) -> Result<(Texture, Lookup, Option<String>), Error> {
        let path = self.entry_path(bytes, srgb);
        if let Ok(f) = std::fs::File::open(&path)
            && let Ok(meta) = f.metadata()
            && let Some(t) =
                Texture::from_cache_reader(&mut std::io::BufReader::new(f), meta.len(), srgb)
        {
            return Ok((t, Lookup::Hit, None));
        }
        let t = decode()?;
        let chain = crate::assets::mip::build_chain(&t);
        let warning = write_atomically(&path, &t.to_cache_bytes(&chain))
            .err()
            .map(|e| {
                format!(
                    "warning: {}: cannot write the texture cache entry: {e}",
                    path.display()
                )
            });
        let t = t.with_cached_chain(chain);
        Ok((t, Lookup::Miss, warning))
    }
}

/// Writes `bytes` to a temporary file beside `path` (created
/// exclusively, with a random name), then renames it.
fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let (mut file, tmp) = crate::files::temp_file(path).map_err(std::io::Error::other)?;
    let r = file
        .write_all(bytes)
        .and_then(|_| std::fs::rename(&tmp, path));
    if r.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::mip::build_chain;

    fn texture(w: u32, h: u32, srgb: bool) -> Texture {
        let texels: Vec<[u8; 4]> = (0..w * h)
            .map(|i| {
                [
                    (i * 7) as u8,
                    (i * 13) as u8,
                    (i * 29) as u8,
                    255 - (i % 3) as u8,
                ]
            })
            .collect();
        Texture::from_rgba8(w, h, &texels, srgb)
    }

    fn same_levels(a: &Texture, b: &Texture) {
        assert_eq!((a.width, a.height, a.srgb), (b.width, b.height, b.srgb));
        assert_eq!(
            (a.has_alpha, a.grey, a.binary_alpha),
            (b.has_alpha, b.grey, b.binary_alpha)
        );
        for y in 0..a.height {
            for x in 0..a.width {
                assert_eq!(a.base().texel(x, y), b.base().texel(x, y));
            }
        }
    }

    #[test]
    fn an_entry_reads_back_as_the_texture_and_its_chain() {
        for (w, h) in [(1, 1), (5, 3), (16, 16), (37, 8)] {
            let t = texture(w, h, true);
            let chain = build_chain(&t);
            let back = Texture::from_cache_bytes(&t.to_cache_bytes(&chain), true).unwrap();
            same_levels(&t, &back);
            let back_chain = back.mip_chain(|_| panic!("the cached chain was not kept"));
            assert_eq!(back_chain.len(), chain.len());
            for (a, b) in chain.iter().zip(back_chain) {
                assert_eq!((a.width, a.height), (b.width, b.height));
                for y in 0..a.height {
                    for x in 0..a.width {
                        assert_eq!(a.texel(x, y), b.texel(x, y));
                    }
                }
            }
            // The wrong colour space is not this entry.
            assert!(Texture::from_cache_bytes(&t.to_cache_bytes(&chain), false).is_none());
        }
    }

    #[test]
    fn damaged_entries_are_misses_not_panics() {
        let t = texture(9, 6, false);
        let bytes = t.to_cache_bytes(&build_chain(&t));
        // Every truncation, and a longer file.
        for n in 0..bytes.len() {
            assert!(
                Texture::from_cache_bytes(&bytes[..n], false).is_none(),
                "{n}"
            );
        }
        let mut long = bytes.clone();
        long.push(0);
        assert!(Texture::from_cache_bytes(&long, false).is_none());
        // Sizes that do not match the data, including enormous ones (the
        // fuzzer's first find: a size whose byte count overflowed).
        let mut b = bytes.clone();
        let magic = b"softraster-texture-1\n".len();
        b[magic..magic + 8].copy_from_slice(&[0xff; 8]);
        assert!(Texture::from_cache_bytes(&b, false).is_none());
        let fuzzed = [
            &b"softraster-texture-1\n"[..],
            &[
                0x89, 0x50, 0x0e, 0xb9, 0xf2, 0xf5, 0x07, 0xd1, 0, 0, 0, 0x0f,
            ],
            &[
                0x49, 0x48, 0x52, 0x60, 0x26, 0x93, 0x09, 0x2b, 0x48, 0x44, 0x52, 0,
            ],
            &[0x37, 0x07, 0, 0],
        ]
        .concat();
        assert!(Texture::from_cache_bytes(&fuzzed, false).is_none());
        assert!(Texture::from_cache_bytes(&fuzzed, true).is_none());
        let magic = b"softraster-texture-1\n".len();
        for (at, v) in [
            (0, u32::MAX),
            (4, 0),
            (4, 1 << 30),
            (16, 0),
            (16, u32::MAX),
            (20, 0),
            (20, 99),
            (24, 7),
        ] {
            let mut b = bytes.clone();
            b[magic + at..magic + at + 4].copy_from_slice(&v.to_le_bytes());
            assert!(Texture::from_cache_bytes(&b, false).is_none(), "{at} {v}");
        }
    }

    #[test]
    fn a_second_load_hits_and_an_edited_image_misses() {
        let dir =
            std::env::temp_dir().join(format!("softraster-cache-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let cache = TextureCache::new(&dir).unwrap();
        let decode = || Ok(texture(8, 8, true));
        let (a, how, warning) = cache.load(b"image one", true, decode).unwrap();
        assert_eq!((how, warning), (Lookup::Miss, None));
        let (b, how, _) = cache
            .load(b"image one", true, || panic!("a hit must not decode"))
            .unwrap();
        assert_eq!(how, Lookup::Hit);
        same_levels(&a, &b);
        let (_, how, _) = cache.load(b"image two", true, decode).unwrap();
        assert_eq!(how, Lookup::Miss);
        // The same bytes as data (not sRGB) are another entry.
        let (_, how, _) = cache
            .load(b"image one", false, || Ok(texture(8, 8, false)))
            .unwrap();
        assert_eq!(how, Lookup::Miss);
        // A damaged entry is decoded again and rewritten.
        let path = cache.entry_path(b"image one", true);
        std::fs::write(&path, b"softraster-texture-1\ngarbage").unwrap();
        let (_, how, _) = cache.load(b"image one", true, decode).unwrap();
        assert_eq!(how, Lookup::Miss);
        let (_, how, _) = cache.load(b"image one", true, decode).unwrap();
        assert_eq!(how, Lookup::Hit);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
