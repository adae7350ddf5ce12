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
use super::desc::{self, Ctx, MaterialOverride, S, SceneDesc};
use super::desc::{AlphaModeDesc, NormalSpace};
use super::light::{Light, LightKind};
use super::material::{AlphaMode, Material, NormalMap};
use super::overrides::{self, SetOverride};
use super::{Model, OutputSettings, RenderSettings, Scene, check_pattern};
use crate::assets::obj::{self, MapSpec, MtlMaterial};
use crate::assets::texture::{Texture, TextureRef};
use crate::error::Error;

/// Options that come from outside the scene file.
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// `--set key=value`, applied in order before parsing.
    pub sets: Vec<SetOverride>,
    /// `--out`: wins over `output.dir`.
    pub out_dir: Option<PathBuf>,
}

const SHADOW_ISSUE: &str = "it comes with shadows, AO and EXR outputs";
const WORKFLOW_ISSUE: &str = "it comes with anti-aliasing and GIF output";
const GLTF_ISSUE: &str = "it comes with glTF support";

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

fn unsupported<T>(ctx: &Ctx, v: &S<T>, what: &str, note: &str) -> Error {
    Error::Unsupported {
        location: ctx.location(v.span()),
        what: what.to_string(),
        note: note.to_string(),
    }
}

fn refuse_unsupported(d: &SceneDesc, ctx: &Ctx) -> Result<(), Error> {
    let r = &d.render;
    if let Some(m) = &r.msaa
        && *m.get_ref() > 1
    {
        return Err(unsupported(ctx, m, "render.msaa > 1", WORKFLOW_ISSUE));
    }
    if let Some(ao) = &r.ao
        && get(&ao.get_ref().method, desc::AoMethod::Off) != desc::AoMethod::Off
    {
        return Err(unsupported(ctx, ao, "render.ao", SHADOW_ISSUE));
    }
    for l in &d.lights {
        if let Some(s) = &l.get_ref().shadows
            && *s.get_ref()
        {
            return Err(unsupported(ctx, s, "light.shadows = true", SHADOW_ISSUE));
        }
    }
    let o = &d.output;
    for (v, key) in [(&o.depth, "output.depth"), (&o.ao, "output.ao")] {
        if let Some(v) = v
            && *v.get_ref()
        {
            return Err(unsupported(ctx, v, key, SHADOW_ISSUE));
        }
    }
    if let Some(g) = &o.gif {
        return Err(unsupported(ctx, g, "output.gif", WORKFLOW_ISSUE));
    }
    for m in &d.models {
        let m = m.get_ref();
        let p = m.path.get_ref().to_ascii_lowercase();
        if p.ends_with(".gltf") || p.ends_with(".glb") {
            return Err(unsupported(ctx, &m.path, "a glTF model", GLTF_ISSUE));
        }
        for (v, key) in [(&m.lights, "model.lights"), (&m.cameras, "model.cameras")] {
            if let Some(v) = v
                && *v.get_ref()
            {
                return Err(unsupported(ctx, v, key, GLTF_ISSUE));
            }
        }
    }
    Ok(())
}

