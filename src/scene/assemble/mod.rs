//! `SceneDesc` -> `Scene`, in a fixed order (pbrt-v4's habit): the
//! settings (`settings`), the models with their materials and textures
//! (`models`, `materials`), the lights (`lights`), the cameras framing the
//! models (`cameras`), the animation. Paths resolve against the scene
//! file's directory; every error names the file, line and column of the key
//! it comes from, or the asset's path.

mod cameras;
mod lights;
mod materials;
mod models;
mod settings;

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::Scene;
use super::animation::{Animation, Turntable, TurntableTarget};
use super::desc::{self, Ctx, SceneDesc, Spanned};
use super::environment::{
    Bounces, DEFAULT_EMITTERS, DEFAULT_ENV_LIGHTS, DEFAULT_PREFILTER_SIZE, EnvMethod, Environment,
};
use super::overrides::{self, SetOverride};
use crate::assets::environment::{EnvImage, TakenLight};
use crate::assets::input::Input;
use crate::error::Error;
use crate::scene::settings::RenderSettings;
use std::sync::Arc;

/// Options that come from outside the scene file.
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// `--set key=value`, applied in order before parsing.
    pub sets: Vec<SetOverride>,
    /// `--out`: wins over `output.dir`.
    pub out_dir: Option<PathBuf>,
    /// No default look: a scene without lights or environment gets a
    /// headlight over black, no ground shadow, the clamp tone map (version
    /// 1's defaults, back-face culling included; the measuring tools use
    /// them so that their workloads stay what they were).
    pub plain_look: bool,
    /// `--strict`: every warning (a missing material library or texture,
    /// an unknown MTL key, a setting without effect) is an error.
    pub strict: bool,
    /// `--cache DIR`: decoded textures and their mip chains kept between
    /// runs (`assets::texture::cache`).
    pub cache: Option<PathBuf>,
    /// `--max-memory`: the memory budget (wins over `render.max_memory`;
    /// neither: `assets::input::default_budget`). Sizes read from asset
    /// headers are checked against it before anything is allocated.
    pub max_memory: Option<u64>,
    /// `--sandbox`: every read stays in the scene's folder (as
    /// `render.sandbox = true`).
    pub sandbox: bool,
}

impl LoadOptions {
    /// How the scene's files are read: the budget (`--max-memory`, else
    /// `render.max_memory`, else what the machine has) and the sandbox.
    pub fn input(&self, settings: &RenderSettings, scene_dir: &Path) -> Input {
        let budget = self
            .max_memory
            .or(settings.max_memory)
            .unwrap_or_else(crate::assets::input::default_budget);
        let input = Input::new(budget);
        if self.sandbox || settings.sandbox {
            input.sandboxed(&[scene_dir])
        } else {
            input
        }
    }

    /// Version 1's defaults for scenes without lights (`plain_look`).
    pub fn plain() -> LoadOptions {
        LoadOptions {
            plain_look: true,
            ..LoadOptions::default()
        }
    }
}

impl Scene {
    /// Reads, parses, validates and loads a scene file. A model file
    /// (`.gltf`, `.glb`, `.obj`) is a scene too: the one-line scene that
    /// names it, read from its directory (output in `out/<model stem>/`).
    pub fn load(path: &Path, opts: &LoadOptions) -> Result<Scene, Error> {
        let (text, generated) = match model_as_scene(path) {
            Some(text) => (text, true),
            None => (read_scene_file(path, opts)?, false),
        };
        let toml_ext = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
        if !generated && !toml_ext && text.parse::<toml_edit::DocumentMut>().is_err() {
            return Err(Error::asset(
                path,
                None,
                format!(
                    "neither a scene (TOML) nor a model file softraster reads ({})",
                    crate::assets::model_extensions_listed()
                ),
            ));
        }
        let edited = overrides::apply(path, &text, &opts.sets)?;
        // Messages name what the user can fix: the scene file's line, the
        // `--set` as typed, or the model file, never generated text.
        let origin = overrides::Origin {
            file: path,
            text: (!generated).then_some(text.as_str()),
            edited: &edited,
            sets: &opts.sets,
        };
        match Scene::from_text(path, &edited, opts) {
            Ok(mut scene) => {
                scene.warnings = scene
                    .warnings
                    .into_iter()
                    .map(|w| origin.warning(w))
                    .collect();
                Ok(scene)
            }
            Err(Error::Strict { file, warnings }) => Err(Error::Strict {
                file,
                warnings: warnings.into_iter().map(|w| origin.warning(w)).collect(),
            }),
            Err(e) => Err(origin.error(overrides::blame(path, &text, &opts.sets, e))),
        }
    }

