//! The renderer library's integration tests, one binary with a module per
//! area. The tests that run the `softraster` binary or the tools that
//! measure the renderer are the command line's (`cli/tests/it`).

mod common;

mod bounce;
mod display;
mod emitters;
mod framing;
mod gltf;
mod gltf_animation;
mod gltf_materials;
mod gltf_pose;
mod known_answers;
mod points_lines;
mod reflections;
mod see_through;
mod shadows;
mod specular_aa;
mod textures;
mod widths;
mod widths_pbr;
