//! `softraster bench`: the reference turntables, set up like the llvmpipe
//! anchor in `../shared/bench/llvmpipe/turntable.py` (same camera framing,
//! lights, ambient, background, material constants, 5-degree steps), so the
//! two can be run side by side and compared as a ratio.
//!
//! Per-frame time = render + resolve to sRGB bytes (llvmpipe's figure ends
//! with glReadPixels of an sRGB8 framebuffer); PNG encoding is timed apart.

mod models;

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;

use models::{floor_disc, obj_bounds, resampled_diablo3, spherical_uv_model, subdivided};
use softraster::error::Error;
use softraster::output;
use softraster::render::{Frame, FrameSequence, Renderer, Shot};
use softraster::scene::Scene;
use softraster::scene::assemble::LoadOptions;
use softraster::scene::light::{Light, LightKind};

#[derive(clap::Args, Debug, Clone)]
pub struct BenchArgs {
    /// The shared model directory.
    #[arg(long, default_value = "../shared/assets")]
    pub assets: PathBuf,
    /// Which workloads: diablo3, nefertiti, flighthelmet (glTF, pbr),
    /// diablo3-4k, diablo3-4k-aniso; the llvmpipe harness's own set-ups
    /// diablo3-matched, diablo3-matched-shadow (a floor and a 2048 shadow
    /// map, like `--shadow 1 --floor 1`), diablo3-4k-matched and
    /// nefertiti-matched (diablo3's maps on spherical UVs, like the
    /// harness's nefertiti); diablo3-sun and diablo3-studio (the matched
    /// model under its directional light alone, or under the built-in
    /// studio environment alone: the cost of environment lighting);
    /// diablo3-lights (the matched model on a floor under 24 point lights
    /// with a range and 4 spots: what per-tile light culling saves, with
    /// --no-light-culling for the other side);
    /// tris-5k, tris-20k, tris-80k, tris-320k,
    /// tris-1m (diablo3-matched subdivided 0 to 4 times: same pixels, more
    /// triangles); filters, shadows, ao, edges (time and error
    /// of each method, CSV; edges at --size x 3/4 --size), or all (the
    /// first three).
    #[arg(long, default_value = "all")]
    pub case: String,
    #[arg(long, default_value_t = 72)]
    pub frames: u32,
    #[arg(long, default_value_t = 700)]
    pub size: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Also write the frames as PNG here (to look at them). Without it
    /// the frames follow each other untouched, as in the llvmpipe
    /// harness's timed loop, and the PNG column is the last frame encoded
    /// three times; with it each frame is written after it is timed.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// MSAA samples for the turntable cases (1, 2, 4, 8 or 16).
    #[arg(long, default_value_t = 1)]
    pub msaa: u32,
    /// Instead of timing, write the case's scene (with its lights) to this
    /// file, e.g. for `softraster chart`. Also `--case bunny-plane`: the
    /// Stanford bunny on a plane under a directional light that casts
    /// shadows.
    #[arg(long)]
    pub write_scene: Option<PathBuf>,
    /// Append one JSON line per case (the table's numbers) to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Keep decoded textures and mip chains in this directory between
    /// runs (as `render --cache`); without it every load is cold.
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
    /// Shade every fragment with every light (per-tile light culling off;
    /// the frames are the same): to measure what the culling saves.
    #[arg(long)]
    pub no_light_culling: bool,
}

#[derive(Debug, Clone)]
pub struct BenchResult {
    pub name: String,
    pub triangles: usize,
    /// Scene load (files read, meshes built, textures decoded, in
    /// parallel) plus mip chains.
    pub load_ms: f64,
    /// The mip chains' share of `load_ms`.
    pub mips_ms: f64,
    /// The environment's prefiltering (once per scene), apart from
    /// `load_ms`; 0 without an environment.
    pub env_ms: f64,
    /// Median of frames 1..n (frame 0 warms caches).
    pub steady_ms: f64,
    pub min_ms: f64,
    pub total_ms: f64,
    pub png_ms: f64,
}

