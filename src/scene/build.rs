//! `SceneDesc` -> `Scene`: resolves paths against the scene file, loads each
//! model once and each texture once (in parallel, only those a material that
//! is drawn uses), applies defaults and material overrides, and refuses
//! features that are specified but not implemented yet, at their location.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{EulerRot, Mat4, Quat, Vec2, Vec3};
use rayon::prelude::*;

use super::animation::{Animation, Turntable};
use super::camera::{Camera, Projection, fitted_planes};
use super::desc::{self, Ctx, S, SceneDesc};
use super::light::{Light, LightKind};
use super::material::NormalMap;
use super::materials::{self, SourceMaterial};
use super::overrides::{self, SetOverride};
use super::{Model, OutputSettings, RenderSettings, Scene, check_pattern};
use crate::assets::gltf::{GltfCamera, GltfProjection, ImageSource};
use crate::assets::obj::{self, MapSpec};
use crate::assets::texture::Texture;
use crate::error::Error;

/// Options that come from outside the scene file.
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// `--set key=value`, applied in order before parsing.
    pub sets: Vec<SetOverride>,
    /// `--out`: wins over `output.dir`.
    pub out_dir: Option<PathBuf>,
}

impl Scene {
    /// Reads, parses, validates and loads a scene file.
    pub fn load(path: &Path, opts: &LoadOptions) -> Result<Scene, Error> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Scene {
            location: crate::error::Location {
                file: path.to_path_buf(),
                line: 1,
                column: 1,
            },
            message: format!("cannot read the scene file: {e}"),
        })?;
        let text = overrides::apply(&text, &opts.sets)?;
        Scene::from_text(path, &text, opts)
    }

    /// Loads a scene from text; `path` names the file in errors and is the
    /// base for relative paths.
    pub fn from_text(path: &Path, text: &str, opts: &LoadOptions) -> Result<Scene, Error> {
        let desc = SceneDesc::parse(path, text)?;
        let ctx = Ctx { file: path, text };
        build(&desc, &ctx, opts)
    }
}

fn get<T: Clone>(v: &Option<S<T>>, default: T) -> T {
    v.as_ref().map(|s| s.get_ref().clone()).unwrap_or(default)
}

fn shadow_bias(r: &desc::RenderDesc) -> super::ShadowBias {
    let d = super::ShadowBias::default();
    match &r.shadow_bias {
        Some(b) => {
            let b = b.get_ref();
            super::ShadowBias {
                constant: get(&b.constant, d.constant),
                slope: get(&b.slope, d.slope),
                normal: get(&b.normal, d.normal),
            }
        }
        None => d,
    }
}

/// `render.shadows`, or without it: pcf when the scene sets a shadow-map
/// key (it asked for maps), otherwise the default (raytraced).
fn shadow_method(r: &desc::RenderDesc) -> desc::ShadowMethod {
    match &r.shadows {
        Some(m) => *m.get_ref(),
        None if r.shadow_map_size.is_some() || r.shadow_bias.is_some() => desc::ShadowMethod::Pcf,
        None => desc::ShadowMethod::default(),
    }
}

/// Keys that are valid but do nothing with the rest of the scene: said as
/// warnings naming where they are, never silently dropped.
fn no_effect_warnings(d: &SceneDesc, ctx: &Ctx, s: &RenderSettings) -> Vec<String> {
    use desc::{AoMethod, ShadowMethod, TextureFilter};
    let (r, o) = (&d.render, &d.output);
    let mut out = Vec::new();
    let mut warn = |span: Option<std::ops::Range<usize>>, what: &str| {
        if let Some(span) = span {
            out.push(format!("{}: {what}", ctx.location(span)));
        }
    };
    if !matches!(s.shadows, ShadowMethod::Hard | ShadowMethod::Pcf) {
        let why = "has no effect: render.shadows is not hard or pcf";
        warn(
            r.shadow_map_size.as_ref().map(|v| v.span()),
            &format!("render.shadow_map_size {why}"),
        );
        warn(
            r.shadow_bias.as_ref().map(|v| v.span()),
            &format!("render.shadow_bias {why}"),
        );
    }
    if s.texture_filter != TextureFilter::Anisotropic {
        warn(
            r.max_anisotropy.as_ref().map(|v| v.span()),
            "render.max_anisotropy has no effect: render.texture_filter is not anisotropic",
        );
    }
    if s.ao.method == AoMethod::Off
        && let Some(ao) = &r.ao
        && (ao.get_ref().radius.is_some() || ao.get_ref().samples.is_some())
    {
        warn(
            Some(ao.span()),
            "render.ao radius/samples have no effect without a method (ssao or raytraced)",
        );
    }
    if o.gif.is_none() {
        let why = "has no effect without output.gif";
        warn(
            o.gif_delay_ms.as_ref().map(|v| v.span()),
            &format!("output.gif_delay_ms {why}"),
        );
        warn(
            o.gif_dither.as_ref().map(|v| v.span()),
            &format!("output.gif_dither {why}"),
        );
    }
    out
}

