//! The corpus of odd and malformed files in `tests/wild/`: each file's
//! outcome (renders, warns, blank, refused, refused under --strict) as
//! `tests/wild/EXPECTED` states it, and never a panic or a crash.

use crate::common;

use glam::Vec4;
use std::path::Path;

#[derive(Debug)]
struct Case {
    file: String,
    outcome: String,
    message: String,
}

fn cases(dir: &Path) -> Vec<Case> {
    let text = std::fs::read_to_string(dir.join("EXPECTED")).expect("tests/wild/EXPECTED");
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let mut w = l.splitn(3, char::is_whitespace);
            let file = w.next().unwrap().to_string();
            let rest = w.next().map(str::trim).unwrap_or("");
            let rest = format!("{rest} {}", w.next().unwrap_or(""));
            let rest = rest.trim();
            let (outcome, message) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
            Case {
                file,
                outcome: outcome.to_string(),
                message: message.trim().to_string(),
            }
        })
        .collect()
}

/// Pixels with any coverage in the PNG the render wrote.
fn visible_pixels(out: &Path) -> usize {
    let Some(png) = std::fs::read_dir(out).ok().and_then(|d| {
        d.flatten()
            .map(|e| e.path())
            .find(|p| p.extension().is_some_and(|e| e == "png"))
    }) else {
        return 0;
    };
    let img = image::open(&png).expect("a readable PNG").to_rgba8();
    img.pixels().filter(|p| p.0[3] > 0).count()
}

fn check(dir: &Path, scratch: &Path, i: usize, c: &Case) -> Result<(), String> {
    let out = scratch.join(format!("{i}"));
    let file = dir.join(&c.file);
    let (file_s, out_s) = (file.to_string_lossy(), out.to_string_lossy());
    let mut args = vec![
        "render",
        &*file_s,
        "--out",
        &*out_s,
        "--set",
        "output.width=48",
        "--set",
        "output.height=48",
        "--set",
        "output.background=\"transparent\"",
        "--set",
        "ground.shadow=false",
    ];
    if c.outcome == "strict" {
        args.push("--strict");
    }
    let (code, _, err) = crate::binary::run(&args);
    let fail = |why: &str| {
        Err(format!(
            "{} ({}): {why}; exit {code}, stderr:\n{err}",
            c.file, c.outcome
        ))
    };
    if code == 101 || code < 0 || err.contains("panicked") {
        return fail("crashed");
    }
    let warned = err.lines().any(|l| l.starts_with("warning:"));
    let has_message = err.contains(&c.message);
    match c.outcome.as_str() {
        "renders" | "warns" | "blank" if code != 0 => fail("expected exit 0"),
        "renders" if warned => fail("expected no warning"),
        "warns" if !(warned && has_message) => fail("expected a warning with the message"),
        "renders" | "warns" if visible_pixels(&out) < 5 => fail("expected visible pixels"),
        "refused" | "strict" if code != 2 || !has_message => {
            fail("expected exit 2 with the message")
        }
        "renders" | "warns" | "blank" | "refused" | "strict" => Ok(()),
        other => fail(&format!("unknown outcome `{other}` in EXPECTED")),
    }
}

#[test]
fn every_file_in_the_corpus_has_its_outcome() {
    let dir = common::root().join("tests/wild");
    let scratch = common::scratch("wild");
    let cases = cases(&dir);
    assert!(cases.len() >= 60, "the corpus has {} cases", cases.len());
    // Every file in the directory is listed (textures and libraries are
    // read through the models that name them).
    for e in std::fs::read_dir(&dir).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let model = softraster::assets::MODEL_EXTENSIONS
            .iter()
            .chain(&["toml"])
            .any(|x| name.ends_with(&format!(".{x}")));
        assert!(
            !model || cases.iter().any(|c| c.file == name),
            "{name} is not in tests/wild/EXPECTED"
        );
    }
    let (dir, scratch) = (&dir, &scratch);
    let half = cases.len() / 2;
    let failures: Vec<String> = std::thread::scope(|s| {
        let (a, b) = cases.split_at(half);
        let run = move |part: &[Case], offset: usize| {
            part.iter()
                .enumerate()
                .filter_map(|(i, c)| check(dir, scratch, offset + i, c).err())
                .collect::<Vec<_>>()
        };
        let ha = s.spawn(move || run(a, 0));
        let hb = s.spawn(move || run(b, half));
        let mut f = ha.join().unwrap();
        f.extend(hb.join().unwrap());
        f
    });
    let counts = |o: &str| cases.iter().filter(|c| c.outcome == o).count();
    eprintln!(
        "corpus: {} cases: {} render, {} warn, {} blank, {} refused, {} refused with --strict",
        cases.len(),
        counts("renders"),
        counts("warns"),
        counts("blank"),
        counts("refused"),
        counts("strict")
    );
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n\n")
    );
}

