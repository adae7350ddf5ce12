//! The command line's integration tests, one binary with a module per area:
//! the `softraster` binary run as users run it, and the renderer measured
//! by the tools (accuracy tables, FLIP against golden frames). The helpers
//! are the library's test helpers, shared by path. The hostile inputs are
//! a binary of their own (`cli/tests/hostile.rs` says why).

#[path = "../../../tests/it/common/mod.rs"]
mod common;

mod binary;

mod accuracy;
mod antialiasing;
mod aov;
mod camera_paths;
mod chart;
mod cli;
mod cycles;
mod environment;
mod golden;
mod light_culling;
mod video;
mod wild_files;
mod workflow;
