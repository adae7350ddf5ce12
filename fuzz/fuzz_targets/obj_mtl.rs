//! OBJ + MTL: the input split at its first NUL byte into an OBJ file (which
//! names the MTL) and an MTL file, loaded as a scene's model (textures,
//! displacement, tangents) and rendered at 16x16.

#![no_main]
#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.iter().position(|b| *b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[][..]),
    };
    let dir = common::dir();
    let mut obj_file = b"mtllib fuzz.mtl\n".to_vec();
    obj_file.extend_from_slice(obj);
    if std::fs::write(dir.join("fuzz.obj"), &obj_file).is_err()
        || std::fs::write(dir.join("fuzz.mtl"), mtl).is_err()
    {
        return;
    }
    let scene = "[output]\nwidth = 16\nheight = 16\n[[model]]\npath = \"fuzz.obj\"\n\
                 [[light]]\nkind = \"directional\"\ndirection = [-1.0, -1.0, -1.0]\nshadows = true\n";
    common::load_and_render("obj.toml", scene, true);
});
