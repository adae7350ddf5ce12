//! `[render]` as the file writes it: its settings, shadow bias, AO,
//! memory sizes and `render.exposure`'s two spellings.

use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};

use super::Spanned;
use crate::scene::settings::{
    AddressMode, AoMethod, CullMode, DepthMode, ShadingMode, ShadowMethod, TextureFilter, Tonemap,
};

/// `[render]`. The defaults are `scene::assemble::settings`'s (and the
/// format's documentation).
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RenderDesc {
    pub shading: Option<Spanned<ShadingMode>>,
    pub msaa: Option<Spanned<i64>>,
    /// Extension: supersampling, the frame rendered at this many times the
    /// output size per axis and box-filtered down (default 1).
    pub ssaa: Option<Spanned<i64>>,
    pub texture_filter: Option<Spanned<TextureFilter>>,
    pub max_anisotropy: Option<Spanned<i64>>,
    /// Extension: widen metallic-roughness lobes by how much the normal
    /// map turns across a pixel (default true).
    pub specular_aa: Option<Spanned<bool>>,
    pub address: Option<Spanned<AddressMode>>,
    pub cull: Option<Spanned<CullMode>>,
    pub depth: Option<Spanned<DepthMode>>,
    pub shadows: Option<Spanned<ShadowMethod>>,
    pub shadow_map_size: Option<Spanned<i64>>,
    /// Extension: shadow-map bias in texels.
    pub shadow_bias: Option<Spanned<ShadowBiasDesc>>,
    pub ao: Option<Spanned<AoDesc>>,
    /// Extension: refuse to render when the memory estimate exceeds this
    /// (`"512M"`, `"2G"`, or bytes).
    pub max_memory: Option<Spanned<MemorySize>>,
    /// Version 3: every read stays inside the scene's folder (no `..`,
    /// absolute path or URI scheme); `--sandbox` sets it too.
    pub sandbox: Option<Spanned<bool>>,
    /// Points (OBJ `p`, glTF points) are discs this many output pixels
    /// across (default 4).
    pub point_size: Option<Spanned<f32>>,
    /// Lines (OBJ `l`, glTF lines) are this many output pixels wide
    /// (default 1.5).
    pub line_width: Option<Spanned<f32>>,
    pub tonemap: Option<Spanned<Tonemap>>,
    /// Stops, or "auto" (version 2).
    pub exposure: Option<Spanned<Exposure>>,
}

/// `render.shadow_bias` (extension), in shadow-map texels at the receiver.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct ShadowBiasDesc {
    pub constant: Option<Spanned<f32>>,
    pub slope: Option<Spanned<f32>>,
    pub normal: Option<Spanned<f32>>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct AoDesc {
    pub method: Option<Spanned<AoMethod>>,
    pub radius: Option<Spanned<f32>>,
    pub samples: Option<Spanned<i64>>,
}

/// A memory size in bytes, written `"512M"`, `"1.5G"` or as a number of
/// bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemorySize(pub u64);

impl<'de> Deserialize<'de> for MemorySize {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = MemorySize;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a size like \"512M\" or \"2G\", or a number of bytes")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<MemorySize, E> {
                parse_size(s).map(MemorySize).map_err(E::custom)
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<MemorySize, E> {
                u64::try_from(v)
                    .ok()
                    .filter(|v| *v > 0)
                    .map(MemorySize)
                    .ok_or_else(|| E::invalid_value(de::Unexpected::Signed(v), &self))
            }
        }
        d.deserialize_any(V)
    }
}

/// Parses a memory size: bytes, or a number with K, M, G or T (powers of 1024;
/// `KiB`, `MB` and the like read the same), e.g. `512M`, `1.5G`.
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let v: f64 = num
        .parse()
        .map_err(|_| format!("`{s}` is not a size: expected e.g. 512M, 2G or 1048576"))?;
    let unit = unit.trim().to_ascii_uppercase();
    let shift = match unit.trim_end_matches("IB").trim_end_matches('B') {
        "" => 0,
        "K" => 10,
        "M" => 20,
        "G" => 30,
        "T" => 40,
        _ => return Err(format!("`{s}`: unknown unit `{unit}` (use K, M, G or T)")),
    };
    let bytes = v * (1u64 << shift) as f64;
    if !bytes.is_finite() || bytes < 1.0 || bytes > u64::MAX as f64 {
        return Err(format!("`{s}` is not a usable size"));
    }
    Ok(bytes as u64)
}

/// `render.exposure`: stops, or "auto".
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exposure {
    Stops(f32),
    Auto,
}

impl<'de> Deserialize<'de> for Exposure {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Exposure;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number of stops or the string \"auto\"")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<Exposure, E> {
                match s {
                    "auto" => Ok(Exposure::Auto),
                    _ => Err(E::invalid_value(de::Unexpected::Str(s), &self)),
                }
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Exposure, E> {
                Ok(Exposure::Stops(v as f32))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Exposure, E> {
                Ok(Exposure::Stops(v as f32))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Exposure, E> {
                Ok(Exposure::Stops(v as f32))
            }
        }
        d.deserialize_any(V)
    }
}
