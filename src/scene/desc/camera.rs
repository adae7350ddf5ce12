//! `[[camera]]` with its keys, and `[animation]` with its turntable, as
//! the file writes them.

use serde::Deserialize;

use super::Spanned;
use crate::scene::animation::TurntableTarget;
use crate::scene::camera::Interpolation;

/// The file's spelling of [`crate::scene::camera::Projection`].
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
