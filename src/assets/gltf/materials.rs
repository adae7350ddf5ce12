//! glTF materials as the file states them: metallic-roughness with its
//! texture references (`TexInfo`: set, sampler, KHR_texture_transform)
//! and the KHR material extensions (specular, ior, emissive strength,
//! unlit, clearcoat, sheen, iridescence, transmission and volume).

use super::*;

/// A texture reference of a material: image, sampler, coordinates.
#[derive(Debug, Clone)]
pub struct TexInfo {
    pub image: ImageSource,
    pub texcoord: u8,
    /// KHR_texture_transform (identity without it).
    pub transform: Affine2,
    pub wrap: Wrap,
    pub min_limit: Option<TextureFilter>,
    pub mag_nearest: bool,
}

/// A material's `alphaMode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GltfAlphaMode {
    Opaque,
    /// Cut out below `alphaCutoff`.
    Mask,
    Blend,
}

/// A glTF metallic-roughness material as the file states it.
#[derive(Debug, Clone)]
pub struct GltfMaterial {
    pub name: String,
    pub base_color: Vec4,
    pub base_color_tex: Option<TexInfo>,
    pub metallic: f32,
    pub roughness: f32,
    pub metallic_roughness_tex: Option<TexInfo>,
    pub normal_tex: Option<TexInfo>,
    pub normal_scale: f32,
    pub occlusion_tex: Option<TexInfo>,
    pub occlusion_strength: f32,
    /// emissiveFactor times KHR_materials_emissive_strength.
    pub emissive: Vec3,
    pub emissive_tex: Option<TexInfo>,
    pub alpha_mode: GltfAlphaMode,
    pub alpha_cutoff: f32,
    pub double_sided: bool,
    /// KHR_materials_unlit: the base colour, without light.
    pub unlit: bool,
    /// KHR_materials_ior (1.5 without it).
    pub ior: f32,
    /// KHR_materials_specular: factor (the dielectric's F90 and weight on
    /// F0), colour factor (on F0), and their textures (alpha; sRGB RGB).
    pub specular: Option<GltfSpecular>,
    /// KHR_materials_clearcoat (None without it, or with a factor of 0).
    pub clearcoat: Option<GltfClearcoat>,
    /// KHR_materials_transmission (None without it, or with a factor of 0).
    pub transmission: Option<GltfTransmission>,
    /// KHR_materials_sheen (None without it, or with a black colour).
    pub sheen: Option<GltfSheen>,
    /// KHR_materials_iridescence (None without it, or with a factor of 0).
    pub iridescence: Option<GltfIridescence>,
    /// KHR_materials_anisotropy (None without it, or with a strength of 0
    /// and no texture).
    pub anisotropy: Option<GltfAnisotropy>,
    /// KHR_materials_diffuse_transmission (None without it, or with a
    /// factor of 0).
    pub diffuse_transmission: Option<GltfDiffuseTransmission>,
}

/// KHR_materials_diffuse_transmission.
#[derive(Debug, Clone)]
pub struct GltfDiffuseTransmission {
    /// 0..1.
    pub factor: f32,
    /// Alpha multiplies `factor`.
    pub texture: Option<TexInfo>,
    pub color: Vec3,
    /// sRGB; RGB multiplies `color`.
    pub color_texture: Option<TexInfo>,
}

/// KHR_materials_anisotropy.
#[derive(Debug, Clone)]
pub struct GltfAnisotropy {
    /// 0..1.
    pub strength: f32,
    /// Radians, counter-clockwise from the tangent.
    pub rotation: f32,
    /// Red and green: the direction in tangent space; blue multiplies
    /// `strength`.
    pub texture: Option<TexInfo>,
}

/// KHR_materials_iridescence.
#[derive(Debug, Clone)]
pub struct GltfIridescence {
    pub factor: f32,
    /// Red multiplies `factor`.
    pub texture: Option<TexInfo>,
    pub ior: f32,
    /// Nanometres.
    pub thickness_min: f32,
    pub thickness_max: f32,
    /// Green: from `thickness_min` to `thickness_max`.
    pub thickness_texture: Option<TexInfo>,
}

/// KHR_materials_sheen.
#[derive(Debug, Clone)]
pub struct GltfSheen {
    pub color: Vec3,
    /// sRGB; RGB multiplies `color`.
    pub color_texture: Option<TexInfo>,
    pub roughness: f32,
    /// Alpha multiplies `roughness`.
    pub roughness_texture: Option<TexInfo>,
}

