//! Materials from the files (MTL or glTF) to what the renderer uses: scene
//! overrides applied, the textures they need listed, then `Material` with
//! both its native description and the one derived by the documented
//! mapping (docs/scene-format.md, "Shading models").

use std::path::Path;
use std::sync::Arc;

use glam::{Affine2, Mat2, Vec2, Vec3, Vec4};

use crate::assets::gltf::{GltfAlphaMode, GltfMaterial, ImageSource, TexInfo};
use crate::assets::obj::{self, MapSpec, MtlMaterial};
use crate::assets::texture::{AddressMode, TextureRef, Wrap};
use crate::error::Error;
use crate::scene::desc::{AlphaModeDesc, Ctx, MaterialOverride, Spanned};
use crate::scene::material::{
    AlphaMode, Anisotropy, Clearcoat, DielectricSpecular, DiffuseTransmission, IridescenceLayer,
    Material, Native, NormalMap, NormalSpace, Pbr, SheenLayer, Transmission, ns_from_roughness,
    roughness_from_ns,
};

/// A material as its file states it, overrides applied.
#[derive(Debug, Clone)]
pub enum SourceMaterial {
    Mtl(Box<MtlSource>),
    Gltf(Box<GltfMaterial>),
}

/// An MTL material and the scene-only keys its overrides set (MTL files
/// have none of them).
#[derive(Debug, Clone)]
pub struct MtlSource {
    pub mtl: MtlMaterial,
    pub bump_scale: Option<f32>,
    pub normal_space: Option<NormalSpace>,
    pub alpha_mode: Option<AlphaModeDesc>,
    pub alpha_cutoff: Option<f32>,
    /// World units per unit of `disp` height.
    pub disp_scale: Option<f32>,
    /// pbr parameters when this material is shaded as pbr.
    pub metallic: Option<f32>,
    pub roughness: Option<f32>,
}

impl MtlSource {
    pub fn new(mtl: MtlMaterial) -> MtlSource {
        MtlSource {
            mtl,
            bump_scale: None,
            normal_space: None,
            alpha_mode: None,
            alpha_cutoff: None,
            disp_scale: None,
            metallic: None,
            roughness: None,
        }
    }
}

impl SourceMaterial {
    pub fn name(&self) -> &str {
        match self {
            SourceMaterial::Mtl(m) => &m.mtl.name,
            SourceMaterial::Gltf(m) => &m.name,
        }
    }

    /// The images shading reads, with whether they hold sRGB color; with
    /// `normals_only`, just the normal and bump maps (the normals view).
    pub fn images(&self, normals_only: bool) -> Vec<(ImageSource, bool)> {
        match self {
            SourceMaterial::Mtl(m) => shading_maps(&m.mtl)
                .into_iter()
                .enumerate()
                .filter(|(k, _)| !normals_only || *k >= 8)
                .filter_map(|(_, (map, srgb))| {
                    map.as_ref()
                        .map(|m| (ImageSource::File(m.path.clone()), srgb))
                })
                .collect(),
            SourceMaterial::Gltf(g) => {
                if normals_only {
                    g.normal_tex
                        .iter()
                        .map(|t| (t.image.clone(), false))
                        .collect()
                } else {
                    g.textures().map(|(t, s)| (t.image.clone(), s)).collect()
                }
            }
        }
    }

    /// Scene overrides. MTL materials take every key; glTF materials take
    /// the keys that have a metallic-roughness meaning.
    pub fn apply_override(
        &mut self,
        o: &MaterialOverride,
        scene_dir: &Path,
        ctx: &Ctx,
    ) -> Result<(), Error> {
        match self {
            SourceMaterial::Mtl(m) => apply_mtl_override(m, o, scene_dir, ctx),
            SourceMaterial::Gltf(g) => apply_gltf_override(g, o, scene_dir, ctx),
        }
    }
}

fn map_override(
    v: &Option<Spanned<String>>,
    scene_dir: &Path,
    ctx: &Ctx,
) -> Result<Option<MapSpec>, Error> {
    let Some(s) = v else { return Ok(None) };
    let spec = obj::parse_map(s.get_ref(), scene_dir).map_err(|msg| ctx.err(s.span(), msg))?;
    if !spec.path.is_file() {
        return Err(Error::asset(
            &spec.path,
            None,
            format!("texture not found (from {})", ctx.location(s.span())),
        ));
    }
    Ok(Some(spec))
}

