//! `[[model]]` tables to `Model`s: each model file read once (in parallel)
//! however many models use it, materials with the scene's overrides, the
//! textures that drawn materials read decoded once per (image, sRGB) in a
//! fixed order, then per model its placement, displacement, tangents and
//! the lights and cameras it imports.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{EulerRot, Mat4, Quat, Vec2, Vec3};
use rayon::prelude::*;

use super::cameras::Bounds;
use super::materials::{self, MtlSource, SourceMaterial};
use super::{get, lights};
use crate::assets::gltf::{GltfCamera, GltfLight, GltfMaterial, GltfModel, ImageSource};
use crate::assets::input::Input;
use crate::assets::mesh::Mesh;
use crate::assets::obj::{self, MapSpec};
use crate::assets::rig::{Parts, Rig};
use crate::assets::texture::cache::TextureCache;
use crate::assets::texture::{AddressMode, Texture};
use crate::error::Error;
use crate::scene::animation::{NodeLight, Playback};
use crate::scene::desc::{self, Ctx, SceneDesc};
use crate::scene::light::Light;
use crate::scene::material::Material;
use crate::scene::{Model, RenderSettings};

/// What the models bring: themselves, the decoded textures (`Texture::id`
/// indexes the list), and the lights and cameras of glTF files that asked
/// for them (cameras with their model's placement).
pub(super) struct Models {
    pub models: Vec<Model>,
    pub textures: Vec<Arc<Texture>>,
    pub lights: Vec<Light>,
    /// The imported lights that follow animated nodes (`light` indexes
    /// `lights`).
    pub node_lights: Vec<NodeLight>,
    pub cameras: Vec<(GltfCamera, Mat4)>,
}

/// A model file as loaded: OBJ (+ MTL) or glTF.
struct SourceModel {
    mesh: Mesh,
    materials: Vec<SourceMaterial>,
    /// glTF only: lights, cameras.
    gltf: Option<GltfModel>,
    /// glTF and FBX files with animation: their rig and clips, or why
    /// they cannot be played.
    rig: Option<Result<Arc<Rig>, String>>,
    /// glTF and FBX files: their lights and cameras, placed in the file's
    /// space (None: the format has none).
    imported: Option<(Vec<GltfLight>, Vec<GltfCamera>)>,
    warnings: Vec<String>,
}

/// The model files, each once, in the order the scene first names them.
struct Files {
    index: BTreeMap<PathBuf, usize>,
    loaded: Vec<SourceModel>,
    scene_dir: PathBuf,
}

impl Files {
    fn of(&self, md: &desc::ModelDesc) -> &SourceModel {
        &self.loaded[self.index[&resolve(&self.scene_dir, md.path.get_ref())]]
    }
}

