//! Time against error of the shadow and ambient-occlusion methods, on the
//! shared models (`softraster bench --case shadows | ao`): each method
//! renders the same 700x700 frames, timed, and is compared with the
//! ray-traced reference of the same frames.

use std::path::Path;
use std::time::Instant;

use softraster::error::Error;
use softraster::output;
use softraster::render::{Frame, Renderer, Shot};
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;

/// One method's row of an accuracy table.
#[derive(Debug, Clone)]
pub struct Row {
    pub method: String,
    /// Median frame time (render and resolve), milliseconds.
    pub ms: f64,
    /// Shadows: mean absolute error of linear RGB; AO: RMSE of the AO
    /// buffer over covered pixels.
    pub error: f64,
    /// Shadows: percentage of pixels whose 8-bit color differs by more than
    /// 8 levels from the reference; AO: worst absolute AO error.
    pub second: f64,
}

fn load(dir: &Path, text: &str) -> Result<Scene, Error> {
    Scene::from_text(&dir.join("accuracy.toml"), text, &LoadOptions::plain())
}

/// Renders frames `frames` of `scene`: the frames and the median time.
fn timed(scene: &Scene, frames: &[u32]) -> Result<(Vec<Frame>, f64), Error> {
    let mut out = Vec::new();
    let mut times = Vec::new();
    // One buffer, as a render job reuses it; copies kept for comparison.
    let mut frame = Frame::new(0, 0);
    let renderer = Renderer::new(scene);
    for &f in frames {
        let t = Instant::now();
        renderer.render(Shot::new(0, f), &mut frame)?;
        let _ = output::resolve(&frame, &scene.settings);
        times.push(t.elapsed().as_secs_f64() * 1e3);
        out.push(frame.clone());
    }
    times.sort_by(f64::total_cmp);
    Ok((out, times[times.len() / 2]))
}

/// diablo3 standing on the tinyrenderer floor, lit by one directional
/// light at 35 degrees elevation that casts shadows, turning 5 degrees a
/// frame. `{render}` is where each method's settings go.
fn diablo3_scene(assets: &Path, size: u32) -> String {
    let t = assets.join("tinyrenderer");
    format!(
        "[output]\nwidth = {size}\nheight = {size}\n[render]\n{{render}}\n\
         [[model]]\npath = \"{}\"\nscale = [2.0, 1.0, 2.0]\n\
         [[model]]\npath = \"{}\"\n[model.material]\nmap_kd = \"{}\"\n\
         [[light]]\nkind = \"directional\"\ndirection = [-0.47, -0.57, -0.67]\nirradiance = 2.0\nshadows = true\n\
         [[camera]]\neye = [0.0, 0.9, 3.6]\ntarget = [0.0, -0.2, 0.0]\nfov = 45.0\n\
         [animation]\nframes = 72\nturntable = {{ axis = [0.0, 1.0, 0.0], degrees = 360.0 }}\n",
        t.join("floor.obj").display(),
        t.join("diablo3_pose/diablo3_pose.obj").display(),
        t.join("diablo3_pose/diablo3_pose_diffuse.tga").display(),
    )
}

/// Shadow methods (hard and PCF at 1024, 2048, 4096; ray-traced) on
/// diablo3, against ray-traced shadows.
pub fn shadows(assets: &Path, size: u32, frames: &[u32]) -> Result<Vec<Row>, Error> {
    let dir = assets.to_path_buf();
    let text = diablo3_scene(assets, size);
    let scene = |render: &str| load(&dir, &text.replace("{render}", render));
    let (reference, rt_ms) = timed(&scene("shadows = \"raytraced\"")?, frames)?;
    let (_, off_ms) = timed(&scene("shadows = \"off\"")?, frames)?;
    let mut rows = vec![Row {
        method: "off (no shadow pass)".into(),
        ms: off_ms,
        error: f64::NAN,
        second: f64::NAN,
    }];
    for filter in ["hard", "pcf"] {
        for map in [1024, 2048, 4096] {
            let s = scene(&format!("shadows = \"{filter}\"\nshadow_map_size = {map}"))?;
            let (got, ms) = timed(&s, frames)?;
            let (mae, off) = color_error(&got, &reference, &s);
            rows.push(Row {
                method: format!("{filter} {map}"),
                ms,
                error: mae,
                second: off,
            });
        }
    }
    rows.push(Row {
        method: "raytraced (reference)".into(),
        ms: rt_ms,
        error: 0.0,
        second: 0.0,
    });
    Ok(rows)
}