/// The checkers of the corpus in other formats (TGA, found by its
/// extension since it has no magic number; DDS uncompressed BGRA, and BC1
/// and BC3 as Pillow writes them; KTX2 as RGBA8 with zlib
/// supercompression and with DDS's BC1 blocks, written by hand, and as
/// Basis Universal ETC1S and UASTC, written by the basis_universal
/// encoder through the npm package ktx2-encoder 0.6.0) decode to the PNG
/// they were made from: exactly when uncompressed, within BC1's 5-6-5
/// quantization, and within the Basis codecs' loss otherwise.
#[test]
fn tga_dds_and_ktx2_textures_decode_to_their_source_image() {
    use softraster::assets::texture::Texture;
    let dir = common::root().join("tests/wild");
    for (name, tolerance) in [
        ("checker.tga", 0),
        ("checker.dds", 0),
        ("checker_bc1.dds", 8),
        ("checker_bc3.dds", 8),
        ("checker_rgba8_zlib.ktx2", 0),
        ("checker_bc1.ktx2", 8),
        ("checker_uastc.ktx2", 8),
        // ETC1S keeps one colour per half block: its file holds 4x4
        // blocks of one colour each (blocks.png).
        ("blocks_etc1s.ktx2", 8),
    ] {
        let png = if name.starts_with("blocks") {
            Texture::load(
                &dir.join("blocks.png"),
                false,
                &softraster::assets::input::Input::default(),
            )
            .unwrap()
        } else {
            Texture::load(
                &dir.join("checker.png"),
                false,
                &softraster::assets::input::Input::default(),
            )
            .unwrap()
        };
        let dds = Texture::load(
            &dir.join(name),
            false,
            &softraster::assets::input::Input::default(),
        )
        .unwrap();
        assert_eq!((dds.width, dds.height), (png.width, png.height), "{name}");
        for y in 0..png.height {
            for x in 0..png.width {
                let (a, b) = (png.base().texel(x, y), dds.base().texel(x, y));
                let worst = (0..4).map(|c| a[c].abs_diff(b[c])).max().unwrap();
                assert!(worst <= tolerance, "{name} ({x}, {y}): {a:?} vs {b:?}");
            }
        }
    }
}

/// Inputs the fuzz targets found crashes with, kept as files: each is now
/// refused (an error or a miss), never a panic.
#[test]
fn fuzz_found_inputs_are_refused_not_panicked_on() {
    use softraster::assets::texture::Texture;
    let dir = common::root().join("tests/wild");
    // The texture target, 2026-11-24: a texture-cache entry whose level
    // sizes overflowed the byte count (a multiplication overflow panic).
    let bytes = std::fs::read(dir.join("fuzz_texture_cache_overflow.srtex")).unwrap();
    for srgb in [false, true] {
        assert!(Texture::from_cache_bytes(&bytes, srgb).is_none());
    }
    // The texture target, 2026-11-25 (CI's fuzzing smoke): a Basis
    // Universal KTX2 file whose Zstandard level claims 432 PB uncompressed;
    // the transcoder allocated it (the process aborted).
    let path = dir.join("fuzz_ktx2_zstd_huge_level.ktx2");
    let err = match Texture::from_bytes(
        &std::fs::read(&path).unwrap(),
        &path,
        true,
        &softraster::assets::input::Input::default(),
    ) {
        Ok(_) => panic!("{} was read", path.display()),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("uncompressed"), "{err}");
    // The texture target, 2026-11-26 (CI's fuzzing smoke): a KTX2 header
    // of 4-billion-texel sides; the memory budget's size check overflowed
    // before `decode` could refuse the size.
    let path = dir.join("fuzz_ktx2_huge_header_size.ktx2");
    let err = match Texture::from_bytes(
        &std::fs::read(&path).unwrap(),
        &path,
        true,
        &softraster::assets::input::Input::default(),
    ) {
        Ok(_) => panic!("{} was read", path.display()),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("cannot decode texture"), "{err}");
}

/// USD through openusd: Blender's cube as text, binary and package
/// arrives as the FBX one does (Z up and metres converted), its checker
/// beside the file or inside the package; with its coordinates named
/// `UVMap` instead of `st`, the same.
#[test]
fn usd_cubes_arrive_upright_in_metres_with_their_checker() {
    for file in ["cube.usda", "cube.usdc", "cube.usdz", "cube_uvmap.usda"] {
        check_blender_cube(file);
    }
}

