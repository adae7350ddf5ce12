//! The scene file as data: serde structs mirroring `docs/scene-format.md`
//! one to one. Nothing here loads files or knows about rendering; every value
//! that can be out of range keeps its span so that `validate` (and later
//! `build`) can point at it. Unknown keys and wrong types are rejected by serde
//! with the span of the offending key or value.

use std::path::Path;

use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};

use super::animation::TurntableTarget;
use super::camera::Interpolation;
use super::material::NormalSpace;
use super::settings::{
    AddressMode, AoMethod, Background, CullMode, DepthMode, GifDither, ShadingMode, ShadowMethod,
    TextureFilter, Tonemap, VideoQuality,
};
use crate::error::{Error, Location};

mod messages;
mod validate;

use messages::{in_words, source_excerpt};
use validate::*;

pub use toml::Spanned;

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    #[serde(default)]
    pub output: OutputDesc,
    #[serde(default)]
    pub render: RenderDesc,
    #[serde(default)]
    pub ambient: AmbientDesc,
    #[serde(default, rename = "model")]
    pub models: Vec<Spanned<ModelDesc>>,
    #[serde(default, rename = "light")]
    pub lights: Vec<Spanned<LightDesc>>,
    #[serde(default, rename = "camera")]
    pub cameras: Vec<Spanned<CameraDesc>>,
    #[serde(default)]
    pub animation: AnimationDesc,
    /// Version 2: image-based lighting.
    pub environment: Option<Spanned<EnvironmentDesc>>,
    /// Version 2: the shadow catcher.
    #[serde(default)]
    pub ground: GroundDesc,
}

/// `[ground]`. Default: no shadow catcher.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct GroundDesc {
    pub shadow: Option<Spanned<bool>>,
}

/// `[environment]`: an equirectangular HDR image lighting the scene.
/// Defaults: intensity 1, rotation 0.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    /// `.hdr` or `.exr`, relative to the scene file (or `preset`).
    pub path: Option<Spanned<String>>,
    /// A built-in environment: "studio" or "neutral".
    pub preset: Option<Spanned<EnvPreset>>,
    pub intensity: Option<Spanned<f32>>,
    /// Degrees about +Y, counter-clockwise seen from above.
    pub rotation: Option<Spanned<f32>>,
    /// "prefiltered" (default) or "sampled" (the Monte Carlo reference).
    pub method: Option<Spanned<EnvMethodName>>,
    /// Sampled: direction pairs a point (default 64).
    pub samples: Option<Spanned<i64>>,
    /// Prefiltered: width in texels of the sharpest glossy level
    /// (roughness 0.2; the rougher levels get half); default 128.
    pub prefilter_size: Option<Spanned<i64>>,
    /// A shadow-casting directional light from the brightest region.
    pub sun: Option<Spanned<bool>>,
}

/// The built-in environments.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum EnvPreset {
    Studio,
    Neutral,
}

/// The file's names of `[environment] method`.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum EnvMethodName {
    Prefiltered,
    Sampled,
}

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