    /// Loads a scene from text; `path` names the file in errors and is the
    /// base for relative paths.
    pub fn from_text(path: &Path, text: &str, opts: &LoadOptions) -> Result<Scene, Error> {
        let desc = SceneDesc::parse(path, text)?;
        let ctx = Ctx { file: path, text };
        let scene = build(&desc, &ctx, opts)?;
        if opts.strict && !scene.warnings.is_empty() {
            return Err(Error::Strict {
                file: path.to_path_buf(),
                warnings: scene.warnings,
            });
        }
        Ok(scene)
    }
}

/// A scene file's text: a regular file, at most the read cap (not a
/// directory, FIFO or device), UTF-8.
fn read_scene_file(path: &Path, opts: &LoadOptions) -> Result<String, Error> {
    // A regular file, at most the read cap: not a directory, FIFO or
    // device.
    let input = Input::new(
        opts.max_memory
            .unwrap_or_else(crate::assets::input::default_budget),
    );
    let bytes = input.read(path, None, None)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        Error::asset(
            path,
            None,
            format!(
                "the scene file is not UTF-8 text (byte {}): a scene is TOML; models are {}",
                e.utf8_error().valid_up_to(),
                crate::assets::model_extensions_listed()
            ),
        )
    })?;
    Ok(text)
}

/// The one-line scene of a model file, or None for other files.
fn model_as_scene(path: &Path) -> Option<String> {
    let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
    if !crate::assets::is_model_extension(&ext) {
        return None;
    }
    let name = path.file_name()?.to_string_lossy().into_owned();
    let mut value = toml_edit::Value::from(name);
    value.decor_mut().clear();
    Some(format!("[[model]]\npath = {value}\n"))
}

/// The value of an optional key, or its default.
fn get<T: Clone>(v: &Option<Spanned<T>>, default: T) -> T {
    v.as_ref().map(|s| s.get_ref().clone()).unwrap_or(default)
}