/// KHR_materials_clearcoat: a second, colourless GGX layer over the
/// material (F0 0.04), with its own roughness and normal map.
#[derive(Debug, Clone)]
pub struct GltfClearcoat {
    pub factor: f32,
    /// Red channel multiplies `factor`.
    pub texture: Option<TexInfo>,
    pub roughness: f32,
    /// Green channel multiplies `roughness`.
    pub roughness_texture: Option<TexInfo>,
    pub normal_texture: Option<TexInfo>,
    pub normal_scale: f32,
}

/// KHR_materials_transmission, with KHR_materials_volume's thickness and
/// attenuation when the material has that extension too.
#[derive(Debug, Clone)]
pub struct GltfTransmission {
    pub factor: f32,
    /// Red channel multiplies `factor`.
    pub texture: Option<TexInfo>,
    /// KHR_materials_volume thicknessFactor (0: thin-walled).
    pub thickness: f32,
    /// Green channel multiplies `thickness`.
    pub thickness_texture: Option<TexInfo>,
    pub attenuation_color: Vec3,
    /// +inf: no attenuation.
    pub attenuation_distance: f32,
    /// KHR_materials_dispersion: 20 / the Abbe number (0: none).
    pub dispersion: f32,
}

#[derive(Debug, Clone)]
pub struct GltfSpecular {
    pub factor: f32,
    pub texture: Option<TexInfo>,
    pub color: Vec3,
    pub color_texture: Option<TexInfo>,
}

impl GltfMaterial {
    /// The material of primitives without one (glTF's default).
    pub(crate) fn default_material() -> GltfMaterial {
        GltfMaterial {
            name: "default".into(),
            base_color: Vec4::ONE,
            base_color_tex: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_tex: None,
            normal_tex: None,
            normal_scale: 1.0,
            occlusion_tex: None,
            occlusion_strength: 1.0,
            emissive: Vec3::ZERO,
            emissive_tex: None,
            alpha_mode: GltfAlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
            unlit: false,
            ior: 1.5,
            specular: None,
            clearcoat: None,
            transmission: None,
            sheen: None,
            iridescence: None,
            anisotropy: None,
            diffuse_transmission: None,
        }
    }

    /// Every texture with whether it holds sRGB color.
    pub fn textures(&self) -> impl Iterator<Item = (&TexInfo, bool)> {
        [
            (self.base_color_tex.as_ref(), true),
            (self.metallic_roughness_tex.as_ref(), false),
            (self.normal_tex.as_ref(), false),
            (self.occlusion_tex.as_ref(), false),
            (self.emissive_tex.as_ref(), true),
            (
                self.specular.as_ref().and_then(|s| s.texture.as_ref()),
                false,
            ),
            (
                self.specular
                    .as_ref()
                    .and_then(|s| s.color_texture.as_ref()),
                true,
            ),
            (
                self.clearcoat.as_ref().and_then(|c| c.texture.as_ref()),
                false,
            ),
            (
                self.clearcoat
                    .as_ref()
                    .and_then(|c| c.roughness_texture.as_ref()),
                false,
            ),
            (
                self.clearcoat
                    .as_ref()
                    .and_then(|c| c.normal_texture.as_ref()),
                false,
            ),
            (
                self.transmission.as_ref().and_then(|t| t.texture.as_ref()),
                false,
            ),
            (
                self.transmission
                    .as_ref()
                    .and_then(|t| t.thickness_texture.as_ref()),
                false,
            ),
            (
                self.sheen.as_ref().and_then(|t| t.color_texture.as_ref()),
                true,
            ),
            (
                self.sheen
                    .as_ref()
                    .and_then(|t| t.roughness_texture.as_ref()),
                false,
            ),
            (
                self.iridescence.as_ref().and_then(|t| t.texture.as_ref()),
                false,
            ),
            (
                self.iridescence
                    .as_ref()
                    .and_then(|t| t.thickness_texture.as_ref()),
                false,
            ),
            (
                self.anisotropy.as_ref().and_then(|t| t.texture.as_ref()),
                false,
            ),
            (
                self.diffuse_transmission
                    .as_ref()
                    .and_then(|t| t.texture.as_ref()),
                false,
            ),
            (
                self.diffuse_transmission
                    .as_ref()
                    .and_then(|t| t.color_texture.as_ref()),
                true,
            ),
        ]
        .into_iter()
        .filter_map(|(t, srgb)| t.map(|t| (t, srgb)))
    }
}

