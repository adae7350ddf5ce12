//! The command line: flags -> validated library objects, progress display,
//! error chain and exit status (0 success, 1 render or I/O failure, 2 bad
//! scene, asset or arguments). Only this module knows about clap.

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::{Parser, Subcommand};

use softraster::batch::RenderJob;
use softraster::error::Error;
use softraster::scene::Scene;
use softraster::scene::build::LoadOptions;
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
    /// Render every frame of a scene to PNG.
    Render(RenderArgs),
    /// Time the reference turntables (load, per-frame, total).
    Bench(softraster::bench::BenchArgs),
    /// Write the procedural showcase assets (meshes, textures) to a directory.
    GenerateAssets {
        /// Output directory (the repository keeps them in assets/showcase).
        dir: PathBuf,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Output directory; wins over `output.dir`.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Half-open frame range `a..b`, or one frame `n`.
    #[arg(long)]
    frames: Option<String>,
    /// Render only this camera.
    #[arg(long)]
    camera: Option<String>,
    /// Override a scene key, e.g. `--set render.msaa=4` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No progress output.
    #[arg(long)]
    quiet: bool,
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
        Command::Render(args) => render(args),
        Command::Bench(args) => softraster::bench::run(&args),
        Command::GenerateAssets { dir } => softraster::procedural::write_showcase_assets(&dir),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e}");
            let mut source = std::error::Error::source(&e);
            while let Some(s) = source {
                eprintln!("  caused by: {s}");
                source = s.source();
            }
            e.exit_code()
        }
    }
}

/// `a..b` (half-open) or `n`.
pub fn parse_frames(s: &str, total: u32) -> Result<std::ops::Range<u32>, Error> {
    let bad = || Error::Argument(format!("--frames {s}: expected a..b (half-open) or n"));
    let r = if let Some((a, b)) = s.split_once("..") {
        let a = if a.is_empty() {
            0
        } else {
            a.trim().parse().map_err(|_| bad())?
        };
        let b = if b.is_empty() {
            total
        } else {
            b.trim().parse().map_err(|_| bad())?
        };
        a..b
    } else {
        let n: u32 = s.trim().parse().map_err(|_| bad())?;
        n..n + 1
    };
    if r.start >= r.end || r.end > total {
        return Err(Error::Argument(format!(
            "--frames {s}: the scene has frames 0..{total}"
        )));
    }
    Ok(r)
}

fn render(args: RenderArgs) -> Result<(), Error> {
    let sets = args
        .sets
        .iter()
        .map(|s| s.parse::<SetOverride>())
        .collect::<Result<Vec<_>, _>>()?;
    let opts = LoadOptions {
        sets,
        out_dir: args.out.clone(),
    };
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        if n == 0 {
            return Err(Error::Argument("--threads must be at least 1".into()));
        }
        builder = builder.num_threads(n);
    }
    let pool = builder
        .build()
        .map_err(|e| Error::Argument(format!("cannot start {:?} threads: {e}", args.threads)))?;
    pool.install(|| {
        let t0 = std::time::Instant::now();
        let scene = Scene::load(&args.scene, &opts)?;
        let load_s = t0.elapsed().as_secs_f64();
        if !args.quiet {
            for w in &scene.warnings {
                eprintln!("warning: {w}");
            }
        }
        let frames = match &args.frames {
            Some(f) => parse_frames(f, scene.animation.frames)?,
            None => 0..scene.animation.frames,
        };
        let cameras = match &args.camera {
            Some(name) => vec![scene
                .cameras
                .iter()
                .position(|c| &c.name == name)
                .ok_or_else(|| {
                    let names: Vec<_> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
                    Error::Argument(format!(
                        "--camera {name}: the scene has {}",
                        names.join(", ")
                    ))
                })?],
            None => (0..scene.cameras.len()).collect(),
        };
        let job = RenderJob {
            scene,
            frames,
            cameras,
        };
        if !args.quiet {
            eprintln!(
                "{}: {} triangles, {} frame(s) x {} camera(s) at {}x{}, loaded in {:.2} s, writing to {}",
                args.scene.display(),
                job.scene.triangle_count(),
                job.frames.len(),
                job.cameras.len(),
                job.scene.settings.width,
                job.scene.settings.height,
                load_s,
                job.scene.output.dir.display()
            );
        }
        let bar = (!args.quiet && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(job.total() as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} frames  {elapsed_precise} (eta {eta})  {msg}",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b
        });
        let t0 = std::time::Instant::now();
        let quiet = args.quiet;
        job.run(|d| {
            if let Some(b) = &bar {
                b.set_message(format!("{:.1} ms/frame", d.render_seconds * 1e3));
                b.inc(1);
            } else if !quiet {
                let files: Vec<_> = d.files.iter().map(|f| f.display().to_string()).collect();
                eprintln!(
                    "frame {} camera {}: {:.1} ms -> {}",
                    d.frame,
                    d.camera,
                    d.render_seconds * 1e3,
                    files.join(", ")
                );
            }
        })?;
        if let Some(b) = &bar {
            b.finish();
        }
        if !quiet {
            eprintln!(
                "done: {} frame(s) in {:.2} s",
                job.total(),
                t0.elapsed().as_secs_f64()
            );
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges() {
        assert_eq!(parse_frames("0..72", 72).unwrap(), 0..72);
        assert_eq!(parse_frames("5", 72).unwrap(), 5..6);
        assert_eq!(parse_frames("10..", 72).unwrap(), 10..72);
        assert!(parse_frames("5..5", 72).is_err());
        assert!(parse_frames("70..80", 72).is_err());
        assert!(parse_frames("x", 72).is_err());
    }
}
