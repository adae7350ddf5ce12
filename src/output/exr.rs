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
    values: Vec<f32>,
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
            FlatSamples::F32(values),
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

/// One channel's samples for `write_channels`.
pub enum Samples {
    /// 32-bit float samples.
    F32(Vec<f32>),
    /// 32-bit unsigned samples (ids).
    U32(Vec<u32>),
}

/// Writes several channels (name, samples; each `width * height` values,
/// row-major from the top) into one layer.
pub fn write_channels(
    path: &Path,
    width: u32,
    height: u32,
    channels: Vec<(&str, Samples)>,
) -> Result<(), Error> {
    let encode = |message: String| Error::Encode {
        path: path.to_path_buf(),
        message,
    };
    let n = width as usize * height as usize;
    let mut list = smallvec::SmallVec::new();
    for (name, samples) in channels {
        let text = Text::new_or_none(name).ok_or_else(|| encode(format!("channel {name}")))?;
        let (len, flat) = match samples {
            Samples::F32(v) => (v.len(), FlatSamples::F32(v)),
            Samples::U32(v) => (v.len(), FlatSamples::U32(v)),
        };
        if len != n {
            return Err(encode(format!(
                "{len} values in {name} for a {width}x{height} image"
            )));
        }
        list.push(AnyChannel::new(text, flat));
    }
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let image = Image::from_layer(layer);
    write_atomic(path, |w| {
        image
            .write()
            .to_buffered(w)
            .map_err(|e| encode(e.to_string()))
    })
}

/// Channel `channel` of the first layer: (width, height, samples).
fn read_samples(path: &Path, channel: &str) -> Result<(u32, u32, FlatSamples), Error> {
    let bad = |message: String| Error::asset(path, None, message);
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| bad(e.to_string()))?;
    let layer = image.layer_data;
    let size = layer.size;
    let ch = layer
        .channel_data
        .list
        .into_iter()
        .find(|c| c.name.to_string() == channel)
        .ok_or_else(|| bad(format!("no channel `{channel}`")))?;
    Ok((size.0 as u32, size.1 as u32, ch.sample_data))
}

/// Reads channel `channel` of the first layer as unsigned integers (a
/// UINT channel exactly; float channels rounded).
pub fn read_channel_u32(path: &Path, channel: &str) -> Result<(u32, u32, Vec<u32>), Error> {
    let (w, h, samples) = read_samples(path, channel)?;
    let values = match samples {
        FlatSamples::U32(v) => v,
        other => other.values_as_f32().map(|x| x.round() as u32).collect(),
    };
    Ok((w, h, values))
}

/// Reads channel `channel` of the first layer as float32: (width, height,
/// values row-major from the top).
pub fn read_channel(path: &Path, channel: &str) -> Result<(u32, u32, Vec<f32>), Error> {
    let (w, h, samples) = read_samples(path, channel)?;
    Ok((w, h, samples.values_as_f32().collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_float32_with_infinity() {
        let dir = std::env::temp_dir().join(format!("softraster-exr-{}", std::process::id()));
        let path = dir.join("z.exr");
        let v = vec![1.0, 2.5e-7, f32::INFINITY, 12345.678, 0.0, 3.0];
        write_channel(&path, 3, 2, "Z", v.clone()).unwrap();
        let (w, h, back) = read_channel(&path, "Z").unwrap();
        assert_eq!((w, h), (3, 2));
        assert_eq!(back, v);
        assert!(read_channel(&path, "AO").is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