/// KHR_texture_transform as an affine map of texture coordinates:
/// translate * rotate * scale, the rotation as implementations and the
/// sample models have it (u' = cos u + sin v, v' = -sin u + cos v: the
/// image turns clockwise on screen for a positive angle). Also returns its
/// texCoord override.
pub(super) fn texture_transform(t: Option<Transform>) -> (Affine2, Option<u32>) {
    let Some(t) = t else {
        return (Affine2::IDENTITY, None);
    };
    let (s, c) = t.rotation.sin_cos();
    let rot = Mat2::from_cols(Vec2::new(c, -s), Vec2::new(s, c));
    let m = Affine2::from_mat2_translation(rot * Mat2::from_diagonal(t.scale), t.offset);
    (m, t.tex_coord)
}

/// KHR_texture_transform's values.
#[derive(Debug, Clone, Copy)]
pub(super) struct Transform {
    offset: Vec2,
    rotation: f32,
    scale: Vec2,
    tex_coord: Option<u32>,
}

impl Transform {
    /// From a textureInfo (the crate parses the extension there).
    fn of_info(i: &gltf::texture::Info) -> Option<Transform> {
        i.texture_transform().map(|t| Transform {
            offset: Vec2::from(t.offset()),
            rotation: t.rotation(),
            scale: Vec2::from(t.scale()),
            tex_coord: t.tex_coord(),
        })
    }

    /// From the raw extension object (normal and occlusion textures, where
    /// the crate leaves it as JSON).
    pub(super) fn of_json(v: Option<&gltf::json::Value>) -> Option<Transform> {
        let v = v?;
        let pair = |k: &str, d: Vec2| -> Vec2 {
            v.get(k)
                .and_then(|a| a.as_array())
                .filter(|a| a.len() == 2)
                .and_then(|a| Some(Vec2::new(a[0].as_f64()? as f32, a[1].as_f64()? as f32)))
                .unwrap_or(d)
        };
        Some(Transform {
            offset: pair("offset", Vec2::ZERO),
            rotation: v.get("rotation").and_then(|r| r.as_f64()).unwrap_or(0.0) as f32,
            scale: pair("scale", Vec2::ONE),
            tex_coord: v.get("texCoord").and_then(|t| t.as_u64()).map(|t| t as u32),
        })
    }
}

pub(super) fn tex_info(
    texture: gltf::Texture,
    tex_coord: u32,
    transform: Option<Transform>,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<TexInfo> {
    // The texture's own image (a PNG or JPEG fallback, when
    // KHR_texture_basisu gives one), else its KTX2 image.
    let basisu = texture
        .extension_value("KHR_texture_basisu")
        .and_then(|v| v.get("source"))
        .and_then(|i| i.as_u64())
        .and_then(|i| usize::try_from(i).ok());
    let Some(index) = texture.source().map(|i| i.index()).or(basisu) else {
        warnings.push(format!(
            "{}: texture {} has no image; materials use it without that map",
            path.display(),
            texture.index()
        ));
        return None;
    };
    let Some(image) = images.get(index).cloned() else {
        warnings.push(format!(
            "{}: texture {} names image {index}, which the file does not have",
            path.display(),
            texture.index()
        ));
        return None;
    };
    let (transform, tc) = texture_transform(transform);
    let set = tc.unwrap_or(tex_coord);
    let texcoord = if set > 1 {
        warnings.push(format!(
            "{}: texture {} reads TEXCOORD_{set}; softraster reads sets 0 and 1 and uses 0",
            path.display(),
            texture.index()
        ));
        0
    } else {
        set as u8
    };
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let sampler = texture.sampler();
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => AddressMode::Clamp,
        WrappingMode::MirroredRepeat => AddressMode::Mirror,
        WrappingMode::Repeat => AddressMode::Repeat,
    };
    let min_limit = match sampler.min_filter() {
        Some(MinFilter::Nearest) => Some(TextureFilter::Nearest),
        Some(MinFilter::Linear) => Some(TextureFilter::Bilinear),
        _ => None,
    };
    Some(TexInfo {
        image,
        texcoord,
        transform,
        wrap: Wrap(wrap(sampler.wrap_s()), wrap(sampler.wrap_t())),
        min_limit,
        mag_nearest: sampler.mag_filter() == Some(MagFilter::Nearest),
    })
}

