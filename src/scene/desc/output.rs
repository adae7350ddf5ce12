//! `[output]` as the file writes it, and `output.background`'s two
//! spellings.

use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};

use super::Spanned;
use super::names::read_vec3;
use crate::scene::settings::{Background, GifDither};

/// `[output]`. Defaults: 800x800, `out/<scene stem>`, `{camera}_{frame:04}`,
/// color PNG on, depth/ao EXR off, no GIF, black background.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputDesc {
    pub width: Option<Spanned<i64>>,
    pub height: Option<Spanned<i64>>,
    pub dir: Option<Spanned<String>>,
    pub name: Option<Spanned<String>>,
    pub color: Option<Spanned<bool>>,
    pub depth: Option<Spanned<bool>>,
    pub ao: Option<Spanned<bool>>,
    pub gif: Option<Spanned<String>>,
    pub gif_delay_ms: Option<Spanned<i64>>,
    /// Extension: "none" (default), "ordered" or "floyd-steinberg".
    pub gif_dither: Option<Spanned<GifDither>>,
    pub background: Option<Spanned<Background>>,
    /// Version 2: how blurred `background = "blurred"` is, 0..1 (0.5).
    pub background_blur: Option<Spanned<f32>>,
    /// Version 2: an H.264 MP4 of each camera's colour frames.
    pub video: Option<Spanned<String>>,
    pub video_fps: Option<Spanned<f32>>,
    /// 1 to 100, or a bitrate string such as "2500k".
    pub video_quality: Option<Spanned<VideoQualityDesc>>,
    /// Version 2: the data passes as EXR.
    pub normal: Option<Spanned<bool>>,
    pub albedo: Option<Spanned<bool>>,
    pub position: Option<Spanned<bool>>,
    pub id: Option<Spanned<bool>>,
}

/// `output.video_quality` as written: a number or a string.
#[derive(Debug, Clone, PartialEq)]
pub enum VideoQualityDesc {
    Number(i64),
    Text(String),
}

impl<'de> Deserialize<'de> for VideoQualityDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = VideoQualityDesc;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a quality from 1 to 100, or a bitrate like \"2500k\"")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<VideoQualityDesc, E> {
                Ok(VideoQualityDesc::Number(v))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<VideoQualityDesc, E> {
                Ok(VideoQualityDesc::Number(v.min(i64::MAX as u64) as i64))
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<VideoQualityDesc, E> {
                Ok(VideoQualityDesc::Text(s.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

impl<'de> Deserialize<'de> for Background {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Background;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "an RGB array like [0.0, 0.0, 0.0], or \"transparent\", \"environment\" or \"blurred\"",
                )
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<Background, E> {
                match s {
                    "transparent" => Ok(Background::Transparent),
                    "environment" => Ok(Background::Environment),
                    // The blur comes from `output.background_blur`.
                    "blurred" => Ok(Background::Blurred(0.5)),
                    _ => Err(E::invalid_value(de::Unexpected::Str(s), &self)),
                }
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Background, A::Error> {
                Ok(Background::Color(read_vec3(seq, &self)?.into()))
            }
        }
        d.deserialize_any(V)
    }
}