fn build(d: &SceneDesc, ctx: &Ctx, opts: &LoadOptions) -> Result<Scene, Error> {
    let scene_dir = ctx.file.parent().unwrap_or(Path::new("")).to_path_buf();
    let stem = ctx
        .file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let default_look = settings::default_look(d) && !opts.plain_look;
    let mut settings = settings::render(d, default_look);
    if opts.plain_look && d.render.cull.is_none() {
        // Version 1 culled back faces everywhere; the measuring tools'
        // workloads (the llvmpipe anchor culls) stay what they were.
        settings.cull = crate::scene::settings::CullMode::Back;
    }
    let output = settings::output(
        d,
        ctx,
        &settings,
        &scene_dir,
        &stem,
        opts.out_dir.as_deref(),
    )?;
    let mut warnings = settings::no_effect_warnings(d, ctx, &settings);
    let cache = match &opts.cache {
        Some(dir) => Some(crate::assets::texture::cache::TextureCache::new(dir)?),
        None => None,
    };
    let input = opts.input(&settings, &scene_dir);
    let mut models = models::build(
        d,
        ctx,
        &settings,
        &scene_dir,
        cache.as_ref(),
        &input,
        &mut warnings,
    )?;
    size_warnings(d, ctx, &models.models, &mut warnings);
    if d.render.point_size.is_none() {
        settings.point_size = cloud_point_size(&models.models, &settings);
    }
    // The clips' frames first: their motion counts in the bounds.
    let mut animation = animation(&d.animation, Vec3::ZERO, &models.models);
    models::sweep(&mut models.models, &animation);
    let bounds = models::bounds(&models.models);
    animation.pivot = bounds.center;
    let mut lights: Vec<_> = d
        .lights
        .iter()
        .map(|l| lights::from_desc(l.get_ref()))
        .collect();
    let node_lights = models
        .node_lights
        .iter()
        .map(|n| super::animation::NodeLight {
            light: n.light + lights.len(),
            ..n.clone()
        })
        .collect();
    lights.extend(models.lights);
    let aspect = settings.width as f32 / settings.height as f32;
    let subject = cameras::Subject::new(&models.models, &animation, aspect);
    let cameras = cameras::build(d, ctx, bounds, &subject, &models.cameras, &animation)?;
    let ground = get(&d.ground.shadow, default_look).then(|| ground_plane(&models.models, bounds));
    let environment = match &d.environment {
        Some(e) => {
            let (env, sun, env_lights) = environment(e.get_ref(), ctx, &scene_dir, &input)?;
            if let Some(v) = &e.get_ref().sun
                && *v.get_ref()
                && sun.is_none()
            {
                warnings.push(format!(
                    "{}: environment.sun = true, but the image has no region bright enough to be a sun (its peak is under 20 times its mean): no sun light",
                    ctx.location(v.span())
                ));
            }
            lights.extend(sun);
            lights.extend(env_lights);
            Some(env)
        }
        None if default_look => Some(Environment::default_look()),
        None => None,
    };
    let emitters = match &environment {
        Some(env) if env.emitters > 0 => super::emitters::patches(
            &models.models,
            settings.shading,
            env.emitters as usize,
            super::emitters::irradiance(env),
            bounds.radius,
        ),
        _ => Vec::new(),
    };
    shadow_warnings(d, ctx, &settings, &lights, &mut warnings);
    if let Some(w) = still_frames(d, ctx, &animation, cameras_move(&cameras)) {
        warnings.push(w);
    }
    Ok(Scene {
        file: ctx.file.to_path_buf(),
        stem,
        settings,
        output,
        models: models.models,
        lights,
        node_lights,
        environment,
        emitters,
        ground,
        cameras,
        animation,
        bounds_center: bounds.center,
        bounds_radius: bounds.radius,
        textures: models.textures,
        warnings,
    })
}

/// Whether any camera moves over the frames (a keyed path).
fn cameras_move(cameras: &[super::Camera]) -> bool {
    cameras.iter().any(|c| c.path.is_some())
}

/// `animation.frames > 1` with nothing that changes between frames (no
/// turntable, no clip playing, no camera path): every frame the same; or
/// a turntable of one frame.
fn still_frames(
    d: &SceneDesc,
    ctx: &Ctx,
    animation: &Animation,
    cameras_move: bool,
) -> Option<String> {
    if let Some(t) = &d.animation.turntable
        && animation.frames == 1
    {
        return Some(format!(
            "{}: a turntable of 1 frame does not turn: set animation.frames (72 gives 5 degrees a frame), or use --turntable",
            ctx.location(t.span())
        ));
    }
    let frames = d.animation.frames.as_ref()?;
    let playing = d.models.iter().any(|m| m.get_ref().animation.is_some());
    if animation.frames <= 1 || animation.turntable.is_some() || playing || cameras_move {
        return None;
    }
    Some(format!(
        "{}: animation.frames = {} but nothing moves: every frame is the same; turn the models with --turntable (or [animation.turntable]), or play a clip with model.animation",
        ctx.location(frames.span()),
        animation.frames
    ))
}

/// Shadow-map keys without a light that casts shadows.
fn shadow_warnings(
    d: &SceneDesc,
    ctx: &Ctx,
    settings: &RenderSettings,
    lights: &[super::Light],
    warnings: &mut Vec<String>,
) {
    use crate::scene::settings::ShadowMethod;
    if !matches!(settings.shadows, ShadowMethod::Hard | ShadowMethod::Pcf)
        || lights.iter().any(|l| l.shadows)
    {
        return;
    }
    for (key, span) in [
        (
            "render.shadow_map_size",
            d.render.shadow_map_size.as_ref().map(|v| v.span()),
        ),
        (
            "render.shadow_bias",
            d.render.shadow_bias.as_ref().map(|v| v.span()),
        ),
    ] {
        if let Some(span) = span {
            warnings.push(format!(
                "{}: {key} has no effect: no light casts shadows (give a [[light]] shadows = true)",
                ctx.location(span)
            ));
        }
    }
}