pub(super) fn build(
    d: &SceneDesc,
    ctx: &Ctx,
    settings: &RenderSettings,
    scene_dir: &Path,
    cache: Option<&TextureCache>,
    input: &Input,
    warnings: &mut Vec<String>,
) -> Result<Models, Error> {
    let files = load_files(d, ctx, scene_dir, input)?;
    warnings.extend(files.loaded.iter().flat_map(|m| m.warnings.clone()));
    let model_mats = source_materials(d, ctx, &files, scene_dir)?;
    confine_images(d, &files, &model_mats, input)?;
    // Depth and wireframe views read no texture; the normals view reads
    // normal and bump maps only.
    let textured = !matches!(
        settings.shading,
        crate::scene::settings::ShadingMode::Depth | crate::scene::settings::ShadingMode::Wireframe
    );
    let normals_view = settings.shading == crate::scene::settings::ShadingMode::Normals;
    // The meshes are displaced and given tangents while the textures
    // decode: the tangents for the set the materials would read if every
    // image decodes (checked below, once the materials are made).
    let mut texture_warnings = Vec::new();
    let (decoded, shaped) = rayon::join(
        || {
            if textured {
                let w = &mut texture_warnings;
                decode_textures(d, &files, &model_mats, normals_view, cache, input, w)
            } else {
                Ok((Vec::new(), BTreeMap::new()))
            }
        },
        || {
            let placeholder = Arc::new(Texture::from_rgba8(1, 1, &[[0; 4]], false));
            let any = |_: &Path, _: bool| Some(placeholder.clone());
            let shape = |(m, mats): (&desc::Spanned<desc::ModelDesc>, &Vec<SourceMaterial>)| {
                let md = m.get_ref();
                let guess: Vec<Material> = mats
                    .iter()
                    .map(|mm| materials::to_material(mm, &any))
                    .collect();
                let set = tangent_set(&guess).filter(|_| textured);
                Shaped::new(md, ctx, files.of(md), mats, set, input)
            };
            d.models
                .iter()
                .zip(&model_mats)
                .map(shape)
                .collect::<Vec<_>>()
        },
    );
    warnings.append(&mut texture_warnings);
    let (textures, by_key) = decoded?;
    let lookup = |p: &Path, srgb: bool| by_key.get(&(p.to_path_buf(), srgb)).cloned();

    let mut out = Models {
        models: Vec::new(),
        textures,
        lights: Vec::new(),
        node_lights: Vec::new(),
        cameras: Vec::new(),
    };
    let models = d.models.iter().zip(&model_mats).zip(shaped);
    for (i, ((m, mats), shaped)) in models.enumerate() {
        let md = m.get_ref();
        let src = files.of(md);
        let materials: Vec<Material> = mats
            .iter()
            .map(|mm| materials::to_material(mm, &lookup))
            .collect();
        let world = placement(md, &src.mesh);
        let mut mesh = shaped.mesh;
        warnings.extend(shaped.warnings);
        shaped.checked?;
        let set = tangent_set(&materials).filter(|_| textured);
        match (set, shaped.tangents) {
            (Some(s), Some((g, t))) if s == g => mesh.tangents = t,
            (Some(s), _) => mesh.compute_tangents(s),
            (None, _) => {}
        }
        let playback = playback(md, ctx, src, &mesh)?;
        let first_light = out.lights.len();
        import_lights_and_cameras(md, ctx, src, world, &mut out, warnings)?;
        if let (Some(p), Some(g)) = (&playback, &src.gltf) {
            // Imported lights follow their nodes.
            for (k, (gl, &node)) in g.lights.iter().zip(&p.rig.light_nodes).enumerate() {
                if first_light + k < out.lights.len() {
                    out.node_lights.push(NodeLight {
                        light: first_light + k,
                        model: i,
                        node,
                        local: lights::from_gltf(&gl.placed(Mat4::IDENTITY), Mat4::IDENTITY),
                    });
                }
            }
        }
        let name = model_name(md, &out.models);
        out.models.push(Model {
            name,
            // Only `cull = "auto"` asks (a sort over the edges).
            closed: settings.cull == crate::scene::settings::CullMode::Auto && mesh.is_closed(),
            mesh: Arc::new(mesh),
            materials,
            world_from_object: world,
            playback,
            motion_points: Vec::new(),
        });
    }
    Ok(out)
}

/// A model's mesh made ready while its textures decode (`build`): its
/// file's mesh displaced by its materials' displacement maps (with a
/// warning for each that cannot be read), its size checked, and the
/// tangents of one texture-coordinate set computed.
struct Shaped {
    mesh: Mesh,
    warnings: Vec<String>,
    checked: Result<(), Error>,
    /// The set and its tangents (the mesh's own are left as they were).
    tangents: Option<(usize, Vec<glam::Vec4>)>,
}

impl Shaped {
    fn new(
        md: &desc::ModelDesc,
        ctx: &Ctx,
        src: &SourceModel,
        mats: &[SourceMaterial],
        set: Option<usize>,
        input: &Input,
    ) -> Shaped {
        let mut mesh = src.mesh.clone();
        let mut warnings = Vec::new();
        for (gi, mm) in mats.iter().enumerate() {
            if let SourceMaterial::Mtl(mm) = mm
                && let Some(spec) = &mm.mtl.disp
            {
                // Lenient: a displacement map that cannot be read leaves
                // the surface as it is.
                if let Err(e) = displace(&mut mesh, gi, spec, mm.disp_scale, input) {
                    warnings.push(format!("{e}; the surface is not displaced"));
                }
            }
        }
        // After displacement, which can move positions anywhere.
        let checked = check_magnitude(md, ctx, &mesh, placement(md, &src.mesh));
        let tangents = set.filter(|_| checked.is_ok()).map(|set| {
            let own = mesh.tangents.clone();
            mesh.compute_tangents(set);
            (set, std::mem::replace(&mut mesh.tangents, own))
        });
        Shaped {
            mesh,
            warnings,
            checked,
            tangents,
        }
    }
}

