//! FBX (binary and ASCII, through ufbx): the input as a model file,
//! loaded and rendered at 16x16.

#![no_main]
#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = common::dir();
    if std::fs::write(dir.join("fuzz.fbx"), data).is_err() {
        return;
    }
    let scene = "[output]\nwidth = 16\nheight = 16\n[[model]]\npath = \"fuzz.fbx\"\n";
    common::load_and_render("fbx.toml", scene, true);
});
