//! softraster: a data-driven CPU batch renderer.
//!
//! Data flows one way: scene file ([`scene::desc`]) -> loaded [`scene::Scene`]
//! -> per-frame draw list ([`render::FrameSetup`]) -> raster pipeline
//! ([`raster`]) and shading ([`shade`]) -> [`render::Frame`] -> writers
//! ([`output`]).

pub mod assets;
pub mod batch;
pub mod color;
pub mod error;
pub mod output;
pub mod procedural;
pub mod raster;
pub mod raytrace;
pub mod render;
pub mod scene;
pub mod shade;
#[cfg(feature = "tools")]
pub mod tools;

pub use error::{Error, Result};