/// `[ambient]`. Default color 0.03 grey.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct AmbientDesc {
    pub color: Option<Spanned<[f32; 3]>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelDesc {
    pub name: Option<Spanned<String>>,
    pub path: Spanned<String>,
    pub translate: Option<Spanned<[f32; 3]>>,
    pub rotate: Option<Spanned<[f32; 3]>>,
    pub scale: Option<Spanned<Scale>>,
    pub normalize: Option<Spanned<bool>>,
    pub lights: Option<Spanned<bool>>,
    pub cameras: Option<Spanned<bool>>,
    pub material: Option<Spanned<MaterialOverride>>,
    #[serde(default)]
    pub materials: std::collections::BTreeMap<String, Spanned<MaterialOverride>>,
    /// Version 2: a glTF animation to play, by name or index.
    pub animation: Option<Spanned<ClipRef>>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale(pub [f32; 3]);

/// `model.animation`: a clip's name, or its index in the file.
#[derive(Debug, Clone, PartialEq)]
pub enum ClipRef {
    Name(String),
    Index(u64),
}

impl<'de> Deserialize<'de> for ClipRef {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = ClipRef;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an animation's name (a string) or index (an integer from 0)")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<ClipRef, E> {
                Ok(ClipRef::Name(s.to_string()))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<ClipRef, E> {
                u64::try_from(v)
                    .map(ClipRef::Index)
                    .map_err(|_| E::invalid_value(de::Unexpected::Signed(v), &self))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<ClipRef, E> {
                Ok(ClipRef::Index(v))
            }
        }
        d.deserialize_any(V)
    }
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

/// Overrides of MTL values; keys are the MTL keys in lower case.
#[derive(Debug, Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
pub struct MaterialOverride {
    pub ka: Option<Spanned<[f32; 3]>>,
    pub kd: Option<Spanned<[f32; 3]>>,
    pub ks: Option<Spanned<[f32; 3]>>,
    pub ke: Option<Spanned<[f32; 3]>>,
    pub ns: Option<Spanned<f32>>,
    pub ni: Option<Spanned<f32>>,
    pub d: Option<Spanned<f32>>,
    pub illum: Option<Spanned<i64>>,
    pub map_ka: Option<Spanned<String>>,
    pub map_kd: Option<Spanned<String>>,
    pub map_ks: Option<Spanned<String>>,
    pub map_ke: Option<Spanned<String>>,
    pub map_ns: Option<Spanned<String>>,
    pub map_d: Option<Spanned<String>>,
    pub map_bump: Option<Spanned<String>>,
    pub norm: Option<Spanned<String>>,
    pub disp: Option<Spanned<String>>,
    pub bump_scale: Option<Spanned<f32>>,
    pub normal_space: Option<Spanned<NormalSpace>>,
    /// Extension: "opaque" | "mask" | "blend" (default: from d, map_d and
    /// the alpha of map_Kd).
    pub alpha_mode: Option<Spanned<AlphaModeDesc>>,
    /// Extension: opacity below which a "mask" pixel is dropped (0.5).
    pub alpha_cutoff: Option<Spanned<f32>>,
    /// Extension: world units per unit of `disp` height (default 1, or the
    /// MTL's `-mm` gain).
    pub disp_scale: Option<Spanned<f32>>,
    /// Extension (pbr shading): metallic factor in [0, 1].
    pub metallic: Option<Spanned<f32>>,
    /// Extension (pbr shading): perceptual roughness in [0, 1].
    pub roughness: Option<Spanned<f32>>,
}

/// The file's spelling of [`super::material::AlphaMode`].
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum AlphaModeDesc {
    Opaque,
    Mask,
    Blend,
}

/// The file's spelling of [`super::light::LightKind`].
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum LightKind {
    Point,
    Directional,
    Spot,
}

/// `[[light]]`. Defaults: point light at the origin, intensity 10, white,
/// directional irradiance 1 travelling down -Y, spot cone 20/30 degrees,
/// no shadows.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    pub kind: Option<Spanned<LightKind>>,
    pub position: Option<Spanned<[f32; 3]>>,
    pub direction: Option<Spanned<[f32; 3]>>,
    pub intensity: Option<Spanned<f32>>,
    pub irradiance: Option<Spanned<f32>>,
    pub color: Option<Spanned<[f32; 3]>>,
    pub shadows: Option<Spanned<bool>>,
    pub inner_angle: Option<Spanned<f32>>,
    pub outer_angle: Option<Spanned<f32>>,
    /// Point and spot: the distance where the light ends (the
    /// KHR_lights_punctual window); none: unlimited.
    pub range: Option<Spanned<f32>>,
}

/// The file's spelling of [`super::camera::Projection`].
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Projection {
    Perspective,
    Orthographic,
}

/// `[[camera]]`. Defaults: framed on the bounding sphere of all models from
/// +Z, up +Y, fov 45, near/far fitted to the bounding sphere.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    pub name: Option<Spanned<String>>,
    pub eye: Option<Spanned<[f32; 3]>>,
    pub target: Option<Spanned<[f32; 3]>>,
    pub up: Option<Spanned<[f32; 3]>>,
    pub fov: Option<Spanned<f32>>,
    pub projection: Option<Spanned<Projection>>,
    pub height: Option<Spanned<f32>>,
    pub near: Option<Spanned<f32>>,
    pub far: Option<Spanned<f32>>,
    /// Version 2, fitted cameras: degrees above the horizon (20).
    pub elevation: Option<Spanned<f32>>,
    /// Version 2, fitted cameras: degrees about +Y, 0 = from +Z.
    pub azimuth: Option<Spanned<f32>>,
    /// Version 2: a camera path's keys (`[[camera.keys]]`).
    #[serde(default)]
    pub keys: Vec<Spanned<CameraKeyDesc>>,
    /// Version 2: "smooth" (Catmull-Rom, the default) or "linear".
    pub interpolation: Option<Spanned<Interpolation>>,
}

