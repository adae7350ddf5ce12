//! The command line: flags -> validated library objects (a `Scene`, a
//! `RenderPlan`), progress display, error chain and exit status (0 success,
//! 1 render or I/O failure, 2 bad scene, asset or arguments). Only the
//! binary and the tools (`bench`'s arguments) know about clap; the
//! renderer library does not depend on it.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

mod inputs;
mod render;

use softraster::batch::thread_pool;
use softraster::error::Error;
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;
use softraster::scene::overrides::SetOverride;

#[derive(Parser)]
#[command(
    name = "softraster",
    version,
    about = "A data-driven CPU batch renderer"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render every frame of a scene to PNG (and EXR, GIF as the scene asks).
    Render(RenderArgs),
    /// Assemble PNG frames into a looping GIF with one shared palette.
    Gif(GifArgs),
    /// Assemble PNG frames into an H.264 MP4 video.
    Video(VideoArgs),
    /// Compare two images, or two directories of images paired by name.
    /// Exit status: 0 pass, 1 fail (or a missing/extra file), 2 error.
    Compare(CompareArgs),
    /// Time against error of every method (anti-aliasing, texture filter,
    /// shadows, AO, depth mode) on one frame of a scene: CSV and chart.
    Chart(ChartArgs),
    /// Time the reference turntables (load, per-frame, total).
    Bench(softraster_cli::tools::bench::BenchArgs),
    /// Write the procedural showcase assets (meshes, textures) to a directory.
    GenerateAssets {
        /// Output directory (the repository keeps them in assets/showcase).
        dir: PathBuf,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene files (TOML), model files to render as the one-line scene
    /// that names them (.gltf, .glb, .obj, .stl, .ply, .fbx, .usd/.usda/.usdc/.usdz,
    /// .3mf), or folders, read
    /// recursively for those. One file: its frames go to `--out` (or
    /// `output.dir`). Several inputs: each file's to `OUT/<stem>/`, each
    /// found in a folder to `OUT/<path in the folder, no extension>/`.
    inputs: Vec<PathBuf>,
    /// A file of inputs, one path a line (`-`: stdin).
    #[arg(long, value_name = "FILE")]
    list: Option<PathBuf>,
    /// Render only inputs I, I + N, I + 2N... of the sorted inputs (I
    /// from 0 to N - 1). Without it, a Slurm array task takes its share
    /// of several inputs (SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN of
    /// SLURM_ARRAY_TASK_COUNT).
    #[arg(long, value_name = "I/N")]
    shard: Option<inputs::Shard>,
    /// Output directory; wins over `output.dir`. With several inputs, the
    /// root of their folders (default `out`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Frames to render: `a..b` (half-open), `a-b` (inclusive), `n`, or a
    /// comma-separated list of those, e.g. `0..36` or `1-100,120`.
    #[arg(long)]
    frames: Option<String>,
    /// Do not render frames whose files all exist already.
    #[arg(long)]
    skip_existing: bool,
    /// Progress report: `auto` (a bar on a terminal, a line per frame
    /// otherwise) or `json` (one JSON object per frame on stdout).
    #[arg(long, value_enum, default_value_t = Progress::Auto)]
    progress: Progress,
    /// Render only this camera.
    #[arg(long)]
    camera: Option<String>,
    /// Override a scene key, e.g. `--set render.msaa=4` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// A turntable: N frames (default 72) of a 360-degree turn of the
    /// models (`animation.frames = N` and `[animation.turntable]`; `--set`
    /// wins).
    #[arg(long, value_name = "N", num_args = 0..=1, default_missing_value = "72",
          value_parser = clap::value_parser!(u32).range(1..=100_000))]
    turntable: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No progress output (warnings and errors are still shown).
    #[arg(long)]
    quiet: bool,
    /// Treat every warning (a missing material library or texture, an
    /// unknown MTL key, a setting without effect) as an error: exit 2.
    #[arg(long)]
    strict: bool,
    /// Refuse (exit 2, with the estimate) to render when the estimated
    /// memory exceeds SIZE (`512M`, `2G`, bytes); wins over
    /// `render.max_memory`.
    #[arg(long, value_name = "SIZE", value_parser = parse_memory)]
    max_memory: Option<u64>,
    /// Confine every read to the scene's folder (as `render.sandbox =
    /// true`): a path with `..`, an absolute path, a URI scheme or a link
    /// leading out is an error (exit 2). For farms and services.
    #[arg(long)]
    sandbox: bool,
    /// Keep decoded textures and their mip chains in DIR between runs,
    /// keyed by a hash of each image's content (opt-in; created if
    /// missing; renders running at the same time may share it).
    #[arg(long, value_name = "DIR")]
    cache: Option<PathBuf>,
}