fn scene_text(
    case: &str,
    assets: &Path,
    size: u32,
    frames: u32,
    msaa: u32,
) -> Result<String, Error> {
    let d3 = assets.join("tinyrenderer/diablo3_pose");
    let p = |p: PathBuf| -> Result<String, Error> {
        if !p.is_file() {
            return Err(Error::asset(
                &p,
                None,
                "benchmark model not found (pass --assets)",
            ));
        }
        Ok(p.display().to_string().replace('\\', "/"))
    };
    let common = format!(
        "[output]\nwidth = {size}\nheight = {size}\nbackground = [0.02, 0.02, 0.025]\n\
         [render]\nmsaa = {msaa}\ntexture_filter = \"bilinear\"\n[ambient]\ncolor = [0.06, 0.06, 0.07]\n\
         [animation]\nframes = {frames}\nturntable = {{ axis = [0.0, 1.0, 0.0], degrees = {} }}\n",
        5.0 * frames as f32
    );
    Ok(match case {
        "diablo3" => format!(
            "{common}[[model]]\npath = \"{}\"\n[model.material]\nkd = [1.0, 1.0, 1.0]\nks = [0.5, 0.5, 0.5]\nns = 32.0\n\
             map_kd = \"{}\"\nmap_ks = \"{}\"\nmap_ke = \"{}\"\nke = [1.0, 1.0, 1.0]\n",
            p(d3.join("diablo3_pose.obj"))?,
            p(d3.join("diablo3_pose_diffuse.tga"))?,
            p(d3.join("diablo3_pose_spec.tga"))?,
            p(d3.join("diablo3_pose_glow.tga"))?,
        ),
        "nefertiti" => format!(
            "{common}[[model]]\npath = \"{}\"\nrotate = [-90.0, 0.0, 0.0]\n[model.material]\n\
             kd = [0.8, 0.8, 0.8]\nks = [0.5, 0.5, 0.5]\nns = 32.0\n",
            p(assets.join("common/nefertiti.obj"))?
        ),
        // glTF with pbr materials (base color, normal, occlusion-roughness-
        // metallic maps, 512x512), trilinear like the 4k case.
        "flighthelmet" => format!(
            "{}[[model]]\npath = \"{}\"\n",
            common.replace("\"bilinear\"", "\"trilinear\""),
            p(assets.join("gltf/FlightHelmet/FlightHelmet.gltf"))?
        ),
        "diablo3-4k" | "diablo3-4k-aniso" => {
            let dir = resampled_diablo3(&d3)?;
            let filter = if case.ends_with("aniso") {
                "anisotropic"
            } else {
                "trilinear"
            };
            format!(
                "{}[[model]]\npath = \"{}\"\n[model.material]\nillum = 2\n",
                common.replace(
                    "\"bilinear\"",
                    &format!("\"{filter}\"\nmax_anisotropy = 16")
                ),
                p(dir.join("diablo3_pose_mtl.obj"))?
            )
        }
        "diablo3-matched"
        | "diablo3-matched-shadow"
        | "diablo3-4k-matched"
        | "nefertiti-matched"
        | "diablo3-sun"
        | "diablo3-studio"
        | "diablo3-lights"
        | "tris-5k"
        | "tris-20k"
        | "tris-80k"
        | "tris-320k"
        | "tris-1m" => matched_scene(case, assets, &d3, &common, &p)?,
        other => {
            return Err(Error::Argument(format!(
                "bench --case {other}: expected diablo3, nefertiti, flighthelmet, diablo3-4k, diablo3-4k-aniso, diablo3-matched, diablo3-matched-shadow, diablo3-4k-matched, nefertiti-matched, diablo3-sun, diablo3-studio, diablo3-lights, tris-5k .. tris-1m, filters, shadows, ao, edges or all"
            )));
        }
    })
}