fn build(d: &SceneDesc, ctx: &Ctx, opts: &LoadOptions) -> Result<Scene, Error> {
    refuse_unsupported(d, ctx)?;
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
    };
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
    };

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
    let loaded: Vec<obj::ObjModel> = file_list
        .par_iter()
        .map(|p| obj::load(p))
        .collect::<Result<_, _>>()?;
    let loaded: Vec<Arc<obj::ObjModel>> = loaded.into_iter().map(Arc::new).collect();

    // Materials (with overrides), then the set of textures they need.
    let mut model_mats: Vec<Vec<MtlMaterial>> = Vec::new();
    for m in &d.models {
        let md = m.get_ref();
        let src = &loaded[files[&resolve(&scene_dir, md.path.get_ref())]];
        for (name, ov) in &md.materials {
            if !src.materials.iter().any(|mm| &mm.name == name) {
                let names: Vec<_> = src.materials.iter().map(|m| m.name.as_str()).collect();
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
                    apply_override(&mut mm, all.get_ref(), &scene_dir, ctx)?;
                }
                if let Some(one) = md.materials.get(&mm.name) {
                    apply_override(&mut mm, one.get_ref(), &scene_dir, ctx)?;
                }
                Ok(mm)
            })
            .collect::<Result<Vec<_>, Error>>()?;
        model_mats.push(mats);
    }
    let mut wanted: BTreeMap<(PathBuf, bool), Option<Arc<Texture>>> = BTreeMap::new();
    if textured {
        for (m, mats) in d.models.iter().zip(&model_mats) {
            let src = &loaded[files[&resolve(&scene_dir, m.get_ref().path.get_ref())]];
            if !src.mesh.has_uvs() {
                continue;
            }
            for (i, mm) in mats.iter().enumerate() {
                if !src.mesh.groups.iter().any(|g| g.material == i) {
                    continue;
                }
                for (k, (map, srgb)) in shading_maps(mm).into_iter().enumerate() {
                    if normals_view && k < 6 {
                        continue;
                    }
                    if let Some(map) = map {
                        wanted.insert((map.path.clone(), srgb), None);
                    }
                }
            }
        }
    }
    let keys: Vec<_> = wanted.keys().cloned().collect();
    let decoded: Vec<Arc<Texture>> = keys
        .par_iter()
        .enumerate()
        .map(|(id, (p, srgb))| {
            Texture::load(p, *srgb).map(|mut t| {
                t.id = id;
                Arc::new(t)
            })
        })
        .collect::<Result<_, _>>()?;
    let textures = decoded.clone();
    for (k, t) in keys.into_iter().zip(decoded) {
        wanted.insert(k, Some(t));
    }
    let tex = |map: &Option<MapSpec>, srgb: bool| -> Option<TextureRef> {
        let map = map.as_ref()?;
        let t = wanted.get(&(map.path.clone(), srgb))?.clone()?;
        Some(TextureRef {
            texture: t,
            scale: Vec2::new(map.scale[0], map.scale[1]),
            offset: Vec2::new(map.offset[0], map.offset[1]),
            address: map.clamp.then_some(desc::AddressMode::Clamp),
        })
    };

    let mut models = Vec::new();
    for (i, (m, mats)) in d.models.iter().zip(&model_mats).enumerate() {
        let md = m.get_ref();
        let src = &loaded[files[&resolve(&scene_dir, md.path.get_ref())]];
        let materials = mats
            .iter()
            .map(|mm| to_material(mm, &tex))
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
            if let Some(spec) = &mm.disp {
                displace(&mut mesh, gi, spec, mm.disp_scale)?;
            }
        }
        if materials.iter().any(|m| m.needs_tangents()) && textured {
            mesh.compute_tangents();
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

    let lights = d
        .lights
        .iter()
        .map(|l| to_light(l.get_ref()))
        .collect::<Vec<_>>();
    let cameras = build_cameras(d, ctx, center, radius)?;

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
    })
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

fn apply_override(
    m: &mut MtlMaterial,
    o: &MaterialOverride,
    scene_dir: &Path,
    ctx: &Ctx,
) -> Result<(), Error> {
    macro_rules! set {
        ($($f:ident),*) => {$(
            if let Some(v) = &o.$f { m.$f = Some(*v.get_ref()); }
        )*};
    }
    set!(ka, kd, ks, ke, ns, ni, d);
    if let Some(v) = &o.illum {
        m.illum = Some(*v.get_ref() as u8);
    }
    let map = |v: &Option<S<String>>| -> Result<Option<MapSpec>, Error> {
        v.as_ref()
            .map(|s| obj::parse_map(s.get_ref(), scene_dir).map_err(|msg| ctx.err(s.span(), msg)))
            .transpose()
    };
    if let Some(v) = &o.bump_scale {
        m.bump_scale = Some(*v.get_ref());
    }
    if let Some(v) = &o.normal_space {
        m.normal_space = Some(*v.get_ref());
    }
    if let Some(v) = &o.alpha_mode {
        m.alpha_mode = Some(*v.get_ref());
    }
    if let Some(v) = &o.alpha_cutoff {
        m.alpha_cutoff = Some(*v.get_ref());
    }
    if let Some(v) = &o.disp_scale {
        m.disp_scale = Some(*v.get_ref());
    }
    for (slot, v) in [
        (&mut m.map_ka, &o.map_ka),
        (&mut m.map_kd, &o.map_kd),
        (&mut m.map_ks, &o.map_ks),
        (&mut m.map_ke, &o.map_ke),
        (&mut m.map_ns, &o.map_ns),
        (&mut m.map_d, &o.map_d),
        (&mut m.map_bump, &o.map_bump),
        (&mut m.norm, &o.norm),
        (&mut m.disp, &o.disp),
    ] {
        if let Some(spec) = map(v)? {
            if !spec.path.is_file() {
                return Err(Error::asset(
                    &spec.path,
                    None,
                    format!(
                        "texture not found (from {})",
                        ctx.location(v.as_ref().map(|s| s.span()).unwrap_or(0..0))
                    ),
                ));
            }
            *slot = Some(spec);
        }
    }
    Ok(())
}