/// The default point size (output pixels): 4, or for a scene of point
/// clouds alone (models with points and no triangles, such as a scanner's
/// PLY) a size that closes the gaps between the points of a model framed
/// to fill the frame: 2.5 times the frame's shorter side over the square
/// root of the number of points, 1 to 24 pixels. (A closed surface shows
/// half its points over a disc about 0.47 times the side in radius; at its
/// centre they lie 3.5 r / sqrt(n) apart, and discs 1.5 times that across
/// overlap enough to leave no gap between three neighbours.)
fn cloud_point_size(models: &[super::Model], s: &crate::scene::settings::RenderSettings) -> f32 {
    let clouds = !models.is_empty()
        && models
            .iter()
            .all(|m| m.mesh.triangles.is_empty() && m.mesh.lines.is_empty());
    let n: usize = models.iter().map(|m| m.mesh.points.len()).sum();
    if !clouds || n == 0 {
        return s.point_size;
    }
    let side = s.width.min(s.height) as f32;
    (2.5 * side / (n as f32).sqrt()).clamp(1.0, 24.0)
}

/// Point and line sizes without points or lines to draw.
fn size_warnings(d: &SceneDesc, ctx: &Ctx, models: &[super::Model], warnings: &mut Vec<String>) {
    for (key, v, has) in [
        (
            "render.point_size",
            &d.render.point_size,
            models.iter().any(|m| !m.mesh.points.is_empty()),
        ),
        (
            "render.line_width",
            &d.render.line_width,
            models.iter().any(|m| !m.mesh.lines.is_empty()),
        ),
    ] {
        if let Some(v) = v
            && !has
        {
            warnings.push(format!(
                "{}: {key} has no effect: no model has {}",
                ctx.location(v.span()),
                if key.ends_with("point_size") {
                    "points"
                } else {
                    "lines"
                }
            ));
        }
    }
}

/// The catcher's plane: at the models' lowest point at rest (and over
/// their clips).
fn ground_plane(models: &[super::Model], bounds: cameras::Bounds) -> super::GroundPlane {
    let lowest = models
        .iter()
        .flat_map(|m| {
            m.reach()
                .map(|p| m.world_from_object.transform_point3(*p).y)
        })
        .fold(f32::INFINITY, f32::min);
    super::GroundPlane {
        height: if lowest.is_finite() {
            lowest
        } else {
            bounds.center.y
        },
        center: bounds.center,
        radius: bounds.radius,
    }
}

