//! The binary end to end: exit codes and messages for bad input,
//! determinism across thread counts, atomic output.

use crate::common;

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    common::root().to_path_buf()
}

/// Exit status and stderr.
fn run(args: &[&str]) -> (i32, String) {
    let (code, _, err) = crate::binary::run(args);
    (code, err)
}

#[test]
fn frames_are_byte_identical_whatever_the_thread_count() {
    let dir = common::scratch("determinism");
    let scene = root().join("scenes/showcase.toml");
    let shadows = [
        "light.0.shadows=true",
        "light.1.shadows=true",
        "light.2.shadows=true",
        "output.depth=true",
        "output.ao=true",
    ];
    for (variant, sets, per_frame) in [
        ("plain", vec![], 1),
        (
            "pcf-ssao",
            [
                &shadows[..],
                &["render.shadows=\"pcf\"", "render.ao={method=\"ssao\"}"],
            ]
            .concat(),
            3,
        ),
        (
            "raytraced",
            [
                &shadows[..],
                &[
                    "render.shadows=\"raytraced\"",
                    "render.ao={method=\"raytraced\",samples=8,radius=0.5}",
                ],
            ]
            .concat(),
            3,
        ),
        (
            "msaa-ssaa",
            [
                &shadows[..],
                &[
                    "render.msaa=8",
                    "render.ssaa=2",
                    "render.ao={method=\"ssao\"}",
                ],
            ]
            .concat(),
            3,
        ),
        (
            "msaa-blend",
            vec!["render.msaa=4", "model.1.material.d=0.5"],
            1,
        ),
    ] {
        let mut outputs = Vec::new();
        for threads in ["1", "4"] {
            let out = dir.join(variant).join(threads);
            let mut args = vec![
                "render",
                scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--threads",
                threads,
                "--frames",
                "0..3",
                "--quiet",
                "--set",
                "output.width=200",
                "--set",
                "output.height=150",
            ];
            for s in &sets {
                args.extend(["--set", s]);
            }
            let (code, err) = run(&args);
            assert_eq!(code, 0, "{variant}: {err}");
            let mut files: Vec<_> = std::fs::read_dir(&out)
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect();
            files.sort();
            assert_eq!(files.len(), 3 * per_frame, "{variant}: {files:?}");
            outputs.push(
                files
                    .iter()
                    .map(|f| std::fs::read(f).unwrap())
                    .collect::<Vec<_>>(),
            );
            // No temporary files left behind.
            assert!(
                files
                    .iter()
                    .all(|f| !f.file_name().unwrap().to_string_lossy().starts_with('.'))
            );
        }
        assert!(
            outputs[0] == outputs[1],
            "{variant}: 1 and 4 threads differ"
        );
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Renders `scene` into `out`, expects exit status 2, returns stderr.
fn exit_2(scene: &Path, out: &Path) -> String {
    let (code, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    err
}

#[test]
fn malformed_toml_exits_2_naming_file_and_line() {
    let dir = common::scratch("bad_toml");
    let s = write(
        &dir,
        "bad.toml",
        "[[model]]\npath = \"a.obj\"\n[render\nmsaa = 4\n",
    );
    let err = exit_2(&s, &dir);
    assert!(err.contains("bad.toml:3:"), "{err}");
    let s = write(
        &dir,
        "unknown.toml",
        "[[model]]\npath = \"a.obj\"\n[render]\nshadin = \"flat\"\n",
    );
    let err = exit_2(&s, &dir);
    assert!(
        err.contains("unknown.toml:4:1") && err.contains("shadin"),
        "{err}"
    );
}

#[test]
fn a_misspelt_tone_map_exits_2_naming_the_key_and_the_names() {
    let dir = common::scratch("bad_tonemap");
    let s = write(
        &dir,
        "t.toml",
        "[render]\ntonemap = \"aces-hil\"\n[[model]]\npath = \"a.obj\"\n",
    );
    let err = exit_2(&s, &dir);
    assert!(
        err.contains("t.toml:2:") && err.contains("tonemap = \"aces-hil\""),
        "{err}"
    );
    assert!(err.contains("`aces-hill`"), "{err}");
    let (code, err) = run(&[
        "render",
        root().join("scenes/showcase.toml").to_str().unwrap(),
        "--set",
        "render.tonemap=\"aces-hil\"",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("render.tonemap") && err.contains("`aces-hill`"),
        "{err}"
    );
}

#[test]
fn missing_model_exits_2_naming_the_resolved_path() {
    let dir = common::scratch("missing_model");
    let s = write(&dir, "s.toml", "[[model]]\npath = \"nowhere/gone.obj\"\n");
    let err = exit_2(&s, &dir);
    assert!(
        err.contains("nowhere/gone.obj") && err.contains("s.toml:2:"),
        "{err}"
    );
}

#[test]
fn out_of_range_obj_index_exits_2_naming_the_line() {
    let dir = common::scratch("bad_obj");
    write(
        &dir,
        "m.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
    );
    let s = write(&dir, "s.toml", "[[model]]\npath = \"m.obj\"\n");
    let err = exit_2(&s, &dir);
    assert!(err.contains("m.obj:5") && err.contains("index 9"), "{err}");
}

#[test]
fn set_overrides_and_bad_arguments() {
    let dir = common::scratch("set");
    write(&dir, "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let s = write(&dir, "s.toml", "[[model]]\npath = \"m.obj\"\n");
    let out = dir.join("out");
    let (code, err) = run(&[
        "render",
        s.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--set",
        "output.width=32",
        "--set",
        "output.height=16",
        "--set",
        "output.name=\"x{frame:02}\"",
    ]);
    assert_eq!(code, 0, "{err}");
    let img = image::open(out.join("x00.png")).unwrap();
    assert_eq!((img.width(), img.height()), (32, 16));
    let fresh = dir.join("fresh");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render",
            s.to_str().unwrap(),
            "--out",
            fresh.to_str().unwrap(),
        ];
        args.extend(extra);
        run(&args)
    };
    // Each refusal says what was wrong, and writes nothing.
    let (code, err) = render(&["--set", "render.msaa=3"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--set render.msaa=3: render.msaa = 3: expected one of 1, 2, 4, 8, 16"),
        "{err}"
    );
    let (code, err) = render(&["--frames", "3..9"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--frames 3..9") && err.contains("the scene has frames 0..1"),
        "{err}"
    );
    let (code, err) = render(&["--camera", "nope"]);
    assert_eq!(code, 2);
    assert!(err.contains("--camera nope: the scene has camera"), "{err}");
    let (code, err) = render(&["--threads", "0"]);
    assert_eq!(code, 2);
    assert!(err.contains("--threads must be at least 1"), "{err}");
    let (code, err) = render(&["--set", "render"]);
    assert_eq!(code, 2);
    assert!(err.contains("--set render: expected key=value"), "{err}");
    assert!(
        !fresh.exists(),
        "a refused render wrote {}",
        fresh.display()
    );
    let (code, err) = run(&["render"]);
    assert_eq!(code, 2);
    assert!(err.contains("no input"), "{err}");
}

#[test]
fn melina_without_the_model_says_where_to_put_it() {
    let scene = root().join("scenes/melina.toml");
    if root().join("assets/melina/melina.obj").exists() {
        eprintln!("SKIPPED: a Melina export is present");
        return;
    }
    let (code, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        common::scratch("melina").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("assets/melina/melina.obj"), "{err}");
}

#[test]
fn unwritable_output_exits_1() {
    let dir = common::scratch("unwritable");
    write(&dir, "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let s = write(
        &dir,
        "s.toml",
        "[[model]]\npath = \"m.obj\"\n[output]\nwidth = 8\nheight = 8\n",
    );
    // A file where the output directory should be.
    let blocker = write(&dir, "blocker", "");
    let (code, err) = run(&[
        "render",
        s.to_str().unwrap(),
        "--out",
        blocker.join("sub").to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    // The message names the path that could not be made.
    assert!(err.contains(&blocker.display().to_string()), "{err}");
    assert_eq!(
        std::fs::read(&blocker).unwrap(),
        b"",
        "the blocking file is untouched"
    );
}

#[test]
fn committed_showcase_assets_are_what_the_generator_makes() {
    let dir = common::scratch("assets");
    softraster_cli::showcase::write_showcase_assets(&dir).unwrap();
    let committed = root().join("assets/showcase");
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap();
        let want = std::fs::read(committed.join(name)).unwrap();
        assert!(
            std::fs::read(&p).unwrap() == want,
            "{name:?} differs: run softraster generate-assets assets/showcase"
        );
    }
}

#[test]
fn bad_gltf_files_exit_2_with_a_clear_message() {
    let dir = common::scratch("bad_gltf");
    let tri = common::Prim {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        indices: vec![0, 1, 2],
        ..Default::default()
    };
    let nodes = r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]"#;
    let scene = |model: &str| write(&dir, "s.toml", &format!("[[model]]\npath = \"{model}\"\n"));

    // A .glb cut short.
    let glb = common::glb(&tri, "", nodes);
    std::fs::write(dir.join("cut.glb"), &glb[..glb.len() - 20]).unwrap();
    let err = exit_2(&scene("cut.glb"), &dir);
    assert!(
        err.contains("cut.glb") && err.contains("truncated .glb"),
        "{err}"
    );
    // The whole one renders.
    std::fs::write(dir.join("whole.glb"), &glb).unwrap();
    let (code, err) = run(&[
        "render",
        scene("whole.glb").to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");

    // A buffer file that is not there.
    let (text, _) = common::gltf_text(&tri, "", nodes, Some("missing.bin"));
    write(&dir, "nobuf.gltf", &text);
    let err = exit_2(&scene("nobuf.gltf"), &dir);
    assert!(
        err.contains("missing.bin") && err.contains("buffer 0"),
        "{err}"
    );

    // An index past the vertices.
    let bad = common::Prim {
        indices: vec![0, 1, 7],
        ..tri.clone()
    };
    let (text, _) = common::gltf_text(&bad, "", nodes, None);
    write(&dir, "index.gltf", &text);
    let err = exit_2(&scene("index.gltf"), &dir);
    assert!(
        err.contains("index.gltf") && err.contains("index 2 is 7") && err.contains("3 vertices"),
        "{err}"
    );

    // A required extension softraster does not have.
    let (text, _) = common::gltf_text(
        &tri,
        "",
        &format!(
            r#"{nodes}, "extensionsUsed": ["EXT_texture_webp"], "extensionsRequired": ["EXT_texture_webp"]"#
        ),
        None,
    );
    write(&dir, "webp.gltf", &text);
    let err = exit_2(&scene("webp.gltf"), &dir);
    assert!(
        err.contains("requires the glTF extension `EXT_texture_webp`"),
        "{err}"
    );

    // An optional one is a warning, and the file renders.
    let (text, _) = common::gltf_text(
        &tri,
        "",
        &format!(r#"{nodes}, "extensionsUsed": ["KHR_materials_sss"]"#),
        None,
    );
    write(&dir, "sss.gltf", &text);
    let (code, err) = run(&[
        "render",
        scene("sss.gltf").to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning:") && err.contains("`KHR_materials_sss`") && err.contains("ignores"),
        "{err}"
    );

    // An accessor reaching past its buffer view.
    let (text, _) = common::gltf_text(&tri, "", nodes, None);
    let text = text.replacen(
        r#""count": 3, "type": "VEC3""#,
        r#""count": 30, "type": "VEC3""#,
        1,
    );
    write(&dir, "short.gltf", &text);
    let err = exit_2(&scene("short.gltf"), &dir);
    assert!(
        err.contains("accessor 0") && err.contains("runs past"),
        "{err}"
    );
}

#[test]
fn keys_without_effect_warn_and_map_keys_mean_shadow_maps() {
    use softraster::scene::settings::ShadowMethod;
    let dir = common::scratch("no_effect");
    let tri = ("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let scene = |text: &str| {
        common::scene_in(
            &dir,
            &format!("[[model]]\npath = \"m.obj\"\n{text}"),
            &[tri],
        )
    };
    // No shadow key: the default, ray-traced; a map key without a method
    // asks for maps.
    assert_eq!(scene("").settings.shadows, ShadowMethod::Raytraced);
    assert_eq!(
        scene("[render]\nshadow_map_size = 4096\n").settings.shadows,
        ShadowMethod::Pcf
    );
    assert!(scene("").warnings.is_empty());
    for (text, key) in [
        (
            "[render]\nshadows = \"raytraced\"\nshadow_map_size = 4096\n",
            "render.shadow_map_size",
        ),
        (
            "[render]\ntexture_filter = \"trilinear\"\nmax_anisotropy = 4\n",
            "render.max_anisotropy",
        ),
        ("[render]\nao = { radius = 0.5 }\n", "render.ao"),
        ("[output]\ngif_delay_ms = 80\n", "output.gif_delay_ms"),
    ] {
        let w = scene(text).warnings;
        assert!(
            w.iter()
                .any(|w| w.contains(key) && w.contains("scene.toml:")),
            "{key}: {w:?}"
        );
    }
}

#[test]
fn a_model_file_renders_as_its_one_line_scene() {
    let dir = common::scratch("model_as_scene");
    write(&dir, "tri.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n");
    let out = dir.join("out");
    let (code, err) = run(&[
        "render",
        dir.join("tri.obj").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--set",
        "output.width=40",
        "--set",
        "output.height=30",
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let img = image::open(out.join("camera_0000.png")).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (40, 30));
    // The default camera frames the triangle: its middle is lit.
    assert!(
        img.get_pixel(20, 15).0.iter().any(|&c| c > 30),
        "{:?}",
        img.get_pixel(20, 15)
    );
    // --set errors name the override.
    let (code, err) = run(&[
        "render",
        dir.join("tri.obj").to_str().unwrap(),
        "--set",
        "render.ssaa=0",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("--set render.ssaa=0"), "{err}");
}

#[test]
fn the_measuring_tools_keep_version_1_defaults_for_scenes_without_lights() {
    use softraster::scene::settings::{Background, Tonemap};
    use softraster::scene::{LoadOptions, Scene};
    let dir = common::scratch("plain_look");
    write(&dir, "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let text = "[[model]]\npath = \"m.obj\"\n";
    let look = Scene::from_text(&dir.join("s.toml"), text, &LoadOptions::default()).unwrap();
    assert!(look.environment.is_some() && look.ground.is_some());
    assert_eq!(look.settings.tonemap, Tonemap::PbrNeutral);
    let plain = Scene::from_text(&dir.join("s.toml"), text, &LoadOptions::plain()).unwrap();
    assert!(plain.environment.is_none() && plain.ground.is_none());
    assert_eq!(plain.settings.tonemap, Tonemap::Clamp);
    assert_eq!(
        plain.settings.background,
        Background::Color(glam::Vec3::ZERO)
    );
    assert_eq!(plain.settings.ambient, glam::Vec3::splat(0.03));
}

#[test]
fn max_memory_refuses_before_rendering() {
    let dir = common::scratch("max-memory");
    let model = root().join("tests/wild/triangle.obj");
    let m = model.to_string_lossy();
    let out = dir.join("out");
    let o = out.to_string_lossy();
    // 2000x2000 needs far more than 8 MiB: refused, with the estimate,
    // and no frame written.
    let (code, err) = run(&[
        "render",
        &m,
        "--out",
        &o,
        "--max-memory",
        "8M",
        "--set",
        "output.width=2000",
        "--set",
        "output.height=2000",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("the render needs about") && err.contains("frame"),
        "{err}"
    );
    assert!(err.contains("more than --max-memory 8.0 MiB"), "{err}");
    assert!(!out.join("camera_0000.png").exists());
    // The scene key, in the same words.
    let (code, err) = run(&[
        "render",
        &m,
        "--out",
        &o,
        "--set",
        "render.max_memory=\"8M\"",
        "--set",
        "output.width=2000",
        "--set",
        "output.height=2000",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("more than render.max_memory 8.0 MiB"), "{err}");
    // A bad size is an argument error; a generous limit renders.
    let (code, err) = run(&["render", &m, "--out", &o, "--max-memory", "lots"]);
    assert_eq!(code, 2, "{err}");
    let (code, err) = run(&[
        "render",
        &m,
        "--out",
        &o,
        "--max-memory",
        "2G",
        "--set",
        "output.width=64",
        "--set",
        "output.height=64",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("memory: about"), "{err}");
    assert!(out.join("camera_0000.png").exists());
}

#[test]
fn texture_cache_gives_the_same_frames_and_survives_damage() {
    let dir = common::scratch("texture_cache");
    let cache = dir.join("cache");
    let scene = root().join("scenes/showcase.toml");
    let render = |name: &str| {
        let out = dir.join(name);
        let (code, err) = run(&[
            "render",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--cache",
            cache.to_str().unwrap(),
            "--frames",
            "0..2",
            "--set",
            "output.width=96",
            "--set",
            "output.height=72",
            "--quiet",
        ]);
        assert_eq!(code, 0, "{err}");
        let mut frames: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "png"))
            .collect();
        frames.sort();
        assert!(!frames.is_empty());
        frames
            .iter()
            .map(|p| std::fs::read(p).unwrap())
            .collect::<Vec<_>>()
    };
    let (code, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        dir.join("plain").to_str().unwrap(),
        "--frames",
        "0..2",
        "--set",
        "output.width=96",
        "--set",
        "output.height=72",
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let mut plain: Vec<_> = std::fs::read_dir(dir.join("plain"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    plain.sort();
    let plain: Vec<_> = plain.iter().map(|p| std::fs::read(p).unwrap()).collect();
    // Cold (entries written), warm (entries read): the frames of a run
    // without the cache, byte for byte.
    assert_eq!(render("cold"), plain);
    let entries: Vec<_> = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert!(
        !entries.is_empty() && entries.iter().all(|p| p.extension().unwrap() == "srtex"),
        "{entries:?}"
    );
    assert_eq!(render("warm"), plain);
    // Damaged entries (cut short, or garbage) are decoded again.
    for (k, p) in entries.iter().enumerate() {
        let bytes = std::fs::read(p).unwrap();
        let damaged = if k % 2 == 0 {
            bytes[..bytes.len() / 2].to_vec()
        } else {
            vec![7u8; 100]
        };
        std::fs::write(p, damaged).unwrap();
    }
    assert_eq!(render("damaged"), plain);
    // A cache path that cannot be a directory: exit 2 naming it.
    let file = write(&dir, "not_a_dir", "x");
    let (code, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        dir.join("bad").to_str().unwrap(),
        "--cache",
        file.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("not_a_dir") && err.contains("texture cache"),
        "{err}"
    );
}

/// `SOFTRASTER_LANES` forces a lane width: every width this build has
/// gives the same PNG bytes (the showcase with MSAA and SSAO, and
/// diablo3's maps under a spot light with a shadow map, where the shared
/// assets are); any other value exits 2 before anything is read, naming
/// the variable and the widths there are.
#[test]
fn every_lane_width_gives_the_same_bytes_and_others_exit_2() {
    let dir = common::scratch("lane-widths");
    let scene = root().join("scenes/showcase.toml");
    let run_with = |lanes: &str, out: &Path, extra: &[&str]| {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--frames",
            "0..2",
            "--quiet",
            "--set",
            "output.width=240",
            "--set",
            "output.height=180",
            "--set",
            "render.msaa=4",
        ];
        args.extend(extra.iter().flat_map(|s| ["--set", s]));
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_softraster"))
            .args(&args)
            .env("SOFTRASTER_LANES", lanes)
            .output()
            .unwrap();
        (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    for bad in ["3", "16", "0", "eight", ""] {
        let (code, err) = run_with(bad, &dir.join("bad"), &[]);
        assert_eq!(code, 2, "SOFTRASTER_LANES={bad}: {err}");
        let widths = softraster::render::lane_widths();
        assert!(
            err.contains(&format!("SOFTRASTER_LANES={bad}:"))
                && err.contains("lane width")
                && widths.iter().all(|w| err.contains(&w.to_string())),
            "{err}"
        );
    }
    assert!(!dir.join("bad").exists(), "nothing is rendered");
    for (variant, extra) in [
        ("plain", vec![]),
        (
            "ssao-spot-pcf",
            vec![
                "render.ao={method=\"ssao\"}",
                "light.2.shadows=true",
                "render.shadows=\"pcf\"",
            ],
        ),
    ] {
        let mut frames: Vec<Vec<Vec<u8>>> = Vec::new();
        for &w in softraster::render::lane_widths() {
            let out = dir.join(variant).join(w.to_string());
            let (code, err) = run_with(&w.to_string(), &out, &extra);
            assert_eq!(code, 0, "{variant}, {w} lanes: {err}");
            let mut files: Vec<_> = std::fs::read_dir(&out)
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect();
            files.sort();
            assert_eq!(files.len(), 2);
            frames.push(files.iter().map(|f| std::fs::read(f).unwrap()).collect());
        }
        for (k, f) in frames.iter().enumerate().skip(1) {
            assert!(
                *f == frames[0],
                "{variant}: {} lanes differ from 1",
                softraster::render::lane_widths()[k]
            );
        }
    }
}

/// The first hour's small fixes: warnings survive `--quiet`, the help
/// names model files, shadow-map keys without a shadow-casting light warn,
/// and the GIF plays at the animation's rate.
#[test]
fn quiet_keeps_warnings_and_the_gif_follows_fps() {
    let dir = common::scratch("first_hour");
    write(
        &dir,
        "tri.obj",
        "mtllib none.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n",
    );
    let scene = write(
        &dir,
        "s.toml",
        "[output]\nwidth = 16\nheight = 16\ngif = \"t.gif\"\n[animation]\nframes = 2\nfps = 12\n\
         [animation.turntable]\n[render]\nshadow_map_size = 1024\nshadows = \"pcf\"\n\
         [[light]]\n[[model]]\npath = \"tri.obj\"\n",
    );
    let out = dir.join("out");
    let (code, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning:") && err.contains("none.mtl"),
        "{err}"
    );
    assert!(
        err.contains("render.shadow_map_size has no effect: no light casts shadows"),
        "{err}"
    );
    // 12 fps: 80 ms a frame (8 hundredths), as the video would play it.
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut dec = opts
        .read_info(std::fs::File::open(out.join("t.gif")).unwrap())
        .unwrap();
    let first = dec.read_next_frame().unwrap().unwrap();
    assert_eq!(first.delay, 8);
    // The help says a model file is a scene.
    let (_, help, _) = crate::binary::run(&["render", "--help"]);
    assert!(
        help.contains(".glb") && help.contains("model file"),
        "{help}"
    );
}

/// Slips a new user makes, and what they are told: the user's words (no
/// Rust types), the place they can fix (their line, their `--set`, never
/// generated text), and a hint.
#[test]
fn messages_are_in_the_users_words() {
    let dir = common::scratch("messages_words");
    write(&dir, "t.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n");
    let model = dir.join("t.obj");
    let out = dir.join("out");
    let render = |target: &Path, extra: &[&str]| {
        let mut a = vec![
            "render",
            target.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    for (text, want) in [
        (
            "[output]\nwidth = \"320\"\n",
            "s.toml:2:9: found text \"320\", expected a whole number",
        ),
        (
            "[camera]\nazimuth = 3.0\n",
            "write [[camera]] (double brackets)",
        ),
        (
            "[render]\nmsaaa = 4\n",
            "unknown key `msaaa`: did you mean `msaa`?",
        ),
        (
            "[[light]]\ncolor = \"red\"\n",
            "found text \"red\", expected a list of 3 numbers",
        ),
    ] {
        let scene = write(
            &dir,
            "s.toml",
            &format!("{text}[[model]]\npath = \"t.obj\"\n"),
        );
        let (code, err) = render(&scene, &[]);
        assert_eq!(code, 2, "{text}: {err}");
        assert!(err.contains(want), "{text}: {err}");
    }
    for (set, want) in [
        (
            "camera.0.azimuth=35",
            "add one with --set 'camera=[{azimuth=35}]'",
        ),
        ("model.animation=\"Run\"", "e.g. `model.0.animation`"),
    ] {
        let (code, err) = render(&model, &["--set", set]);
        assert_eq!(code, 2, "{set}: {err}");
        assert!(err.contains(want), "{set}: {err}");
    }
    // The hint works.
    let (code, err) = render(&model, &["--set", "camera=[{azimuth=35}]"]);
    assert_eq!(code, 0, "{err}");
    // A model file's scene is generated text: a message names the --set
    // as typed, or the model file, never a line of the generated scene.
    let (code, err) = render(&model, &["--set", "render.msaa=3"]);
    assert_eq!(code, 2);
    assert!(
        err.starts_with("error: --set render.msaa=3: ") && !err.contains(" | "),
        "{err}"
    );
    let (code, err) = render(&model, &["--set", "animation.frames=3"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning: --set animation.frames=3: animation.frames = 3 but nothing moves")
            && !err.contains("t.obj:"),
        "{err}"
    );
    // An error whose message names a place: the --set, too.
    let (code, err) = render(
        &model,
        &["--set", "model.0.material.map_kd=\"missing.png\""],
    );
    assert_eq!(code, 2);
    assert!(
        err.contains("(from --set model.0.material.map_kd=\"missing.png\")"),
        "{err}"
    );
    // A turntable of one frame.
    let (code, err) = render(&model, &["--set", "animation.turntable.degrees=360"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("a turntable of 1 frame does not turn"),
        "{err}"
    );
    // Neither TOML nor a model; not there at all.
    let notes = write(&dir, "notes.txt", "hello\n");
    let (code, err) = render(&notes, &[]);
    assert_eq!(code, 2);
    assert!(
        err.contains("notes.txt: neither a scene (TOML) nor a model file"),
        "{err}"
    );
    let (code, err) = render(&dir.join("nothing.toml"), &[]);
    assert_eq!(code, 2);
    assert!(
        err.contains("nothing.toml: no such file or folder") && !err.contains(":1:1"),
        "{err}"
    );
    // --turntable: 5 frames of a turn, and no warning.
    let _ = std::fs::remove_dir_all(&out);
    let (code, err) = render(
        &model,
        &[
            "--turntable",
            "5",
            "--set",
            "output.width=16",
            "--set",
            "output.height=16",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("nothing moves"), "{err}");
    let pngs = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "png"))
        .count();
    assert_eq!(pngs, 5);
}
