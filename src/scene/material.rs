//! Materials as the renderer uses them: MTL or glTF values, scene overrides
//! applied, textures resolved. Every material carries both a Blinn-Phong and
//! a metallic-roughness (pbr) description, one of them native (the file's)
//! and the other derived by the documented mapping, so that any
//! `render.shading` can draw any model.

use glam::Vec3;

use crate::assets::texture::TextureRef;

/// The space a normal map's vectors are in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NormalSpace {
    /// Relative to the surface's tangent frame (the usual kind).
    Tangent,
    /// The model's object space.
    Object,
}

/// How a material's opacity (d, map_d, alpha of map_Kd) is used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AlphaMode {
    /// Opacity ignored.
    Opaque,
    /// Cutout: pixels with opacity below the cutoff are not drawn (alpha
    /// test in the visibility pass, so they hide nothing).
    Mask(f32),
    /// Blended over what is behind, after the opaque triangles, back to
    /// front within each band.
    Blend,
}

/// A perturbation of the shading normal.
#[derive(Debug, Clone)]
pub enum NormalMap {
    /// RGB normal map in tangent or object space; `scale` multiplies the
    /// tangent-space x and y (`-bm`).
    Normals {
        /// The normal map (linear).
        map: TextureRef,
        /// Tangent or object space.
        space: NormalSpace,
        /// Multiplies the tangent-space x and y (`-bm`, glTF `scale`).
        scale: f32,
    },
    /// Height map (bump): the normal tilts against the height gradient,
    /// `scale` (`-bm`) height units per texel step.
    Height {
        /// The height map (red, linear).
        map: TextureRef,
        /// Height units per texel step.
        scale: f32,
    },
}

/// Which shading model a material's file describes (`shading = "auto"`
/// uses it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Native {
    /// An MTL material: Blinn-Phong.
    BlinnPhong,
    /// A glTF (or FBX, USD) material: metallic-roughness.
    Pbr,
}

/// glTF 2.0 metallic-roughness parameters (factors times textures).
#[derive(Debug, Clone)]
pub struct Pbr {
    /// Linear RGBA base color factor.
    pub base_color: glam::Vec4,
    /// sRGB RGBA.
    pub base_color_map: Option<TextureRef>,
    /// Metallic factor, 0..1.
    pub metallic: f32,
    /// Perceptual roughness factor, 0..1.
    pub roughness: f32,
    /// Linear; roughness in green, metallic in blue.
    pub metallic_roughness_map: Option<TextureRef>,
    /// Linear, red: separate roughness and metallic maps (MTL `map_Pr`,
    /// `map_Pm`), multiplying the factors like the combined map.
    pub roughness_map: Option<TextureRef>,
    /// Linear, red: the metallic map (MTL `map_Pm`).
    pub metallic_map: Option<TextureRef>,
    /// Linear; occlusion in red, applied to the ambient term.
    pub occlusion_map: Option<TextureRef>,
    /// How much of the occlusion map applies, 0..1.
    pub occlusion_strength: f32,
    /// Linear RGB, KHR_materials_emissive_strength folded in.
    pub emissive: Vec3,
    /// sRGB.
    pub emissive_map: Option<TextureRef>,
    /// KHR_materials_ior / KHR_materials_specular; None: ior 1.5 (F0
    /// 0.04), F90 1.
    pub specular: Option<DielectricSpecular>,
    /// KHR_materials_clearcoat (glTF; MTL `Pc`/`Pcr`).
    pub clearcoat: Option<Clearcoat>,
    /// KHR_materials_transmission with KHR_materials_volume.
    pub transmission: Option<Transmission>,
    /// KHR_materials_sheen.
    pub sheen: Option<SheenLayer>,
    /// KHR_materials_iridescence.
    pub iridescence: Option<IridescenceLayer>,
    /// KHR_materials_anisotropy.
    pub anisotropy: Option<Anisotropy>,
    /// KHR_materials_diffuse_transmission.
    pub diffuse_transmission: Option<DiffuseTransmission>,
}