/// Mean absolute linear error, and the percentage of pixels whose 8-bit
/// colors differ by more than 8 levels.
fn color_error(got: &[Frame], reference: &[Frame], s: &Scene) -> (f64, f64) {
    let (mut sum, mut off, mut n) = (0.0f64, 0usize, 0usize);
    for (a, b) in got.iter().zip(reference) {
        for (x, y) in a.color.iter().zip(&b.color) {
            sum += (x.truncate() - y.truncate()).abs().element_sum() as f64 / 3.0;
        }
        let (ia, ib) = (
            output::resolve(a, &s.settings),
            output::resolve(b, &s.settings),
        );
        for (pa, pb) in ia.data.chunks(3).zip(ib.data.chunks(3)) {
            if pa.iter().zip(pb).any(|(u, v)| u.abs_diff(*v) > 8) {
                off += 1;
            }
        }
        n += a.color.len();
    }
    (sum / n as f64, 100.0 * off as f64 / n as f64)
}

/// AO methods (SSAO at 8..64 samples, ray-traced at 16..256 rays) on
/// bunny-on-plane and diablo3-on-plane, against ray-traced AO with
/// `reference_samples` rays, at the SSAO default radius (a fifth of the
/// scene's bounding radius).
pub fn ao(
    assets: &Path,
    size: u32,
    frames: &[u32],
    reference_samples: u32,
) -> Result<Vec<(String, Vec<Row>)>, Error> {
    let dir = std::env::temp_dir().join(format!("softraster-ao-{}", std::process::id()));
    let mut out = Vec::new();
    for (name, model, eye) in AO_SCENES {
        let (text, radius) = ao_scene(&dir, &assets.join(model), eye, size)?;
        let scene = |ao: &str| load(&dir, &text.replace("{ao}", ao));
        let rt = |n: u32| format!("{{ method = \"raytraced\", samples = {n}, radius = {radius} }}");
        let (reference, ref_ms) = timed(&scene(&rt(reference_samples))?, frames)?;
        let (_, off_ms) = timed(&scene("{ method = \"off\" }")?, frames)?;
        let mut rows = vec![Row {
            method: "off".into(),
            ms: off_ms,
            error: f64::NAN,
            second: f64::NAN,
        }];
        let mut methods: Vec<(String, String)> = [4, 8, 16, 32, 64]
            .iter()
            .map(|n| {
                (
                    format!("ssao {n}"),
                    format!("{{ method = \"ssao\", samples = {n}, radius = {radius} }}"),
                )
            })
            .collect();
        for n in [16, 64, 256] {
            methods.push((format!("raytraced {n}"), rt(n)));
        }
        for (label, ao) in methods {
            let (got, ms) = timed(&scene(&ao)?, frames)?;
            let (rmse, worst) = ao_error(got.iter().zip(&reference));
            rows.push(Row {
                method: label,
                ms,
                error: rmse,
                second: worst,
            });
        }
        rows.push(Row {
            method: format!("raytraced {reference_samples} (reference)"),
            ms: ref_ms,
            error: 0.0,
            second: 0.0,
        });
        out.push((name.to_string(), rows));
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(out)
}

/// The AO comparison scenes: name, model under the shared assets, eye.
pub const AO_SCENES: [(&str, &str, &str); 2] = [
    (
        "bunny on a plane",
        "common/stanford-bunny.obj",
        "[0.6, 0.7, 2.0]",
    ),
    (
        "diablo3 on a plane",
        "tinyrenderer/diablo3_pose/diablo3_pose.obj",
        "[0.6, 0.45, 1.9]",
    ),
];

/// `model` normalized, standing on a ground plane (written into `dir`) at
/// its lowest point, seen from `eye`, turning 5 degrees a frame. The text
/// holds `{ao}` where `render.ao` goes. Returns it and the SSAO default
/// radius (a fifth of the scene's bounding radius), used by every method.
pub fn ao_scene(dir: &Path, model: &Path, eye: &str, size: u32) -> Result<(String, f32), Error> {
    if !model.is_file() {
        return Err(Error::asset(model, None, "missing shared model"));
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let ground = dir.join("ground.obj");
    std::fs::write(
        &ground,
        softraster::procedural::ground(1.0, 0.0, 1.0)
            .to_obj("g", "none.mtl", "m")
            .text
            .replace("mtllib none.mtl\n", "")
            .replace("usemtl m\n", ""),
    )
    .map_err(|e| Error::io(&ground, e))?;
    let models = format!(
        "[[model]]\npath = \"{}\"\nnormalize = true\n",
        model.display()
    );
    let probe = load(dir, &format!("[output]\nwidth = 8\nheight = 8\n{models}"))?;
    let mut lo = f32::INFINITY;
    for m in &probe.models {
        for p in &m.mesh.positions {
            lo = lo.min(m.world_from_object.transform_point3(*p).y);
        }
    }
    let text = format!(
        "[output]\nwidth = {size}\nheight = {size}\n[render]\nao = {{ao}}\n{models}\
         [[model]]\npath = \"ground.obj\"\ntranslate = [0.0, {lo}, 0.0]\nscale = {}\n\
         [[camera]]\neye = {eye}\ntarget = [0.0, -0.05, 0.0]\nfov = 45.0\n\
         [animation]\nframes = 72\nturntable = {{ axis = [0.0, 1.0, 0.0], degrees = 360.0 }}\n",
        probe.bounds_radius * 3.0
    );
    Ok((text, probe.bounds_radius * 0.2))
}

/// RMSE and worst absolute error of the AO buffers over the reference's
/// covered pixels, pooled over pairs of frames (got, reference).
pub fn ao_error<'a>(pairs: impl IntoIterator<Item = (&'a Frame, &'a Frame)>) -> (f64, f64) {
    let (mut sum, mut worst, mut n) = (0.0f64, 0.0f64, 0usize);
    for (a, b) in pairs {
        for i in 0..a.ao.len().min(b.ao.len()) {
            if b.depth[i].is_finite() {
                let e = (a.ao[i] - b.ao[i]) as f64;
                sum += e * e;
                worst = worst.max(e.abs());
                n += 1;
            }
        }
    }
    ((sum / n.max(1) as f64).sqrt(), worst)
}

/// A bound on the noise of ray-traced AO with `rays` rays per pixel:
/// sqrt(mean p(1-p)/rays) over covered pixels, the RMSE of that many
/// independent rays. softraster's rays are stratified (Hammersley), which
/// is far less noisy: 1024 of them are within 0.0011 RMSE of the analytic
/// AO in tests/it/shadows.rs, against a bound of about 0.01.
pub fn ao_noise_bound(frame: &Frame, rays: u32) -> f64 {
    let (mut var, mut n) = (0.0f64, 0usize);
    for (a, d) in frame.ao.iter().zip(&frame.depth) {
        if d.is_finite() {
            let p = *a as f64;
            var += p * (1.0 - p) / rays as f64;
            n += 1;
        }
    }
    (var / n.max(1) as f64).sqrt()
}

/// One anti-aliasing setting's row of the edge-accuracy table.
#[derive(Debug, Clone)]
pub struct EdgeRow {
    pub method: String,
    /// Median frame time (render and resolve), milliseconds.
    pub ms: f64,
    /// Mean absolute error of linear RGB against the reference (the scene
    /// is white on black and unlit, so this is the coverage error).
    pub mae: f64,
    /// Root-mean-square error of linear RGB.
    pub rmse: f64,
    /// Mean FLIP error of the 8-bit frames (`softraster compare`).
    pub flip: f64,
}

/// The edge-accuracy scene, written into `dir`: white unlit shapes on
/// black seen by an orthographic camera, each a known hard case for
/// coverage: a star of 12 thin wedges meeting at a point, sub-pixel wires
/// (0.2 to 0.6 pixels wide at 160x120) at three angles, and a sphere's
/// silhouette. Returns the scene text with `{render}` for the settings.
pub fn edge_scene(dir: &Path) -> Result<String, Error> {
    use std::fmt::Write as _;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut star = String::from("# softraster edge-accuracy star (generated)\n");
    let (cx, cy, r, wedges) = (-0.75f32, 0.05f32, 0.8f32, 24);
    let _ = writeln!(star, "v {cx} {cy} 0");
    for k in 0..=wedges {
        let a = k as f32 / wedges as f32 * std::f32::consts::TAU;
        let _ = writeln!(star, "v {} {} 0", cx + r * a.cos(), cy + r * a.sin());
    }
    for k in (0..wedges).step_by(2) {
        let _ = writeln!(star, "f 1 {} {}", k + 2, k + 3);
    }
    let mut wires = String::from("# softraster edge-accuracy wires (generated)\n");
    for (i, (deg, width)) in [(8.0f32, 0.004f32), (33.0, 0.008), (71.0, 0.012)]
        .iter()
        .enumerate()
    {
        let (s, c) = deg.to_radians().sin_cos();
        let (ox, oy) = (0.35 + 0.35 * i as f32, -0.55);
        let (hl, hw) = (0.55, width * 0.5);
        let corners = [(-hl, -hw), (hl, -hw), (hl, hw), (-hl, hw)];
        for (x, y) in corners {
            let _ = writeln!(wires, "v {} {} 0", ox + x * c - y * s, oy + x * s + y * c);
        }
        let b = i * 4;
        let _ = writeln!(wires, "f {} {} {}", b + 1, b + 2, b + 3);
        let _ = writeln!(wires, "f {} {} {}", b + 1, b + 3, b + 4);
    }
    let sphere = softraster::procedural::sphere(0.45, 64, 32)
        .to_obj("sphere", "none.mtl", "m")
        .text
        .replace("mtllib none.mtl\n", "")
        .replace("usemtl m\n", "");
    for (name, text) in [
        ("star.obj", star),
        ("wires.obj", wires),
        ("sphere.obj", sphere),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, text).map_err(|e| Error::io(&p, e))?;
    }
    Ok("[output]\nwidth = {width}\nheight = {height}\n\
        [render]\nshading = \"unlit\"\ncull = \"none\"\n{render}\n\
        [[model]]\npath = \"star.obj\"\n[model.material]\nkd = [1.0, 1.0, 1.0]\n\
        [[model]]\npath = \"wires.obj\"\n[model.material]\nkd = [1.0, 1.0, 1.0]\n\
        [[model]]\npath = \"sphere.obj\"\ntranslate = [0.85, 0.3, 0.0]\n[model.material]\nkd = [1.0, 1.0, 1.0]\n\
        [[camera]]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 2.4\n"
        .to_string())
}

