//! `softraster render INPUT...`: each input loaded, checked and rendered
//! in one worker pool, progress reported, and, with several inputs, each
//! input's outcome and a summary (a failing input never stops the
//! others).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use softraster::batch::{JobSummary, RenderJob, RenderPlan, ShotDone, thread_pool};
use softraster::error::Error;
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;

use super::inputs::{self, Input, Shard};
use super::{Progress, RenderArgs, load_options, print_error};

/// Runs the command; its exit status: 0 when every input rendered, 1 when
/// one failed to render (with several inputs: when any failed), 2 for bad
/// arguments (and a lone input's bad scene or asset).
pub fn run(args: RenderArgs) -> i32 {
    let prepared = select(&args).and_then(|inputs| {
        let opts = options(&args)?;
        let pool = thread_pool(args.threads)?;
        Ok((inputs, opts, pool))
    });
    let (inputs, opts, pool) = match prepared {
        Ok(p) => p,
        Err(e) => {
            print_error(&e);
            return e.exit_code();
        }
    };
    pool.install(|| match &inputs[..] {
        [Input { path, name: None }] => match render_one(&args, path, &opts, None) {
            Ok(_) => 0,
            Err(e) => {
                print_error(&e);
                e.exit_code()
            }
        },
        _ => many(&args, &inputs, &opts),
    })
}

/// The inputs this process renders: all it was given, or its shard.
fn select(args: &RenderArgs) -> Result<Vec<Input>, Error> {
    let all = inputs::gather(&args.inputs, args.list.as_deref())?;
    // A lone file is never split by Slurm: an array task rendering part of
    // one scene's frames names them with --frames.
    let several = all.len() > 1 || all[0].name.is_some();
    let shard = match args.shard {
        Some(s) => Some(s),
        None if several => Shard::from_slurm(|k| std::env::var(k).ok())?,
        None => None,
    };
    Ok(match shard {
        Some(s) => s.take(all),
        None => all,
    })
}

/// The load options every input shares: `--set` (after `--turntable`'s
/// two), `--out`, `--strict`, `--cache`, `--max-memory`, `--sandbox`.
fn options(args: &RenderArgs) -> Result<LoadOptions, Error> {
    // --turntable N: two overrides before the user's own.
    let sets: Vec<String> = args
        .turntable
        .map(|n| {
            vec![
                format!("animation.frames={n}"),
                "animation.turntable.degrees=360".to_string(),
            ]
        })
        .unwrap_or_default()
        .into_iter()
        .chain(args.sets.iter().cloned())
        .collect();
    let mut opts = load_options(&sets, args.out.clone(), args.strict, args.cache.clone())?;
    opts.max_memory = args.max_memory;
    opts.sandbox = args.sandbox;
    Ok(opts)
}

/// What rendering one input came to.
struct Outcome {
    /// Frames rendered or found (frames times cameras).
    frames: usize,
    warnings: usize,
}

/// Renders every input in turn, each into its folder under the output
/// root, reporting each and then the summary.
fn many(args: &RenderArgs, inputs: &[Input], opts: &LoadOptions) -> i32 {
    let json = args.progress == Progress::Json;
    let root = args.out.clone().unwrap_or_else(|| PathBuf::from("out"));
    let (mut rendered, mut warned, mut failed) = (0usize, 0usize, 0usize);
    for (k, input) in inputs.iter().enumerate() {
        let dir = root.join(input.name.as_deref().unwrap_or(Path::new("")));
        let mut opts = opts.clone();
        opts.out_dir = Some(dir.clone());
        let t0 = Instant::now();
        // A panic is a bug, but it must not cost the other inputs their
        // frames: it fails this input (its message is on stderr already).
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            render_one(args, &input.path, &opts, Some(&input.path))
        }))
        .unwrap_or_else(|_| Err(Error::Render("internal error (a panic; see above)".into())));
        let seconds = t0.elapsed().as_secs_f64();
        let (status, message, frames) = match &result {
            Ok(o) if o.warnings == 0 => ("rendered", None, o.frames),
            Ok(o) => (
                "warned",
                Some(format!("{} warning(s)", o.warnings)),
                o.frames,
            ),
            Err(e) => ("failed", Some(e.to_string()), 0),
        };
        match status {
            "rendered" => rendered += 1,
            "warned" => warned += 1,
            _ => failed += 1,
        }
        if let Err(e) = &result {
            // Most errors name the file already.
            if !e.to_string().contains(&*input.path.to_string_lossy()) {
                eprint!("{}: ", input.path.display());
            }
            print_error(e);
        }
        if json {
            let line = serde_json::json!({
                "event": "input",
                "path": input.path,
                "out": dir,
                "status": status,
                "message": message,
                "frames": frames,
                "seconds": seconds,
            });
            println!("{line}");
        } else if !args.quiet && result.is_ok() {
            eprintln!(
                "[{}/{}] {} -> {}: {frames} frame(s) in {seconds:.2} s",
                k + 1,
                inputs.len(),
                input.path.display(),
                dir.display()
            );
        }
    }
    if json {
        let line = serde_json::json!({
            "event": "summary",
            "rendered": rendered,
            "warned": warned,
            "failed": failed,
        });
        println!("{line}");
    }
    if !args.quiet || failed > 0 {
        eprintln!("{rendered} rendered, {warned} with warnings, {failed} failed");
    }
    if failed > 0 { 1 } else { 0 }
}