/// Light let through diffusely, as by a leaf or paper
/// (KHR_materials_diffuse_transmission).
#[derive(Debug, Clone)]
pub struct DiffuseTransmission {
    /// The share of the diffuse lobe that is transmitted, 0..1.
    pub factor: f32,
    /// Linear; alpha multiplies `factor`.
    pub map: Option<TextureRef>,
    /// Linear colour of the light let through.
    pub color: Vec3,
    /// sRGB; RGB multiplies `color`.
    pub color_map: Option<TextureRef>,
}

/// A lobe rougher along one direction of the surface than across it
/// (KHR_materials_anisotropy): brushed metal.
#[derive(Debug, Clone)]
pub struct Anisotropy {
    /// 0..1: alpha along the direction is lerp(alpha, 1, strength^2).
    pub strength: f32,
    /// Radians, counter-clockwise from the tangent, in the tangent plane.
    pub rotation: f32,
    /// Linear: red and green the direction in tangent space (times two
    /// minus one), blue multiplies `strength`.
    pub map: Option<TextureRef>,
}

/// A thin film over the material (KHR_materials_iridescence).
#[derive(Debug, Clone)]
pub struct IridescenceLayer {
    /// The film's strength, 0..1.
    pub factor: f32,
    /// Linear; red multiplies `factor`.
    pub map: Option<TextureRef>,
    /// The film's index of refraction.
    pub ior: f32,
    /// Thickness in nanometres: `thickness_max` without a map, else
    /// from `thickness_min` to `thickness_max` by the map's green.
    pub thickness_min: f32,
    /// The film's thickest, in nanometres.
    pub thickness_max: f32,
    /// Linear; green picks the thickness between min and max.
    pub thickness_map: Option<TextureRef>,
}

/// The fuzz of cloth: a sheen layer (`shade::sheen`) of this colour and
/// roughness.
#[derive(Debug, Clone)]
pub struct SheenLayer {
    /// Linear.
    pub color: Vec3,
    /// sRGB; RGB multiplies `color`.
    pub color_map: Option<TextureRef>,
    /// Perceptual roughness of the sheen lobe.
    pub roughness: f32,
    /// Linear; alpha multiplies `roughness`.
    pub roughness_map: Option<TextureRef>,
}

/// A clear, colourless GGX layer over the material: F0 0.04, its own
/// roughness and normal.
#[derive(Debug, Clone)]
pub struct Clearcoat {
    /// The coat's strength, 0..1.
    pub factor: f32,
    /// Linear; red multiplies `factor`.
    pub map: Option<TextureRef>,
    /// The coat's perceptual roughness.
    pub roughness: f32,
    /// Linear; green multiplies `roughness`.
    pub roughness_map: Option<TextureRef>,
    /// The layer's own normal map (None: the interpolated normal).
    pub normal_map: Option<NormalMap>,
}

/// Light passing through a dielectric surface, tinted by the base colour,
/// refracted through the volume's thickness (none for a thin wall) and,
/// with a volume, attenuated along the thickness by Beer's law.
#[derive(Debug, Clone)]
pub struct Transmission {
    /// The share of light transmitted, 0..1.
    pub factor: f32,
    /// Linear; red multiplies `factor`.
    pub map: Option<TextureRef>,
    /// Path length through the volume in the model's units (0: thin).
    pub thickness: f32,
    /// The volume's index of refraction (KHR_materials_ior; 1.5 without
    /// it): how far the view ray bends into it.
    pub ior: f32,
    /// Linear; green multiplies `thickness`.
    pub thickness_map: Option<TextureRef>,
    /// Colour that white light becomes after `attenuation_distance`.
    pub attenuation_color: Vec3,
    /// The distance at which white light becomes `attenuation_color`
    /// (infinite: no attenuation).
    pub attenuation_distance: f32,
    /// KHR_materials_dispersion: 20 / the Abbe number (0: none); the
    /// indices of red and blue spread about `ior` by it.
    pub dispersion: f32,
}

/// A dielectric's reflectance when the file gives it.
#[derive(Debug, Clone)]
pub struct DielectricSpecular {
    /// ((ior - 1) / (ior + 1))^2 times the specular colour factor.
    pub f0: Vec3,
    /// The specular factor: F90, and the weight on F0.
    pub weight: f32,
    /// Its alpha multiplies `weight` (linear).
    pub weight_map: Option<TextureRef>,
    /// Its RGB multiplies `f0` (sRGB).
    pub color_map: Option<TextureRef>,
}