fn parse_memory(s: &str) -> Result<u64, String> {
    softraster::scene::parse_size(s)
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Progress {
    Auto,
    Json,
}

#[derive(clap::Args)]
struct ChartArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// The frame to measure.
    #[arg(long, default_value_t = 0)]
    frame: u32,
    /// Where chart.csv, chart.png and chart.svg go (default `out/<stem>-chart`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Timed renders per setting (fewer for settings that take seconds).
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Comma-separated knobs: aa, texture, shadows, ao, depth, env (default all).
    #[arg(long)]
    knobs: Option<String>,
    /// Fewer settings and smaller references (a quick look, and the tests).
    #[arg(long)]
    quick: bool,
    /// Override a scene key (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

#[derive(clap::Args)]
struct CompareArgs {
    /// Reference image or directory.
    reference: PathBuf,
    /// Test image or directory.
    test: PathBuf,
    /// flip (mean FLIP error, pass <= threshold), ssim (pass >=), psnr (dB,
    /// pass >=) or mae (fraction of full scale, pass <=).
    #[arg(long, default_value = "flip")]
    metric: String,
    /// Pass/fail threshold (defaults: flip 0.05, ssim 0.98, psnr 40, mae 0.01).
    #[arg(long)]
    threshold: Option<f64>,
    /// Write the error map: a PNG (two images) or a directory of PNGs.
    #[arg(long)]
    diff: Option<PathBuf>,
    /// One JSON report on stdout instead of text.
    #[arg(long)]
    json: bool,
    /// Write a self-contained HTML review page (images embedded, failures
    /// first).
    #[arg(long)]
    report: Option<PathBuf>,
    /// Bless the test images: copy each failing one over its reference
    /// (and add the ones the references lack), printing what changed.
    #[arg(long)]
    update: bool,
}

#[derive(clap::Args)]
struct GifArgs {
    /// PNG frames, in order (all of one size).
    #[arg(required = true)]
    frames: Vec<PathBuf>,
    /// The GIF to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Per frame, in milliseconds (GIF stores hundredths of a second).
    #[arg(long, default_value_t = 40)]
    delay_ms: u32,
    /// none | ordered | floyd-steinberg.
    #[arg(long, default_value = "none")]
    dither: String,
}

#[derive(clap::Args)]
struct VideoArgs {
    /// PNG frames, in order (all of one size).
    #[arg(required = true)]
    frames: Vec<PathBuf>,
    /// The video to write (.mp4).
    #[arg(short, long)]
    output: PathBuf,
    /// Frames per second.
    #[arg(long, default_value_t = 24.0)]
    fps: f64,
    /// 1 (smallest) to 100 (best), or a bitrate such as 2500k or 4M.
    #[arg(long, default_value = "75")]
    quality: String,
}

pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    let result = match cli.command {
        Command::Render(args) => return render::run(args),
        Command::Gif(args) => gif(args),
        Command::Video(args) => video(args),
        Command::Chart(args) => chart(args),
        Command::Compare(args) => return compare(args),
        Command::Bench(args) => softraster_cli::tools::bench::run(&args),
        Command::GenerateAssets { dir } => softraster_cli::showcase::write_showcase_assets(&dir),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            print_error(&e);
            e.exit_code()
        }
    }
}