/// `model.name`, else the file's stem (`bunny`, then `bunny_2` for a
/// second model of that file): what the object-id pass calls it.
fn model_name(md: &desc::ModelDesc, before: &[Model]) -> String {
    if let Some(n) = &md.name {
        return n.get_ref().clone();
    }
    let stem = Path::new(md.path.get_ref())
        .file_stem()
        .map_or_else(|| "model".to_string(), |s| s.to_string_lossy().into_owned());
    let mut name = stem.clone();
    let mut k = 1;
    while before.iter().any(|m| m.name == name) {
        k += 1;
        name = format!("{stem}_{k}");
    }
    name
}

/// `model.animation`: the clip it names in the model's glTF or FBX file,
/// ready to play (an error lists the clips the file has).
fn playback(
    md: &desc::ModelDesc,
    ctx: &Ctx,
    src: &SourceModel,
    mesh: &Mesh,
) -> Result<Option<Arc<Playback>>, Error> {
    let Some(want) = &md.animation else {
        return Ok(None);
    };
    let err = |m: String| Err(ctx.err(want.span(), m));
    let format = format_name(md.path.get_ref());
    if src.gltf.is_none() && format != "FBX" {
        return err(format!(
            "model.animation: only glTF and FBX models' animations are read; this one is {format}"
        ));
    }
    let rig = match &src.rig {
        Some(Ok(r)) if r.clips.is_empty() => {
            return err(format!(
                "model.animation: {} has no animations",
                md.path.get_ref()
            ));
        }
        None => {
            return err(format!(
                "model.animation: {} has no animations",
                md.path.get_ref()
            ));
        }
        Some(Err(e)) => {
            return err(format!(
                "model.animation: {} cannot be animated: {e}",
                md.path.get_ref()
            ));
        }
        Some(Ok(r)) => r.clone(),
    };
    let found = match want.get_ref() {
        desc::ClipRef::Name(n) => rig.clips.iter().position(|(name, _)| name == n),
        desc::ClipRef::Index(i) => usize::try_from(*i).ok().filter(|&i| i < rig.clips.len()),
    };
    let Some(index) = found else {
        let what = match want.get_ref() {
            desc::ClipRef::Name(n) => format!("no animation named \"{n}\""),
            desc::ClipRef::Index(i) => format!("no animation {i}"),
        };
        return err(format!(
            "model.animation: {} has {what}; it has: {}",
            md.path.get_ref(),
            rig.clip_names()
        ));
    };
    let clip = match &rig.clips[index].1 {
        Ok(c) => c.clone(),
        Err(e) => {
            return err(format!(
                "model.animation: animation {index} of {} cannot be played: {e}",
                md.path.get_ref()
            ));
        }
    };
    let tangents = rig.source_tangents(mesh);
    Ok(Some(Arc::new(Playback {
        rig,
        clip,
        index,
        tangents,
    })))
}

/// Frames sampled for a clip's motion points at most.
const MOTION_FRAMES: u32 = 48;
/// Vertices kept per sampled frame at most (besides each axis' extremes).
const MOTION_SAMPLE: usize = 2_000;