impl Pbr {
    /// The glTF defaults: white, fully metallic, fully rough.
    pub fn gltf_default() -> Pbr {
        Pbr {
            base_color: glam::Vec4::ONE,
            base_color_map: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_map: None,
            roughness_map: None,
            metallic_map: None,
            occlusion_map: None,
            occlusion_strength: 1.0,
            emissive: Vec3::ZERO,
            emissive_map: None,
            specular: None,
            clearcoat: None,
            transmission: None,
            sheen: None,
            iridescence: None,
            anisotropy: None,
            diffuse_transmission: None,
        }
    }
}

/// Blinn-Phong exponent <-> GGX roughness: Ns = 2 / alpha^2 - 2 with
/// alpha = roughness^2 (the lobes match near their peak).
pub fn ns_from_roughness(roughness: f32) -> f32 {
    let a = (roughness * roughness).max(1e-3);
    (2.0 / (a * a) - 2.0).clamp(1.0, 10_000.0)
}

/// The inverse of `ns_from_roughness`.
pub fn roughness_from_ns(ns: f32) -> f32 {
    let a = (2.0 / (ns.max(0.0) + 2.0)).sqrt();
    a.sqrt().clamp(0.0, 1.0)
}

/// Defaults for a model without an MTL: grey diffuse 0.8, a faint specular
/// 0.2 with exponent 32, illum 2. A constant that the MTL leaves unset but
/// whose map is given is 1 (the map alone decides).
#[derive(Debug, Clone)]
pub struct Material {
    /// Its name in the file.
    pub name: String,
    /// None: the ambient term uses the (textured) diffuse color.
    pub ka: Option<Vec3>,
    /// Diffuse colour, linear.
    pub kd: Vec3,
    /// Specular colour, linear.
    pub ks: Vec3,
    /// Emitted colour, linear.
    pub ke: Vec3,
    /// Blinn-Phong exponent.
    pub ns: f32,
    /// MTL illumination model (0: colour alone, 1: diffuse, 2: and
    /// specular).
    pub illum: u8,
    /// Ambient colour map (sRGB).
    pub map_ka: Option<TextureRef>,
    /// Diffuse colour map (sRGB).
    pub map_kd: Option<TextureRef>,
    /// Specular colour map (sRGB).
    pub map_ks: Option<TextureRef>,
    /// Emission map (sRGB).
    pub map_ke: Option<TextureRef>,
    /// Scales Ns (red channel, linear).
    pub map_ns: Option<TextureRef>,
    /// Opacity (`d`, or 1 - `Tr`).
    pub d: f32,
    /// Opacity map (linear; its alpha if it has one, else its red channel).
    pub map_d: Option<TextureRef>,
    /// Normal or bump map.
    pub normal_map: Option<NormalMap>,
    /// How opacity is used: opaque, a cutout or blended.
    pub alpha: AlphaMode,
    /// Metallic-roughness description (native for glTF, derived for MTL).
    pub pbr: Pbr,
    /// The model its file describes.
    pub native: Native,
    /// glTF doubleSided: never culled, whatever `render.cull` says.
    pub double_sided: bool,
    /// KHR_materials_unlit: lit modes show its colour without light.
    pub unlit: bool,
}

impl Material {
    /// The diffuse colour without textures or light (Kd, or glTF's base
    /// colour factor): what unlit points and lines are drawn with.
    pub fn diffuse_color(&self) -> glam::Vec3 {
        match self.native {
            Native::Pbr => self.pbr.base_color.truncate(),
            Native::BlinnPhong => self.kd,
        }
    }

    /// The defaults above, named `name`.
    pub fn default_named(name: &str) -> Material {
        Material {
            name: name.to_string(),
            ka: None,
            kd: Vec3::splat(0.8),
            ks: Vec3::splat(0.2),
            ke: Vec3::ZERO,
            ns: 32.0,
            illum: 2,
            map_ka: None,
            map_kd: None,
            map_ks: None,
            map_ke: None,
            map_ns: None,
            d: 1.0,
            map_d: None,
            normal_map: None,
            alpha: AlphaMode::Opaque,
            pbr: Pbr {
                base_color: Vec3::splat(0.8).extend(1.0),
                metallic: 0.0,
                roughness: roughness_from_ns(32.0),
                ..Pbr::gltf_default()
            },
            native: Native::BlinnPhong,
            double_sided: false,
            unlit: false,
        }
    }
}

