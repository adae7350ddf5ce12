//! The corpus of odd and malformed files in `tests/wild/`: each file's
//! outcome (renders, warns, blank, refused, refused under --strict) as
//! `tests/wild/EXPECTED` states it, and never a panic or a crash.

mod common;

use std::path::{Path, PathBuf};

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
    let (code, _, err) = common::run(&args);
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
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/wild");
    let scratch = common::scratch("wild");
    let cases = cases(&dir);
    assert!(cases.len() >= 60, "the corpus has {} cases", cases.len());
    // Every file in the directory is listed (textures and libraries are
    // read through the models that name them).
    for e in std::fs::read_dir(&dir).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let model = ["obj", "stl", "ply", "gltf", "glb", "toml"]
            .iter()
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
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/wild");
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
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/wild");
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

/// FBX through ufbx: Blender's 2-unit cube, turned 30 degrees about its up
/// axis and standing on the ground, arrives in Y-up metres, and its
/// checker (embedded in one file, beside the other) shows red and white.
#[test]
fn fbx_cubes_arrive_upright_in_metres_with_their_checker() {
    use softraster::scene::Scene;
    use softraster::scene::build::LoadOptions;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/wild");
    for file in ["cube_embedded.fbx", "cube_external.fbx"] {
        let opts = LoadOptions {
            sets: ["output.width=96", "output.height=96"]
                .iter()
                .map(|s| s.parse().unwrap())
                .collect(),
            ..Default::default()
        };
        let scene = Scene::load(&dir.join(file), &opts).unwrap_or_else(|e| panic!("{e}"));
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
}
