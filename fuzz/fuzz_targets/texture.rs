//! Texture decoding: the input as an image file of any format softraster
//! reads (DDS by its own reader; PNG, JPEG, TGA, BMP, TIFF and HDR by the
//! image crate), decoded as a colour map and as a data map, with its mip
//! chain built. Errors are fine; a panic, crash or hang is not.

#![no_main]

use libfuzzer_sys::fuzz_target;
use softraster::assets::texture::Texture;

fuzz_target!(|data: &[u8]| {
    let name = std::path::Path::new("fuzz.img");
    for srgb in [true, false] {
        if let Ok(t) = Texture::from_bytes(data, name, srgb) {
            // Keep the work per input small: mip chains of big images
            // would only slow the fuzzer down.
            if (t.width as u64) * (t.height as u64) <= 1 << 16 {
                let _ = softraster::assets::mip::build_chain(&t);
            }
        }
    }
});