fn apply_mtl_override(
    x: &mut MtlSource,
    o: &MaterialOverride,
    scene_dir: &Path,
    ctx: &Ctx,
) -> Result<(), Error> {
    macro_rules! set {
        ($to:ident: $($f:ident),*) => {$(
            if let Some(v) = &o.$f { $to.$f = Some(*v.get_ref()); }
        )*};
    }
    set!(x: bump_scale, normal_space, alpha_mode, alpha_cutoff, disp_scale);
    set!(x: metallic, roughness);
    let m = &mut x.mtl;
    set!(m: ka, kd, ks, ke, ns, ni, d);
    if let Some(v) = &o.illum {
        m.illum = Some(*v.get_ref() as u8);
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
        if let Some(spec) = map_override(v, scene_dir, ctx)? {
            *slot = Some(spec);
        }
    }
    Ok(())
}

/// The keys a glTF material takes, for the error that names the others.
const GLTF_KEYS: &str = "kd (base color), d (base alpha), ke (emissive), map_kd, map_ke, norm or map_bump (normal texture), bump_scale, alpha_mode, alpha_cutoff, metallic, roughness";

fn apply_gltf_override(
    g: &mut GltfMaterial,
    o: &MaterialOverride,
    scene_dir: &Path,
    ctx: &Ctx,
) -> Result<(), Error> {
    let refuse = |span: Option<std::ops::Range<usize>>, key: &str| -> Result<(), Error> {
        match span {
            Some(span) => Err(ctx.err(
                span,
                format!(
                    "`{key}` has no meaning for the glTF material `{}`; glTF materials take {GLTF_KEYS}",
                    g.name
                ),
            )),
            None => Ok(()),
        }
    };
    refuse(o.ka.as_ref().map(|v| v.span()), "ka")?;
    refuse(o.ks.as_ref().map(|v| v.span()), "ks")?;
    refuse(o.ns.as_ref().map(|v| v.span()), "ns")?;
    refuse(o.ni.as_ref().map(|v| v.span()), "ni")?;
    refuse(o.illum.as_ref().map(|v| v.span()), "illum")?;
    refuse(o.normal_space.as_ref().map(|v| v.span()), "normal_space")?;
    refuse(o.disp_scale.as_ref().map(|v| v.span()), "disp_scale")?;
    for (v, key) in [
        (&o.map_ka, "map_ka"),
        (&o.map_ks, "map_ks"),
        (&o.map_ns, "map_ns"),
        (&o.map_d, "map_d"),
        (&o.disp, "disp"),
    ] {
        refuse(v.as_ref().map(|v| v.span()), key)?;
    }
    if let Some(v) = &o.kd {
        let c = v.get_ref();
        g.base_color = Vec4::new(c[0], c[1], c[2], g.base_color.w);
    }
    if let Some(v) = &o.d {
        g.base_color.w = *v.get_ref();
    }
    if let Some(v) = &o.ke {
        g.emissive = Vec3::from(*v.get_ref());
    }
    if let Some(v) = &o.metallic {
        g.metallic = *v.get_ref();
    }
    if let Some(v) = &o.roughness {
        g.roughness = *v.get_ref();
    }
    if let Some(v) = &o.bump_scale {
        g.normal_scale = *v.get_ref();
    }
    if let Some(v) = &o.alpha_mode {
        g.alpha_mode = match v.get_ref() {
            AlphaModeDesc::Opaque => GltfAlphaMode::Opaque,
            AlphaModeDesc::Mask => GltfAlphaMode::Mask,
            AlphaModeDesc::Blend => GltfAlphaMode::Blend,
        };
    }
    if let Some(v) = &o.alpha_cutoff {
        g.alpha_cutoff = *v.get_ref();
    }
    let info = |spec: MapSpec| TexInfo {
        image: ImageSource::File(spec.path.clone()),
        texcoord: 0,
        transform: mtl_transform(&spec),
        wrap: Wrap::from(if spec.clamp {
            AddressMode::Clamp
        } else {
            AddressMode::Repeat
        }),
        min_limit: None,
        mag_nearest: false,
    };
    if let Some(spec) = map_override(&o.map_kd, scene_dir, ctx)? {
        g.base_color_tex = Some(info(spec));
    }
    if let Some(spec) = map_override(&o.map_ke, scene_dir, ctx)? {
        g.emissive_tex = Some(info(spec));
        if g.emissive == Vec3::ZERO && o.ke.is_none() {
            g.emissive = Vec3::ONE;
        }
    }
    for v in [&o.map_bump, &o.norm] {
        if let Some(spec) = map_override(v, scene_dir, ctx)? {
            if let Some(s) = spec.bump_scale
                && o.bump_scale.is_none()
            {
                g.normal_scale = s;
            }
            g.normal_tex = Some(info(spec));
        }
    }
    Ok(())
}