/// `[environment]`: the image read (relative to the scene file); a
/// missing file names the `path` key.
fn environment(
    e: &desc::EnvironmentDesc,
    ctx: &Ctx,
    scene_dir: &Path,
    input: &Input,
) -> Result<(Environment, Option<super::Light>, Vec<super::Light>), Error> {
    let mut image = match (&e.path, e.preset.as_ref().map(|p| *p.get_ref())) {
        (Some(p), _) => {
            let path = scene_dir.join(p.get_ref().replace('\\', "/"));
            input.confine(&path, Some(ctx.file))?;
            if std::fs::symlink_metadata(&path).is_err() {
                return Err(Error::asset(
                    &path,
                    None,
                    format!(
                        "environment file not found (from {})",
                        ctx.location(p.span())
                    ),
                ));
            }
            Arc::new(EnvImage::load(&path, input)?)
        }
        (None, Some(desc::EnvPreset::Neutral)) => Arc::new(EnvImage::uniform(glam::Vec3::ONE)),
        // Validation leaves only the studio here.
        (None, _) => EnvImage::studio(),
    };
    let method = match e.method.as_ref().map(|m| *m.get_ref()) {
        Some(desc::EnvMethodName::Sampled) => EnvMethod::Sampled {
            samples: get(&e.samples, 64) as u32,
            bounces: get(&e.bounces, 1) as u32,
        },
        _ => EnvMethod::Prefiltered,
    };
    let (intensity, rotation) = (get(&e.intensity, 1.0), get(&e.rotation, 0.0));
    // `sun = true`: the brightest region becomes a shadow-casting light
    // (turned and scaled like the image), and leaves the image; then
    // `lights`: the compact bright regions, each with its spread.
    let to_light = |t: TakenLight, angle: f32| {
        let world = glam::Mat3::from_rotation_y(rotation.to_radians()) * t.direction;
        let e = t.irradiance * intensity;
        let peak = e.max_element().max(1e-12);
        super::Light {
            kind: super::light::LightKind::Directional {
                direction: world.normalize(),
                irradiance: peak,
                angle,
            },
            color: e / peak,
            shadows: true,
            range: None,
        }
    };
    let read = image.clone();
    let sun = if get(&e.sun, false) {
        Arc::make_mut(&mut image)
            .extract_sun()
            .map(|t| to_light(t, 0.0))
    } else {
        None
    };
    let sampled = matches!(method, EnvMethod::Sampled { .. });
    let wanted = get(&e.lights, if sampled { 0 } else { DEFAULT_ENV_LIGHTS }) as usize;
    // On a copy, kept only when it gave lights: an image without any (the
    // built-in presets) stays the shared one, which the lighting cache
    // finds without hashing it.
    let mut lights = Vec::new();
    if wanted > 0 {
        let mut copy = (*image).clone();
        lights = copy
            .extract_lights(wanted)
            .into_iter()
            .map(|t| to_light(t, t.angle))
            .collect();
        if !lights.is_empty() {
            image = Arc::new(copy);
        }
    }
    Ok((
        Environment {
            method,
            backdrop: (sun.is_some() || !lights.is_empty()).then_some(read),
            image,
            intensity,
            rotation,
            prefilter_size: get(&e.prefilter_size, DEFAULT_PREFILTER_SIZE as i64) as u32,
            emitters: if sampled {
                0
            } else {
                get(&e.emitters, DEFAULT_EMITTERS) as u32
            },
            // An image's reflections by default; the presets' soft panels
            // (the default look) keep their speed.
            reflections: !sampled && get(&e.reflections, e.path.is_some()),
            // Prefiltered: bounced light where the scene asks for it, and
            // under an image's light where the camera looks into an
            // enclosure (elsewhere it costs more than it gains); sampled
            // bounces in its own rays.
            bounce: match e.bounces.as_ref().map(|b| *b.get_ref()) {
                _ if sampled => Bounces::Off,
                Some(b) if b > 0 => Bounces::On,
                Some(_) => Bounces::Off,
                None if e.path.is_some() => Bounces::WhereEnclosed,
                None => Bounces::Off,
            },
        },
        sun,
        lights,
    ))
}

/// `[animation]`: one frame and no turntable by default; a turntable turns
/// about +Y by 360 degrees over the frames, turning the models, about the
/// models' center. Models that play clips make the default frame count the
/// longest clip's length times fps (at least 1).
fn animation(a: &desc::AnimationDesc, pivot: Vec3, models: &[super::Model]) -> Animation {
    let fps = get(&a.fps, 24.0);
    let clip_frames = models
        .iter()
        .filter_map(|m| m.playback.as_ref())
        .map(|p| {
            (p.clip.duration as f64 * fps as f64)
                .round()
                .clamp(1.0, 1e6) as i64
        })
        .max()
        .unwrap_or(1);
    let turntable = a.turntable.as_ref().map(|t| {
        let t = t.get_ref();
        Turntable {
            axis: Vec3::from(get(&t.axis, [0.0, 1.0, 0.0])).normalize(),
            degrees: get(&t.degrees, 360.0),
            rotate: get(&t.rotate, TurntableTarget::Models),
            elevation: t.elevation.as_ref().map(|e| *e.get_ref()),
        }
    });
    Animation {
        frames: get(&a.frames, clip_frames) as u32,
        fps,
        turntable,
        pivot,
    }
}