/// `error: ...` and its causes, on stderr.
fn print_error(e: &Error) {
    eprintln!("error: {e}");
    let mut source = std::error::Error::source(e);
    while let Some(s) = source {
        eprintln!("  caused by: {s}");
        source = s.source();
    }
}

fn compare(args: CompareArgs) -> i32 {
    use softraster_cli::tools::compare::{Metric, compare_paths};
    let Some(metric) = Metric::parse(&args.metric) else {
        eprintln!(
            "error: --metric {}: expected flip, ssim, psnr or mae",
            args.metric
        );
        return 2;
    };
    let threshold = args.threshold.unwrap_or_else(|| metric.default_threshold());
    if !threshold.is_finite() {
        eprintln!("error: --threshold must be a finite number");
        return 2;
    }
    // Blessing into a folder that does not exist yet: make it.
    if args.update && args.test.is_dir() && !args.reference.exists() {
        if let Err(e) = std::fs::create_dir_all(&args.reference) {
            eprintln!("error: {}: {e}", args.reference.display());
            return 1;
        }
        eprintln!("created {}", args.reference.display());
    }
    match compare_paths(
        &args.reference,
        &args.test,
        metric,
        threshold,
        args.diff.as_deref(),
    ) {
        Ok(report) => {
            if report.files.is_empty() && !args.update {
                // A gate that compared nothing has not passed (exit 1).
                eprintln!(
                    "error: nothing to compare: neither {} nor {} holds an image (.png, .jpg, .jpeg, .tga)",
                    args.reference.display(),
                    args.test.display()
                );
            }
            if args.json {
                println!("{}", report.to_json());
            } else if args.update {
                // The verdicts, without the pass count: the blessing's
                // summary says what happened.
                let text = report.to_text();
                print!("{}", text.strip_suffix(&report.summary()).unwrap_or(&text));
            } else {
                print!("{}", report.to_text());
            }
            if let Some(page) = &args.report {
                if let Err(e) = softraster_cli::tools::report::write_html(&report, page) {
                    eprintln!("error: {e}");
                    return e.exit_code();
                }
                eprintln!("report: {}", page.display());
            }
            if args.update && report.exit_code() != 2 {
                // Exit 0 when every failing or new image was blessed (a
                // reference the test set lacks is left alone).
                return match softraster_cli::tools::report::update_references(
                    &report,
                    &args.reference,
                ) {
                    Ok(blessed) => {
                        println!("{blessed}");
                        0
                    }
                    Err(e) => {
                        eprintln!("error: {e}");
                        e.exit_code()
                    }
                };
            }
            report.exit_code()
        }
        Err(e) => {
            eprintln!("error: {e}");
            e.exit_code()
        }
    }
}

fn chart(args: ChartArgs) -> Result<(), Error> {
    use softraster_cli::tools::chart::{self, ChartOptions, Knob};
    let knobs = match &args.knobs {
        None => Knob::ALL.to_vec(),
        Some(list) => list
            .split(',')
            .map(|k| {
                Knob::parse(k.trim()).ok_or_else(|| {
                    Error::Argument(format!(
                        "--knobs {list}: `{k}` is not one of aa, texture, shadows, ao, depth, env"
                    ))
                })
            })
            .collect::<Result<_, _>>()?,
    };
    if args.runs == 0 {
        return Err(Error::Argument("--runs must be at least 1".into()));
    }
    let opts = load_options(&args.sets, None, false, None)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| chart::default_out(&args.scene));
    let pool = thread_pool(args.threads)?;
    pool.install(|| {
        let mut scene = Scene::load(&args.scene, &opts)?;
        let title = format!(
            "{} frame {}, {}x{}, {} thread(s): time against error",
            args.scene
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            args.frame,
            scene.settings.width,
            scene.settings.height,
            rayon::current_num_threads()
        );
        eprintln!("{title}");
        let rows = chart::run(
            &mut scene,
            &ChartOptions {
                frame: args.frame,
                runs: args.runs,
                knobs,
                quick: args.quick,
            },
            &out,
            &title,
        )?;
        println!("| knob | setting | ms (median, min-max) | error | pareto |");
        println!("|---|---|---|---|---|");
        for r in &rows {
            println!(
                "| {} | {}{}{} | {:.1} ({:.1}-{:.1}) | {:.5} {} | {} |",
                r.knob.name(),
                r.setting,
                if r.default { " (default)" } else { "" },
                if r.reference { " (reference)" } else { "" },
                r.time.median_ms,
                r.time.min_ms,
                r.time.max_ms,
                r.error,
                r.knob.metric(),
                if r.pareto { "yes" } else { "" }
            );
        }
        eprintln!(
            "wrote {}, chart.png and chart.svg",
            out.join("chart.csv").display()
        );
        Ok(())
    })
}