/// MTL `-s` and `-o` as an affine map.
fn mtl_transform(spec: &MapSpec) -> Affine2 {
    Affine2::from_mat2_translation(
        Mat2::from_diagonal(Vec2::new(spec.scale[0], spec.scale[1])),
        Vec2::new(spec.offset[0], spec.offset[1]),
    )
}

/// The maps shading reads, with whether they hold sRGB color (`disp` is
/// read at load time, by `displace`). The last two are the normal maps
/// (indices 8 and 9).
fn shading_maps(m: &MtlMaterial) -> [(&Option<MapSpec>, bool); 10] {
    [
        (&m.map_ka, true),
        (&m.map_kd, true),
        (&m.map_ks, true),
        (&m.map_ke, true),
        (&m.map_ns, false),
        (&m.map_d, false),
        (&m.map_pr, false),
        (&m.map_pm, false),
        (&m.map_bump, false),
        (&m.norm, false),
    ]
}

/// Decoded textures by (image path or name, sRGB).
pub type TextureLookup<'a> =
    dyn Fn(&Path, bool) -> Option<Arc<crate::assets::texture::Texture>> + 'a;

pub fn to_material(src: &SourceMaterial, tex: &TextureLookup) -> Material {
    match src {
        SourceMaterial::Mtl(m) => mtl_material(m, tex),
        SourceMaterial::Gltf(g) => gltf_material(g, tex),
    }
}

/// An MTL material's alpha mode: the scene's where it gives one; else a
/// constant opacity below 1 blends, and an alpha channel (of map_d, else
/// map_Kd) that is (almost) all-or-nothing is a cutout, a gradual one
/// blends.
fn mtl_alpha(
    x: &MtlSource,
    opacity: f32,
    map_d: &Option<TextureRef>,
    map_kd: &Option<TextureRef>,
) -> AlphaMode {
    let alpha_texture = map_d
        .iter()
        .chain(map_kd.iter())
        .find(|t| t.texture.has_alpha);
    let cutoff = x.alpha_cutoff.unwrap_or(0.5);
    match x.alpha_mode {
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
    }
}

