//! The turntable workflow end to end, through the binary: render-farm
//! shards against one run, --skip-existing, JSON progress, frame lists,
//! the GIF (decoded back), and `softraster compare` exit codes, reports and
//! diff images.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::binary::run;

/// The showcase as a 72-frame turntable, 5 degrees a frame, small and with
/// MSAA 4 and a GIF, as a scene file in `dir`.
fn turntable(dir: &Path) -> PathBuf {
    let root = common::root();
    let text = std::fs::read_to_string(root.join("scenes/showcase.toml"))
        .unwrap()
        .replace("../assets/", &format!("{}/assets/", root.display()))
        .replace("video = \"showcase.mp4\"", "");
    let text = format!(
        "{text}\n",
        text = text
            .replace("width = 640", "width = 64")
            .replace("height = 480", "height = 48")
    );
    let p = dir.join("turntable.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn listing(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    files.sort();
    files
}

fn sets() -> Vec<&'static str> {
    vec![
        "--set",
        "animation.frames=72",
        "--set",
        "animation.turntable={axis=[0.0,1.0,0.0],degrees=360.0}",
        "--set",
        "render.msaa=4",
        "--set",
        "output.gif=\"turntable.gif\"",
        "--set",
        "output.gif_delay_ms=60",
    ]
}

#[test]
fn four_shards_in_separate_processes_match_one_run() {
    let dir = common::scratch("shards");
    let scene = turntable(&dir);
    let (one, sharded) = (dir.join("one"), dir.join("sharded"));

    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--out",
        one.to_str().unwrap(),
        "--quiet",
    ];
    args.extend(sets());
    let (code, _, err) = run(&args);
    assert_eq!(code, 0, "{err}");

    // Four shards as separate processes, four at a time (xargs -P), the
    // way a farm or GNU parallel runs them.
    let quoted: Vec<String> = sets().iter().map(|s| format!("'{s}'")).collect();
    let script = format!(
        "printf '0..18\\n18..36\\n36-53\\n54,55,56..72\\n' | xargs -P 4 -I RANGE '{}' render '{}' --out '{}' --frames RANGE --quiet {}",
        crate::binary::BIN,
        scene.display(),
        sharded.display(),
        quoted.join(" ")
    );
    let status = Command::new("sh").arg("-c").arg(&script).status().unwrap();
    assert!(status.success(), "{script}");
    // The shards each had part of the animation: no GIF yet.
    assert!(!sharded.join("turntable.gif").exists());
    let png_count = |d: &Path| {
        listing(d)
            .iter()
            .filter(|(n, _)| n.ends_with(".png"))
            .count()
    };
    assert_eq!(png_count(&sharded), 72);

    // A final pass with --skip-existing renders nothing and writes the GIF.
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--out",
        sharded.to_str().unwrap(),
        "--skip-existing",
        "--progress",
        "json",
    ];
    args.extend(sets());
    let (code, out, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l}: {e}")))
        .collect();
    let frames: Vec<_> = lines.iter().filter(|l| l["event"] == "frame").collect();
    assert_eq!(frames.len(), 72);
    for (i, f) in frames.iter().enumerate() {
        assert_eq!(f["frame"], i as u64);
        assert_eq!(f["skipped"], true);
        assert!(f["seconds"].is_number());
        assert_eq!(f["files"].as_array().unwrap().len(), 1);
    }
    assert!(lines.iter().any(|l| l["event"] == "gif"));

    let (a, b) = (listing(&one), listing(&sharded));
    assert_eq!(a.len(), 73, "72 frames and the GIF");
    assert_eq!(
        a.iter().map(|f| &f.0).collect::<Vec<_>>(),
        b.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for (fa, fb) in a.iter().zip(&b) {
        assert!(fa.1 == fb.1, "{} differs between one run and shards", fa.0);
    }

    // The GIF decodes to 72 frames of the right size and delay, sharing
    // one palette, looping forever.
    let g = softraster::output::gif::decode(&one.join("turntable.gif")).unwrap();
    assert_eq!((g.width, g.height), (64, 48));
    assert_eq!(g.frames.len(), 72);
    assert!(g.repeat_infinite);
    assert!(g.global_palette.as_ref().is_some_and(|p| p.len() >= 3 * 64));
    assert!(g.frames.iter().all(|&(delay, local)| delay == 6 && !local));

    // `softraster gif` on the same PNGs writes the same bytes.
    let pngs: Vec<String> = (0..72)
        .map(|f| one.join(format!("front_{f:04}.png")).display().to_string())
        .collect();
    let again = dir.join("again.gif");
    let mut args = vec!["gif"];
    args.extend(pngs.iter().map(|s| s.as_str()));
    // (The showcase scene dithers with Floyd-Steinberg.)
    args.extend([
        "-o",
        again.to_str().unwrap(),
        "--delay-ms",
        "60",
        "--dither",
        "floyd-steinberg",
    ]);
    let (code, _, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    assert!(std::fs::read(&again).unwrap() == std::fs::read(one.join("turntable.gif")).unwrap());
}

#[test]
fn frame_lists_and_skip_existing() {
    let dir = common::scratch("frame_lists");
    let scene = turntable(&dir);
    let out = dir.join("out");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--progress",
            "json",
        ];
        args.extend(extra);
        run(&args)
    };
    let (code, json, err) = render(&["--frames", "1-3,7"]);
    assert_eq!(code, 0, "{err}");
    let names: Vec<_> = listing(&out).into_iter().map(|f| f.0).collect();
    assert_eq!(
        names,
        [
            "front_0001.png",
            "front_0002.png",
            "front_0003.png",
            "front_0007.png"
        ]
    );
    assert_eq!(json.lines().count(), 4);
    // The frames exist: only frame 4 is rendered.
    let (code, json, _) = render(&["--frames", "2..5", "--skip-existing"]);
    assert_eq!(code, 0);
    let skipped: Vec<bool> = json
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["skipped"] == true)
        .collect();
    assert_eq!(skipped, [true, true, false]);
    for bad in ["5..5", "70..80", "x", "3-1", "1,,2"] {
        let (code, _, err) = render(&["--frames", bad]);
        assert_eq!(code, 2, "--frames {bad}: {err}");
        assert!(err.contains("--frames"), "{err}");
    }
}