/// Fills each playing model's `motion_points`: its vertices at up to
/// `MOTION_FRAMES` of the animation's frames (evenly spread), a sample of
/// them and each frame's extremes along every axis.
pub(super) fn sweep(models: &mut [Model], animation: &crate::scene::Animation) {
    for m in models.iter_mut() {
        let Some(p) = &m.playback else { continue };
        let frames = animation.frames.max(1);
        let n = frames.min(MOTION_FRAMES);
        let stride = m.mesh.positions.len().div_ceil(MOTION_SAMPLE).max(1);
        let points: Vec<Vec3> = (0..n)
            .into_par_iter()
            .flat_map_iter(|k| {
                let frame = (k as u64 * frames as u64 / n as u64) as u32;
                let posed = p.pose(&m.mesh, animation.time(frame), Parts::Positions);
                let mut pts: Vec<Vec3> = posed.positions.iter().step_by(stride).copied().collect();
                for axis in 0..3 {
                    let key = |p: &&Vec3| p[axis];
                    let by = |a: &&Vec3, b: &&Vec3| key(a).total_cmp(&key(b));
                    pts.extend(posed.positions.iter().min_by(by).copied());
                    pts.extend(posed.positions.iter().max_by(by).copied());
                }
                pts
            })
            .filter(|p| p.is_finite())
            .collect();
        m.motion_points = points;
    }
}

/// Reads every model file once, in parallel; a missing file is an error
/// naming the `path` key that points at it.
fn load_files(d: &SceneDesc, ctx: &Ctx, scene_dir: &Path, input: &Input) -> Result<Files, Error> {
    let mut index: BTreeMap<PathBuf, usize> = BTreeMap::new();
    let mut list = Vec::new();
    for m in &d.models {
        let p = resolve(scene_dir, m.get_ref().path.get_ref());
        input.confine(&p, Some(ctx.file))?;
        // A directory, FIFO or device is named as such when it is read.
        if std::fs::symlink_metadata(&p).is_err() {
            return Err(Error::Asset {
                path: p,
                line: None,
                message: format!(
                    "model file not found: put the model there or change `path` (from {})",
                    ctx.location(m.get_ref().path.span())
                ),
            });
        }
        index.entry(p.clone()).or_insert_with(|| {
            list.push(p);
            list.len() - 1
        });
    }
    let loaded = list
        .par_iter()
        .map(|p| SourceModel::load(p, input))
        .collect::<Result<_, _>>()?;
    Ok(Files {
        index,
        loaded,
        scene_dir: scene_dir.to_path_buf(),
    })
}

/// Per model, its file's materials with `model.material` (all) and then
/// `model.materials."name"` (one) applied; a name the file lacks is an
/// error listing the names it has.
fn source_materials(
    d: &SceneDesc,
    ctx: &Ctx,
    files: &Files,
    scene_dir: &Path,
) -> Result<Vec<Vec<SourceMaterial>>, Error> {
    let mut out = Vec::new();
    for m in &d.models {
        let md = m.get_ref();
        let src = files.of(md);
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
        let mats = variant_materials(md, ctx, src)?
            .iter()
            .map(|mm| {
                let mut mm = mm.clone();
                if let Some(all) = &md.material {
                    mm.apply_override(all.get_ref(), scene_dir, ctx)?;
                }
                if let Some(one) = md.materials.get(mm.name()) {
                    mm.apply_override(one.get_ref(), scene_dir, ctx)?;
                }
                Ok(mm)
            })
            .collect::<Result<Vec<_>, Error>>()?;
        out.push(mats);
    }
    Ok(out)
}

/// The model file's materials with `model.variant` applied: each slot a
/// KHR_materials_variants mapping names for that variant takes the
/// variant's material. A name the file lacks is an error listing the
/// variants it has.
fn variant_materials(
    md: &desc::ModelDesc,
    ctx: &Ctx,
    src: &SourceModel,
) -> Result<Vec<SourceMaterial>, Error> {
    let mut mats = src.materials.clone();
    let Some(want) = &md.variant else {
        return Ok(mats);
    };
    let (names, slots) = src.gltf.as_ref().map_or((&[][..], &[][..]), |g| {
        (&g.variants[..], &g.variant_slots[..])
    });
    let Some(v) = names.iter().position(|n| n == want.get_ref()) else {
        let path = md.path.get_ref();
        let has = if names.is_empty() {
            "no variants (KHR_materials_variants)".to_string()
        } else {
            let quoted: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
            format!("the variants {}", quoted.join(", "))
        };
        return Err(ctx.err(
            want.span(),
            format!(
                "model.variant = \"{}\": {path} has no variant of that name; it has {has}",
                want.get_ref()
            ),
        ));
    };
    for s in slots {
        if let Some(&(_, m)) = s.mappings.iter().find(|(variant, _)| *variant == v) {
            mats[s.slot] = src.materials[m].clone();
        }
    }
    Ok(mats)
}

