//! `[[light]]` as the file writes it.

use serde::Deserialize;

use super::Spanned;

/// The file's spelling of [`crate::scene::light::LightKind`].
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