impl Material {
    /// Whether shading needs per-corner tangents.
    pub fn needs_tangents(&self) -> bool {
        self.tangent_set().is_some()
    }

    /// The texture-coordinate set whose tangents shading needs: that of
    /// `tangent_map`, else an anisotropy's map's (set 0 without a map).
    pub fn tangent_set(&self) -> Option<usize> {
        let set = |t: &TextureRef| t.texcoord as usize;
        self.tangent_map().map(set).or_else(|| {
            let a = self.pbr.anisotropy.as_ref()?;
            Some(a.map.as_ref().map_or(0, set))
        })
    }

    /// The first map read in the surface's tangent frame (the normal or
    /// bump map, else the clearcoat's normal map): its set decides the
    /// tangents.
    pub fn tangent_map(&self) -> Option<&TextureRef> {
        fn in_tangent_space(nm: &Option<NormalMap>) -> Option<&TextureRef> {
            match nm {
                Some(NormalMap::Height { map, .. })
                | Some(NormalMap::Normals {
                    map,
                    space: NormalSpace::Tangent,
                    ..
                }) => Some(map),
                _ => None,
            }
        }
        in_tangent_space(&self.normal_map).or_else(|| {
            self.pbr
                .clearcoat
                .as_ref()
                .and_then(|c| in_tangent_space(&c.normal_map))
        })
    }

    /// Every texture the material samples.
    pub fn maps(&self) -> impl Iterator<Item = &TextureRef> {
        let nm = match &self.normal_map {
            Some(NormalMap::Normals { map, .. }) | Some(NormalMap::Height { map, .. }) => Some(map),
            None => None,
        };
        let p = &self.pbr;
        [
            self.map_ka.as_ref(),
            self.map_kd.as_ref(),
            self.map_ks.as_ref(),
            self.map_ke.as_ref(),
            self.map_ns.as_ref(),
            self.map_d.as_ref(),
            nm,
            p.base_color_map.as_ref(),
            p.metallic_roughness_map.as_ref(),
            p.occlusion_map.as_ref(),
            p.emissive_map.as_ref(),
            p.specular.as_ref().and_then(|s| s.weight_map.as_ref()),
            p.specular.as_ref().and_then(|s| s.color_map.as_ref()),
            p.roughness_map.as_ref(),
            p.metallic_map.as_ref(),
        ]
        .into_iter()
        .chain(p.clearcoat.iter().flat_map(|c| {
            let nm = match &c.normal_map {
                Some(NormalMap::Normals { map, .. }) | Some(NormalMap::Height { map, .. }) => {
                    Some(map)
                }
                None => None,
            };
            [c.map.as_ref(), c.roughness_map.as_ref(), nm]
        }))
        .chain(
            p.transmission
                .iter()
                .flat_map(|t| [t.map.as_ref(), t.thickness_map.as_ref()]),
        )
        .chain(
            p.sheen
                .iter()
                .flat_map(|t| [t.color_map.as_ref(), t.roughness_map.as_ref()]),
        )
        .chain(
            p.iridescence
                .iter()
                .flat_map(|t| [t.map.as_ref(), t.thickness_map.as_ref()]),
        )
        .chain(p.anisotropy.iter().map(|a| a.map.as_ref()))
        .chain(
            p.diffuse_transmission
                .iter()
                .flat_map(|t| [t.map.as_ref(), t.color_map.as_ref()]),
        )
        .flatten()
    }
}

/// Whether shading mode `mode` shades material `m` as metallic-roughness.
pub fn shades_pbr(mode: super::settings::ShadingMode, m: &Material) -> bool {
    use super::settings::ShadingMode;
    match mode {
        ShadingMode::Pbr => true,
        ShadingMode::Auto => m.native == Native::Pbr && !m.unlit,
        _ => false,
    }
}