pub(super) fn material(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> GltfMaterial {
    const TT: &str = "KHR_texture_transform";
    let pbr = m.pbr_metallic_roughness();
    let info = |i: Option<gltf::texture::Info>, w: &mut Vec<String>| {
        i.and_then(|i| {
            tex_info(
                i.texture(),
                i.tex_coord(),
                Transform::of_info(&i),
                images,
                w,
                path,
            )
        })
    };
    let base_color_tex = info(pbr.base_color_texture(), warnings);
    let metallic_roughness_tex = info(pbr.metallic_roughness_texture(), warnings);
    let emissive_tex = info(m.emissive_texture(), warnings);
    let normal = m.normal_texture();
    let normal_tex = normal.as_ref().and_then(|n| {
        tex_info(
            n.texture(),
            n.tex_coord(),
            Transform::of_json(n.extension_value(TT)),
            images,
            warnings,
            path,
        )
    });
    let occlusion = m.occlusion_texture();
    let occlusion_tex = occlusion.as_ref().and_then(|o| {
        tex_info(
            o.texture(),
            o.tex_coord(),
            Transform::of_json(o.extension_value(TT)),
            images,
            warnings,
            path,
        )
    });
    GltfMaterial {
        name: m
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("material{}", m.index().unwrap_or(0))),
        base_color: Vec4::from(pbr.base_color_factor()),
        base_color_tex,
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        metallic_roughness_tex,
        normal_tex,
        normal_scale: normal.as_ref().map(|n| n.scale()).unwrap_or(1.0),
        occlusion_tex,
        occlusion_strength: occlusion.as_ref().map(|o| o.strength()).unwrap_or(1.0),
        emissive: Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
        emissive_tex,
        alpha_mode: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => GltfAlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => GltfAlphaMode::Mask,
            gltf::material::AlphaMode::Blend => GltfAlphaMode::Blend,
        },
        alpha_cutoff: m.alpha_cutoff().unwrap_or(0.5),
        double_sided: m.double_sided(),
        unlit: m.unlit(),
        ior: m
            .ior()
            .filter(|i| i.is_finite() && *i >= 1.0)
            .unwrap_or(1.5),
        specular: m.specular().map(|s| GltfSpecular {
            factor: s.specular_factor().clamp(0.0, 1.0),
            texture: info(s.specular_texture(), warnings),
            color: Vec3::from(s.specular_color_factor()).max(Vec3::ZERO),
            color_texture: info(s.specular_color_texture(), warnings),
        }),
        clearcoat: clearcoat(m, doc, images, warnings, path),
        transmission: transmission(m, doc, images, warnings, path),
        sheen: sheen(m, doc, images, warnings, path),
        iridescence: iridescence(m, doc, images, warnings, path),
        anisotropy: anisotropy(m, doc, images, warnings, path),
        diffuse_transmission: diffuse_transmission(m, doc, images, warnings, path),
    }
}

