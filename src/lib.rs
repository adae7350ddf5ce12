//! softraster: a data-driven CPU batch renderer.
//!
//! Data flows one way: scene file ([`scene::desc`]) -> loaded
//! [`scene::Scene`] ([`scene::assemble`]) -> per-frame draw list
//! ([`render::FrameSetup`]) -> the frame's passes ([`render`]: vertex,
//! shadows, geometry through [`raster`], visibility, AO and shading through
//! [`shade`]) -> [`render::Frame`] -> writers ([`output`]), driven frame by
//! frame by [`batch`]. [`color`], [`error`], [`files`], [`powers`], [`raster`], [`raytrace`] and
//! [`simd`] are the ground floor: they import nothing of the layers above.
//!
//! This package is the renderer alone. The `softraster` binary, the tools
//! that measure the renderer (bench, chart, accuracy tables, image
//! comparison) and the showcase's asset generator are the workspace's
//! `softraster-cli` package (`cli/`).
//!
//! Rendering a frame from Rust:
//!
//! ```
//! use softraster::output::{png, resolve};
//! use softraster::render::{Frame, Renderer, Shot};
//! use softraster::scene::{LoadOptions, Scene};
//!
//! # fn main() -> Result<(), softraster::Error> {
//! let dir = std::env::temp_dir().join(format!("softraster-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! std::fs::write(dir.join("tri.obj"), "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n").unwrap();
//! let text = "[output]\nwidth = 64\nheight = 64\n[[model]]\npath = \"tri.obj\"\n";
//! let scene = Scene::from_text(&dir.join("tri.toml"), text, &LoadOptions::default())?;
//!
//! // The renderer borrows the scene and keeps BVHs and shadow maps
//! // across its frames: make it once.
//! let renderer = Renderer::new(&scene);
//! let mut frame = Frame::new(0, 0);
//! renderer.render(Shot::new(0, 0), &mut frame)?; // camera 0, frame 0
//! assert!(frame.depth.iter().any(|d| d.is_finite()));
//!
//! // Tone map and encode as the scene says, and write it.
//! let image = resolve(&frame, &scene.settings);
//! png::write(&dir.join("tri.png"), &image)?;
//! # Ok(())
//! # }
//! ```

pub mod assets;
pub mod batch;
pub mod bigbuf;
pub mod color;
pub mod error;
pub mod files;
pub mod output;
pub mod powers;
pub mod procedural;
pub mod raster;
pub mod raytrace;
pub mod render;
pub mod scene;
pub mod shade;
pub mod simd;
#[cfg(test)]
mod testing;

pub use error::{Error, Result};