/// MSAA 1, 2, 4, 8, 16 and SSAA 2x2, 4x4 on the edge scene at
/// `width` x `height`, each against 16x16 supersampling (256 samples per
/// pixel on a regular grid). Times are medians of `runs` renders. With
/// `images`, every frame is also written there as PNG.
pub fn edges(
    dir: &Path,
    width: u32,
    height: u32,
    runs: usize,
    images: Option<&Path>,
) -> Result<Vec<EdgeRow>, Error> {
    let text = edge_scene(dir)?
        .replace("{width}", &width.to_string())
        .replace("{height}", &height.to_string());
    let scene = |render: &str| load(dir, &text.replace("{render}", render));
    let frames = vec![0; runs.max(1)];
    let reference_scene = scene("ssaa = 16")?;
    let (reference, _) = timed(&reference_scene, &[0])?;
    let reference_img = output::resolve(&reference[0], &reference_scene.settings);
    let save = |name: &str, img: &output::Image8| -> Result<(), Error> {
        match images {
            Some(d) => output::png::write(&d.join(format!("{}.png", name.replace(' ', "_"))), img),
            None => Ok(()),
        }
    };
    save("reference_ssaa_16x16", &reference_img)?;
    let mut rows = Vec::new();
    let methods = [
        ("msaa 1", "msaa = 1"),
        ("msaa 2", "msaa = 2"),
        ("msaa 4", "msaa = 4"),
        ("msaa 8", "msaa = 8"),
        ("msaa 16", "msaa = 16"),
        ("ssaa 2x2", "ssaa = 2"),
        ("ssaa 4x4", "ssaa = 4"),
    ];
    for (name, render) in methods {
        let s = scene(render)?;
        let (got, ms) = timed(&s, &frames)?;
        let (mut abs, mut sq) = (0.0f64, 0.0f64);
        for (a, b) in got[0].color.iter().zip(&reference[0].color) {
            let d = (a.truncate() - b.truncate()).abs();
            abs += d.element_sum() as f64 / 3.0;
            sq += d.length_squared() as f64 / 3.0;
        }
        let n = got[0].color.len().max(1) as f64;
        let img = output::resolve(&got[0], &s.settings);
        save(name, &img)?;
        let flip =
            crate::tools::compare::score(&reference_img, &img, crate::tools::compare::Metric::Flip)
                .map_err(|e| Error::Render(format!("edge accuracy: {e}")))?
                .value;
        rows.push(EdgeRow {
            method: name.to_string(),
            ms,
            mae: abs / n,
            rmse: (sq / n).sqrt(),
            flip,
        });
    }
    Ok(rows)
}
