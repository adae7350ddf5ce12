//! `softraster chart`: what each knob costs in time and buys in error, for
//! one frame of the user's own scene.
//!
//! Each knob is swept with everything else at the scene's settings (AO off
//! outside its own sweep: at the reference's sample counts it would
//! dominate every other measurement), and each setting is compared with the
//! most accurate setting softraster has for that knob:
//!
//! | knob | settings | reference | error |
//! |---|---|---|---|
//! | aa | MSAA 1/2/4/8/16, SSAA 2x2/4x4 | SSAA 16x16 (less when 16x the frame exceeds 16384 px) | mean FLIP |
//! | texture | nearest, bilinear, trilinear, anisotropic 2/4/8/16 | SSAA 16x16 with anisotropic 16 | mean FLIP over interior pixels |
//! | shadows | hard, pcf at 512-4096 | ray-traced shadows | mean FLIP |
//! | ao | SSAO 4-32 samples at 0.5, 1 and 2 times the radius; ray-traced 16-256 | ray-traced, 1024 rays, same radius | RMSE of the AO buffer |
//! | depth | standard, reverse-Z | the analytic nearest surface | fraction of pixels where the depth test picks the farther of two near-coplanar quads (a built-in far test scene) |
//!
//! Times: the frame's render and resolve, median of `runs` renders with
//! their spread, threads as configured. Errors are deterministic: the same
//! command gives the same errors.

pub mod plot;

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::tools::compare::{Metric, score};
use softraster::error::Error;
use softraster::output::{self, Image8};
use softraster::render::{Frame, Renderer, Shot};
use softraster::scene::environment::{DEFAULT_PREFILTER_SIZE, EnvMethod};
use softraster::scene::settings::{AoMethod, DepthMode, ShadowMethod, TextureFilter};
use softraster::scene::{AoSettings, Scene};

/// The knobs, in chart order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Knob {
    Aa,
    Texture,
    Shadows,
    Ao,
    Depth,
    /// Environment lighting: prefiltered against sampled.
    Env,
}

impl Knob {
    pub const ALL: [Knob; 6] = [
        Knob::Aa,
        Knob::Texture,
        Knob::Shadows,
        Knob::Ao,
        Knob::Depth,
        Knob::Env,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Knob::Aa => "aa",
            Knob::Texture => "texture",
            Knob::Shadows => "shadows",
            Knob::Ao => "ao",
            Knob::Depth => "depth",
            Knob::Env => "env",
        }
    }

    pub fn parse(s: &str) -> Option<Knob> {
        Knob::ALL.into_iter().find(|k| k.name() == s)
    }

    pub fn metric(self) -> &'static str {
        match self {
            Knob::Aa | Knob::Shadows | Knob::Env => "flip",
            Knob::Texture => "flip-interior",
            Knob::Ao => "rmse",
            Knob::Depth => "failure-fraction",
        }
    }
}

/// Wall time of one setting's frame.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    pub median_ms: f64,
    pub min_ms: f64,
    pub max_ms: f64,
    pub runs: usize,
}

/// One row of the chart's CSV.
#[derive(Debug, Clone)]
pub struct Row {
    pub knob: Knob,
    pub setting: String,
    /// softraster's default for this knob.
    pub default: bool,
    /// This row is the knob's reference (its error is against itself).
    pub reference: bool,
    pub time: Timing,
    pub error: f64,
    /// What the error was measured against.
    pub against: String,
    /// Not dominated among the settings of its knob measured against the
    /// same reference (no other is at least as fast and at least as
    /// accurate, and better in one). AO has one reference per radius.
    pub pareto: bool,
}

/// What to sweep.
#[derive(Debug, Clone)]
pub struct ChartOptions {
    pub frame: u32,
    pub runs: usize,
    pub knobs: Vec<Knob>,
    /// Fewer settings per knob and a smaller reference (for tests).
    pub quick: bool,
}

