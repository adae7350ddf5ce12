//! USD (text, binary and package, through openusd) and 3MF (a zip of
//! XML): the first byte picks the extension (`.usda`, `.usdc`, `.usdz`,
//! `.3mf`, by its value mod 4), the rest is the model file, loaded and
//! rendered at 16x16.

#![no_main]
#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, body)) = data.split_first() else {
        return;
    };
    let ext = ["usda", "usdc", "usdz", "3mf"][pick as usize % 4];
    let dir = common::dir();
    let name = format!("fuzz.{ext}");
    if std::fs::write(dir.join(&name), body).is_err() {
        return;
    }
    let scene = format!("[output]\nwidth = 16\nheight = 16\n[[model]]\npath = \"{name}\"\n");
    common::load_and_render("usd.toml", &scene, true);
});