/// In the sandbox a USD file loads with its own layers, and one whose
/// sublayer lies outside its folder is refused, naming that layer.
#[test]
fn usd_layers_stay_in_the_sandbox() {
    use softraster::scene::Scene;
    use softraster::scene::assemble::LoadOptions;
    let opts = LoadOptions {
        sandbox: true,
        ..Default::default()
    };
    let wild = common::root().join("tests/wild");
    for file in ["cube.usda", "cube.usdz"] {
        Scene::load(&wild.join(file), &opts).unwrap_or_else(|e| panic!("{file}: {e}"));
    }
    let dir = common::scratch("usd_sandbox");
    std::fs::create_dir_all(dir.join("inner")).unwrap();
    std::fs::copy(wild.join("usd_subsets.usda"), dir.join("outside.usda")).unwrap();
    let model = dir.join("inner/model.usda");
    std::fs::write(
        &model,
        "#usda 1.0\n(\n    subLayers = [@../outside.usda@]\n)\n",
    )
    .unwrap();
    // Outside the sandbox the sublayer is read.
    Scene::load(&model, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let e = Scene::load(&model, &opts).unwrap_err().to_string();
    assert!(
        e.contains("outside.usda") && e.contains("outside the model's folder"),
        "{e}"
    );
}

/// A hand-written USD file: no `metersPerUnit` is centimetres, a
/// left-handed plate faces up once its winding is reversed, a GeomSubset
/// binds its own material to one face, indexed coordinates are looked up,
/// `displayColor` colours a mesh with no material, and an invisible mesh
/// is left out.
#[test]
fn usd_units_winding_subsets_and_display_colour() {
    let scene = load_wild("usd_subsets.usda", &[]);
    let model = &scene.models[0];
    let mesh = &model.mesh;
    // The plate spans 2 m by 1 m, 1 m up; the marker reaches 1.3 m; the
    // hidden triangle (10 m) is not there.
    let (lo, hi) = mesh.bounds();
    for (got, want) in [
        (lo.x, -1.0),
        (hi.x, 1.0),
        (lo.y, 1.0),
        (hi.y, 1.3),
        (hi.z, 0.5),
    ] {
        assert!((got - want).abs() < 1e-4, "{lo} {hi}");
    }
    assert_eq!(mesh.triangles.len(), 5);
    let plate: Vec<_> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| mesh.positions[i as usize]))
        .filter(|[a, b, c]| a.y == 1.0 && b.y == 1.0 && c.y == 1.0)
        .collect();
    assert_eq!(plate.len(), 4);
    for [a, b, c] in &plate {
        assert!(
            (*b - *a).cross(*c - *a).y > 0.0,
            "a plate triangle faces down"
        );
    }
    let colour_of = |x: f32| {
        let g = mesh
            .groups
            .iter()
            .find(|g| {
                g.triangles.clone().any(|t| {
                    let p = mesh.triangles[t as usize].map(|i| mesh.positions[i as usize]);
                    p.iter().all(|p| p.y == 1.0) && p.iter().map(|p| p.x).sum::<f32>() * x > 0.0
                })
            })
            .expect("a group");
        model.materials[g.material].pbr.base_color
    };
    let (left, right) = (colour_of(-1.0), colour_of(1.0));
    assert!(left.y > 0.5 && left.z < 0.2, "left face {left}");
    assert!(right.z > 0.5 && right.y < 0.2, "right face {right}");
    // The indexed coordinates: (0, 0) on the left face, (1, 1) on the
    // right (t flipped to the image's rows: (0, 1) and (1, 0)).
    for (p, uv) in mesh.positions.iter().zip(&mesh.uvs) {
        if p.y == 1.0 && p.x != 0.0 {
            let want = if p.x < 0.0 {
                glam::Vec2::new(0.0, 1.0)
            } else {
                glam::Vec2::new(1.0, 0.0)
            };
            assert_eq!(*uv, want, "at {p}");
        }
    }
    // The marker's orange is its vertex colour.
    let orange = mesh
        .colors
        .iter()
        .any(|c| (c.x - 1.0).abs() < 1e-6 && (c.y - 0.5).abs() < 1e-6);
    assert!(orange, "no displayColor on the marker");
}

