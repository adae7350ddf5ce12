//! `[environment]` as loaded: the radiance image and how it is placed.
//! Shading prefilters it once per scene (`shade::env`).

use std::sync::Arc;

use crate::assets::environment::EnvImage;

#[derive(Debug, Clone)]
pub struct Environment {
    pub image: Arc<EnvImage>,
    /// Multiplies the radiance (default 1).
    pub intensity: f32,
    /// Degrees about +Y, counter-clockwise seen from above (default 0).
    pub rotation: f32,
}