/// Renders `frame` of `scene` up to `runs` times (fewer when a render takes
/// seconds: at most about 4 s per setting after the first), timed; the
/// last frame and its 8-bit image. The setting's renderer is prepared
/// first, untimed: mip chains (kept with the textures, so built once per
/// sweep), BVHs and the environment are loading, not rendering.
fn timed(scene: &Scene, frame: u32, runs: usize) -> Result<(Frame, Image8, Timing), Error> {
    let renderer = Renderer::new(scene);
    renderer.prepare();
    let mut f = Frame::new(0, 0);
    let mut times = Vec::new();
    let t_all = Instant::now();
    let mut img = None;
    while times.len() < runs.max(1) && (times.is_empty() || t_all.elapsed().as_secs_f64() < 4.0) {
        let t = Instant::now();
        renderer.render(Shot::new(0, frame), &mut f)?;
        img = Some(output::resolve(&f, &scene.settings));
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let timing = Timing {
        median_ms: times[times.len() / 2],
        min_ms: times[0],
        max_ms: times[times.len() - 1],
        runs: times.len(),
    };
    let img = img.unwrap_or_else(|| output::resolve(&f, &scene.settings));
    Ok((f, img, timing))
}

/// The reference setting measured like the others: rendered again,
/// compared with the first render (deterministic rendering makes this 0),
/// its time the median of both renders.
fn reference_row(
    scene: &Scene,
    opts: &ChartOptions,
    first: Timing,
    error: impl FnOnce(&Frame, &Image8) -> Result<f64, Error>,
) -> Result<(Timing, f64), Error> {
    let (f, img, t) = timed(scene, opts.frame, 1)?;
    let (lo, hi) = (first.min_ms.min(t.min_ms), first.max_ms.max(t.max_ms));
    let time = Timing {
        median_ms: (first.median_ms + t.median_ms) * 0.5,
        min_ms: lo,
        max_ms: hi,
        runs: first.runs + t.runs,
    };
    Ok((time, error(&f, &img)?))
}

fn flip(reference: &Image8, img: &Image8, mask: Option<&[bool]>) -> Result<f64, Error> {
    let s =
        score(reference, img, Metric::Flip).map_err(|e| Error::Render(format!("chart: {e}")))?;
    Ok(match mask {
        None => s.value,
        Some(m) => {
            let (mut sum, mut n) = (0.0f64, 0usize);
            for (e, &keep) in s.error_map.iter().zip(m) {
                if keep {
                    sum += *e as f64;
                    n += 1;
                }
            }
            sum / n.max(1) as f64
        }
    })
}

/// Pixels away from silhouettes and depth edges: the pixel and its four
/// neighbours are covered and within 1% of each other's depth. Texture
/// filtering is judged there, so edge anti-aliasing does not enter.
fn interior_mask(f: &Frame) -> Vec<bool> {
    let (w, h) = (f.width as usize, f.height as usize);
    let mut m = vec![false; w * h];
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let i = y * w + x;
            let d = f.depth[i];
            if !d.is_finite() {
                continue;
            }
            m[i] = [i - 1, i + 1, i - w, i + w].iter().all(|&j| {
                let e = f.depth[j];
                e.is_finite() && (e - d).abs() <= 0.01 * d
            });
        }
    }
    m
}

/// RMSE of the AO buffer against the reference's, over covered pixels.
fn ao_rmse(got: &Frame, reference: &Frame) -> f64 {
    crate::tools::accuracy::ao_error([(got, reference)]).0
}

/// Marks the Pareto front of each knob and reference, by the time and
/// error as `csv` writes them (so a reader of the CSV finds the same
/// front: two times equal to the written microsecond tie).
fn mark_pareto(rows: &mut [Row]) {
    let written = |x: f64, places: usize| -> f64 { format!("{x:.places$}").parse().unwrap_or(x) };
    let key: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (written(r.time.median_ms, 3), written(r.error, 6)))
        .collect();
    for i in 0..rows.len() {
        let (r, (t, e)) = (&rows[i], key[i]);
        let dominated = rows
            .iter()
            .zip(&key)
            .enumerate()
            .any(|(j, (o, &(ot, oe)))| {
                j != i
                    && o.knob == r.knob
                    && o.against == r.against
                    && ot <= t
                    && oe <= e
                    && (ot < t || oe < e)
            });
        rows[i].pareto = !dominated;
    }
}

/// The largest supersampling factor (at most 16) the frame allows.
fn reference_ssaa(scene: &Scene, quick: bool) -> u32 {
    let side = scene.settings.width.max(scene.settings.height).max(1);
    let cap = if quick { 4 } else { 16 };
    (16384 / side).clamp(1, cap)
}