/// 3MF: millimetres and Z up arrive as metres and Y up, build items and
/// components are placed by their transforms, and colours come from base
/// materials (per object) and colour groups (per corner).
#[test]
fn three_mf_cubes_arrive_in_metres_with_their_colours() {
    let scene = load_wild("colour_cubes.3mf", &[]);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let mesh = &scene.models[0].mesh;
    assert_eq!(mesh.triangles.len(), 24);
    // The red cube spans 0..20 mm; the assembly's 40..60 mm along x and
    // 10..30 mm up; the file's +y runs away from the viewer (-z).
    let (lo, hi) = mesh.bounds();
    for (got, want) in [
        (lo.x, 0.0),
        (hi.x, 0.06),
        (lo.y, 0.0),
        (hi.y, 0.03),
        (lo.z, -0.02),
        (hi.z, 0.0),
    ] {
        assert!((got - want).abs() < 1e-6, "{lo} {hi}");
    }
    let has = |want: Vec4| {
        mesh.colors
            .iter()
            .any(|c| (*c - want).abs().max_element() < 1e-6)
    };
    assert!(has(Vec4::new(1.0, 0.0, 0.0, 1.0)), "no red");
    assert!(has(Vec4::new(0.0, 1.0, 0.0, 1.0)), "no green corner");
    assert!(has(Vec4::new(0.0, 0.0, 1.0, 1.0)), "no blue corner");
    assert!(has(Vec4::ONE), "no white");
    // Every corner of the red cube is red.
    for (p, c) in mesh.positions.iter().zip(&mesh.colors) {
        if p.x < 0.03 {
            assert_eq!(*c, Vec4::new(1.0, 0.0, 0.0, 1.0), "at {p}");
        }
    }
}

/// FBX skins and animation stacks through the glTF rig and clip code:
/// Blender's cylinder (0 to 2 up) skinned to two bones, the upper turned
/// 0.8 rad about Blender's X at the end of its stack. At the start the
/// pose is the rest mesh; at the end the top ring's centre has swung
/// about the joint at 1 m: up to 1 + cos 0.8, forward (+Z, Blender's -Y)
/// by sin 0.8.
#[test]
fn fbx_skin_bends_with_its_animation_stack() {
    use softraster::assets::rig::Parts;
    let scene = load_wild("rigged.fbx", &["model.0.animation=0"]);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let model = &scene.models[0];
    let p = model.playback.as_ref().expect("the stack plays");
    let rest = p.pose(&model.mesh, 0.0, Parts::All);
    for (a, b) in rest.positions.iter().zip(&model.mesh.positions) {
        assert!(
            (*a - *b).length() < 1e-4,
            "at the start {a} is not the rest {b}"
        );
    }
    let end = p.pose(&model.mesh, f64::from(p.clip.duration) - 1e-4, Parts::All);
    // The ring's twelve points, each once (corners repeat them).
    let mut top: Vec<(glam::Vec3, glam::Vec3)> = Vec::new();
    for (rest, posed) in model.mesh.positions.iter().zip(&end.positions) {
        if rest.y > 1.99 && !top.iter().any(|(r, _)| (*r - *rest).length() < 1e-5) {
            top.push((*rest, *posed));
        }
    }
    assert_eq!(top.len(), 12);
    let top: Vec<_> = top.into_iter().map(|(_, posed)| posed).collect();
    assert!(!top.is_empty());
    let centre = top.iter().copied().sum::<glam::Vec3>() / top.len() as f32;
    let want = glam::Vec3::new(0.0, 1.0 + 0.8f32.cos(), 0.8f32.sin());
    assert!(
        (centre - want).length() < 0.02,
        "the top's centre is at {centre}, not {want}"
    );
}

/// FBX blend shapes as morph targets: Blender's cube whose shape key
/// raises its top by 1 m, keyed from 0 to 1 over the stack. The top is at
/// 1 m at the start, 1.5 m halfway and 2 m at the end; the bottom stays.
#[test]
fn fbx_blend_shape_follows_its_keys() {
    use softraster::assets::rig::Parts;
    let scene = load_wild("shape_keys.fbx", &["model.0.animation=0"]);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let model = &scene.models[0];
    let p = model.playback.as_ref().expect("the stack plays");
    let d = f64::from(p.clip.duration);
    for (t, top) in [(0.0, 1.0), (0.5 * d, 1.5), (d - 1e-5, 2.0)] {
        let posed = p.pose(&model.mesh, t, Parts::All);
        let (lo, hi) = posed
            .positions
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), q| {
                (lo.min(q.y), hi.max(q.y))
            });
        assert!((lo + 1.0).abs() < 1e-3, "at {t}: bottom {lo}");
        assert!((hi - top).abs() < 0.02, "at {t}: top {hi}, not {top}");
    }
}

