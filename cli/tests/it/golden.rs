//! Golden images: small scenes rendered and compared with committed PNGs
//! under `tests/golden/`, through the code path of `softraster compare`
//! (FLIP). Tolerance: mean FLIP error at most 0.001, and at most 0.1% of
//! pixels with a FLIP error above 0.1 (room for last-bit floating-point
//! differences across CPUs, none for a real regression: one wrong 8x8
//! block in a 320x240 frame fails).
//!
//! On a mismatch the new image and the FLIP error map are written to
//! `tests/failures/`. To accept new output as the golden:
//! `UPDATE_GOLDENS=1 cargo test -p softraster-cli --test it golden::` rewrites the images and fails
//! (so an update never passes as a green run); look at the images, then run
//! the tests again without it.

use crate::common;

use std::path::{Path, PathBuf};

use common::render_frame;
use softraster::output::{Image8, png, resolve};
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;
use softraster::scene::overrides::SetOverride;
use softraster_cli::tools::compare::{Metric, score};

const MEAN_FLIP: f64 = 0.001;
const LOCAL_FLIP: f32 = 0.1;
const LOCAL_FRACTION: f64 = 0.001;

fn root() -> PathBuf {
    common::root().to_path_buf()
}

/// Golden checks of one test: every image is checked (or, with
/// `UPDATE_GOLDENS`, rewritten) before the test reports, so one mismatch
/// does not hide the next.
#[derive(Default)]
struct Goldens {
    failed: Vec<String>,
    updated: Vec<String>,
}

impl Goldens {
    fn check(&mut self, name: &str, scene: &Path, frame: u32, sets: &[&str]) {
        let opts = LoadOptions {
            sets: sets
                .iter()
                .map(|s| s.parse::<SetOverride>().unwrap())
                .collect(),
            out_dir: None,
            plain_look: false,
            strict: false,
            cache: None,
            ..LoadOptions::default()
        };
        let scene = Scene::load(scene, &opts).unwrap_or_else(|e| panic!("{e}"));
        let img = resolve(&render_frame(&scene, 0, frame), &scene.settings);
        let golden = root().join("tests/golden").join(format!("{name}.png"));
        if std::env::var_os("UPDATE_GOLDENS").is_some() {
            png::write(&golden, &img).unwrap();
            self.updated.push(golden.display().to_string());
            return;
        }
        if let Err(why) = compare(name, &golden, &img) {
            self.failed.push(why);
        }
    }

    /// Fails the test on any mismatch, and after an update: rewritten
    /// goldens are to be looked at before they are trusted.
    fn finish(self) {
        assert!(
            self.updated.is_empty(),
            "UPDATE_GOLDENS rewrote {} golden image(s): look at them, then run the tests again without UPDATE_GOLDENS:\n{}",
            self.updated.len(),
            self.updated.join("\n")
        );
        assert!(self.failed.is_empty(), "{}", self.failed.join("\n"));
    }
}

fn check(name: &str, scene: &Path, frame: u32, sets: &[&str]) {
    let mut g = Goldens::default();
    g.check(name, scene, frame, sets);
    g.finish();
}

/// `img` against the golden at `golden`, under the module's tolerance; on
/// a mismatch the new image and the FLIP error map go to tests/failures.
fn compare(name: &str, golden: &Path, img: &Image8) -> Result<(), String> {
    let reference = png::read(golden).map_err(|e| {
        format!("{e}: no golden yet? run UPDATE_GOLDENS=1 cargo test -p softraster-cli --test it golden::")
    })?;
    let fail_dir = root().join("tests/failures");
    let save = || {
        png::write(&fail_dir.join(format!("{name}.new.png")), img).unwrap();
    };
    let s = score(&reference, img, Metric::Flip).map_err(|e| {
        save();
        format!("{name}: {e} ({})", golden.display())
    })?;
    let local = s.error_map.iter().filter(|&&e| e > LOCAL_FLIP).count();
    let pixels = s.error_map.len();
    if s.value > MEAN_FLIP || local as f64 > LOCAL_FRACTION * pixels as f64 {
        save();
        png::write(&fail_dir.join(format!("{name}.flip.png")), &s.diff_image()).unwrap();
        return Err(format!(
            "{name}: mean FLIP {:.5} (max {MEAN_FLIP}), {local} of {pixels} pixels above {LOCAL_FLIP}; new image and error map in {}",
            s.value,
            fail_dir.display()
        ));
    }
    Ok(())
}

#[test]
fn showcase() {
    check(
        "showcase_f3",
        &root().join("scenes/showcase.toml"),
        3,
        &["output.width=320", "output.height=240"],
    );
}

#[test]
fn showcase_shading_modes() {
    let mut g = Goldens::default();
    for mode in ["flat", "gouraud", "unlit", "normals", "depth", "wireframe"] {
        g.check(
            &format!("showcase_{mode}"),
            &root().join("scenes/showcase.toml"),
            0,
            &[
                "output.width=160",
                "output.height=120",
                &format!("render.shading={mode}"),
            ],
        );
    }
    g.finish();
}

/// Scenes on the shared models, checked together: SKIPPED without the
/// models, a failure naming their path under CI.
fn real(names: &[&str]) {
    if common::shared_assets().is_none() {
        return;
    }
    let mut g = Goldens::default();
    for name in names {
        let scene = root().join(format!("tests/scenes/{name}.toml"));
        g.check(name, &scene, 0, &[]);
    }
    g.finish();
}

#[test]
fn diablo3_pose_textures_by_override() {
    real(&["diablo3_pose"]);
}

#[test]
fn diablo3_pose_mtl() {
    real(&["diablo3_pose_mtl"]);
}

#[test]
fn african_head_full_three_objects() {
    real(&["african_head_full"]);
}

#[test]
fn spot_triangulated_and_quads() {
    real(&["spot_triangulated", "spot_quads"]);
}

#[test]
fn gltf_flight_helmet_and_cornell_box() {
    real(&["flight_helmet", "cornell_box"]);
}

#[test]
fn bunny_nefertiti_teapot() {
    real(&["bunny", "nefertiti", "teapot"]);
}

#[test]
fn address_modes() {
    let mut g = Goldens::default();
    for mode in ["repeat", "mirror", "clamp", "border"] {
        g.check(
            &format!("address_{mode}"),
            &root().join("tests/scenes/address.toml"),
            0,
            &[&format!("render.address={mode}")],
        );
    }
    g.finish();
}

#[test]
fn displacement_map() {
    check(
        "displacement",
        &root().join("tests/scenes/displacement.toml"),
        0,
        &[],
    );
}

#[test]
fn african_head_blended_eye_shell_over_the_iris() {
    real(&["african_head_eye"]);
}

#[test]
fn a_material_with_five_slots() {
    // Maps in five slots (two sizes, two transforms, both coordinate
    // sets): the lanes carry three footprints per fragment and compute
    // the others per call. The golden was the one-fragment path's frame
    // (byte-identical to the lanes'); its blended cube's triangle edges
    // are now composited per MSAA sample, and its noisy normal map's
    // lobes widened by specular anti-aliasing (fewer lone bright texels),
    // or, where the map turns far faster than the lobe is wide, shaded
    // at four of the pixel's normals.
    check(
        "many_slots",
        &root().join("tests/data/many_slots/scene.toml"),
        0,
        &[],
    );
}