/// Writes an RGB PNG of 96x64 made by `f`.
fn png(path: &Path, f: impl Fn(u32, u32) -> [u8; 3]) {
    let img = image::RgbImage::from_fn(96, 64, |x, y| image::Rgb(f(x, y)));
    img.save(path).unwrap();
}

#[test]
fn compare_exit_codes_reports_and_diff_images() {
    let dir = common::scratch("compare");
    let base = |x: u32, y: u32| [(x * 2) as u8, (y * 3) as u8, 120];
    let (r, same, slight, very) = (
        dir.join("ref.png"),
        dir.join("same.png"),
        dir.join("slight.png"),
        dir.join("very.png"),
    );
    png(&r, base);
    png(&same, base);
    // Two levels brighter in a 16x16 block: below the default threshold.
    png(&slight, |x, y| {
        let mut p = base(x, y);
        if (40..56).contains(&x) && (20..36).contains(&y) {
            p[1] += 2;
        }
        p
    });
    png(&very, |x, y| [255 - (x * 2) as u8, 30, (y * 3) as u8]);
    let cmp = |test: &Path, extra: &[&str]| {
        let mut args = vec!["compare", r.to_str().unwrap(), test.to_str().unwrap()];
        args.extend(extra);
        run(&args)
    };
    assert_eq!(cmp(&same, &[]).0, 0);
    assert_eq!(cmp(&slight, &[]).0, 0);
    assert_eq!(cmp(&very, &[]).0, 1);
    // The threshold decides: the slight difference fails a strict one.
    assert_eq!(cmp(&slight, &["--threshold", "0.00001"]).0, 1);
    for metric in ["ssim", "psnr", "mae"] {
        assert_eq!(cmp(&same, &["--metric", metric]).0, 0, "{metric}");
        assert_eq!(cmp(&slight, &["--metric", metric]).0, 0, "{metric}");
        assert_eq!(cmp(&very, &["--metric", metric]).0, 1, "{metric}");
    }
    // A missing file fails (1); an unreadable one is an error (2); so is a
    // bad metric.
    assert_eq!(cmp(&dir.join("nope.png"), &[]).0, 1);
    let corrupt = dir.join("corrupt.png");
    std::fs::write(&corrupt, b"not a png").unwrap();
    assert_eq!(cmp(&corrupt, &[]).0, 2);
    assert_eq!(cmp(&same, &["--metric", "nope"]).0, 2);

    // JSON report and the diff image: bright in the changed block only.
    let diff = dir.join("diff.png");
    let (code, out, _) = cmp(
        &slight,
        &[
            "--json",
            "--diff",
            diff.to_str().unwrap(),
            "--metric",
            "mae",
        ],
    );
    assert_eq!(code, 0);
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["metric"], "mae");
    assert_eq!(report["pass"], true);
    assert_eq!(report["files"][0]["status"], "pass");
    let d = image::open(&diff).unwrap().to_rgb8();
    let brightness = |x: u32, y: u32| d.get_pixel(x, y).0.iter().map(|&v| v as u32).sum::<u32>();
    for y in 0..64 {
        for x in 0..96 {
            let inside = (40..56).contains(&x) && (20..36).contains(&y);
            assert_eq!(brightness(x, y) > 20, inside, "diff at ({x}, {y})");
        }
    }

    // Directories: paired by name; a missing and an extra file fail.
    let (a, b) = (dir.join("a"), dir.join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    for d in [&a, &b] {
        png(&d.join("f0.png"), base);
        png(&d.join("f1.png"), base);
    }
    let dirs = |extra: &[&str]| {
        let mut args = vec!["compare", a.to_str().unwrap(), b.to_str().unwrap()];
        args.extend(extra);
        run(&args)
    };
    assert_eq!(dirs(&[]).0, 0);
    png(&b.join("f2.png"), base);
    let (code, out, _) = dirs(&["--json"]);
    assert_eq!(code, 1);
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["files"][2]["status"], "extra");
    std::fs::remove_file(b.join("f2.png")).unwrap();
    std::fs::remove_file(b.join("f1.png")).unwrap();
    let (code, out, _) = dirs(&[]);
    assert_eq!(code, 1);
    assert!(out.contains("MISSING f1.png"), "{out}");
    let diffs = dir.join("diffs");
    png(&b.join("f1.png"), |x, y| {
        [255 - (x * 2) as u8, 30, (y * 3) as u8]
    });
    let (code, out, _) = dirs(&["--diff", diffs.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("FAIL f1.png") && out.contains("PASS f0.png"),
        "{out}"
    );
    assert!(diffs.join("f0.png").is_file() && diffs.join("f1.png").is_file());
}