/// FBX lights and cameras on request: Blender's camera 10 m in front of
/// the cube looking at it (its exporter writes the lens as a 63.7-degree
/// horizontal field at 16:9, 38.5 degrees vertically), a point light
/// 4 m above, a sun shining down and a 60-degree spot at +X pointing at
/// the cube, all in Y-up metres.
#[test]
fn fbx_lights_and_cameras_arrive_where_blender_put_them() {
    use softraster::scene::camera::Projection;
    use softraster::scene::light::LightKind;
    let scene = load_wild(
        "lit_camera.fbx",
        &["model.0.lights=true", "model.0.cameras=true"],
    );
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let close = |a: glam::Vec3, b: glam::Vec3| (a - b).length() < 1e-3;
    let cam = &scene.cameras[0];
    assert!(
        close(cam.eye, glam::Vec3::new(0.0, 0.0, 10.0)),
        "{:?}",
        cam.eye
    );
    assert!(
        close((cam.target - cam.eye).normalize(), glam::Vec3::NEG_Z),
        "{cam:?}"
    );
    assert!(close(cam.up, glam::Vec3::Y), "{cam:?}");
    match cam.projection {
        Projection::Perspective { fov_y } => assert!((fov_y - 38.53).abs() < 0.01, "{fov_y}"),
        ref other => panic!("{other:?}"),
    }
    let (mut point, mut sun, mut spot) = (false, false, false);
    for l in &scene.lights {
        match l.kind {
            LightKind::Point {
                position,
                intensity,
            } => {
                point |= close(position, glam::Vec3::new(0.0, 4.0, 0.0)) && intensity > 0.0;
            }
            LightKind::Directional {
                direction,
                irradiance,
                ..
            } => {
                sun |= close(direction, glam::Vec3::NEG_Y) && irradiance > 0.0;
            }
            LightKind::Spot {
                position,
                direction,
                cos_outer,
                cos_inner,
                ..
            } => {
                spot |= close(position, glam::Vec3::new(6.0, 0.0, 0.0))
                    && close(direction, glam::Vec3::NEG_X)
                    && (cos_outer - 30f32.to_radians().cos()).abs() < 1e-3
                    && cos_inner > cos_outer;
            }
            LightKind::Area { .. } => panic!("a file's light read as an area light: {l:?}"),
        }
    }
    assert!(point && sun && spot, "{point} {sun} {spot}");
}

/// FBX through ufbx: Blender's 2-unit cube, turned 30 degrees about its up
/// axis and standing on the ground, arrives in Y-up metres, and its
/// checker (embedded in one file, beside the other) shows red and white.
#[test]
fn fbx_cubes_arrive_upright_in_metres_with_their_checker() {
    for file in ["cube_embedded.fbx", "cube_external.fbx"] {
        check_blender_cube(file);
    }
}

/// Scene `file` of tests/wild (a model file: its one-line scene) with
/// `sets` applied as `--set` does.
fn load_wild(file: &str, sets: &[&str]) -> softraster::scene::Scene {
    use softraster::scene::assemble::LoadOptions;
    let dir = common::root().join("tests/wild");
    let opts = LoadOptions {
        sets: sets.iter().map(|s| s.parse().unwrap()).collect(),
        ..Default::default()
    };
    softraster::scene::Scene::load(&dir.join(file), &opts).unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// Blender's 2-unit cube of tests/wild `file` (turned 30 degrees about its
/// up axis, standing on the ground, a red and white checker): upright in
/// metres, red and white in a 96x96 frame, without a warning.
fn check_blender_cube(file: &str) {
    let scene = load_wild(file, &["output.width=96", "output.height=96"]);
    assert!(scene.warnings.is_empty(), "{file}: {:?}", scene.warnings);
    let (lo, hi) = scene.models[0].mesh.bounds();
    // Up is +Y, from 0 to 2; across, cos 30 + sin 30 on either side.
    let across = 30f32.to_radians().cos() + 30f32.to_radians().sin();
    for (got, want) in [
        (lo.y, 0.0),
        (hi.y, 2.0),
        (hi.x, across),
        (-lo.x, across),
        (hi.z, across),
    ] {
        assert!((got - want).abs() < 1e-3, "{file}: {lo} {hi}");
    }
    let f = common::render_frame(&scene, 0, 0);
    let (mut red, mut white, mut covered) = (0, 0, 0);
    for (i, c) in f.color.iter().enumerate() {
        if !f.depth[i].is_finite() {
            continue;
        }
        covered += 1;
        red += (c.x > 2.0 * c.y.max(c.z) && c.x > 0.2) as usize;
        white += (c.min_element() > 0.3 && c.y > 0.7 * c.x) as usize;
    }
    assert!(
        red * 5 > covered && white * 5 > covered,
        "{file}: {red} red, {white} white of {covered}"
    );
}
