//! The showcase scene's assets, made by code so the repository holds no
//! third-party model: meshes and textures from `softraster::procedural`,
//! and a walking figure (`walker`, a skinned and animated glTF).
//! `softraster generate-assets assets/showcase` writes them; a test checks
//! the committed files are what this code produces.

pub mod walker;

use std::path::Path;

use softraster::error::Error;
use softraster::output::{self, png};
use softraster::procedural::{bands, checker, cube, ground, sphere, torus};

const MTL: &str = "# softraster showcase materials (generated, do not edit)
newmtl ground
Kd 1.0 1.0 1.0
Ks 0.05 0.05 0.05
Ns 16
illum 2
map_Kd checker.png

newmtl sphere
Kd 0.9 0.9 0.9
Ks 0.6 0.6 0.6
Ns 96
illum 2
map_Kd -s 1 1 globe.png

newmtl torus
Kd 1.0 1.0 1.0
Ks 0.4 0.4 0.4
Ns 48
illum 2
map_Kd bands.png

newmtl cube
Kd 0.2 0.45 0.8
Ks 0.3 0.3 0.3
Ns 32
Ke 0.0 0.0 0.0
illum 2
";

/// Writes the showcase's meshes, material library and textures into `dir`.
pub fn write_showcase_assets(dir: &Path) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let text_files = [
        ("showcase.mtl", MTL.to_string()),
        (
            "ground.obj",
            ground(4.0, 0.0, 8.0)
                .to_obj("ground", "showcase.mtl", "ground")
                .text,
        ),
        (
            "sphere.obj",
            sphere(0.8, 48, 24)
                .to_obj("sphere", "showcase.mtl", "sphere")
                .text,
        ),
        (
            "torus.obj",
            torus(0.75, 0.28, 64, 24)
                .to_obj("torus", "showcase.mtl", "torus")
                .text,
        ),
        (
            "cube.obj",
            cube([0.0, 0.0, 0.0], 0.45)
                .to_obj("cube", "showcase.mtl", "cube")
                .text,
        ),
    ];
    for (name, text) in text_files {
        let p = dir.join(name);
        output::write_atomic(&p, |w| {
            use std::io::Write;
            w.write_all(text.as_bytes()).map_err(|e| Error::io(&p, e))
        })?;
    }
    let glb = dir.join("walker.glb");
    output::write_atomic(&glb, |w| {
        use std::io::Write;
        w.write_all(&walker::walker_glb())
            .map_err(|e| Error::io(&glb, e))
    })?;
    png::write(
        &dir.join("checker.png"),
        &checker(256, 8, [230, 226, 214], [62, 66, 78]),
    )?;
    png::write(
        &dir.join("globe.png"),
        &checker(256, 16, [214, 92, 62], [245, 236, 200]),
    )?;
    png::write(
        &dir.join("bands.png"),
        &bands(
            256,
            &[
                [60, 170, 140],
                [240, 190, 70],
                [200, 80, 90],
                [90, 120, 210],
            ],
        ),
    )?;
    Ok(())
}
