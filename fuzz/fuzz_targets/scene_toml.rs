//! Scene files: the input as TOML text in a directory with small models
//! and textures (`tri.obj`, `lib.mtl`, `tex.png`, `nm.png`, `quad.gltf`),
//! through parsing, validation and the whole build; scenes of at most
//! 64x64 pixels are rendered too, and their output names expanded.

#![no_main]
#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use softraster::scene::{LoadOptions, Scene};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = common::dir().join("scene.toml");
    if let Ok(scene) = Scene::from_text(&path, text, &LoadOptions::plain()) {
        if let Ok(plan) = softraster::batch::RenderPlan::select(&scene, None, None) {
            for &f in plan.frames.iter().take(2) {
                let _ = softraster::scene::expand_pattern(&scene.output.name, "s", "c", f);
            }
        }
    }
    common::load_and_render("scene.toml", text, true);
});