/// The maps shading reads, with whether they hold sRGB color (`disp` is
/// read at load time, by `displace`).
fn shading_maps(m: &MtlMaterial) -> [(&Option<MapSpec>, bool); 8] {
    [
        (&m.map_ka, true),
        (&m.map_kd, true),
        (&m.map_ks, true),
        (&m.map_ke, true),
        (&m.map_ns, false),
        (&m.map_d, false),
        (&m.map_bump, false),
        (&m.norm, false),
    ]
}

fn to_material(
    m: &MtlMaterial,
    tex: &dyn Fn(&Option<MapSpec>, bool) -> Option<TextureRef>,
) -> Material {
    let d = Material::default_named(&m.name);
    // A constant left unset but with a map is 1: the map alone decides.
    let constant = |c: Option<[f32; 3]>, map: &Option<MapSpec>, fallback: Vec3| {
        c.map(Vec3::from)
            .unwrap_or(if map.is_some() { Vec3::ONE } else { fallback })
    };
    let map_kd = tex(&m.map_kd, true);
    let map_d = tex(&m.map_d, false);
    let opacity = m.d.unwrap_or(1.0);
    let bump_scale = |spec: &Option<MapSpec>| {
        m.bump_scale
            .or(spec.as_ref().and_then(|s| s.bump_scale))
            .unwrap_or(1.0)
    };
    let space = m.normal_space.unwrap_or(NormalSpace::Tangent);
    let normal_map = if let Some(map) = tex(&m.norm, false) {
        Some(NormalMap::Normals {
            map,
            space,
            scale: bump_scale(&m.norm),
        })
    } else if let Some(map) = tex(&m.map_bump, false) {
        // map_Bump holds either: a grey image is heights, a colored one normals.
        let scale = bump_scale(&m.map_bump);
        if map.texture.grey && m.normal_space.is_none() {
            Some(NormalMap::Height { map, scale })
        } else {
            Some(NormalMap::Normals { map, space, scale })
        }
    } else {
        None
    };
    // Opacity: a constant below 1 blends; an alpha channel that is (almost)
    // all-or-nothing is a cutout, a gradual one blends.
    let alpha_texture = map_d
        .iter()
        .chain(map_kd.iter())
        .find(|t| t.texture.has_alpha);
    let cutoff = m.alpha_cutoff.unwrap_or(0.5);
    let alpha = match m.alpha_mode {
        Some(AlphaModeDesc::Opaque) => AlphaMode::Opaque,
        Some(AlphaModeDesc::Mask) => AlphaMode::Mask(cutoff),
        Some(AlphaModeDesc::Blend) => AlphaMode::Blend,
        None if opacity < 1.0 => AlphaMode::Blend,
        None => match alpha_texture {
            Some(t) if t.texture.binary_alpha >= 0.9 => AlphaMode::Mask(cutoff),
            Some(_) => AlphaMode::Blend,
            // A grey map_d without alpha channel: its red channel.
            None if map_d.is_some() => AlphaMode::Blend,
            None => AlphaMode::Opaque,
        },
    };
    Material {
        name: m.name.clone(),
        ka: m
            .ka
            .map(Vec3::from)
            .or(m.map_ka.as_ref().map(|_| Vec3::ONE)),
        kd: constant(m.kd, &m.map_kd, d.kd),
        ks: constant(m.ks, &m.map_ks, if m.synthetic { d.ks } else { Vec3::ZERO }),
        ke: constant(m.ke, &m.map_ke, Vec3::ZERO),
        ns: m.ns.unwrap_or(d.ns),
        illum: m.illum.unwrap_or(2),
        map_ka: tex(&m.map_ka, true),
        map_kd,
        map_ks: tex(&m.map_ks, true),
        map_ke: tex(&m.map_ke, true),
        map_ns: tex(&m.map_ns, false),
        d: opacity,
        map_d,
        normal_map,
        alpha,
    }
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
    }
}

fn build_cameras(
    d: &SceneDesc,
    ctx: &Ctx,
    center: Vec3,
    radius: f32,
) -> Result<Vec<Camera>, Error> {
    if d.cameras.is_empty() {
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
    Ok(cams)
}