/// Loads, checks and renders the input at `path`. `input`: the path when
/// it is one of several (its frame lines name it, and the one-scene
/// messages are left out).
fn render_one(
    args: &RenderArgs,
    path: &Path,
    opts: &LoadOptions,
    input: Option<&Path>,
) -> Result<Outcome, Error> {
    let t0 = Instant::now();
    let scene = Scene::load(path, opts)?;
    let auto = scene.settings.auto_exposure;
    let mut job = RenderJob::all(scene);
    let scene = job.scene();
    let load_s = t0.elapsed().as_secs_f64();
    let one = input.is_none();
    if auto && args.progress == Progress::Json {
        let stops = job.exposure();
        println!(
            "{}",
            serde_json::json!({ "event": "exposure", "stops": stops })
        );
    } else if auto && !args.quiet && one {
        eprintln!("exposure: auto, {:+.2} stops", job.exposure());
    }
    // Warnings are shown with --quiet too: it silences progress only.
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let warnings = scene.warnings.len();
    check_memory(scene, args.max_memory, path, args.quiet || !one)?;
    let plan = RenderPlan::select(scene, args.frames.as_deref(), args.camera.as_deref())?;
    job.plan = plan;
    job.skip_existing = args.skip_existing;
    if !args.quiet && one {
        eprintln!(
            "{}: {} triangles, {} frame(s) x {} camera(s) at {}x{}, loaded in {:.2} s, writing to {}",
            path.display(),
            job.scene().triangle_count(),
            job.plan.frames.len(),
            job.plan.cameras.len(),
            job.scene().settings.width,
            job.scene().settings.height,
            load_s,
            job.scene().output.dir.display()
        );
    }
    let t0 = Instant::now();
    let report = Reporter::new(args, job.plan.total(), input);
    let summary = job.run(|d| report.frame(d))?;
    report.finish(&summary);
    if !args.quiet && one {
        eprintln!(
            "done: {} frame(s) in {:.2} s",
            job.plan.total(),
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(Outcome {
        frames: job.plan.total(),
        warnings,
    })
}

/// `--max-memory` (or `render.max_memory`, or by default what the
/// machine has: the smaller of the memory available and the address-space
/// limit, less headroom): the estimate against the limit, before the
/// first frame. `quiet`: no note when it fits.
fn check_memory(scene: &Scene, flag: Option<u64>, path: &Path, quiet: bool) -> Result<(), Error> {
    let estimate = softraster::render::memory::estimate(scene, rayon::current_num_threads());
    let (limit, what) = match (flag, scene.settings.max_memory) {
        (Some(f), _) => (f, "--max-memory"),
        (None, Some(s)) => (s, "render.max_memory"),
        (None, None) => (
            softraster::assets::input::default_budget(),
            "the default budget (the memory available, or the address-space limit, less headroom; --max-memory sets it):",
        ),
    };
    let chosen = flag.is_some() || scene.settings.max_memory.is_some();
    if estimate.total() > limit {
        return Err(Error::Argument(format!(
            "{}: the render needs about {estimate}, more than {what} {}",
            path.display(),
            softraster::render::memory::human(limit)
        )));
    }
    if chosen && !quiet {
        eprintln!(
            "memory: about {estimate}, within {what} {}",
            softraster::render::memory::human(limit)
        );
    }
    Ok(())
}

/// How `render` reports progress: JSON lines on stdout, a bar on a
/// terminal, a line per frame otherwise, or nothing (`--quiet`; and, with
/// several inputs, anything but JSON: those report per input).
struct Reporter<'a> {
    json: bool,
    quiet: bool,
    input: Option<&'a Path>,
    bar: Option<indicatif::ProgressBar>,
}

impl<'a> Reporter<'a> {
    fn new(args: &RenderArgs, total: usize, input: Option<&'a Path>) -> Reporter<'a> {
        let json = args.progress == Progress::Json;
        let quiet = args.quiet || (input.is_some() && !json);
        let bar = (!quiet && !json && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(total as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} frames  {elapsed_precise} (eta {eta})  {msg}",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b
        });
        Reporter {
            json,
            quiet,
            input,
            bar,
        }
    }

    fn frame(&self, d: &ShotDone) {
        if self.json {
            let mut line = serde_json::json!({
                "event": "frame",
                "frame": d.frame,
                "camera": d.camera,
                "files": d.files,
                "seconds": d.render_seconds,
                "skipped": d.skipped,
            });
            if let Some(p) = self.input {
                line["input"] = serde_json::json!(p);
            }
            println!("{line}");
        } else if let Some(b) = &self.bar {
            b.set_message(format!("{:.1} ms/frame", d.render_seconds * 1e3));
            b.inc(1);
        } else if !self.quiet {
            let files: Vec<_> = d.files.iter().map(|f| f.display().to_string()).collect();
            if d.skipped {
                eprintln!(
                    "frame {} camera {}: exists, skipped ({})",
                    d.frame,
                    d.camera,
                    files.join(", ")
                );
            } else {
                eprintln!(
                    "frame {} camera {}: {:.1} ms -> {}",
                    d.frame,
                    d.camera,
                    d.render_seconds * 1e3,
                    files.join(", ")
                );
            }
        }
    }

    fn finish(&self, summary: &JobSummary) {
        if let Some(b) = &self.bar {
            b.finish();
            // indicatif leaves the cursor at the end of the bar's line
            // (padded to the terminal's width): end it, so the next line
            // starts on its own.
            eprintln!();
        }
        for g in &summary.gifs {
            if self.json {
                println!("{}", serde_json::json!({ "event": "gif", "file": g }));
            } else if !self.quiet {
                eprintln!("gif: {}", g.display());
            }
        }
        for v in &summary.videos {
            if self.json {
                println!("{}", serde_json::json!({ "event": "video", "file": v }));
            } else if !self.quiet {
                eprintln!("video: {}", v.display());
            }
        }
        // Why a GIF or video was not written: shown with --quiet too.
        for why in [&summary.gif_skipped, &summary.video_skipped]
            .into_iter()
            .flatten()
        {
            eprintln!("note: {why}");
        }
    }
}