/// The llvmpipe harness's set-up (`turntable.py`): one material with
/// kd 1, ks 0.5, Ns 32, the diffuse (sRGB), specular and tangent-space
/// normal maps and no glow map; trilinear mip maps, back faces culled.
/// `-shadow`: a grey floor under the model (a disc of the harness's
/// quad's area: the floor turns with the model here, and a disc looks the
/// same at every angle) and a 2048 PCF shadow map of the directional
/// light (set in `anchor_lights`).
fn matched_scene(
    case: &str,
    assets: &Path,
    d3: &Path,
    common: &str,
    p: &dyn Fn(PathBuf) -> Result<String, Error>,
) -> Result<String, Error> {
    let (obj, maps) = match case {
        "diablo3-4k-matched" => {
            let dir = resampled_diablo3(d3)?;
            (dir.join("diablo3_pose.obj"), dir)
        }
        "nefertiti-matched" => (
            spherical_uv_model(&assets.join("common/nefertiti.obj"))?,
            d3.to_path_buf(),
        ),
        _ => match case.strip_prefix("tris-") {
            Some(n) => {
                let levels = ["5k", "20k", "80k", "320k", "1m"]
                    .iter()
                    .position(|k| *k == n)
                    .unwrap_or(0);
                (
                    subdivided(&d3.join("diablo3_pose.obj"), levels)?,
                    d3.to_path_buf(),
                )
            }
            None => (d3.join("diablo3_pose.obj"), d3.to_path_buf()),
        },
    };
    let map = |m: &str| p(maps.join(format!("diablo3_pose_{m}.tga")));
    let mut render = "texture_filter = \"trilinear\"\ncull = \"back\"".to_string();
    let mut floor = String::new();
    if case == "diablo3-studio" {
        // Lit by the built-in studio alone (no lights: see `anchor_lights`).
        floor.push_str("[environment]\npreset = \"studio\"\n");
    }
    if case.ends_with("-shadow") {
        render.push_str("\nshadows = \"pcf\"\nshadow_map_size = 2048");
    }
    if case.ends_with("-shadow") || case == "diablo3-lights" {
        let (lo, hi) = obj_bounds(Path::new(&p(obj.clone())?))?;
        let path = floor_disc(lo, hi)?;
        // The harness's floor: sRGB 200 grey, ks 0.1, Ns 16.
        let grey = softraster::color::srgb_to_linear(200.0 / 255.0);
        floor = format!(
            "[[model]]\npath = \"{}\"\n[model.material]\nillum = 2\nkd = [{grey}, {grey}, {grey}]\n\
             ks = [0.1, 0.1, 0.1]\nns = 16.0\n",
            p(path)?
        );
    }
    Ok(format!(
        "{}[[model]]\npath = \"{}\"\n[model.material]\nillum = 2\nkd = [1.0, 1.0, 1.0]\n\
         ks = [0.5, 0.5, 0.5]\nns = 32.0\nmap_kd = \"{}\"\nmap_ks = \"{}\"\nnorm = \"{}\"\n{floor}",
        common.replace("texture_filter = \"bilinear\"", &render),
        p(obj)?,
        map("diffuse")?,
        map("spec")?,
        map("nm_tangent")?,
    ))
}

/// The bounding box center and half diagonal of model 0 as placed (the
/// harness frames and lights the model alone, never its floor).
fn subject_bounds(scene: &Scene) -> (Vec3, f32) {
    let Some(m) = scene.models.first() else {
        return (scene.bounds_center, scene.bounds_radius);
    };
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for p in &m.mesh.positions {
        let w = m.world_from_object.transform_point3(*p);
        lo = lo.min(w);
        hi = hi.max(w);
    }
    ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-6))
}

/// The llvmpipe harness's two lights, placed relative to the model's
/// bounding sphere; the directional one casts shadows in the `-shadow`
/// cases. `diablo3-sun` keeps the directional one alone and
/// `diablo3-studio` none (the environment lights it): the pair measures
/// what an environment costs over one directional light.
fn case_lights(case: &str, scene: &Scene) -> Vec<Light> {
    let mut lights = anchor_lights(scene, case.ends_with("-shadow"));
    match case {
        "diablo3-sun" => lights.truncate(1),
        "diablo3-studio" => lights.clear(),
        "diablo3-lights" => {
            lights.truncate(1);
            lights.extend(local_lights(scene));
        }
        _ => {}
    }
    lights
}