#[test]
fn gifs_per_camera_and_their_keys_are_checked() {
    let dir = common::scratch("gif_cameras");
    let scene = turntable(&dir);
    let text = std::fs::read_to_string(&scene).unwrap()
        + "\n[[camera]]\nname = \"top\"\neye = [0.0, 6.0, 0.5]\ntarget = [0.0, 0.0, 0.0]\n";
    std::fs::write(&scene, text).unwrap();
    let render = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--out",
            out,
            "--quiet",
            "--set",
            "animation.frames=3",
        ];
        args.extend(extra);
        run(&args)
    };
    let out = dir.join("a");
    let (code, _, err) = render(out.to_str().unwrap(), &["--set", "output.gif=\"t.gif\""]);
    assert_eq!(code, 0, "{err}");
    for cam in ["front", "top"] {
        let g = softraster::output::gif::decode(&out.join(format!("t_{cam}.gif"))).unwrap();
        assert_eq!((g.width, g.height, g.frames.len()), (64, 48, 3));
    }
    let out = dir.join("b");
    let (code, _, err) = render(
        out.to_str().unwrap(),
        &[
            "--set",
            "output.gif=\"{camera}-spin.gif\"",
            "--camera",
            "top",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.join("top-spin.gif").is_file() && !out.join("front-spin.gif").exists());
    // The GIF is made of the PNGs: without them it is an error at the key.
    let (code, _, err) = render(
        dir.join("c").to_str().unwrap(),
        &["--set", "output.color=false"],
    );
    assert_eq!(code, 2);
    assert!(
        err.contains("output.gif") && err.contains("turntable.toml:"),
        "{err}"
    );
    let (code, _, err) = render(
        dir.join("c").to_str().unwrap(),
        &["--set", "output.gif_delay_ms=5"],
    );
    assert_eq!(code, 2, "{err}");
}