/// Runs the sweep. `scene` is changed setting by setting and restored.
pub fn sweep(scene: &mut Scene, opts: &ChartOptions) -> Result<Vec<Row>, Error> {
    if opts.frame >= scene.animation.frames {
        return Err(Error::Argument(format!(
            "--frame {}: the scene has frames 0..{}",
            opts.frame, scene.animation.frames
        )));
    }
    // Mip chains up front: building them is loading, not rendering.
    // They stay with the textures, which every setting's renderer shares.
    Renderer::new(scene).build_all_mips();
    let original = scene.settings.clone();
    let original_lights = scene.lights.clone();
    let mut rows = Vec::new();
    let result = (|| -> Result<(), Error> {
        for &knob in &opts.knobs {
            scene.settings = original.clone();
            scene.lights = original_lights.clone();
            if knob != Knob::Ao {
                scene.settings.ao.method = AoMethod::Off;
            }
            match knob {
                Knob::Aa => sweep_aa(scene, opts, &mut rows)?,
                Knob::Texture => sweep_texture(scene, opts, &mut rows)?,
                Knob::Shadows => sweep_shadows(scene, opts, &mut rows)?,
                Knob::Ao => sweep_ao(scene, opts, &mut rows)?,
                Knob::Depth => sweep_depth(opts, &mut rows)?,
                Knob::Env => sweep_env(scene, opts, &mut rows)?,
            }
        }
        Ok(())
    })();
    scene.settings = original;
    scene.lights = original_lights;
    result?;
    mark_pareto(&mut rows);
    Ok(rows)
}

fn row(
    knob: Knob,
    setting: impl Into<String>,
    default: bool,
    reference: bool,
    time: Timing,
    error: f64,
    against: &str,
) -> Row {
    Row {
        knob,
        setting: setting.into(),
        default,
        reference,
        time,
        error,
        against: against.to_string(),
        pareto: false,
    }
}

fn sweep_aa(scene: &mut Scene, opts: &ChartOptions, rows: &mut Vec<Row>) -> Result<(), Error> {
    let k = reference_ssaa(scene, opts.quick);
    scene.settings.msaa = 1;
    scene.settings.ssaa = k;
    let (_, reference, t) = timed(scene, opts.frame, 1)?;
    let against = format!("ssaa {k}x{k}");
    let (t, e) = reference_row(scene, opts, t, |_, img| flip(&reference, img, None))?;
    rows.push(row(Knob::Aa, &against, false, true, t, e, &against));
    let settings: &[(u32, u32)] = if opts.quick {
        &[(1, 1), (4, 1), (1, 2)]
    } else {
        &[(1, 1), (2, 1), (4, 1), (8, 1), (16, 1), (1, 2), (1, 4)]
    };
    for &(msaa, ssaa) in settings {
        scene.settings.msaa = msaa;
        scene.settings.ssaa = ssaa;
        let (_, img, t) = timed(scene, opts.frame, opts.runs)?;
        let name = if ssaa > 1 {
            format!("ssaa {ssaa}x{ssaa}")
        } else {
            format!("msaa {msaa}")
        };
        let e = flip(&reference, &img, None)?;
        rows.push(row(
            Knob::Aa,
            name,
            msaa == 1 && ssaa == 1,
            false,
            t,
            e,
            &against,
        ));
    }
    Ok(())
}