fn ao_settings(r: &desc::RenderDesc) -> super::AoSettings {
    let (method, radius, samples) = match &r.ao {
        Some(a) => {
            let a = a.get_ref();
            (
                get(&a.method, desc::AoMethod::Off),
                a.radius.as_ref().map(|r| *r.get_ref()),
                a.samples.as_ref().map(|s| *s.get_ref() as u32),
            )
        }
        None => (desc::AoMethod::Off, None, None),
    };
    let default_samples = if method == desc::AoMethod::Raytraced {
        64
    } else {
        16
    };
    super::AoSettings {
        method,
        radius,
        samples: samples.unwrap_or(default_samples),
    }
}

fn build(d: &SceneDesc, ctx: &Ctx, opts: &LoadOptions) -> Result<Scene, Error> {
    let scene_dir = ctx.file.parent().unwrap_or(Path::new("")).to_path_buf();
    let stem = ctx
        .file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let r = &d.render;
    let o = &d.output;
    let settings = RenderSettings {
        width: get(&o.width, 800) as u32,
        height: get(&o.height, 800) as u32,
        shading: get(&r.shading, Default::default()),
        texture_filter: get(&r.texture_filter, Default::default()),
        max_anisotropy: get(&r.max_anisotropy, 16) as f32,
        address: get(&r.address, Default::default()),
        cull: get(&r.cull, Default::default()),
        depth: get(&r.depth, Default::default()),
        tonemap: get(&r.tonemap, Default::default()),
        exposure: get(&r.exposure, 0.0),
        background: get(&o.background, desc::Background::Color([0.0; 3])),
        ambient: Vec3::from(get(&d.ambient.color, [0.03; 3])),
        shadows: shadow_method(r),
        shadow_map_size: get(&r.shadow_map_size, 2048) as u32,
        shadow_bias: shadow_bias(r),
        ao: ao_settings(r),
        msaa: get(&r.msaa, 1) as u32,
        ssaa: get(&r.ssaa, 1) as u32,
    };
    if let Some(v) = &o.ao
        && *v.get_ref()
        && settings.ao.method == desc::AoMethod::Off
    {
        return Err(ctx.err(
            v.span(),
            "output.ao = true needs render.ao with method = \"ssao\" or \"raytraced\"",
        ));
    }
    let name = get(&o.name, "{camera}_{frame:04}".to_string());
    if let Err(msg) = check_pattern(&name) {
        let span = o.name.as_ref().map(|n| n.span()).unwrap_or(0..0);
        return Err(ctx.err(span, format!("output.name: {msg}")));
    }
    let dir = match (&opts.out_dir, &o.dir) {
        (Some(out), _) => out.clone(),
        (None, Some(dir)) => scene_dir.join(dir.get_ref()),
        (None, None) => PathBuf::from("out").join(&stem),
    };
    let output = OutputSettings {
        dir,
        name,
        color: get(&o.color, true),
        depth: get(&o.depth, false),
        ao: get(&o.ao, false),
        gif: o.gif.as_ref().map(|g| g.get_ref().clone()),
        gif_delay_ms: get(&o.gif_delay_ms, 40) as u32,
        gif_dither: get(&o.gif_dither, Default::default()),
    };
    if let (Some(g), Some(c)) = (&o.gif, &o.color)
        && !*c.get_ref()
    {
        return Err(ctx.err(
            g.span(),
            "output.gif is assembled from the color frames: it needs output.color = true",
        ));
    }

    // Models: each file parsed once, even if several [[model]] use it.
    let textured = !matches!(
        settings.shading,
        desc::ShadingMode::Depth | desc::ShadingMode::Wireframe
    );
    // The normals view reads normal and bump maps only.
    let normals_view = settings.shading == desc::ShadingMode::Normals;
    let mut files: BTreeMap<PathBuf, usize> = BTreeMap::new();
    let mut file_list = Vec::new();
    for m in &d.models {
        let p = resolve(&scene_dir, m.get_ref().path.get_ref());
        files.entry(p.clone()).or_insert_with(|| {
            file_list.push(p);
            file_list.len() - 1
        });
    }
    for m in &d.models {
        let p = resolve(&scene_dir, m.get_ref().path.get_ref());
        if !p.is_file() {
            return Err(Error::Asset {
                path: p,
                line: None,
                message: format!(
                    "model file not found: put the model there or change `path` (from {})",
                    ctx.location(m.get_ref().path.span())
                ),
            });
        }
    }
    let loaded: Vec<SourceModel> = file_list
        .par_iter()
        .map(|p| SourceModel::load(p))
        .collect::<Result<_, _>>()?;
    let mut warnings = no_effect_warnings(d, ctx, &settings);
    warnings.extend(loaded.iter().flat_map(|m| m.warnings.clone()));
    let source = |md: &desc::ModelDesc| &loaded[files[&resolve(&scene_dir, md.path.get_ref())]];

    // Materials (with overrides), then the set of textures they need.
    let mut model_mats: Vec<Vec<SourceMaterial>> = Vec::new();
    for m in &d.models {
        let md = m.get_ref();
        let src = source(md);
        for (name, ov) in &md.materials {
            if !src.materials.iter().any(|mm| mm.name() == name) {
                let names: Vec<_> = src.materials.iter().map(|m| m.name()).collect();
                return Err(ctx.err(
                    ov.span(),
                    format!(
                        "model.materials.\"{name}\": the model has no material of that name (it has: {})",
                        names.join(", ")
                    ),
                ));
            }
        }
        let mats = src
            .materials
            .iter()
            .map(|mm| {
                let mut mm = mm.clone();
                if let Some(all) = &md.material {
                    mm.apply_override(all.get_ref(), &scene_dir, ctx)?;
                }
                if let Some(one) = md.materials.get(mm.name()) {
                    mm.apply_override(one.get_ref(), &scene_dir, ctx)?;
                }
                Ok(mm)
            })
            .collect::<Result<Vec<_>, Error>>()?;
        model_mats.push(mats);
    }
    // Images to decode, once per (image, sRGB), in a fixed order.
    let mut wanted: BTreeMap<(PathBuf, bool), ImageSource> = BTreeMap::new();
    if textured {
        for (m, mats) in d.models.iter().zip(&model_mats) {
            let src = source(m.get_ref());
            if !src.mesh.has_uvs() && src.mesh.uvs1.is_empty() {
                continue;
            }
            for (i, mm) in mats.iter().enumerate() {
                if !src.mesh.groups.iter().any(|g| g.material == i) {
                    continue;
                }
                for (img, srgb) in mm.images(normals_view) {
                    wanted.insert((img.key().to_path_buf(), srgb), img);
                }
            }
        }
    }
    let keys: Vec<_> = wanted.iter().collect();
    let decoded: Vec<Arc<Texture>> = keys
        .par_iter()
        .enumerate()
        .map(|(id, ((_, srgb), img))| {
            let t = match img {
                ImageSource::File(p) => Texture::load(p, *srgb),
                ImageSource::Memory { name, bytes } => Texture::from_bytes(bytes, name, *srgb),
            };
            t.map(|mut t| {
                t.id = id;
                Arc::new(t)
            })
        })
        .collect::<Result<_, _>>()?;
    let by_key: BTreeMap<(PathBuf, bool), Arc<Texture>> = keys
        .iter()
        .map(|(k, _)| (*k).clone())
        .zip(decoded.iter().cloned())
        .collect();
    let textures = decoded;
    let lookup = |p: &Path, srgb: bool| by_key.get(&(p.to_path_buf(), srgb)).cloned();

    let mut models = Vec::new();
    let mut imported_lights = Vec::new();
    let mut imported_cameras = Vec::new();
    for (i, (m, mats)) in d.models.iter().zip(&model_mats).enumerate() {
        let md = m.get_ref();
        let src = source(md);
        let materials = mats
            .iter()
            .map(|mm| materials::to_material(mm, &lookup))
            .collect::<Vec<_>>();
        let mut world = placement(md);
        if get(&md.normalize, false) {
            let (lo, hi) = src.mesh.bounds();
            let extent = (hi - lo).max_element().max(1e-20);
            world = world
                * Mat4::from_scale(Vec3::splat(1.0 / extent))
                * Mat4::from_translation(-(lo + hi) * 0.5);
        }
        let mut mesh = src.mesh.clone();
        for (gi, mm) in mats.iter().enumerate() {
            if let SourceMaterial::Mtl(mm) = mm
                && let Some(spec) = &mm.disp
            {
                displace(&mut mesh, gi, spec, mm.disp_scale)?;
            }
        }
        if let Some(nm) = materials.iter().find(|m| m.needs_tangents())
            && textured
        {
            let set = match &nm.normal_map {
                Some(NormalMap::Normals { map, .. }) | Some(NormalMap::Height { map, .. }) => {
                    map.texcoord as usize
                }
                None => 0,
            };
            mesh.compute_tangents(set);
        }
        for (v, key, what) in [
            (&md.lights, "model.lights", "lights"),
            (&md.cameras, "model.cameras", "cameras"),
        ] {
            if let Some(v) = v
                && *v.get_ref()
                && src.gltf.is_none()
            {
                return Err(ctx.err(
                    v.span(),
                    format!("{key} = true: only glTF models carry {what}; this one is OBJ"),
                ));
            }
        }
        if let Some(g) = &src.gltf {
            if get(&md.lights, false) {
                if g.lights.is_empty() {
                    warnings.push(format!(
                        "{}: model.lights = true, but the file has no KHR_lights_punctual lights",
                        md.path.get_ref()
                    ));
                }
                imported_lights.extend(g.lights.iter().map(|l| l.light.transformed(world)));
            }
            if get(&md.cameras, false) {
                if g.cameras.is_empty() {
                    warnings.push(format!(
                        "{}: model.cameras = true, but the file has no cameras",
                        md.path.get_ref()
                    ));
                }
                imported_cameras.extend(g.cameras.iter().map(|c| (c.clone(), world)));
            }
        }
        models.push(Model {
            name: md
                .name
                .as_ref()
                .map(|n| n.get_ref().clone())
                .unwrap_or_else(|| format!("model{i}")),
            mesh: Arc::new(mesh),
            materials,
            world_from_object: world,
        });
    }

    // World bounds at rest: box center is the turntable pivot, the sphere
    // around the box frames the default camera.
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for m in &models {
        for p in &m.mesh.positions {
            let w = m.world_from_object.transform_point3(*p);
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-6);

    let mut lights = d
        .lights
        .iter()
        .map(|l| to_light(l.get_ref()))
        .collect::<Vec<_>>();
    lights.extend(imported_lights);
    let cameras = build_cameras(d, ctx, center, radius, &imported_cameras)?;

    let frames = get(&d.animation.frames, 1) as u32;
    let turntable = d.animation.turntable.as_ref().map(|t| {
        let t = t.get_ref();
        Turntable {
            axis: Vec3::from(get(&t.axis, [0.0, 1.0, 0.0])).normalize(),
            degrees: get(&t.degrees, 360.0),
            rotate: get(&t.rotate, Default::default()),
        }
    });

    Ok(Scene {
        file: ctx.file.to_path_buf(),
        stem,
        settings,
        output,
        models,
        lights,
        cameras,
        animation: Animation {
            frames,
            turntable,
            pivot: center,
        },
        bounds_center: center,
        bounds_radius: radius,
        textures,
        warnings,
    })
}

/// A model file as loaded: OBJ (+ MTL) or glTF.
struct SourceModel {
    mesh: crate::assets::mesh::Mesh,
    materials: Vec<SourceMaterial>,
    /// glTF only: lights, cameras.
    gltf: Option<crate::assets::gltf::GltfModel>,
    warnings: Vec<String>,
}

impl SourceModel {
    fn load(path: &Path) -> Result<SourceModel, Error> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if ext == "gltf" || ext == "glb" {
            let mut g = crate::assets::gltf::load(path)?;
            Ok(SourceModel {
                mesh: std::mem::take(&mut g.mesh),
                materials: g
                    .materials
                    .drain(..)
                    .map(|m| SourceMaterial::Gltf(Box::new(m)))
                    .collect(),
                warnings: std::mem::take(&mut g.warnings),
                gltf: Some(g),
            })
        } else {
            let o = obj::load(path)?;
            Ok(SourceModel {
                mesh: o.mesh,
                materials: o
                    .materials
                    .into_iter()
                    .map(|m| SourceMaterial::Mtl(Box::new(m)))
                    .collect(),
                gltf: None,
                warnings: Vec::new(),
            })
        }
    }
}

