//! PNG writer (8-bit sRGB, RGB or RGBA). Fast deflate: a 700x700 frame
//! encodes in a few milliseconds instead of tens, for files about 10% larger.

use std::path::Path;

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};

use super::{Image8, write_atomic};
use crate::error::Error;

/// Writes `img` as a PNG at `path` (to a temporary name, then renamed:
/// a file already there stays whole until the new one is complete).
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

/// Reads a PNG back as 8-bit RGB(A) (for golden comparisons, GIFs and
/// videos): its size from the header first, against the memory budget.
pub fn read(path: &Path) -> Result<Image8, Error> {
    let img = read_any(path)?;
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

/// Any image the image library reads, decoded only when its size (the
/// decode and an 8-bit RGBA copy) fits the default memory budget.
pub fn read_any(path: &Path) -> Result<image::DynamicImage, Error> {
    let input = crate::assets::input::Input::default();
    let (file, _) = input.open(path, None)?;
    let mut reader = image::ImageReader::new(std::io::BufReader::new(file))
        .with_guessed_format()
        .map_err(|e| Error::asset(path, None, e.to_string()))?;
    if reader.format().is_none()
        && let Ok(f) = image::ImageFormat::from_path(path)
    {
        reader.set_format(f);
    }
    crate::assets::texture::decode_within(reader, &input, path, "the image", 4)
}
