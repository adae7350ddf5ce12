//! `[environment]` as loaded: the radiance image and how it is placed.
//! Shading prefilters it once per scene (`shade::env`).

use std::sync::Arc;

use crate::assets::environment::EnvImage;

/// How the environment's light is integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EnvMethod {
    /// Irradiance harmonics and the split sum, prefiltered once per run.
    #[default]
    Prefiltered,
    /// Monte Carlo with visibility: `samples` environment and `samples`
    /// BRDF directions a point, combined by MIS (the reference).
    Sampled {
        /// Directions of each kind per point (default 64).
        samples: u32,
        /// Bounces between surfaces: 1 (default) counts what a ray that
        /// meets a surface brings from it (`shade::env::bounce`), 0 counts
        /// it as dark.
        bounces: u32,
    },
}

/// `[environment]`: an image lighting the scene from every direction.
#[derive(Debug, Clone)]
pub struct Environment {
    /// How its light is integrated.
    pub method: EnvMethod,
    /// The equirectangular radiance image (linear), less the lights taken
    /// out of it (`lights`, `sun`).
    pub image: Arc<EnvImage>,
    /// The image as read, when lights were taken out of it: what the
    /// background shows.
    pub backdrop: Option<Arc<EnvImage>>,
    /// Multiplies the radiance (default 1).
    pub intensity: f32,
    /// Degrees about +Y, counter-clockwise seen from above (default 0).
    pub rotation: f32,
    /// Prefiltered: width of the sharpest glossy level (default
    /// `DEFAULT_PREFILTER_SIZE`).
    pub prefilter_size: u32,
    /// Prefiltered: how many emissive surfaces light the scene as area
    /// lights (default `DEFAULT_EMITTERS`; sampled: 0, its rays find them).
    pub emitters: u32,
    /// Prefiltered: whether the specular lobes' dominant directions are
    /// traced against the models (`shade::env::reflect`); sampled: false.
    pub reflections: bool,
    /// Prefiltered: when light bounced between surfaces is gathered
    /// (`environment.bounces`, `shade::env::reflect`); sampled: `Off`
    /// (`EnvMethod::Sampled::bounces`).
    pub bounce: Bounces,
}

/// When the prefiltered environment gathers light bounced between
/// surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bounces {
    /// Never (`environment.bounces = 0`; the presets).
    Off,
    /// In every frame (`environment.bounces = 1`).
    On,
    /// In frames whose camera looks into an enclosure: a room, a box
    /// (the default for an image's light, `environment.bounces` unset).
    WhereEnclosed,
}

impl Environment {
    /// The default look's environment: the built-in studio, prefiltered,
    /// its emitters as lights, without traced light (its soft panels keep
    /// the default look's speed).
    pub fn default_look() -> Environment {
        Environment {
            method: EnvMethod::Prefiltered,
            image: EnvImage::studio(),
            backdrop: None,
            intensity: 1.0,
            rotation: 0.0,
            prefilter_size: DEFAULT_PREFILTER_SIZE,
            emitters: DEFAULT_EMITTERS as u32,
            reflections: false,
            bounce: Bounces::Off,
        }
    }
}

/// `environment.emitters` when the scene does not give it and the method
/// is prefiltered.
pub const DEFAULT_EMITTERS: i64 = 4;

/// `environment.prefilter_size` when the scene does not give it.
pub const DEFAULT_PREFILTER_SIZE: u32 = 128;

/// `environment.lights` when the scene does not give it and the method is
/// prefiltered (sampled: 0, its rays find the bright regions themselves).
pub const DEFAULT_ENV_LIGHTS: i64 = 4;