fn resolve(base: &Path, p: &str) -> PathBuf {
    base.join(p.replace('\\', "/"))
}

/// translate * rotate (XYZ Euler, degrees) * scale.
fn placement(m: &desc::ModelDesc) -> Mat4 {
    let t = Vec3::from(get(&m.translate, [0.0; 3]));
    let r = get(&m.rotate, [0.0; 3]);
    let s = get(&m.scale, desc::Scale([1.0; 3])).0;
    let q = Quat::from_euler(
        EulerRot::XYZ,
        r[0].to_radians(),
        r[1].to_radians(),
        r[2].to_radians(),
    );
    Mat4::from_scale_rotation_translation(Vec3::from(s), q, t)
}

/// Displacement at load time: every vertex of material `group_material`'s
/// triangles moves along its normal by `base + gain * height` (MTL `-mm`,
/// default 0 and 1) times `scale` (scene `disp_scale`, default 1), the height
/// read bilinearly from the map. Vertices at one position (UV seams) move by
/// their mean, so the surface does not crack; their normals are then
/// recomputed from the displaced faces.
fn displace(
    mesh: &mut crate::assets::mesh::Mesh,
    group_material: usize,
    spec: &MapSpec,
    scale: Option<f32>,
) -> Result<(), Error> {
    let used: Vec<bool> = {
        let mut used = vec![false; mesh.positions.len()];
        for g in mesh.groups.iter().filter(|g| g.material == group_material) {
            for t in &mesh.triangles[g.triangles.start as usize..g.triangles.end as usize] {
                for &i in t {
                    used[i as usize] = true;
                }
            }
        }
        used
    };
    if !used.iter().any(|u| *u) {
        return Ok(());
    }
    if !mesh.has_uvs() {
        return Err(Error::asset(
            &spec.path,
            None,
            "disp: the model has no texture coordinates to read heights with",
        ));
    }
    let tex = Texture::load(&spec.path, false)?;
    let (base, gain) = spec.mm.unwrap_or((0.0, 1.0));
    let scale = scale.unwrap_or(1.0);
    let mode = if spec.clamp {
        desc::AddressMode::Clamp
    } else {
        desc::AddressMode::Repeat
    };
    let map = |uv: Vec2| {
        let uv = uv * Vec2::new(spec.scale[0], spec.scale[1])
            + Vec2::new(spec.offset[0], spec.offset[1]);
        tex.sample_bilinear(uv, mode).x
    };
    // Mean offset per welded position.
    let mut sums: std::collections::HashMap<[u32; 3], (f32, u32)> = Default::default();
    let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    for (i, _) in used.iter().enumerate().filter(|u| *u.1) {
        let h = (base + gain * map(mesh.uvs[i])) * scale;
        let e = sums.entry(key(mesh.positions[i])).or_insert((0.0, 0));
        e.0 += h;
        e.1 += 1;
    }
    let old = mesh.positions.clone();
    for (i, _) in used.iter().enumerate().filter(|u| *u.1) {
        let (sum, n) = sums[&key(old[i])];
        mesh.positions[i] = old[i] + mesh.normals[i] * (sum / n as f32);
    }
    crate::assets::mesh::smooth_normals(&mesh.positions, &mesh.triangles, &mut mesh.normals, &used);
    Ok(())
}