/// `diablo3-lights`: 24 coloured point lights with a range of a third of
/// the model's radius, in three rings of eight around it (feet, waist,
/// head), and four spots of 12 degrees from above on its quarters.
fn local_lights(scene: &Scene) -> Vec<Light> {
    let (center, r) = subject_bounds(scene);
    let mut out = Vec::new();
    for ring in 0..3 {
        let y = center.y + r * (ring as f32 - 1.0) * 0.55;
        for k in 0..8 {
            let a = (k as f32 + 0.5 * ring as f32) * std::f32::consts::TAU / 8.0;
            let position = Vec3::new(
                center.x + 0.45 * r * a.cos(),
                y,
                center.z + 0.45 * r * a.sin(),
            );
            let hue = (k * 3 + ring) as f32 / 24.0 * std::f32::consts::TAU;
            let color = Vec3::new(
                0.6 + 0.4 * hue.cos(),
                0.6 + 0.4 * (hue + 2.1).cos(),
                0.6 + 0.4 * (hue + 4.2).cos(),
            );
            out.push(Light {
                kind: LightKind::Point {
                    position,
                    intensity: 0.08 * r * r,
                },
                color,
                shadows: false,
                range: Some(r / 3.0),
            });
        }
    }
    for k in 0..4 {
        let a = (k as f32 + 0.5) * std::f32::consts::TAU / 4.0;
        let target = center + Vec3::new(0.3 * r * a.cos(), 0.0, 0.3 * r * a.sin());
        let position = center + Vec3::new(0.0, 2.0 * r, 0.0);
        out.push(Light {
            kind: LightKind::Spot {
                position,
                direction: (target - position).normalize(),
                intensity: 0.6 * r * r,
                cos_inner: 8f32.to_radians().cos(),
                cos_outer: 12f32.to_radians().cos(),
            },
            color: Vec3::new(1.0, 0.97, 0.9),
            shadows: false,
            range: None,
        });
    }
    out
}

fn anchor_lights(scene: &Scene, shadows: bool) -> Vec<Light> {
    let (center, r) = subject_bounds(scene);
    let dir_l = Vec3::new(-0.5, 0.75, 0.45).normalize();
    let pt = Vec3::new(1.2, 0.6, 1.6) * r;
    let e = 0.6 * pt.length_squared();
    vec![
        Light {
            kind: LightKind::Directional {
                direction: -dir_l,
                irradiance: 1.0,
                angle: 0.0,
            },
            color: Vec3::new(0.9, 0.88, 0.85),
            shadows,
            range: None,
        },
        Light {
            kind: LightKind::Point {
                position: center + pt,
                intensity: e,
            },
            color: Vec3::new(1.0, 0.95, 0.9),
            shadows: false,
            range: None,
        },
    ]
}

pub fn run_case(case: &str, args: &BenchArgs) -> Result<BenchResult, Error> {
    let text = scene_text(case, &args.assets, args.size, args.frames, args.msaa)?;
    let t0 = Instant::now();
    let mut scene = Scene::from_text(
        Path::new(&format!("bench-{case}.toml")),
        &text,
        &LoadOptions {
            cache: args.cache.clone(),
            ..LoadOptions::plain()
        },
    )?;
    scene.lights = case_lights(case, &scene);
    // The anchor's camera: the model's bounding sphere from +Z at fov 45
    // (the version 1 default; fitted cameras frame tighter).
    let (center, radius) = subject_bounds(&scene);
    scene.cameras = vec![softraster::scene::Camera::framing(
        "camera".into(),
        center,
        radius,
        45.0,
    )];
    // Mip chains are built when a frame first minifies a texture; the
    // benchmark builds them up front and counts them as loading.
    let renderer = Renderer::new(&scene).with_light_culling(!args.no_light_culling);
    let t_mips = Instant::now();
    if matches!(
        scene.settings.texture_filter,
        softraster::scene::settings::TextureFilter::Trilinear
            | softraster::scene::settings::TextureFilter::Anisotropic
    ) {
        renderer.build_all_mips();
    }
    let mips_ms = t_mips.elapsed().as_secs_f64() * 1e3;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t_env = Instant::now();
    renderer.build_environment();
    let env_ms = t_env.elapsed().as_secs_f64() * 1e3;
    let mut times = Vec::new();
    let (mut png_ms, mut pngs) = (0.0, 0);
    let mut frames = FrameSequence::new();
    let mut img = output::Image8::empty();
    let mut write_png = |path: &Path, img: &output::Image8| -> Result<(), Error> {
        let t = Instant::now();
        output::png::write(path, img)?;
        png_ms += t.elapsed().as_secs_f64() * 1e3;
        pngs += 1;
        Ok(())
    };
    for f in 0..args.frames {
        let t = Instant::now();
        renderer.render_next(Shot::new(0, f), &mut frames, Some(&mut img))?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
        // Frames follow each other as in the harness's timed loop (its
        // `--no-write`): a PNG encoded between two frames would idle the
        // workers and cool the caches for the next. With --out each frame
        // is written after it is timed.
        if let Some(dir) = &args.out {
            write_png(
                &dir.join(format!("softraster-bench-{case}-{f:04}.png")),
                &img,
            )?;
        }
    }
    if args.out.is_none() && args.frames > 0 {
        // The PNG column: the last frame, encoded three times.
        let path = std::env::temp_dir().join(format!(
            "softraster-bench-{case}-{}.png",
            std::process::id()
        ));
        for _ in 0..3 {
            write_png(&path, &img)?;
        }
        let _ = std::fs::remove_file(&path);
    }
    let mut steady: Vec<f64> = times.iter().skip(1).copied().collect();
    if steady.is_empty() {
        steady = times.clone();
    }
    steady.sort_by(f64::total_cmp);
    Ok(BenchResult {
        name: case.to_string(),
        triangles: scene.triangle_count(),
        load_ms,
        mips_ms,
        env_ms,
        steady_ms: steady[steady.len() / 2],
        min_ms: steady[0],
        total_ms: times.iter().sum(),
        png_ms: png_ms / pngs.max(1) as f64,
    })
}

