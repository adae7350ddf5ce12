//! softraster: a data-driven CPU batch renderer.
//!
//! Data flows one way: scene file (`scene::desc`, private) -> loaded
//! [`scene::Scene`] ([`scene::assemble`]) -> per-frame draw list
//! ([`render::DrawList`]) -> the frame's passes ([`render`]: vertex,
//! shadows, geometry through `raster`, visibility, AO and shading through
//! `shade`) -> [`render::Frame`] -> writers ([`output`]), driven frame by
//! frame by [`batch`]. [`color`], [`error`], `raster`, `simd`, `files`,
//! `powers`, `raytrace` and `bigbuf` are the ground floor: they import
//! nothing of the layers above.
//!
//! The documented API is scene loading ([`scene`], with the meshes and
//! textures of [`assets`] and the primitives of [`procedural`]), the
//! renderer and its frames ([`render`]), a scene's whole run ([`batch`]),
//! the writers ([`output`]) and the errors ([`error`]). The internals
//! (`raster`, `shade`, `simd`, `raytrace`, and the loaders behind
//! `Scene::load`) are private.
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
//!
//! // A camera the scene lacks is an error that names it.
//! let e = renderer.render(Shot::new(5, 0), &mut frame).unwrap_err();
//! assert!(e.to_string().contains("camera 5"));
//! # Ok(())
//! # }
//! ```
//!
//! A turntable: the scene's animation turns the model, and a
//! [`render::FrameSequence`] keeps one buffer across the frames (the rows
//! that stay plain background are not filled again). Each frame's display
//! image is made as it renders:
//!
//! ```
//! use softraster::output::{Image8, png};
//! use softraster::render::{FrameSequence, Renderer, Shot};
//! use softraster::scene::{LoadOptions, Scene};
//!
//! # fn main() -> Result<(), softraster::Error> {
//! let dir = std::env::temp_dir().join(format!("softraster-doc-turn-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let cube = softraster::procedural::cube([0.0; 3], 0.5).to_obj("cube", "none.mtl", "m");
//! std::fs::write(dir.join("cube.obj"), cube.text).unwrap();
//! let text = "[output]\nwidth = 48\nheight = 48\n\
//!             [animation]\nframes = 4\nturntable = { degrees = 360.0 }\n\
//!             [[model]]\npath = \"cube.obj\"\n";
//! let scene = Scene::from_text(&dir.join("turn.toml"), text, &LoadOptions::default())?;
//! let renderer = Renderer::new(&scene);
//! let (mut seq, mut image) = (FrameSequence::new(), Image8::empty());
//! for f in 0..scene.animation.frames {
//!     renderer.render_next(Shot::new(0, f), &mut seq, Some(&mut image))?;
//!     png::write(&dir.join(format!("turn_{f:04}.png")), &image)?;
//! }
//! # Ok(())
//! # }
//! ```
//!
//! The data passes (normals, albedo, world position, ids) are rendered
//! when the scene asks for them (`output.normal` and the like), one
//! [`render::AovPixel`] per pixel, and written as EXR channels:
//!
//! ```
//! use softraster::output::exr::{Samples, write_channels};
//! use softraster::render::{Frame, Renderer, Shot};
//! use softraster::scene::{LoadOptions, Scene};
//!
//! # fn main() -> Result<(), softraster::Error> {
//! let dir = std::env::temp_dir().join(format!("softraster-doc-aov-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let ball = softraster::procedural::sphere(1.0, 32, 16).to_obj("ball", "none.mtl", "m");
//! std::fs::write(dir.join("ball.obj"), ball.text).unwrap();
//! let text = "[output]\nwidth = 32\nheight = 32\nnormal = true\n\
//!             [[model]]\npath = \"ball.obj\"\n";
//! let scene = Scene::from_text(&dir.join("aov.toml"), text, &LoadOptions::default())?;
//! let mut frame = Frame::new(0, 0);
//! Renderer::new(&scene).render(Shot::new(0, 0), &mut frame)?;
//! assert_eq!(frame.aov.len(), frame.color.len());
//! let axis = |k: usize| Samples::F32(frame.aov.iter().map(|a| a.normal[k]).collect());
//! let channels = vec![("N.X", axis(0)), ("N.Y", axis(1)), ("N.Z", axis(2))];
//! write_channels(&dir.join("normal.exr"), frame.width, frame.height, channels)?;
//! # Ok(())
//! # }
//! ```

#![deny(missing_docs)]

pub mod assets;
pub mod batch;
mod bigbuf;
pub mod color;
pub mod error;
mod files;
pub mod output;
mod powers;
pub mod procedural;
mod raster;
mod raytrace;
pub mod render;
pub mod scene;
mod shade;
mod simd;
#[cfg(test)]
mod testing;

pub use error::{Error, Result};
