//! Texture decoding: the input as an image file of any format softraster
//! reads (DDS by its own reader; PNG, JPEG, TGA, BMP, TIFF and HDR by the
//! image crate), decoded as a colour map and as a data map, with its mip
//! chain built; and as a texture-cache entry (`--cache`), while every small
//! image that decodes must come back from its own entry unchanged. Errors
//! are fine; a panic, crash or hang is not.

#![no_main]

use libfuzzer_sys::fuzz_target;
use softraster::assets::texture::Texture;

fuzz_target!(|data: &[u8]| {
    // Images whose header claims more than 4 megapixels decode correctly
    // but take tens of seconds under the sanitizer (a 977-byte JPEG of
    // 65288x254 did; 0.74 s in a release build of the CLI): skipped, so
    // that the timeout finds hangs rather than big pictures.
    if let Ok(r) = image::ImageReader::new(std::io::Cursor::new(data)).with_guessed_format()
        && let Ok((w, h)) = r.into_dimensions()
        && (w as u64) * (h as u64) > 1 << 22
    {
        return;
    }
    let name = std::path::Path::new("fuzz.img");
    for srgb in [true, false] {
        if let Ok(t) = Texture::from_bytes(
            data,
            name,
            srgb,
            &softraster::assets::input::Input::new(256 << 20),
        ) {
            // Keep the work per input small: mip chains of big images
            // would only slow the fuzzer down.
            if (t.width as u64) * (t.height as u64) <= 1 << 16 {
                let chain = softraster::assets::mip::build_chain(&t);
                let entry = t.to_cache_bytes(&chain);
                let back = Texture::from_cache_bytes(&entry, srgb).expect("own cache entry");
                assert_eq!((back.width, back.height), (t.width, t.height));
                for y in 0..t.height {
                    for x in 0..t.width {
                        assert_eq!(back.base().texel(x, y), t.base().texel(x, y));
                    }
                }
                assert_eq!(
                    softraster::assets::mip::build_chain(&back).len(),
                    chain.len()
                );
            }
        }
        if let Some(t) = Texture::from_cache_bytes(data, srgb) {
            let _ = softraster::assets::mip::build_chain(&t);
        }
    }
});