fn to_light(l: &desc::LightDesc) -> Light {
    let color = Vec3::from(get(&l.color, [1.0; 3]));
    let position = Vec3::from(get(&l.position, [0.0; 3]));
    let direction = Vec3::from(get(&l.direction, [0.0, -1.0, 0.0])).normalize();
    let intensity = get(&l.intensity, 10.0);
    let kind = match get(&l.kind, Default::default()) {
        desc::LightKind::Point => LightKind::Point {
            position,
            intensity,
        },
        desc::LightKind::Directional => LightKind::Directional {
            direction,
            irradiance: get(&l.irradiance, 1.0),
        },
        desc::LightKind::Spot => LightKind::Spot {
            position,
            direction,
            intensity,
            cos_inner: get(&l.inner_angle, 20.0).to_radians().cos(),
            cos_outer: get(&l.outer_angle, 30.0).to_radians().cos(),
        },
    };
    Light {
        kind,
        color,
        shadows: get(&l.shadows, false),
        range: None,
    }
}

/// The scene's cameras, then those imported from glTF files (named by the
/// file, made unique with a suffix); the default framing camera only when
/// there are neither.
fn build_cameras(
    d: &SceneDesc,
    ctx: &Ctx,
    center: Vec3,
    radius: f32,
    imported: &[(GltfCamera, Mat4)],
) -> Result<Vec<Camera>, Error> {
    if d.cameras.is_empty() && imported.is_empty() {
        return Ok(vec![Camera::framing("camera".into(), center, radius, 45.0)]);
    }
    let mut cams: Vec<Camera> = Vec::new();
    let several = d.cameras.len() > 1;
    for (i, c) in d.cameras.iter().enumerate() {
        let cd = c.get_ref();
        let name = cd
            .name
            .as_ref()
            .map(|n| n.get_ref().clone())
            .unwrap_or_else(|| {
                if several {
                    format!("camera{i}")
                } else {
                    "camera".into()
                }
            });
        if cams.iter().any(|c| c.name == name) {
            return Err(ctx.err(c.span(), format!("two cameras are named `{name}`")));
        }
        let fov = get(&cd.fov, 45.0);
        let up = Vec3::from(get(&cd.up, [0.0, 1.0, 0.0])).normalize();
        let (eye, target) = match (&cd.eye, &cd.target) {
            (None, None) => {
                let f = Camera::framing(name.clone(), center, radius, fov);
                (f.eye, f.target)
            }
            (Some(e), None) => (Vec3::from(*e.get_ref()), center),
            (None, Some(t)) => {
                let t = Vec3::from(*t.get_ref());
                let f = Camera::framing(name.clone(), center, radius, fov);
                (t + (f.eye - f.target), t)
            }
            (Some(e), Some(t)) => (Vec3::from(*e.get_ref()), Vec3::from(*t.get_ref())),
        };
        if (target - eye).length_squared() == 0.0 {
            return Err(ctx.err(c.span(), "the camera's eye is at its target"));
        }
        if (target - eye).normalize().cross(up).length() < 1e-6 {
            return Err(ctx.err(
                c.span(),
                "the camera looks along its `up` vector: give another `up`",
            ));
        }
        let projection = match get(&cd.projection, Default::default()) {
            desc::Projection::Perspective => Projection::Perspective { fov_y: fov },
            desc::Projection::Orthographic => Projection::Orthographic {
                height: get(&cd.height, radius * 2.0),
            },
        };
        let dist = (center - eye).length();
        let (fit_near, fit_far) = fitted_planes(dist, radius);
        let near = get(&cd.near, fit_near);
        let far = get(&cd.far, fit_far.max(near * 2.0));
        if far <= near {
            return Err(ctx.err(
                c.span(),
                format!("camera `{name}`: far ({far}) must be greater than near ({near})"),
            ));
        }
        cams.push(Camera {
            name,
            eye,
            target,
            up,
            projection,
            near,
            far,
        });
    }
    for (g, world) in imported {
        let eye = world.transform_point3(g.eye);
        let forward = world
            .transform_vector3(g.forward)
            .try_normalize()
            .unwrap_or(Vec3::NEG_Z);
        let up = world
            .transform_vector3(g.up)
            .try_normalize()
            .unwrap_or(Vec3::Y);
        let up = if forward.cross(up).length() < 1e-6 {
            forward.any_orthonormal_vector()
        } else {
            up
        };
        // A target straight ahead, as far as the models' center.
        let dist = (center - eye).dot(forward).max(radius * 1e-3).max(1e-6);
        // The model's scale applies to the planes too.
        let s = world.transform_vector3(g.forward).length().max(1e-20);
        let (_, fit_far) = fitted_planes((center - eye).length(), radius);
        let near = (g.near * s).max(1e-6);
        let far = g.far.map(|f| f * s).unwrap_or(fit_far).max(near * 2.0);
        let mut name = g.name.clone();
        let mut k = 1;
        while cams.iter().any(|c| c.name == name) {
            k += 1;
            name = format!("{}_{k}", g.name);
        }
        cams.push(Camera {
            name,
            eye,
            target: eye + forward * dist,
            up,
            projection: match g.projection {
                GltfProjection::Perspective { fov_y } => Projection::Perspective { fov_y },
                GltfProjection::Orthographic { height } => {
                    Projection::Orthographic { height: height * s }
                }
            },
            near,
            far,
        });
    }
    Ok(cams)
}