/// TOML for `lights` (the ones the benchmark sets in code).
fn lights_toml(lights: &[Light]) -> String {
    let v = |v: Vec3| format!("[{}, {}, {}]", v.x, v.y, v.z);
    let mut s = String::new();
    // Area lights are the renderer's (from emissive surfaces), not a
    // scene file's.
    for l in lights
        .iter()
        .filter(|l| !matches!(l.kind, LightKind::Area { .. }))
    {
        s.push_str("\n[[light]]\n");
        match l.kind {
            LightKind::Directional {
                direction,
                irradiance,
                ..
            } => s.push_str(&format!(
                "kind = \"directional\"\ndirection = {}\nirradiance = {irradiance}\n",
                v(direction)
            )),
            LightKind::Point {
                position,
                intensity,
            } => s.push_str(&format!(
                "kind = \"point\"\nposition = {}\nintensity = {intensity}\n",
                v(position)
            )),
            LightKind::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
            } => s.push_str(&format!(
                "kind = \"spot\"\nposition = {}\ndirection = {}\nintensity = {intensity}\n\
                 inner_angle = {}\nouter_angle = {}\n",
                v(position),
                v(direction),
                cos_inner.clamp(-1.0, 1.0).acos().to_degrees(),
                cos_outer.clamp(-1.0, 1.0).acos().to_degrees()
            )),
            LightKind::Area { .. } => {}
        }
        if let Some(r) = l.range {
            s.push_str(&format!("range = {r}\n"));
        }
        s.push_str(&format!("color = {}\n", v(l.color)));
        if l.shadows {
            s.push_str("shadows = true\n");
        }
    }
    s
}

/// Writes the scene of `args.case` to `path` (absolute model paths).
fn write_scene(args: &BenchArgs, path: &Path) -> Result<(), Error> {
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    // The scene lives elsewhere: model paths must not depend on the cwd.
    let assets = std::fs::canonicalize(&args.assets).map_err(|e| Error::io(&args.assets, e))?;
    let args = &BenchArgs {
        assets,
        ..args.clone()
    };
    let text = if args.case == "bunny-plane" {
        let (name, model, eye) = crate::tools::accuracy::AO_SCENES[0];
        debug_assert!(name.starts_with("bunny"));
        let (text, _) =
            crate::tools::accuracy::ao_scene(&dir, &args.assets.join(model), eye, args.size)?;
        text.replace("ao = {ao}", "msaa = 1")
            + "\n[[light]]\nkind = \"directional\"\ndirection = [-0.5, -0.8, -0.35]\nirradiance = 2.0\nshadows = true\n\
               \n[ambient]\ncolor = [0.08, 0.08, 0.09]\n"
    } else {
        let text = scene_text(&args.case, &args.assets, args.size, args.frames, args.msaa)?;
        let scene = Scene::from_text(path, &text, &LoadOptions::default())?;
        let (center, radius) = subject_bounds(&scene);
        let cam = softraster::scene::Camera::framing("camera".into(), center, radius, 45.0);
        let v = |v: Vec3| format!("[{}, {}, {}]", v.x, v.y, v.z);
        text + &lights_toml(&case_lights(&args.case, &scene))
            + &format!(
                "\n[[camera]]\neye = {}\ntarget = {}\nfov = 45.0\nnear = {}\nfar = {}\n",
                v(cam.eye),
                v(cam.target),
                cam.near,
                cam.far
            )
    };
    softraster::output::write_atomic(path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| Error::io(path, e))
    })?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