fn mtl_material(x: &MtlSource, textures: &TextureLookup) -> Material {
    let m = &x.mtl;
    let tex = |map: &Option<MapSpec>, srgb: bool| -> Option<TextureRef> {
        let map = map.as_ref()?;
        let t = textures(&map.path, srgb)?;
        Some(TextureRef {
            transform: mtl_transform(map),
            address: map.clamp.then_some(AddressMode::Clamp.into()),
            ..TextureRef::new(t)
        })
    };
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
        x.bump_scale
            .or(spec.as_ref().and_then(|s| s.bump_scale))
            .unwrap_or(1.0)
    };
    let space = x.normal_space.unwrap_or(NormalSpace::Tangent);
    let normal_map = if let Some(map) = tex(&m.norm, false) {
        Some(NormalMap::Normals {
            map,
            space,
            scale: bump_scale(&m.norm),
        })
    } else if let Some(map) = tex(&m.map_bump, false) {
        // map_Bump holds either: a grey image is heights, a colored one normals.
        let scale = bump_scale(&m.map_bump);
        if map.texture.grey && x.normal_space.is_none() {
            Some(NormalMap::Height { map, scale })
        } else {
            Some(NormalMap::Normals { map, space, scale })
        }
    } else {
        None
    };
    let alpha = mtl_alpha(x, opacity, &map_d, &map_kd);
    let kd = constant(m.kd, &m.map_kd, d.kd);
    let ke = constant(m.ke, &m.map_ke, Vec3::ZERO);
    let ns = m.ns.unwrap_or(d.ns);
    let map_ke = tex(&m.map_ke, true);
    // MTL as pbr: Kd is the base color; the PBR extension's Pr and Pm
    // (and their maps) where the file gives them, else a dielectric
    // (metallic 0) with the roughness whose GGX lobe matches Ns; Ks does
    // not carry over. Pc and Pcr are a clearcoat.
    let pbr_keys = m.pr.is_some() || m.pm.is_some() || m.map_pr.is_some() || m.map_pm.is_some();
    let unit = |v: f32| v.clamp(0.0, 1.0);
    let pbr = Pbr {
        base_color: kd.extend(opacity),
        base_color_map: map_kd.clone(),
        metallic: x
            .metallic
            .or(m.pm.map(unit))
            .unwrap_or(if m.map_pm.is_some() { 1.0 } else { 0.0 }),
        roughness: x.roughness.or(m.pr.map(unit)).unwrap_or_else(|| {
            if m.map_pr.is_some() {
                1.0
            } else {
                roughness_from_ns(ns)
            }
        }),
        metallic_roughness_map: None,
        roughness_map: tex(&m.map_pr, false),
        metallic_map: tex(&m.map_pm, false),
        occlusion_map: None,
        occlusion_strength: 1.0,
        emissive: ke,
        emissive_map: map_ke.clone(),
        specular: None,
        sheen: None,
        iridescence: None,
        anisotropy: None,
        diffuse_transmission: None,
        clearcoat: m.pc.map(unit).filter(|c| *c > 0.0).map(|factor| Clearcoat {
            factor,
            map: None,
            roughness: m.pcr.map_or(0.0, unit),
            roughness_map: None,
            normal_map: None,
        }),
        transmission: None,
    };
    Material {
        name: m.name.clone(),
        ka: m
            .ka
            .map(Vec3::from)
            .or(m.map_ka.as_ref().map(|_| Vec3::ONE)),
        kd,
        ks: constant(m.ks, &m.map_ks, if m.synthetic { d.ks } else { Vec3::ZERO }),
        ke,
        ns,
        illum: m.illum.unwrap_or(2),
        map_ka: tex(&m.map_ka, true),
        map_kd,
        map_ks: tex(&m.map_ks, true),
        map_ke,
        map_ns: tex(&m.map_ns, false),
        d: opacity,
        map_d,
        normal_map,
        alpha,
        pbr,
        // A file that gives the PBR extension's roughness or metallic is
        // described in metallic-roughness terms.
        native: if pbr_keys {
            Native::Pbr
        } else {
            Native::BlinnPhong
        },
        double_sided: false,
        unlit: false,
    }
}

/// KHR_materials_ior and KHR_materials_specular as the dielectric's F0 and
/// F90 (None: the defaults, ior 1.5 and no specular extension).
fn dielectric_specular(
    g: &GltfMaterial,
    tex: &dyn Fn(&Option<TexInfo>, bool) -> Option<TextureRef>,
) -> Option<DielectricSpecular> {
    if g.specular.is_none() && g.ior == 1.5 {
        return None;
    }
    let r = (g.ior - 1.0) / (g.ior + 1.0);
    let s = g.specular.as_ref();
    Some(DielectricSpecular {
        f0: Vec3::splat(r * r) * s.map_or(Vec3::ONE, |s| s.color),
        weight: s.map_or(1.0, |s| s.factor),
        weight_map: s.and_then(|s| tex(&s.texture, false)),
        color_map: s.and_then(|s| tex(&s.color_texture, true)),
    })
}