#[test]
fn update_makes_a_missing_golden_folder_and_says_what_it_blessed() {
    let dir = common::scratch("compare_bless_new");
    let (refs, tests) = (dir.join("golden"), dir.join("out"));
    std::fs::create_dir_all(&tests).unwrap();
    for name in ["a.png", "b.png"] {
        png(&tests.join(name), |x, y| [x as u8, y as u8, 9]);
    }
    let (r, t) = (refs.to_str().unwrap(), tests.to_str().unwrap());
    let (code, out, err) = run(&["compare", r, t, "--update"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(err.contains("created"), "{err}");
    assert!(
        out.contains("blessed 2 new, 0 changed (0 unchanged)"),
        "{out}"
    );
    for name in ["a.png", "b.png"] {
        assert_eq!(
            std::fs::read(refs.join(name)).unwrap(),
            std::fs::read(tests.join(name)).unwrap()
        );
    }
    // Blessed: the gate passes now.
    let (code, out, _) = run(&["compare", r, t]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("2 of 2 passed"), "{out}");
}

#[test]
fn review_report_lists_failures_first_and_update_blesses_them() {
    let dir = common::scratch("compare_report");
    let (refs, tests) = (dir.join("ref"), dir.join("test"));
    std::fs::create_dir_all(&refs).unwrap();
    std::fs::create_dir_all(&tests).unwrap();
    let base = |x: u32, y: u32| [(x * 2) as u8, (y * 3) as u8, 120];
    // a_same passes, b_changed fails, c_new is in the test set only.
    png(&refs.join("a_same.png"), base);
    png(&tests.join("a_same.png"), base);
    png(&refs.join("b_changed.png"), base);
    png(&tests.join("b_changed.png"), |x, y| {
        [255 - (x * 2) as u8, 30, (y * 3) as u8]
    });
    png(&tests.join("c_new.png"), base);
    let page = dir.join("report.html");
    let args = |extra: &[&str]| {
        let mut a = vec![
            "compare",
            refs.to_str().unwrap(),
            tests.to_str().unwrap(),
            "--report",
            page.to_str().unwrap(),
        ];
        a.extend(extra);
        run(&a)
    };
    let (code, _, err) = args(&[]);
    assert_eq!(code, 1, "{err}");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("2 of 3 failed"), "{html:.300}");
    // Failures first: the failing file's row comes before the passing one.
    let (fail, new, pass) = (
        html.find("b_changed.png").unwrap(),
        html.find("c_new.png").unwrap(),
        html.find("a_same.png").unwrap(),
    );
    assert!(fail < new && new < pass, "{fail} {new} {pass}");
    // Self-contained: reference, test and error map of both pairs and the
    // new file's test image, embedded; no other file referenced.
    assert_eq!(html.matches("data:image/png;base64,").count(), 7);
    assert!(!html.contains("src=\"/") && !html.contains("src=\"ref"));
    // --update copies the failing and the new test images into the
    // references and prints what changed; then everything passes.
    let (code, out, err) = args(&["--update"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("b_changed.png") && err.contains("c_new.png"),
        "{err}"
    );
    // The summary says what was done, not the pass count before it.
    assert!(
        out.contains("blessed 1 new, 1 changed (1 unchanged)") && !out.contains("passed"),
        "{out}"
    );
    for name in ["b_changed.png", "c_new.png"] {
        assert_eq!(
            std::fs::read(refs.join(name)).unwrap(),
            std::fs::read(tests.join(name)).unwrap()
        );
    }
    let (code, out, err) = args(&[]);
    assert_eq!(code, 0, "{out}{err}");
}

/// `softraster render` with `args`, outside any Slurm array unless `env`
/// says so: (exit status, stdout, stderr).
fn render_many(args: &[&str], env: &[(&str, &str)]) -> (i32, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_softraster"));
    c.arg("render").args(args);
    for v in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_COUNT",
    ] {
        c.env_remove(v);
    }
    c.envs(env.iter().copied());
    let out = c.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The JSON lines of `stdout` whose event is `event`.
fn events(stdout: &str, event: &str) -> Vec<serde_json::Value> {
    stdout
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| v["event"] == event)
        .collect()
}

/// A folder of two good models, a bad one and a file that is no model,
/// rendered in one run: each good input's frame in its folder (the same
/// bytes as rendering it alone), the bad one reported without stopping
/// the others, a summary, exit 1; then resumed, sharded (by flag and by
/// Slurm's variables) and listed.
#[test]
fn a_folder_of_models_in_one_run() {
    let dir = common::scratch("many_inputs");
    let lib = dir.join("lib");
    std::fs::create_dir_all(lib.join("sub")).unwrap();
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::fs::write(lib.join("a.obj"), tri).unwrap();
    std::fs::write(lib.join("sub/b.obj"), format!("{tri}v 1 1 0\nf 2 4 3\n")).unwrap();
    std::fs::write(lib.join("sub/bad.obj"), "v 0 0 0\nf 1 2 9\n").unwrap();
    std::fs::write(lib.join("notes.txt"), "not a model").unwrap();
    let out = dir.join("out");
    let small = ["--set", "output.width=40", "--set", "output.height=30"];
    let (lib_s, out_s) = (lib.to_str().unwrap(), out.to_str().unwrap());
    let args = |extra: &[&str]| -> Vec<String> {
        [lib_s, "--out", out_s, "--progress", "json"]
            .iter()
            .chain(&small)
            .chain(extra)
            .map(|s| s.to_string())
            .collect()
    };
    let run = |extra: &[&str], env: &[(&str, &str)]| {
        let a = args(extra);
        render_many(&a.iter().map(String::as_str).collect::<Vec<_>>(), env)
    };
    let (code, stdout, stderr) = run(&[], &[]);
    assert_eq!(code, 1, "{stderr}");
    let inputs = events(&stdout, "input");
    let status: Vec<_> = inputs
        .iter()
        .map(|v| (v["path"].as_str().unwrap().to_string(), v["status"].clone()))
        .collect();
    let at = |p: &str| lib.join(p).to_string_lossy().into_owned();
    assert_eq!(
        status,
        [
            (at("a.obj"), "rendered".into()),
            (at("sub/b.obj"), "rendered".into()),
            (at("sub/bad.obj"), "failed".into()),
        ]
    );
    assert!(inputs[2]["message"].as_str().unwrap().contains("bad.obj:2"));
    assert_eq!(inputs[0]["frames"], 1);
    let summary = events(&stdout, "summary");
    assert_eq!(
        (&summary[0]["rendered"], &summary[0]["failed"]),
        (&2.into(), &1.into())
    );
    assert!(stderr.contains("bad.obj:2"), "{stderr}");
    assert!(out.join("a/camera_0000.png").is_file());
    assert!(!out.join("sub/bad").join("camera_0000.png").exists());
    // The second input (its studio lighting found, not made) is the same
    // bytes as when rendered alone.
    let alone = dir.join("alone");
    let b = lib.join("sub/b.obj");
    let one = [
        b.to_str().unwrap(),
        "--out",
        alone.to_str().unwrap(),
        "--quiet",
    ];
    let (code, _, stderr) = render_many(&[&one[..], &small[..]].concat(), &[]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(
        std::fs::read(alone.join("camera_0000.png")).unwrap(),
        std::fs::read(out.join("sub/b/camera_0000.png")).unwrap()
    );
    // Resumed: nothing rendered again.
    let (_, stdout, _) = run(&["--skip-existing"], &[]);
    assert!(
        events(&stdout, "frame")
            .iter()
            .all(|f| f["skipped"] == true)
    );
    // Shards: by flag, and from a Slurm array task's variables.
    let paths = |stdout: &str| -> Vec<String> {
        events(stdout, "input")
            .iter()
            .map(|v| v["path"].as_str().unwrap().to_string())
            .collect()
    };
    let (code, stdout, _) = run(&["--shard", "1/2"], &[]);
    assert_eq!((code, paths(&stdout)), (0, vec![at("sub/b.obj")]));
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "7"),
        ("SLURM_ARRAY_TASK_MIN", "5"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    let (code, stdout, _) = run(&[], &slurm);
    assert_eq!((code, paths(&stdout)), (1, vec![at("sub/bad.obj")]));
    // A list: files named by it go to OUT/<stem>/.
    let list = dir.join("list.txt");
    std::fs::write(
        &list,
        format!("# two models\n{}\n\n{}\n", at("a.obj"), at("sub/b.obj")),
    )
    .unwrap();
    let listed = dir.join("listed");
    let (code, _, stderr) = render_many(
        &[
            &[
                "--list",
                list.to_str().unwrap(),
                "--out",
                listed.to_str().unwrap(),
            ][..],
            &small[..],
        ]
        .concat(),
        &[],
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(
        listed.join("a/camera_0000.png").is_file() && listed.join("b/camera_0000.png").is_file()
    );
}

/// Inputs that cannot be rendered at all are bad arguments: exit 2 with
/// a message, before anything renders.
#[test]
fn bad_input_lists_are_refused() {
    let dir = common::scratch("many_inputs_bad");
    let empty = dir.join("empty");
    std::fs::create_dir_all(empty.join("deeper")).unwrap();
    std::fs::write(empty.join("deeper/readme.txt"), "").unwrap();
    let model = dir.join("m.obj");
    std::fs::write(&model, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let list = dir.join("list.txt");
    std::fs::write(
        &list,
        format!("{}\n{}\n", model.display(), dir.join("gone.obj").display()),
    )
    .unwrap();
    let m = model.to_str().unwrap();
    for (args, says) in [
        (vec![empty.to_str().unwrap()], "no file softraster reads"),
        (vec!["--list", list.to_str().unwrap()], "list.txt:2"),
        (vec![m, "--shard", "3/2"], "--shard"),
        (vec![m, "--shard", "0/0"], "--shard"),
        (
            vec![dir.join("nothing").to_str().unwrap()],
            "no such file or folder",
        ),
        (vec![], "no input"),
    ] {
        let (code, _, stderr) = render_many(&args, &[]);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
}