fn gif(args: GifArgs) -> Result<(), Error> {
    use softraster::scene::settings::GifDither;
    let dither = match args.dither.as_str() {
        "none" => GifDither::None,
        "ordered" => GifDither::Ordered,
        "floyd-steinberg" => GifDither::FloydSteinberg,
        other => {
            return Err(Error::Argument(format!(
                "--dither {other}: expected none, ordered or floyd-steinberg"
            )));
        }
    };
    if args.delay_ms < 10 {
        return Err(Error::Argument(format!(
            "--delay-ms {}: GIF delays start at 10 ms",
            args.delay_ms
        )));
    }
    let info = softraster::output::gif::assemble(
        &args.frames,
        &args.output,
        softraster::output::gif::GifOptions {
            delay_ms: args.delay_ms,
            dither,
        },
    )?;
    eprintln!(
        "{}: {} frames, {}x{}, {} colors{}",
        args.output.display(),
        info.frames,
        info.width,
        info.height,
        info.colors,
        if info.transparent {
            " (one transparent)"
        } else {
            ""
        }
    );
    Ok(())
}

fn video(args: VideoArgs) -> Result<(), Error> {
    use softraster::output::video::{self, VideoOptions, VideoQuality};
    let quality = match args.quality.parse::<u8>() {
        Ok(q) if (1..=100).contains(&q) => VideoQuality::Quality(q),
        _ => VideoQuality::parse_bitrate(&args.quality).ok_or_else(|| {
            Error::Argument(format!(
                "--quality {}: expected 1 to 100, or a bitrate from 10k to 200M such as 2500k",
                args.quality
            ))
        })?,
    };
    if !(args.fps.is_finite() && args.fps > 0.0 && args.fps <= 240.0) {
        return Err(Error::Argument(format!(
            "--fps {}: expected more than 0 and at most 240",
            args.fps
        )));
    }
    match args.output.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("mp4") => {}
        _ => {
            return Err(Error::Argument(format!(
                "--output {}: the video must be an .mp4 file",
                args.output.display()
            )));
        }
    }
    let info = video::assemble(
        &args.frames,
        &args.output,
        VideoOptions {
            fps: args.fps,
            quality,
        },
    )?;
    eprintln!(
        "{}: {} frames, {}x{}, {} fps, {} bytes",
        args.output.display(),
        info.frames,
        info.width,
        info.height,
        info.fps,
        info.bytes
    );
    Ok(())
}

/// `--set` overrides (parsed) and `--out`, for loading a scene.
fn load_options(
    sets: &[String],
    out_dir: Option<PathBuf>,
    strict: bool,
    cache: Option<PathBuf>,
) -> Result<LoadOptions, Error> {
    let sets = sets
        .iter()
        .map(|s| s.parse::<SetOverride>())
        .collect::<Result<Vec<_>, _>>()?;
    Ok(LoadOptions {
        sets,
        out_dir,
        plain_look: false,
        strict,
        cache,
        max_memory: None,
        sandbox: false,
    })
}