pub fn run(args: &BenchArgs) -> Result<(), Error> {
    if let Some(p) = &args.write_scene {
        return write_scene(args, p);
    }
    if args.case == "filters" {
        let dir = std::env::temp_dir().join(format!("softraster-filters-{}", std::process::id()));
        let r = filter_accuracy(&dir, 320, 240);
        let _ = std::fs::remove_dir_all(&dir);
        println!("filter,mean_abs_error_linear,ms_per_frame_320x240");
        for f in r? {
            println!("{},{:.5},{:.2}", f.filter, f.mean_error, f.ms);
        }
        return Ok(());
    }
    if args.case == "edges" {
        let dir = std::env::temp_dir().join(format!("softraster-edges-{}", std::process::id()));
        let pool = thread_pool(args)?;
        let (w, h) = (args.size, args.size * 3 / 4);
        let r = pool.install(|| crate::tools::accuracy::edges(&dir, w, h, 5, args.out.as_deref()));
        let _ = std::fs::remove_dir_all(&dir);
        println!("method,ms_per_frame_{w}x{h},mae_linear,rmse_linear,flip_mean");
        for row in r? {
            println!(
                "{},{:.2},{:.5},{:.5},{:.5}",
                row.method, row.ms, row.mae, row.rmse, row.flip
            );
        }
        return Ok(());
    }
    if args.case == "shadows" || args.case == "ao" {
        return accuracy_tables(args);
    }
    let cases: Vec<&str> = match args.case.as_str() {
        "all" => vec!["diablo3", "nefertiti", "flighthelmet"],
        c => vec![c],
    };
    let pool = thread_pool(args)?;
    println!(
        "softraster bench: {} frames at {}x{}, {} thread(s)",
        args.frames,
        args.size,
        args.size,
        pool.current_num_threads()
    );
    println!(
        "| case | triangles | load ms (of which mip chains) | environment prefilter ms | steady ms/frame (median 1..n) | min ms | render total ms | png ms/frame |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for c in cases {
        let r = pool.install(|| run_case(c, args))?;
        if let Some(path) = &args.json {
            let line = serde_json::json!({
                "case": r.name,
                "triangles": r.triangles,
                "size": args.size,
                "frames": args.frames,
                "msaa": args.msaa,
                "threads": pool.current_num_threads(),
                "load_ms": r.load_ms,
                "mips_ms": r.mips_ms,
                "env_prefilter_ms": r.env_ms,
                "frame_median_ms": r.steady_ms,
                "frame_min_ms": r.min_ms,
                "render_total_ms": r.total_ms,
                "png_ms_per_frame": r.png_ms,
            });
            use std::io::Write;
            let mut f = std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(path)
                .map_err(|e| Error::io(path, e))?;
            writeln!(f, "{line}").map_err(|e| Error::io(path, e))?;
        }
        println!(
            "| {} | {} | {:.1} ({:.1}) | {:.1} | {:.2} | {:.2} | {:.0} | {:.2} |",
            r.name,
            r.triangles,
            r.load_ms,
            r.mips_ms,
            r.env_ms,
            r.steady_ms,
            r.min_ms,
            r.total_ms,
            r.png_ms
        );
    }
    Ok(())
}

/// The worker pool `--threads` asks for (all cores by default).
fn thread_pool(args: &BenchArgs) -> Result<rayon::ThreadPool, Error> {
    softraster::batch::thread_pool(args.threads)
}