fn sweep_texture(scene: &mut Scene, opts: &ChartOptions, rows: &mut Vec<Row>) -> Result<(), Error> {
    if scene.textures.is_empty() {
        return Ok(());
    }
    let k = reference_ssaa(scene, opts.quick);
    let base = scene.settings.clone();
    scene.settings.ssaa = k;
    scene.settings.msaa = 1;
    scene.settings.texture_filter = TextureFilter::Anisotropic;
    scene.settings.max_anisotropy = 16.0;
    let (reference_frame, reference, t) = timed(scene, opts.frame, 1)?;
    let against = format!("ssaa {k}x{k}, anisotropic 16");
    let (t, e) = reference_row(scene, opts, t, |_, img| {
        flip(&reference, img, Some(&interior_mask(&reference_frame)))
    })?;
    rows.push(row(Knob::Texture, &against, false, true, t, e, &against));
    scene.settings = base;
    let settings: &[(TextureFilter, f32, &str)] = if opts.quick {
        &[
            (TextureFilter::Nearest, 1.0, "nearest"),
            (TextureFilter::Anisotropic, 16.0, "anisotropic 16"),
        ]
    } else {
        &[
            (TextureFilter::Nearest, 1.0, "nearest"),
            (TextureFilter::Bilinear, 1.0, "bilinear"),
            (TextureFilter::Trilinear, 1.0, "trilinear"),
            (TextureFilter::Anisotropic, 2.0, "anisotropic 2"),
            (TextureFilter::Anisotropic, 4.0, "anisotropic 4"),
            (TextureFilter::Anisotropic, 8.0, "anisotropic 8"),
            (TextureFilter::Anisotropic, 16.0, "anisotropic 16"),
        ]
    };
    let mut mask = None;
    for &(filter, aniso, name) in settings {
        scene.settings.texture_filter = filter;
        scene.settings.max_anisotropy = aniso;
        let (f, img, t) = timed(scene, opts.frame, opts.runs)?;
        let m = mask.get_or_insert_with(|| interior_mask(&f));
        let e = flip(&reference, &img, Some(m))?;
        let default = filter == TextureFilter::Anisotropic && aniso == 16.0;
        rows.push(row(Knob::Texture, name, default, false, t, e, &against));
    }
    Ok(())
}

/// Environment lighting, for scenes with an `[environment]`: the
/// prefiltered split sum at several prefilter sizes (the sharpest glossy
/// level 32 to 256 texels wide; each with a renderer of its own, prepared
/// first, so the time is per frame; the one-off prefiltering time goes to
/// standard error) and sampled estimates of 4 to 64 direction pairs,
/// against the sampled reference (256 pairs; 64 with `quick`).
fn sweep_env(scene: &mut Scene, opts: &ChartOptions, rows: &mut Vec<Row>) -> Result<(), Error> {
    let Some(original) = scene
        .environment
        .as_ref()
        .map(|e| (e.method, e.prefilter_size))
    else {
        return Ok(());
    };
    let set = |scene: &mut Scene, m: EnvMethod, size: u32| {
        if let Some(e) = scene.environment.as_mut() {
            e.method = m;
            e.prefilter_size = size;
        }
    };
    let reference = if opts.quick { 64 } else { 256 };
    set(
        scene,
        EnvMethod::Sampled {
            samples: reference,
            bounces: 1,
        },
        original.1,
    );
    let (_, reference_img, t) = timed(scene, opts.frame, 1)?;
    let against = format!("sampled {reference}");
    let (t, e) = reference_row(scene, opts, t, |_, img| flip(&reference_img, img, None))?;
    rows.push(row(Knob::Env, &against, false, true, t, e, &against));
    let sizes: &[u32] = if opts.quick {
        &[64, 128]
    } else {
        &[32, 64, 128, 256]
    };
    for &size in sizes {
        set(scene, EnvMethod::Prefiltered, size);
        let prefilter = Renderer::new(scene).time_environment_prefilter() * 1e3;
        let (_, img, t) = timed(scene, opts.frame, opts.runs)?;
        let e = flip(&reference_img, &img, None)?;
        // Once per run, not per frame: printed beside the table (the
        // setting's name stays the same from run to run).
        eprintln!("env: prefilter_size {size}: prefiltering takes {prefilter:.0} ms once");
        rows.push(row(
            Knob::Env,
            format!("prefiltered {size}"),
            size == DEFAULT_PREFILTER_SIZE,
            false,
            t,
            e,
            &against,
        ));
    }
    let counts: &[u32] = if opts.quick { &[4, 16] } else { &[4, 16, 64] };
    for &samples in counts {
        set(
            scene,
            EnvMethod::Sampled {
                samples,
                bounces: 1,
            },
            original.1,
        );
        let (_, img, t) = timed(scene, opts.frame, opts.runs)?;
        let e = flip(&reference_img, &img, None)?;
        rows.push(row(
            Knob::Env,
            format!("sampled {samples}"),
            false,
            false,
            t,
            e,
            &against,
        ));
    }
    set(scene, original.0, original.1);
    Ok(())
}