/// In the sandbox, every image a material names (and every displacement
/// map) stays in the scene's folder; the error names the model file.
fn confine_images(
    d: &SceneDesc,
    files: &Files,
    model_mats: &[Vec<SourceMaterial>],
    input: &Input,
) -> Result<(), Error> {
    if !input.is_sandboxed() {
        return Ok(());
    }
    for (m, mats) in d.models.iter().zip(model_mats) {
        let model = resolve(&files.scene_dir, m.get_ref().path.get_ref());
        for mm in mats {
            for (img, _) in mm.images(false) {
                if let ImageSource::File(p) = img {
                    input.confine(&p, Some(&model))?;
                }
            }
            if let SourceMaterial::Mtl(x) = mm
                && let Some(spec) = &x.mtl.disp
            {
                input.confine(&spec.path, Some(&model))?;
            }
        }
    }
    Ok(())
}

type TextureKeys = BTreeMap<(PathBuf, bool), Arc<Texture>>;

/// Decodes, in parallel and once per (image, sRGB), the images that the
/// materials of drawn triangles read (or reads them from `cache`, which
/// then also holds their mip chains); ids follow the images' sorted order.
fn decode_textures(
    d: &SceneDesc,
    files: &Files,
    model_mats: &[Vec<SourceMaterial>],
    normals_view: bool,
    cache: Option<&TextureCache>,
    input: &Input,
    warnings: &mut Vec<String>,
) -> Result<(Vec<Arc<Texture>>, TextureKeys), Error> {
    let mut wanted: BTreeMap<(PathBuf, bool), ImageSource> = BTreeMap::new();
    for (m, mats) in d.models.iter().zip(model_mats) {
        let src = files.of(m.get_ref());
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
    let keys: Vec<_> = wanted.iter().collect();
    let results: Vec<Result<(Texture, Option<String>), Error>> = keys
        .par_iter()
        .map(|((_, srgb), img)| {
            let srgb = *srgb;
            match (img, cache) {
                (ImageSource::File(p), None) => Ok((Texture::load(p, srgb, input)?, None)),
                (ImageSource::Memory { name, bytes }, None) => {
                    Ok((Texture::from_bytes(bytes, name, srgb, input)?, None))
                }
                (ImageSource::File(p), Some(c)) => {
                    let bytes = input.read(p, None, None)?;
                    let (t, _, w) =
                        c.load(&bytes, srgb, || Texture::from_bytes(&bytes, p, srgb, input))?;
                    Ok((t, w))
                }
                (ImageSource::Memory { name, bytes }, Some(c)) => {
                    let (t, _, w) = c.load(bytes, srgb, || {
                        Texture::from_bytes(bytes, name, srgb, input)
                    })?;
                    Ok((t, w))
                }
            }
        })
        .collect();
    // Lenient: a texture that cannot be read is a warning, and the
    // materials that use it render without that map. Ids follow the
    // readable images' sorted order.
    let mut decoded = Vec::new();
    let mut by_key = TextureKeys::new();
    for ((key, _), r) in keys.iter().zip(results) {
        match r {
            Ok((mut t, cache_warning)) => {
                warnings.extend(cache_warning);
                t.id = decoded.len();
                let t = Arc::new(t);
                decoded.push(t.clone());
                by_key.insert((*key).clone(), t);
            }
            // The sandbox and the memory budget are not lenient.
            Err(e @ (Error::Sandbox { .. } | Error::Memory { .. })) => return Err(e),
            Err(e) => {
                if !warnings.iter().any(|w| w.starts_with(&e.to_string())) {
                    warnings.push(format!("{e}; rendering without this map"));
                }
            }
        }
    }
    Ok((decoded, by_key))
}

/// The texture-coordinate set of the first material whose normal or bump
/// map needs per-corner tangents (None: no material needs them).
fn tangent_set(materials: &[Material]) -> Option<usize> {
    materials.iter().find_map(|m| m.tangent_set())
}

/// `model.lights` and `model.cameras`: glTF and FBX files only; an import
/// that finds nothing is a warning.
fn import_lights_and_cameras(
    md: &desc::ModelDesc,
    ctx: &Ctx,
    src: &SourceModel,
    world: Mat4,
    out: &mut Models,
    warnings: &mut Vec<String>,
) -> Result<(), Error> {
    for (v, key, what) in [
        (&md.lights, "model.lights", "lights"),
        (&md.cameras, "model.cameras", "cameras"),
    ] {
        if let Some(v) = v
            && *v.get_ref()
            && src.imported.is_none()
        {
            return Err(ctx.err(
                v.span(),
                format!(
                    "{key} = true: only glTF and FBX models' {what} are read; this one is {}",
                    format_name(md.path.get_ref())
                ),
            ));
        }
    }
    let Some((file_lights, file_cameras)) = &src.imported else {
        return Ok(());
    };
    if get(&md.lights, false) {
        if file_lights.is_empty() {
            let what = if src.gltf.is_some() {
                "KHR_lights_punctual lights"
            } else {
                "lights"
            };
            warnings.push(format!(
                "{}: model.lights = true, but the file has no {what}",
                md.path.get_ref()
            ));
        }
        out.lights
            .extend(file_lights.iter().map(|l| lights::from_gltf(l, world)));
    }
    if get(&md.cameras, false) {
        if file_cameras.is_empty() {
            warnings.push(format!(
                "{}: model.cameras = true, but the file has no cameras",
                md.path.get_ref()
            ));
        }
        out.cameras
            .extend(file_cameras.iter().map(|c| (c.clone(), world)));
    }
    Ok(())
}

/// The models' bounding sphere at rest: the box's center (the turntable's
/// pivot) and the sphere around the box.
pub(super) fn bounds(models: &[Model]) -> Bounds {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for m in models {
        for p in m.reach() {
            let w = m.world_from_object.transform_point3(*p);
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    Bounds {
        center: (lo + hi) * 0.5,
        radius: ((hi - lo).length() * 0.5).max(1e-6),
    }
}

impl SourceModel {
    /// A model of metallic-roughness materials with nothing more to
    /// import (no rig, lights or cameras).
    fn pbr(mesh: Mesh, materials: Vec<GltfMaterial>, warnings: Vec<String>) -> SourceModel {
        SourceModel {
            mesh,
            materials: materials
                .into_iter()
                .map(|m| SourceMaterial::Gltf(Box::new(m)))
                .collect(),
            gltf: None,
            rig: None,
            imported: None,
            warnings,
        }
    }

    fn load(path: &Path, input: &Input) -> Result<SourceModel, Error> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if ext == "gltf" || ext == "glb" {
            let mut g = crate::assets::gltf::load(path, input)?;
            Ok(SourceModel {
                mesh: std::mem::take(&mut g.mesh),
                materials: g
                    .materials
                    .drain(..)
                    .map(|m| SourceMaterial::Gltf(Box::new(m)))
                    .collect(),
                warnings: std::mem::take(&mut g.warnings),
                rig: g.rig.clone(),
                imported: Some((g.lights.clone(), g.cameras.clone())),
                gltf: Some(g),
            })
        } else if ext == "fbx" {
            let f = crate::assets::fbx::load(path, input)?;
            let mut m = SourceModel::pbr(f.mesh, f.materials, f.warnings);
            m.rig = f.rig;
            m.imported = Some((f.lights, f.cameras));
            Ok(m)
        } else if matches!(ext.as_str(), "usd" | "usda" | "usdc" | "usdz") {
            let u = crate::assets::usd::load(path, input)?;
            Ok(SourceModel::pbr(u.mesh, u.materials, u.warnings))
        } else if ext == "3mf" {
            let t = crate::assets::threemf::load(path, input)?;
            Ok(SourceModel::pbr(t.mesh, t.materials, t.warnings))
        } else if ext == "stl" || ext == "ply" {
            let mesh = if ext == "stl" {
                crate::assets::stl::load(path, input)?
            } else {
                crate::assets::ply::load(path, input)?
            };
            Ok(SourceModel {
                mesh,
                materials: vec![SourceMaterial::Mtl(Box::new(MtlSource::new(
                    obj::MtlMaterial {
                        name: "default".into(),
                        synthetic: true,
                        ..Default::default()
                    },
                )))],
                gltf: None,
                rig: None,
                imported: None,
                warnings: Vec::new(),
            })
        } else {
            let o = obj::load(path, input)?;
            Ok(SourceModel {
                mesh: o.mesh,
                materials: o
                    .materials
                    .into_iter()
                    .map(|m| SourceMaterial::Mtl(Box::new(MtlSource::new(m))))
                    .collect(),
                gltf: None,
                rig: None,
                imported: None,
                warnings: o.warnings,
            })
        }
    }
}

/// Largest world-space coordinate magnitude accepted: squared distances
/// of such points (1e36) stay finite in f32, with room for the products
/// of camera and light transforms.
const MAX_COORDINATE: f32 = 1e18;

/// Refuses a model whose placed positions are not finite or so large that
/// f32 arithmetic on them (squares, projections) would overflow.
fn check_magnitude(md: &desc::ModelDesc, ctx: &Ctx, mesh: &Mesh, world: Mat4) -> Result<(), Error> {
    let worst = mesh
        .positions
        .iter()
        .map(|p| world.transform_point3(*p).abs().max_element())
        .fold(0.0f32, |a, b| {
            if b.is_nan() || a.is_nan() {
                f32::NAN
            } else {
                a.max(b)
            }
        });
    if worst <= MAX_COORDINATE {
        return Ok(());
    }
    let what = if worst.is_nan() {
        "placed (or displaced) positions are not finite".to_string()
    } else {
        format!("placed positions reach {worst:e}")
    };
    Err(ctx.err(
        md.path.span(),
        format!(
            "{}: {what}; coordinates beyond {MAX_COORDINATE:e} overflow 32-bit float arithmetic: scale the model down (model.scale or normalize = true)",
            md.path.get_ref()
        ),
    ))
}

fn resolve(base: &Path, p: &str) -> PathBuf {
    base.join(p.replace('\\', "/"))
}

/// translate * rotate (XYZ Euler, degrees) * scale, then with `normalize`
/// the mesh scaled to a unit box about its center.
fn placement(m: &desc::ModelDesc, mesh: &Mesh) -> Mat4 {
    let t = Vec3::from(get(&m.translate, [0.0; 3]));
    let r = get(&m.rotate, [0.0; 3]);
    let s = get(&m.scale, desc::Scale([1.0; 3])).0;
    let q = Quat::from_euler(
        EulerRot::XYZ,
        r[0].to_radians(),
        r[1].to_radians(),
        r[2].to_radians(),
    );
    let world = Mat4::from_scale_rotation_translation(Vec3::from(s), q, t);
    if !get(&m.normalize, false) {
        return world;
    }
    let (lo, hi) = mesh.bounds();
    let extent = (hi - lo).max_element().max(1e-20);
    world * Mat4::from_scale(Vec3::splat(1.0 / extent)) * Mat4::from_translation(-(lo + hi) * 0.5)
}
/// Displacement at load time: every vertex of material `group_material`'s
/// triangles moves along its normal by `base + gain * height` (MTL `-mm`,
/// default 0 and 1) times `scale` (scene `disp_scale`, default 1), the height
/// read bilinearly from the map. Vertices at one position (UV seams) move by
/// their mean, so the surface does not crack; their normals are then
/// recomputed from the displaced faces.
fn displace(
    mesh: &mut Mesh,
    group_material: usize,
    spec: &MapSpec,
    scale: Option<f32>,
    input: &Input,
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
    let tex = Texture::load(&spec.path, false, input)?;
    let (base, gain) = spec.mm.unwrap_or((0.0, 1.0));
    let scale = scale.unwrap_or(1.0);
    let mode = if spec.clamp {
        AddressMode::Clamp
    } else {
        AddressMode::Repeat
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

/// The format of a model file, as messages name it (by its extension).
fn format_name(path: &str) -> String {
    Path::new(path)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_uppercase())
        .unwrap_or_else(|| "not glTF".into())
}
