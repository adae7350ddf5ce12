//! glTF and GLB: the input as a model file (`.glb` when it starts with the
//! binary magic, `.gltf` otherwise), loaded with its lights and cameras and
//! rendered at 16x16; a file that mentions animations plays its first clip
//! (frames 0 and 1 at 3 fps), and then its second.

#![no_main]
#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = common::dir();
    let name = if data.starts_with(b"glTF") {
        "fuzz.glb"
    } else {
        "fuzz.gltf"
    };
    if std::fs::write(dir.join(name), data).is_err() {
        return;
    }
    let scene = format!(
        "[output]\nwidth = 16\nheight = 16\n[[model]]\npath = \"{name}\"\nlights = true\n\
         [[light]]\nkind = \"point\"\nposition = [2.0, 3.0, 4.0]\n"
    );
    common::load_and_render("gltf.toml", &scene, true);
    if data.windows(10).any(|w| w == b"animations") {
        for clip in ["0", "1"] {
            let animated = format!(
                "{scene}[animation]\nfps = 3.0\nframes = 2\n[[model]]\npath = \"{name}\"\nanimation = {clip}\nlights = true\n"
            );
            common::load_and_render_frames("gltf_anim.toml", &animated, true, &[0, 1]);
        }
    }
});