fn sweep_shadows(scene: &mut Scene, opts: &ChartOptions, rows: &mut Vec<Row>) -> Result<(), Error> {
    if scene.lights.is_empty() {
        return Ok(());
    }
    // Without a shadowing light, measure what shadows from every light
    // would cost.
    let note = if scene.lights.iter().any(|l| l.shadows) {
        ""
    } else {
        for l in &mut scene.lights {
            l.shadows = true;
        }
        " (all lights made to cast)"
    };
    scene.settings.shadows = ShadowMethod::Raytraced;
    let (_, reference, t) = timed(scene, opts.frame, opts.runs)?;
    let against = format!("raytraced{note}");
    let (t, e) = reference_row(scene, opts, t, |_, img| flip(&reference, img, None))?;
    rows.push(row(Knob::Shadows, "raytraced", true, true, t, e, &against));
    let sizes: &[u32] = if opts.quick {
        &[512, 2048]
    } else {
        &[512, 1024, 2048, 4096]
    };
    for (method, name) in [(ShadowMethod::Hard, "hard"), (ShadowMethod::Pcf, "pcf")] {
        for &size in sizes {
            scene.settings.shadows = method;
            scene.settings.shadow_map_size = size;
            let (_, img, t) = timed(scene, opts.frame, opts.runs)?;
            let e = flip(&reference, &img, None)?;
            rows.push(row(
                Knob::Shadows,
                format!("{name} {size}"),
                false,
                false,
                t,
                e,
                &against,
            ));
        }
    }
    Ok(())
}

fn sweep_ao(scene: &mut Scene, opts: &ChartOptions, rows: &mut Vec<Row>) -> Result<(), Error> {
    let r = scene
        .settings
        .ao
        .radius
        .unwrap_or(scene.bounds_radius * 0.2);
    let default_r = scene.bounds_radius * 0.2;
    let rays = if opts.quick { 256 } else { 1024 };
    let radii: &[f32] = if opts.quick { &[1.0] } else { &[0.5, 1.0, 2.0] };
    let samples: &[u32] = if opts.quick {
        &[4, 16]
    } else {
        &[4, 8, 16, 32]
    };
    for &scale in radii {
        let radius = r * scale;
        scene.settings.ao = AoSettings {
            method: AoMethod::Raytraced,
            radius: Some(radius),
            samples: rays,
        };
        let (reference, _, t) = timed(scene, opts.frame, 1)?;
        let noise = crate::tools::accuracy::ao_noise_bound(&reference, rays);
        let against =
            format!("raytraced {rays} rays, radius {radius:.4} (noise RMSE below {noise:.4})");
        let (t, e) = reference_row(scene, opts, t, |f, _| Ok(ao_rmse(f, &reference)))?;
        rows.push(row(
            Knob::Ao,
            format!("raytraced {rays} r{scale}"),
            false,
            true,
            t,
            e,
            &against,
        ));
        // SSAO at every radius; ray-traced with fewer rays at the scene's.
        let mut methods: Vec<(AoMethod, u32)> =
            samples.iter().map(|&n| (AoMethod::Gtao, n)).collect();
        if (scale - 1.0).abs() < 1e-6 {
            let rt: &[u32] = if opts.quick { &[16] } else { &[16, 64, 256] };
            methods.extend(rt.iter().map(|&n| (AoMethod::Raytraced, n)));
        }
        for (method, n) in methods {
            scene.settings.ao = AoSettings {
                method,
                radius: Some(radius),
                samples: n,
            };
            let (f, _, t) = timed(scene, opts.frame, opts.runs)?;
            let e = ao_rmse(&f, &reference);
            let ssao = method == AoMethod::Gtao;
            let default =
                ssao && n == 16 && (radius - default_r).abs() <= 1e-6 * default_r.max(1e-6);
            let name = if ssao { "ssao" } else { "raytraced" };
            rows.push(row(
                Knob::Ao,
                format!("{name} {n} r{scale}"),
                default,
                false,
                t,
                e,
                &against,
            ));
        }
    }
    Ok(())
}

