//! Output settings and names against a temporary folder: the input, split
//! at NUL bytes, gives `output.name`, `output.gif`, `output.video`, a scene
//! camera's name and a glTF camera's name (imported with `cameras = true`).
//! Whatever loads is rendered (one 8x8 frame per camera, with its GIF and
//! video), and nothing may be written outside the output folder.

#![no_main]
#[path = "common.rs"]
mod common;

use std::path::{Path, PathBuf};

use libfuzzer_sys::fuzz_target;
use softraster::batch::{RenderJob, RenderPlan};
use softraster::scene::{LoadOptions, Scene};

/// A basic string, quoted (TOML and JSON escape alike here).
fn quoted(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => {
                out.push_str(&format!("\\u{:04x}", c as u32))
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Every file under `dir`, relative to it.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                stack.push(p.clone());
            }
            out.push(p.strip_prefix(dir).unwrap_or(&p).to_path_buf());
        }
    }
    out.sort();
    out
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let mut fields = text.split('\0');
    let mut next = || fields.next().map(str::to_string);
    let (name, gif, video, camera, gltf_camera) = (next(), next(), next(), next(), next());
    // root/case/ holds the scene and its models; root/case/out/ the output.
    let root = common::dir().join("names");
    let case = root.join("case");
    let out = case.join("out");
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&case).expect("case dir");
    let gltf = common::QUAD_GLTF.replacen(
        r#""nodes":[{"mesh":0}]"#,
        &format!(
            r#""nodes":[{{"mesh":0}},{{"camera":0,"name":{},"translation":[0,0,4]}}],"cameras":[{{"type":"perspective","perspective":{{"yfov":0.8,"znear":0.1}}}}]"#,
            quoted(gltf_camera.as_deref().unwrap_or("cam"))
        ),
        1,
    );
    let gltf = gltf.replacen(
        r#""scenes":[{"nodes":[0]}]"#,
        r#""scenes":[{"nodes":[0,1]}]"#,
        1,
    );
    std::fs::write(case.join("quad.gltf"), gltf).expect("quad.gltf");
    let mut scene = String::from("[output]\nwidth = 8\nheight = 8\n");
    for (key, v) in [("name", &name), ("gif", &gif), ("video", &video)] {
        if let Some(v) = v {
            scene.push_str(&format!("{key} = {}\n", quoted(v)));
        }
    }
    scene.push_str("[animation]\nframes = 1\n[[model]]\npath = \"quad.gltf\"\ncameras = true\n");
    if let Some(c) = &camera {
        scene.push_str(&format!("[[camera]]\nname = {}\n", quoted(c)));
    }
    let path = case.join("scene.toml");
    std::fs::write(&path, &scene).expect("scene.toml");
    let before = files(&root);
    let opts = LoadOptions {
        out_dir: Some(out.clone()),
        ..LoadOptions::plain()
    };
    let Ok(scene) = Scene::load(&path, &opts) else {
        assert_eq!(files(&root), before, "a refused scene wrote files");
        return;
    };
    let Ok(plan) = RenderPlan::select(&scene, None, None) else {
        return;
    };
    let mut job = RenderJob::all(scene);
    job.plan = plan;
    let _ = job.run(|_| {});
    for f in files(&root) {
        assert!(
            before.contains(&f) || f.starts_with("case/out"),
            "written outside the output folder: {} (scene:\n{})",
            f.display(),
            std::fs::read_to_string(&path).unwrap_or_default()
        );
    }
});
