//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use softraster::scene::Scene;
use softraster::scene::build::LoadOptions;

/// A fresh directory under the target dir for one test's files.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `files` into `dir` and loads `scene` (TOML text) from there.
pub fn scene_in(dir: &Path, scene: &str, files: &[(&str, &str)]) -> Scene {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    Scene::load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The shared model directory, or None (tests that need it say they skip).
pub fn shared_assets() -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets");
    if p.is_dir() {
        Some(p)
    } else {
        eprintln!("SKIPPED: ../shared/assets not found; tests on real models did not run");
        None
    }
}

/// Direction through the center of pixel (px, py) in view space (z = -1)
/// for a perspective camera with vertical fov `fov` degrees.
pub fn view_ray(px: u32, py: u32, w: u32, h: u32, fov: f32) -> glam::Vec3 {
    let t = (fov.to_radians() * 0.5).tan();
    let aspect = w as f32 / h as f32;
    let x = ((px as f32 + 0.5) / w as f32 * 2.0 - 1.0) * t * aspect;
    let y = (1.0 - (py as f32 + 0.5) / h as f32 * 2.0) * t;
    glam::Vec3::new(x, y, -1.0)
}