/// `--case shadows | ao`: time and error of each method (CSV on stdout).
fn accuracy_tables(args: &BenchArgs) -> Result<(), Error> {
    let pool = thread_pool(args)?;
    let threads = pool.current_num_threads();
    let assets = std::fs::canonicalize(&args.assets).map_err(|e| Error::io(&args.assets, e))?;
    pool.install(|| {
        if args.case == "shadows" {
            // Every 9th frame of the turntable (8 frames of 72).
            let frames: Vec<u32> = (0..args.frames).step_by(9).collect();
            let rows = crate::tools::accuracy::shadows(&assets, args.size, &frames)?;
            println!(
                "# diablo3 on the floor, one directional light, {}x{}, frames {frames:?}, {threads} thread(s); reference: raytraced",
                args.size, args.size
            );
            println!("scene,method,ms_per_frame,mean_abs_error_linear,pct_pixels_off_by_8_levels");
            for r in rows {
                println!(
                    "diablo3,{},{:.2},{:.5},{:.3}",
                    r.method, r.ms, r.error, r.second
                );
            }
        } else {
            // Every 18th frame (4 of 72): the reference is 1024 rays a pixel.
            let frames: Vec<u32> = (0..args.frames).step_by(18).collect();
            let tables = crate::tools::accuracy::ao(&assets, args.size, &frames, 1024)?;
            println!(
                "# {}x{}, frames {frames:?}, {threads} thread(s); reference: raytraced, 1024 rays, same radius",
                args.size, args.size
            );
            println!("scene,method,ms_per_frame,rmse_ao,worst_abs_ao");
            for (scene, rows) in tables {
                for r in rows {
                    println!("{scene},{},{:.2},{:.4},{:.3}", r.method, r.ms, r.error, r.second);
                }
            }
        }
        Ok(())
    })
}

/// One texture filter's accuracy on the grazing-angle checkerboard.
#[derive(Debug, Clone)]
pub struct FilterResult {
    pub filter: &'static str,
    /// Mean absolute error per channel against the 16x16 supersampled
    /// reference, linear RGB.
    pub mean_error: f64,
    pub ms: f64,
}

/// A checkerboard plane seen at a grazing angle, rendered `width` x
/// `height` with each texture filter and compared with the same frame
/// rendered at 16x16 the resolution (anisotropic 16x) and box-averaged.
/// Writes its plane and texture into `dir`.
pub fn filter_accuracy(dir: &Path, width: u32, height: u32) -> Result<Vec<FilterResult>, Error> {
    use softraster::procedural;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let obj = procedural::ground(40.0, 0.0, 40.0).to_obj("plane", "plane.mtl", "checker");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).map_err(|e| Error::io(&p, e))
    };
    write("plane.obj", &obj.text)?;
    write(
        "plane.mtl",
        "newmtl checker\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd checker.png\n",
    )?;
    output::png::write(
        &dir.join("checker.png"),
        &procedural::checker(64, 2, [235, 235, 235], [20, 20, 20]),
    )?;
    let scene = |w: u32, h: u32, filter: &str| -> Result<Scene, Error> {
        let text = format!(
            "[output]\nwidth = {w}\nheight = {h}\n[render]\ntexture_filter = \"{filter}\"\n\
             max_anisotropy = 16\nshading = \"unlit\"\n[[model]]\npath = \"plane.obj\"\n\
             [[camera]]\neye = [0.0, 0.6, 40.0]\ntarget = [3.0, 0.0, 20.0]\nfov = 50.0\nnear = 0.05\nfar = 200.0\n"
        );
        Scene::from_text(&dir.join("filters.toml"), &text, &LoadOptions::plain())
    };
    const SS: u32 = 16;
    let render = |s: &Scene| -> Result<Frame, Error> {
        let mut f = Frame::new(0, 0);
        Renderer::new(s).render(Shot::new(0, 0), &mut f)?;
        Ok(f)
    };
    let reference = render(&scene(width * SS, height * SS, "anisotropic")?)?;
    let mut results = Vec::new();
    for filter in ["nearest", "bilinear", "trilinear", "anisotropic"] {
        let s = scene(width, height, filter)?;
        let t = Instant::now();
        let f = render(&s)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let mut err = 0.0f64;
        for y in 0..height {
            for x in 0..width {
                let mut acc = Vec3::ZERO;
                for sy in 0..SS {
                    let row = ((y * SS + sy) * width * SS + x * SS) as usize;
                    for c in &reference.color[row..row + SS as usize] {
                        acc += c.truncate();
                    }
                }
                let r = acc / (SS * SS) as f32;
                let c = f.color[(y * width + x) as usize].truncate();
                err += (c - r).abs().element_sum() as f64;
            }
        }
        results.push(FilterResult {
            filter,
            mean_error: err / (width * height * 3) as f64,
            ms,
        });
    }
    Ok(results)
}