/// KHR_materials_diffuse_transmission: factor clamped to 0..1, colour to
/// 0..1 per channel.
pub(super) fn diffuse_transmission(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfDiffuseTransmission> {
    let v = m.extension_value("KHR_materials_diffuse_transmission")?;
    let factor = json_number(v, "diffuseTransmissionFactor")
        .unwrap_or(0.0)
        .clamp(0.0, 1.0);
    if factor <= 0.0 {
        return None;
    }
    Some(GltfDiffuseTransmission {
        factor,
        texture: json_tex(v, "diffuseTransmissionTexture", doc, images, warnings, path),
        color: json_rgb(v, "diffuseTransmissionColorFactor")
            .unwrap_or(Vec3::ONE)
            .clamp(Vec3::ZERO, Vec3::ONE),
        color_texture: json_tex(
            v,
            "diffuseTransmissionColorTexture",
            doc,
            images,
            warnings,
            path,
        ),
    })
}

/// Three finite numbers at `key` of `v`, as a colour.
pub(super) fn json_rgb(v: &gltf::json::Value, key: &str) -> Option<Vec3> {
    let c = v.get(key)?.as_array().filter(|c| c.len() == 3)?;
    let ch = |i: usize| c[i].as_f64().map(|x| x as f32).filter(|x| x.is_finite());
    Some(Vec3::new(ch(0)?, ch(1)?, ch(2)?))
}

/// KHR_materials_anisotropy: strength clamped to 0..1, a rotation that is
/// not a finite number read as 0.
pub(super) fn anisotropy(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfAnisotropy> {
    let v = m.extension_value("KHR_materials_anisotropy")?;
    let strength = json_number(v, "anisotropyStrength")
        .unwrap_or(0.0)
        .clamp(0.0, 1.0);
    let texture = json_tex(v, "anisotropyTexture", doc, images, warnings, path);
    if strength <= 0.0 {
        // Zero strength is an isotropic lobe, whatever the texture says.
        return None;
    }
    Some(GltfAnisotropy {
        strength,
        rotation: json_number(v, "anisotropyRotation")
            .filter(|r| r.is_finite())
            .unwrap_or(0.0),
        texture,
    })
}

pub(super) fn iridescence(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfIridescence> {
    let v = m.extension_value("KHR_materials_iridescence")?;
    let factor = json_number(v, "iridescenceFactor")
        .unwrap_or(0.0)
        .clamp(0.0, 1.0);
    if factor <= 0.0 {
        return None;
    }
    // An index of refraction below 1 or absurdly high is clamped to what
    // films are made of; thicknesses are kept to 0..10 um.
    let thickness =
        |key: &str, default: f32| json_number(v, key).unwrap_or(default).clamp(0.0, 10_000.0);
    Some(GltfIridescence {
        factor,
        texture: json_tex(v, "iridescenceTexture", doc, images, warnings, path),
        ior: json_number(v, "iridescenceIor")
            .unwrap_or(1.3)
            .clamp(1.0, 4.0),
        thickness_min: thickness("iridescenceThicknessMinimum", 100.0),
        thickness_max: thickness("iridescenceThicknessMaximum", 400.0),
        thickness_texture: json_tex(
            v,
            "iridescenceThicknessTexture",
            doc,
            images,
            warnings,
            path,
        ),
    })
}

pub(super) fn sheen(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfSheen> {
    let v = m.extension_value("KHR_materials_sheen")?;
    let color = json_rgb(v, "sheenColorFactor")
        .unwrap_or(Vec3::ZERO)
        .clamp(Vec3::ZERO, Vec3::ONE);
    if color == Vec3::ZERO {
        return None;
    }
    Some(GltfSheen {
        color,
        color_texture: json_tex(v, "sheenColorTexture", doc, images, warnings, path),
        roughness: json_number(v, "sheenRoughnessFactor")
            .unwrap_or(0.0)
            .clamp(0.0, 1.0),
        roughness_texture: json_tex(v, "sheenRoughnessTexture", doc, images, warnings, path),
    })
}

/// A number of an extension object, when it is a finite number.
pub(super) fn json_number(v: &gltf::json::Value, key: &str) -> Option<f32> {
    v.get(key)
        .and_then(|x| x.as_f64())
        .map(|x| x as f32)
        .filter(|x| x.is_finite())
}

/// A textureInfo given as raw JSON inside a material extension (the
/// gltf crate does not parse these extensions): its texture, set and
/// KHR_texture_transform. An index that names no texture is a warning.
pub(super) fn json_tex(
    v: &gltf::json::Value,
    key: &str,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<TexInfo> {
    let t = v.get(key)?;
    let texture = t
        .get("index")
        .and_then(|i| i.as_u64())
        .and_then(|i| doc.textures().nth(usize::try_from(i).ok()?));
    let Some(texture) = texture else {
        warnings.push(format!(
            "{}: `{key}` names no texture of the file; it is ignored",
            path.display()
        ));
        return None;
    };
    let set = t.get("texCoord").and_then(|c| c.as_u64()).unwrap_or(0);
    let transform = Transform::of_json(
        t.get("extensions")
            .and_then(|e| e.get("KHR_texture_transform")),
    );
    tex_info(
        texture,
        u32::try_from(set).unwrap_or(u32::MAX),
        transform,
        images,
        warnings,
        path,
    )
}

pub(super) fn clearcoat(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfClearcoat> {
    let v = m.extension_value("KHR_materials_clearcoat")?;
    let factor = json_number(v, "clearcoatFactor")
        .unwrap_or(0.0)
        .clamp(0.0, 1.0);
    if factor <= 0.0 {
        return None;
    }
    let normal_scale = v
        .get("clearcoatNormalTexture")
        .map_or(1.0, |t| json_number(t, "scale").unwrap_or(1.0));
    Some(GltfClearcoat {
        factor,
        texture: json_tex(v, "clearcoatTexture", doc, images, warnings, path),
        roughness: json_number(v, "clearcoatRoughnessFactor")
            .unwrap_or(0.0)
            .clamp(0.0, 1.0),
        roughness_texture: json_tex(v, "clearcoatRoughnessTexture", doc, images, warnings, path),
        normal_texture: json_tex(v, "clearcoatNormalTexture", doc, images, warnings, path),
        normal_scale,
    })
}

pub(super) fn transmission(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfTransmission> {
    let v = m.extension_value("KHR_materials_transmission")?;
    let factor = json_number(v, "transmissionFactor")
        .unwrap_or(0.0)
        .clamp(0.0, 1.0);
    if factor <= 0.0 {
        return None;
    }
    let volume = m.extension_value("KHR_materials_volume");
    let vol_number = |k: &str| volume.and_then(|v| json_number(v, k));
    let material = match (m.index(), m.name()) {
        (Some(i), Some(n)) => format!("material {i} (\"{n}\")"),
        (Some(i), None) => format!("material {i}"),
        (None, _) => "the default material".to_string(),
    };
    // The extension's bounds: a thickness of at least 0, a distance above 0.
    let mut out_of_range = |key: &str, value: f32, bound: &str, instead: &str| {
        warnings.push(format!(
            "{}: {material}: KHR_materials_volume {key} {value} is {bound}; {instead}",
            path.display()
        ));
    };
    let thickness = match vol_number("thicknessFactor") {
        Some(t) if t < 0.0 => {
            out_of_range("thicknessFactor", t, "negative", "0 (thin-walled) is used");
            0.0
        }
        t => t.unwrap_or(0.0),
    };
    let attenuation_distance = match vol_number("attenuationDistance") {
        Some(d) if d <= 0.0 => {
            out_of_range(
                "attenuationDistance",
                d,
                "not positive",
                "the volume does not attenuate",
            );
            f32::INFINITY
        }
        d => d.unwrap_or(f32::INFINITY),
    };
    let attenuation_color = volume
        .and_then(|v| json_rgb(v, "attenuationColor"))
        .unwrap_or(Vec3::ONE)
        .clamp(Vec3::ZERO, Vec3::ONE);
    Some(GltfTransmission {
        factor,
        texture: json_tex(v, "transmissionTexture", doc, images, warnings, path),
        thickness,
        thickness_texture: volume
            .and_then(|vv| json_tex(vv, "thicknessTexture", doc, images, warnings, path)),
        attenuation_color,
        attenuation_distance,
        // Negative or not a number: none.
        dispersion: m
            .extension_value("KHR_materials_dispersion")
            .and_then(|d| json_number(d, "dispersion"))
            .unwrap_or(0.0)
            .max(0.0),
    })
}

/// A primitive that KHR_materials_variants maps: the material slot it
/// draws with (a copy of its default material, its own), and per variant
/// (its index in `GltfModel::variants`) the material the slot takes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VariantSlot {
    pub slot: usize,
    pub mappings: Vec<(usize, usize)>,
}

/// The names of the file's KHR_materials_variants, in order.
pub(super) fn variant_names(doc: &gltf::Document) -> Vec<String> {
    doc.variants()
        .map(|v| v.map(|v| v.name().to_string()).collect())
        .unwrap_or_default()
}

/// The material slot of primitive `prim` of mesh `mesh`, whose default
/// material is `mat`:
/// `mat` itself, or, where KHR_materials_variants maps the primitive, a
/// slot of its own (recorded in `slots`). A mapping that names a material
/// or a variant the file lacks is an error.
pub(super) fn variant_slot(
    doc: &gltf::Document,
    (mesh, prim): (usize, usize),
    mat: usize,
    materials: &mut Vec<GltfMaterial>,
    slots: &mut Vec<VariantSlot>,
) -> Result<usize, String> {
    let json = &doc.as_json().meshes[mesh].primitives[prim];
    let Some(v) = json
        .extensions
        .as_ref()
        .and_then(|e| e.khr_materials_variants.as_ref())
    else {
        return Ok(mat);
    };
    let (n_materials, n_variants) = (doc.materials().count(), variant_names(doc).len());
    let mut mappings = Vec::new();
    for m in &v.mappings {
        let material = m.material as usize;
        if material >= n_materials {
            return Err(format!(
                "KHR_materials_variants maps material {material}; the file has {n_materials}"
            ));
        }
        for &variant in &m.variants {
            let variant = variant as usize;
            if variant >= n_variants {
                return Err(format!(
                    "KHR_materials_variants maps variant {variant}; the file has {n_variants}"
                ));
            }
            mappings.push((variant, material));
        }
    }
    let slot = materials.len();
    materials.push(materials[mat].clone());
    slots.push(VariantSlot { slot, mappings });
    Ok(slot)
}
