//! EXR writer for the data buffers: one float32 channel per file (`Z` for
//! depth, `AO` for ambient occlusion), ZIP-compressed (lossless), written
//! atomically like every other output. And the matching reader, for tests
//! and for `compare`.

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, ReadChannels,
    ReadLayers, Text, WritableImage, read,
};

use super::write_atomic;
use crate::error::Error;

/// Writes `values` (row-major from the top, `width * height` of them) as a
/// single float32 channel named `channel`.
pub fn write_channel(
    path: &Path,
    width: u32,
    height: u32,
    channel: &str,
    values: &[f32],
) -> Result<(), Error> {
    let encode = |message: String| Error::Encode {
        path: path.to_path_buf(),
        message,
    };
    if values.len() != width as usize * height as usize {
        return Err(encode(format!(
            "{} values for a {width}x{height} image",
            values.len()
        )));
    }
    let name = Text::new_or_none(channel).ok_or_else(|| encode(format!("channel {channel}")))?;
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(smallvec::smallvec![AnyChannel::new(
            name,
            FlatSamples::F32(values.to_vec()),
        )]),
    );
    let image = Image::from_layer(layer);
    write_atomic(path, |w| {
        image
            .write()
            .to_buffered(w)
            .map_err(|e| encode(e.to_string()))
    })
}

/// Reads channel `channel` of the first layer as float32: (width, height,
/// values row-major from the top).
pub fn read_channel(path: &Path, channel: &str) -> Result<(u32, u32, Vec<f32>), Error> {
    let bad = |message: String| Error::asset(path, None, message);
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| bad(e.to_string()))?;
    let layer = &image.layer_data;
    let size = layer.size;
    let ch = layer
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == channel)
        .ok_or_else(|| bad(format!("no channel `{channel}`")))?;
    let values: Vec<f32> = ch.sample_data.values_as_f32().collect();
    Ok((size.0 as u32, size.1 as u32, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_float32_with_infinity() {
        let dir = std::env::temp_dir().join(format!("softraster-exr-{}", std::process::id()));
        let path = dir.join("z.exr");
        let v = vec![1.0, 2.5e-7, f32::INFINITY, 12345.678, 0.0, 3.0];
        write_channel(&path, 3, 2, "Z", &v).unwrap();
        let (w, h, back) = read_channel(&path, "Z").unwrap();
        assert_eq!((w, h), (3, 2));
        assert_eq!(back, v);
        assert!(read_channel(&path, "AO").is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