/// The depth test scene: four pairs of quads, the back one of each 0.02%
/// of its distance behind the front one and drawn first, at 20, 100, 500
/// and 2500 units from a camera with near = 0.05. Unlit: front red, back
/// green.
fn depth_scene(dir: &Path, mode: &str) -> Result<Scene, Error> {
    use std::fmt::Write as _;
    let mut obj = String::from("# softraster depth test quads (generated)\nmtllib quads.mtl\n");
    let mut v = 0;
    for (i, d) in [20.0f32, 100.0, 500.0, 2500.0].iter().enumerate() {
        // Quarter i of the view: x from -0.36 + 0.18 i (times the distance).
        let x0 = -0.36 + 0.18 * i as f32;
        for (layer, mat) in [(1.0002f32, "back"), (1.0, "front")] {
            let z = d * layer;
            let (xa, xb, ya, yb) = (x0 * z, (x0 + 0.16) * z, -0.15 * z, 0.15 * z);
            let _ = writeln!(obj, "usemtl {mat}");
            for (x, y) in [(xa, ya), (xb, ya), (xb, yb), (xa, yb)] {
                let _ = writeln!(obj, "v {x} {y} {}", -z);
            }
            let _ = writeln!(obj, "f {} {} {}", v + 1, v + 2, v + 3);
            let _ = writeln!(obj, "f {} {} {}", v + 1, v + 3, v + 4);
            v += 4;
        }
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    for (name, text) in [
        ("quads.obj", obj),
        (
            "quads.mtl",
            "newmtl back\nKd 0 1 0\nnewmtl front\nKd 1 0 0\n".to_string(),
        ),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, text).map_err(|e| Error::io(&p, e))?;
    }
    let text = format!(
        "[output]\nwidth = 320\nheight = 120\n[render]\nshading = \"unlit\"\ndepth = \"{mode}\"\n\
         [[model]]\npath = \"quads.obj\"\n\
         [[camera]]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\nfov = 40.0\nnear = 0.05\nfar = 5000.0\n"
    );
    Scene::from_text(
        &dir.join("depth.toml"),
        &text,
        &softraster::scene::assemble::LoadOptions::plain(),
    )
}

fn sweep_depth(opts: &ChartOptions, rows: &mut Vec<Row>) -> Result<(), Error> {
    let dir = std::env::temp_dir().join(format!("softraster-chart-depth-{}", std::process::id()));
    let result = (|| {
        for (mode, name) in [
            (DepthMode::Standard, "standard"),
            (DepthMode::ReverseZ, "reverse-z"),
        ] {
            let scene = depth_scene(&dir, name)?;
            debug_assert_eq!(scene.settings.depth, mode);
            let (f, _, t) = timed(&scene, 0, opts.runs)?;
            let (mut red, mut green) = (0usize, 0usize);
            for c in &f.color {
                if c.x > 0.5 && c.y < 0.5 {
                    red += 1;
                } else if c.y > 0.5 && c.x < 0.5 {
                    green += 1;
                }
            }
            let e = green as f64 / (red + green).max(1) as f64;
            rows.push(row(
                Knob::Depth,
                name,
                mode == DepthMode::ReverseZ,
                false,
                t,
                e,
                "the nearer quad everywhere (analytic)",
            ));
        }
        Ok(())
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// A CSV field, quoted when it holds a comma or a quote (RFC 4180).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The CSV: one row per setting.
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "knob,setting,default,reference,ms_median,ms_min,ms_max,runs,error,metric,pareto,against\n",
    );
    for r in rows {
        s.push_str(&format!(
            "{},{},{},{},{:.3},{:.3},{:.3},{},{:.6},{},{},{}\n",
            r.knob.name(),
            csv_field(&r.setting),
            r.default,
            r.reference,
            r.time.median_ms,
            r.time.min_ms,
            r.time.max_ms,
            r.time.runs,
            r.error,
            r.knob.metric(),
            r.pareto,
            csv_field(&r.against)
        ));
    }
    s
}

/// Runs the sweep and writes `chart.csv`, `chart.png` and `chart.svg` into
/// `out`. Returns the rows.
pub fn run(
    scene: &mut Scene,
    opts: &ChartOptions,
    out: &Path,
    title: &str,
) -> Result<Vec<Row>, Error> {
    let rows = sweep(scene, opts)?;
    let csv_path = out.join("chart.csv");
    let text = csv(&rows);
    output::write_atomic(&csv_path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes())
            .map_err(|e| Error::io(&csv_path, e))
    })?;
    plot::write(&rows, title, &out.join("chart.png"), &out.join("chart.svg"))?;
    Ok(rows)
}

/// The default output directory: `out/<scene stem>-chart`.
pub fn default_out(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    PathBuf::from("out").join(format!("{stem}-chart"))
}