/// `[[camera.keys]]`: where the camera is at a frame.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKeyDesc {
    pub frame: Spanned<i64>,
    pub eye: Spanned<[f32; 3]>,
    pub target: Spanned<[f32; 3]>,
    pub up: Option<Spanned<[f32; 3]>>,
    pub fov: Option<Spanned<f32>>,
}

/// `[animation]`. Default: one frame, no turntable.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct AnimationDesc {
    pub frames: Option<Spanned<i64>>,
    /// Version 2: frame i is at time i / fps (24).
    pub fps: Option<Spanned<f32>>,
    pub turntable: Option<Spanned<TurntableDesc>>,
}

/// Defaults: axis +Y, 360 degrees, rotate the models.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct TurntableDesc {
    pub axis: Option<Spanned<[f32; 3]>>,
    pub degrees: Option<Spanned<f32>>,
    pub rotate: Option<Spanned<TurntableTarget>>,
    /// Version 2: degrees above the plane of the turn (`rotate = "camera"`).
    pub elevation: Option<Spanned<f32>>,
}

// ---------------------------------------------------------------------------
// The file's names of the renderer's values: the spelling lives here, the
// types with their stages (`scene::settings` and what it re-exports).

/// `Deserialize` for a renderer type from the names the file uses for its
/// values; anything else is "unknown variant `x`, expected one of ...".
macro_rules! file_names {
    ($t:ident { $($name:literal => $v:ident),+ $(,)? }) => {
        impl<'de> Deserialize<'de> for $t {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<$t, D::Error> {
                const NAMES: &[&str] = &[$($name),+];
                let s = String::deserialize(d)?;
                match s.as_str() {
                    $($name => Ok($t::$v),)+
                    other => Err(de::Error::unknown_variant(other, NAMES)),
                }
            }
        }
    };
}

file_names!(ShadingMode {
    "auto" => Auto, "blinn-phong" => BlinnPhong, "pbr" => Pbr, "flat" => Flat,
    "gouraud" => Gouraud, "unlit" => Unlit, "normals" => Normals, "depth" => Depth,
    "wireframe" => Wireframe,
});
file_names!(TextureFilter {
    "nearest" => Nearest, "bilinear" => Bilinear, "trilinear" => Trilinear,
    "anisotropic" => Anisotropic,
});
file_names!(AddressMode {
    "repeat" => Repeat, "mirror" => Mirror, "clamp" => Clamp, "border" => Border,
});
file_names!(CullMode { "auto" => Auto, "back" => Back, "front" => Front, "none" => None });
file_names!(DepthMode { "reverse-z" => ReverseZ, "standard" => Standard });
file_names!(ShadowMethod {
    "off" => Off, "hard" => Hard, "pcf" => Pcf, "raytraced" => Raytraced,
});
// The screen-space method is GTAO; the file calls it `ssao`.
file_names!(AoMethod { "off" => Off, "ssao" => Gtao, "raytraced" => Raytraced });
file_names!(Tonemap {
    "clamp" => Clamp, "reinhard" => Reinhard, "aces" => Aces, "pbr-neutral" => PbrNeutral,
    "agx" => Agx,
});
file_names!(GifDither {
    "none" => None, "ordered" => Ordered, "floyd-steinberg" => FloydSteinberg,
});
file_names!(NormalSpace { "tangent" => Tangent, "object" => Object });
file_names!(TurntableTarget { "models" => Models, "camera" => Camera });

