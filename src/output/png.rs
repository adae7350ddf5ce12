//! PNG writer (8-bit sRGB, RGB or RGBA). Fast deflate: a 700x700 frame
//! encodes in a few milliseconds instead of tens, for files about 10% larger.

use std::path::Path;

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};

use super::{Image8, write_atomic};
use crate::error::Error;

pub fn write(path: &Path, img: &Image8) -> Result<(), Error> {
    write_atomic(path, |w| {
        let enc = PngEncoder::new_with_quality(w, CompressionType::Fast, FilterType::Adaptive);
        let color = if img.channels == 4 {
            ExtendedColorType::Rgba8
        } else {
            ExtendedColorType::Rgb8
        };
        enc.write_image(&img.data, img.width, img.height, color)
            .map_err(|e| Error::Encode {
                path: path.to_path_buf(),
                message: e.to_string(),
            })
    })
}

/// Reads a PNG back as 8-bit RGB(A) (for golden comparisons).
pub fn read(path: &Path) -> Result<Image8, Error> {
    let img = image::open(path).map_err(|e| Error::asset(path, None, e.to_string()))?;
    let (channels, data) = if img.color().has_alpha() {
        (4, img.to_rgba8().into_raw())
    } else {
        (3, img.to_rgb8().into_raw())
    };
    Ok(Image8 {
        width: img.width(),
        height: img.height(),
        channels,
        data,
    })
}
