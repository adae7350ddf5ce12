//! `[environment]`, `[ground]` and `[ambient]` as the file writes them.

use serde::Deserialize;

use super::Spanned;

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
    /// Bounces of light between surfaces, 0 or 1 (sampled: default 1;
    /// prefiltered: default 0).
    pub bounces: Option<Spanned<i64>>,
    /// Prefiltered: width in texels of the sharpest glossy level
    /// (roughness 0.2; the rougher levels get half); default 128.
    pub prefilter_size: Option<Spanned<i64>>,
    /// A shadow-casting directional light from the brightest region.
    pub sun: Option<Spanned<bool>>,
    /// How many compact bright regions become shadow-casting lights
    /// (default 4 prefiltered, 0 sampled).
    pub lights: Option<Spanned<i64>>,
    /// How many emissive surfaces become shadow-casting area lights
    /// (default 4 prefiltered; sampled lights with all of them).
    pub emitters: Option<Spanned<i64>>,
    /// Prefiltered: trace the specular lobes' reflections of the models
    /// (default true with an image, false with a preset).
    pub reflections: Option<Spanned<bool>>,
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

/// `[ambient]`. Default color 0.03 grey.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct AmbientDesc {
    pub color: Option<Spanned<[f32; 3]>>,
}