// ---------------------------------------------------------------------------
// Values with two spellings.

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

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Scale;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array [x, y, z]")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Scale, E> {
                Ok(Scale([v as f32; 3]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Scale, E> {
                Ok(Scale([v as f32; 3]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Scale, E> {
                Ok(Scale([v as f32; 3]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Scale, A::Error> {
                Ok(Scale(read_vec3(seq, &self)?))
            }
        }
        d.deserialize_any(V)
    }
}

fn read_vec3<'de, A: SeqAccess<'de>>(
    mut seq: A,
    exp: &dyn de::Expected,
) -> Result<[f32; 3], A::Error> {
    let mut out = [0.0f32; 3];
    for (i, slot) in out.iter_mut().enumerate() {
        *slot = seq
            .next_element::<f32>()?
            .ok_or_else(|| de::Error::invalid_length(i, exp))?;
    }
    if seq.next_element::<de::IgnoredAny>()?.is_some() {
        return Err(de::Error::invalid_length(4, exp));
    }
    Ok(out)
}

file_names!(Interpolation {
    "smooth" => Smooth,
    "linear" => Linear,
});

// ---------------------------------------------------------------------------
// Parsing and validation.

impl SceneDesc {
    /// Parses scene text. `file` is only used to name locations in errors.
    pub fn parse(file: &Path, text: &str) -> Result<SceneDesc, Error> {
        let desc: SceneDesc = toml::from_str(text).map_err(|e| {
            let offset = e.span().map(|s| s.start).unwrap_or(0);
            Error::Scene {
                location: Location::from_offset(file, text, offset),
                message: format!(
                    "{}{}",
                    in_words(e.message().trim_end(), text, offset),
                    source_excerpt(text, offset)
                ),
            }
        })?;
        desc.validate(&Ctx { file, text })?;
        Ok(desc)
    }

    fn validate(&self, c: &Ctx) -> Result<(), Error> {
        if self.models.is_empty() {
            return Err(Error::SceneGlobal {
                file: c.file.to_path_buf(),
                message: "the scene has no [[model]]: at least one with a `path` is required"
                    .into(),
            });
        }
        let o = &self.output;
        c.int_range(&o.width, "output.width", 1, 16384)?;
        c.int_range(&o.height, "output.height", 1, 16384)?;
        c.int_range(&o.gif_delay_ms, "output.gif_delay_ms", 10, 655_350)?;
        if let Some(bg) = &o.background
            && let Background::Color(col) = bg.get_ref()
        {
            c.color(bg.span(), &col.to_array(), "output.background")?;
        }
        c.float_range(&o.background_blur, "output.background_blur", 0.0, 1.0)?;
        if let Some(bg) = &o.background
            && matches!(
                bg.get_ref(),
                Background::Environment | Background::Blurred(_)
            )
            && self.environment.is_none()
        {
            return Err(c.err(
                bg.span(),
                "output.background shows the environment: the scene needs an [environment]",
            ));
        }
        validate_video(c, o)?;
        if let Some(n) = &o.name
            && n.get_ref().trim().is_empty()
        {
            return Err(c.err(n.span(), "output.name must not be empty"));
        }
        let r = &self.render;
        if let Some(m) = &r.msaa
            && ![1, 2, 4, 8, 16].contains(m.get_ref())
        {
            return Err(c.err(
                m.span(),
                format!(
                    "render.msaa = {}: expected one of 1, 2, 4, 8, 16",
                    m.get_ref()
                ),
            ));
        }
        c.int_range(&r.ssaa, "render.ssaa", 1, 16)?;
        c.float_range(&r.point_size, "render.point_size", 0.5, 256.0)?;
        c.float_range(&r.line_width, "render.line_width", 0.25, 256.0)?;
        if let Some(k) = &r.ssaa {
            let side = get_i64(&o.width, 800).max(get_i64(&o.height, 800));
            if side * k.get_ref() > 16384 {
                return Err(c.err(
                    k.span(),
                    format!(
                        "render.ssaa = {}: the supersampled frame ({} px per side) may not exceed 16384",
                        k.get_ref(),
                        side * k.get_ref()
                    ),
                ));
            }
        }
        c.int_range(&r.max_anisotropy, "render.max_anisotropy", 1, 16)?;
        c.int_range(&r.shadow_map_size, "render.shadow_map_size", 16, 16384)?;
        if let Some(e) = &r.exposure
            && let Exposure::Stops(x) = e.get_ref()
            && !(x.is_finite() && (-64.0..=64.0).contains(x))
        {
            return Err(c.err(
                e.span(),
                format!("render.exposure = {x}: expected a number from -64 to 64, or \"auto\""),
            ));
        }
        if let Some(ao) = &r.ao {
            let ao = ao.get_ref();
            c.float_range(&ao.radius, "render.ao.radius", f32::MIN_POSITIVE, 1e9)?;
            c.int_range(&ao.samples, "render.ao.samples", 1, 4096)?;
        }
        if let Some(b) = &r.shadow_bias {
            let b = b.get_ref();
            for (v, key) in [
                (&b.constant, "render.shadow_bias.constant"),
                (&b.slope, "render.shadow_bias.slope"),
                (&b.normal, "render.shadow_bias.normal"),
            ] {
                c.float_range(v, key, 0.0, 1000.0)?;
            }
        }
        if let Some(a) = &self.ambient.color {
            c.color(a.span(), a.get_ref(), "ambient.color")?;
        }
        for m in &self.models {
            validate_model(c, m.get_ref())?;
        }
        for l in &self.lights {
            validate_light(c, l.get_ref())?;
        }
        for cam in &self.cameras {
            validate_camera(c, cam.get_ref())?;
        }
        if let Some(e) = &self.environment {
            validate_environment(c, e)?;
        }
        let a = &self.animation;
        c.int_range(&a.frames, "animation.frames", 1, 1_000_000)?;
        c.float_range(&a.fps, "animation.fps", 0.001, 1000.0)?;
        if let Some(t) = &a.turntable {
            let t = t.get_ref();
            c.finite(&t.degrees, "animation.turntable.degrees")?;
            c.direction(&t.axis, "animation.turntable.axis")?;
            c.float_range(&t.elevation, "animation.turntable.elevation", -89.0, 89.0)?;
        }
        Ok(())
    }
}

/// Validation context: turns spans into located errors.
pub struct Ctx<'a> {
    pub file: &'a Path,
    pub text: &'a str,
}

impl Ctx<'_> {
    pub fn err(&self, span: std::ops::Range<usize>, message: impl Into<String>) -> Error {
        Error::Scene {
            location: Location::from_offset(self.file, self.text, span.start),
            message: format!(
                "{}{}",
                message.into(),
                source_excerpt(self.text, span.start)
            ),
        }
    }

    pub fn location(&self, span: std::ops::Range<usize>) -> Location {
        Location::from_offset(self.file, self.text, span.start)
    }

    fn int_range(
        &self,
        v: &Option<Spanned<i64>>,
        key: &str,
        lo: i64,
        hi: i64,
    ) -> Result<(), Error> {
        if let Some(v) = v
            && !(lo..=hi).contains(v.get_ref())
        {
            return Err(self.err(
                v.span(),
                format!(
                    "{key} = {}: expected an integer from {lo} to {hi}",
                    v.get_ref()
                ),
            ));
        }
        Ok(())
    }

    fn float_range(
        &self,
        v: &Option<Spanned<f32>>,
        key: &str,
        lo: f32,
        hi: f32,
    ) -> Result<(), Error> {
        if let Some(v) = v {
            let x = *v.get_ref();
            if !(x.is_finite() && x >= lo && x <= hi) {
                return Err(self.err(
                    v.span(),
                    format!("{key} = {x}: expected a number from {lo} to {hi}"),
                ));
            }
        }
        Ok(())
    }

    fn finite(&self, v: &Option<Spanned<f32>>, key: &str) -> Result<(), Error> {
        self.float_range(v, key, f32::MIN, f32::MAX)
    }

    fn vec3(&self, v: &Option<Spanned<[f32; 3]>>, key: &str) -> Result<(), Error> {
        if let Some(v) = v
            && v.get_ref().iter().any(|x| !x.is_finite())
        {
            return Err(self.err(v.span(), format!("{key}: expected three finite numbers")));
        }
        Ok(())
    }

    fn direction(&self, v: &Option<Spanned<[f32; 3]>>, key: &str) -> Result<(), Error> {
        self.vec3(v, key)?;
        if let Some(v) = v
            && v.get_ref().iter().all(|x| *x == 0.0)
        {
            return Err(self.err(v.span(), format!("{key}: expected a non-zero direction")));
        }
        Ok(())
    }

    fn color(&self, span: std::ops::Range<usize>, c: &[f32; 3], key: &str) -> Result<(), Error> {
        if c.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(self.err(
                span,
                format!("{key}: expected three finite, non-negative linear RGB values"),
            ));
        }
        Ok(())
    }
}

/// The offending line of the scene, printed under a message, compiler style.
#[cfg(test)]
mod tests {
    use super::*;

    fn parse(t: &str) -> Result<SceneDesc, Error> {
        SceneDesc::parse(Path::new("t.toml"), t)
    }

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("1048576"), Ok(1 << 20));
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("512MiB"), Ok(512 << 20));
        assert_eq!(parse_size("1.5G"), Ok(3 << 29));
        assert_eq!(parse_size("2 gb"), Ok(2 << 30));
        assert!(parse_size("lots").is_err());
        assert!(parse_size("5X").is_err());
        assert!(parse_size("0").is_err());
        let m = "[[model]]\npath = \"a.obj\"\n";
        let s = parse(&format!("{m}[render]\nmax_memory = \"64M\"\n")).unwrap();
        assert_eq!(s.render.max_memory.map(|m| m.get_ref().0), Some(64 << 20));
        let e = parse(&format!("{m}[render]\nmax_memory = \"a lot\"\n")).unwrap_err();
        assert!(e.to_string().contains("is not a size"), "{e}");
    }

    #[test]
    fn smallest_scene_parses() {
        let d = parse("[[model]]\npath = \"a.obj\"\n").unwrap();
        assert_eq!(d.models.len(), 1);
        assert!(d.cameras.is_empty());
    }

    #[test]
    fn full_example_of_the_contract_parses() {
        let d = parse(include_str!("../../../tests/data/full_example.toml")).unwrap();
        assert_eq!(d.lights.len(), 3);
        assert_eq!(
            d.models[0].get_ref().materials.len(),
            1,
            "per-material override table"
        );
    }

    #[test]
    fn unknown_key_names_line_and_column() {
        let e = parse("[[model]]\npath = \"a.obj\"\n[render]\nmsa = 4\n").unwrap_err();
        let s = e.to_string();
        assert!(s.starts_with("t.toml:4:1:"), "{s}");
        assert!(s.contains("msa"), "{s}");
    }

    #[test]
    fn wrong_type_and_range_are_located() {
        let e = parse("[[model]]\npath = \"a.obj\"\n[output]\nwidth = \"big\"\n").unwrap_err();
        assert!(e.to_string().starts_with("t.toml:4:9:"), "{e}");
        let e = parse("[[model]]\npath = \"a.obj\"\n[render]\nmsaa = 3\n").unwrap_err();
        assert!(
            e.to_string().contains("expected one of 1, 2, 4, 8, 16"),
            "{e}"
        );
        assert!(e.to_string().starts_with("t.toml:4:8:"), "{e}");
        let e = parse("[[model]]\npath = \"a.obj\"\n[render]\nshading = \"toon\"\n").unwrap_err();
        assert!(e.to_string().contains("blinn-phong"), "{e}");
    }

    #[test]
    fn missing_model_is_an_error() {
        let e = parse("[output]\nwidth = 10\n").unwrap_err();
        assert!(e.to_string().contains("[[model]]"));
        assert_eq!(e.exit_code(), 2);
    }

    #[test]
    fn scale_and_background_accept_both_spellings() {
        let d = parse(
            "[[model]]\npath = \"a.obj\"\nscale = 2\n[output]\nbackground = \"transparent\"\n",
        )
        .unwrap();
        assert_eq!(
            d.models[0].get_ref().scale.as_ref().unwrap().get_ref().0,
            [2.0; 3]
        );
        assert_eq!(
            *d.output.background.as_ref().unwrap().get_ref(),
            Background::Transparent
        );
        let d = parse("[[model]]\npath = \"a.obj\"\nscale = [1, 2, 3.5]\n").unwrap();
        assert_eq!(
            d.models[0].get_ref().scale.as_ref().unwrap().get_ref().0,
            [1.0, 2.0, 3.5]
        );
        assert!(parse("[[model]]\npath = \"a.obj\"\nscale = [1, 2]\n").is_err());
        assert!(parse("[[model]]\npath = \"a.obj\"\nscale = 0\n").is_err());
    }

    #[test]
    fn spot_cone_must_be_ordered() {
        let e = parse(
            "[[model]]\npath = \"a.obj\"\n[[light]]\nkind = \"spot\"\ninner_angle = 40\nouter_angle = 30\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("inner_angle"), "{e}");
    }

    #[test]
    fn a_light_range_is_a_positive_distance_of_a_point_or_spot() {
        let light =
            |body: &str| parse(&format!("[[model]]\npath = \"a.obj\"\n[[light]]\n{body}\n"));
        let d = light("kind = \"spot\"\nrange = 2.5").unwrap();
        let r = d.lights[0].get_ref().range.as_ref().map(|r| *r.get_ref());
        assert_eq!(r, Some(2.5));
        assert!(light("range = 3").is_ok(), "a point light by default");
        for (body, says) in [
            ("range = 0", "light.range = 0"),
            ("range = -1", "light.range = -1"),
            ("range = inf", "light.range = inf"),
            ("kind = \"directional\"\nrange = 2", "not directional"),
        ] {
            let e = light(body).unwrap_err().to_string();
            // The file, and the line of `range`.
            let line = format!("t.toml:{}:", 3 + body.lines().count());
            assert!(e.contains(says) && e.starts_with(&line), "{body}: {e}");
        }
    }
}