fn gltf_material(g: &GltfMaterial, textures: &TextureLookup) -> Material {
    let tex = |t: &Option<TexInfo>, srgb: bool| -> Option<TextureRef> {
        let t = t.as_ref()?;
        Some(TextureRef {
            transform: t.transform,
            address: Some(t.wrap),
            texcoord: t.texcoord,
            min_limit: t.min_limit,
            mag_nearest: t.mag_nearest,
            ..TextureRef::new(textures(t.image.key(), srgb)?)
        })
    };
    let base_color_map = tex(&g.base_color_tex, true);
    let emissive_map = tex(&g.emissive_tex, true);
    let base = g.base_color.truncate();
    let pbr = Pbr {
        base_color: g.base_color,
        base_color_map: base_color_map.clone(),
        metallic: g.metallic,
        roughness: g.roughness,
        metallic_roughness_map: tex(&g.metallic_roughness_tex, false),
        roughness_map: None,
        metallic_map: None,
        occlusion_map: tex(&g.occlusion_tex, false),
        occlusion_strength: g.occlusion_strength,
        emissive: g.emissive,
        emissive_map: emissive_map.clone(),
        specular: dielectric_specular(g, &tex),
        clearcoat: g.clearcoat.as_ref().map(|c| Clearcoat {
            factor: c.factor,
            map: tex(&c.texture, false),
            roughness: c.roughness,
            roughness_map: tex(&c.roughness_texture, false),
            normal_map: tex(&c.normal_texture, false).map(|map| NormalMap::Normals {
                map,
                space: NormalSpace::Tangent,
                scale: c.normal_scale,
            }),
        }),
        transmission: g.transmission.as_ref().map(|t| Transmission {
            factor: t.factor,
            map: tex(&t.texture, false),
            thickness: t.thickness,
            ior: g.ior,
            thickness_map: tex(&t.thickness_texture, false),
            attenuation_color: t.attenuation_color,
            attenuation_distance: t.attenuation_distance,
            dispersion: t.dispersion,
        }),
        sheen: g.sheen.as_ref().map(|t| SheenLayer {
            color: t.color,
            color_map: tex(&t.color_texture, true),
            roughness: t.roughness,
            roughness_map: tex(&t.roughness_texture, false),
        }),
        iridescence: g.iridescence.as_ref().map(|t| IridescenceLayer {
            factor: t.factor,
            map: tex(&t.texture, false),
            ior: t.ior,
            thickness_min: t.thickness_min,
            thickness_max: t.thickness_max,
            thickness_map: tex(&t.thickness_texture, false),
        }),
        anisotropy: g.anisotropy.as_ref().map(|a| Anisotropy {
            strength: a.strength,
            rotation: a.rotation,
            map: tex(&a.texture, false),
        }),
        diffuse_transmission: g
            .diffuse_transmission
            .as_ref()
            .map(|t| DiffuseTransmission {
                factor: t.factor,
                map: tex(&t.texture, false),
                color: t.color,
                color_map: tex(&t.color_texture, true),
            }),
    };
    // glTF as Blinn-Phong: the diffuse part of the base color as Kd, the
    // specular color at normal incidence (0.04 for dielectrics, the base
    // color for metals) as Ks, the exponent whose lobe matches the GGX
    // roughness as Ns. The metallic-roughness and occlusion maps have no
    // Blinn-Phong counterpart and are not read; with a metallic-roughness
    // map the factor only scales the map (often 1 over a mostly dielectric
    // map), so such materials are taken as dielectrics.
    let m = if g.metallic_roughness_tex.is_some() {
        0.0
    } else {
        g.metallic
    };
    Material {
        name: g.name.clone(),
        ka: None,
        kd: base * (1.0 - m),
        ks: Vec3::splat(0.04).lerp(base, m),
        ke: g.emissive,
        ns: ns_from_roughness(g.roughness),
        illum: 2,
        map_ka: None,
        map_kd: base_color_map,
        map_ks: None,
        map_ke: emissive_map,
        map_ns: None,
        // Transmitted light shows what is behind; as Blinn-Phong, that is
        // a partly transparent surface.
        d: g.base_color.w * (1.0 - g.transmission.as_ref().map_or(0.0, |t| t.factor)),
        map_d: None,
        normal_map: tex(&g.normal_tex, false).map(|map| NormalMap::Normals {
            map,
            space: NormalSpace::Tangent,
            scale: g.normal_scale,
        }),
        alpha: match g.alpha_mode {
            // Transmission is composited over what lies behind.
            _ if g.transmission.is_some() => AlphaMode::Blend,
            GltfAlphaMode::Opaque => AlphaMode::Opaque,
            GltfAlphaMode::Mask => AlphaMode::Mask(g.alpha_cutoff),
            GltfAlphaMode::Blend => AlphaMode::Blend,
        },
        pbr,
        native: Native::Pbr,
        double_sided: g.double_sided,
        unlit: g.unlit,
    }
}
