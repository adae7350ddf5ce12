//! Blinn-Phong materials as the renderer uses them: MTL values, scene
//! overrides applied, textures resolved.

use glam::Vec3;

use crate::assets::texture::TextureRef;
pub use crate::scene::desc::NormalSpace;

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
        map: TextureRef,
        space: NormalSpace,
        scale: f32,
    },
    /// Height map (bump): the normal tilts against the height gradient,
    /// `scale` (`-bm`) height units per texel step.
    Height { map: TextureRef, scale: f32 },
}

/// Defaults for a model without an MTL: grey diffuse 0.8, a faint specular
/// 0.2 with exponent 32, illum 2. A constant that the MTL leaves unset but
/// whose map is given is 1 (the map alone decides).
#[derive(Debug, Clone)]
pub struct Material {
    pub name: String,
    /// None: the ambient term uses the (textured) diffuse color.
    pub ka: Option<Vec3>,
    pub kd: Vec3,
    pub ks: Vec3,
    pub ke: Vec3,
    pub ns: f32,
    pub illum: u8,
    pub map_ka: Option<TextureRef>,
    pub map_kd: Option<TextureRef>,
    pub map_ks: Option<TextureRef>,
    pub map_ke: Option<TextureRef>,
    /// Scales Ns (red channel, linear).
    pub map_ns: Option<TextureRef>,
    /// Opacity (`d`, or 1 - `Tr`).
    pub d: f32,
    /// Opacity map (linear; its alpha if it has one, else its red channel).
    pub map_d: Option<TextureRef>,
    pub normal_map: Option<NormalMap>,
    pub alpha: AlphaMode,
}

impl Material {
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
        }
    }
}

impl Material {
    /// Whether shading needs per-corner tangents.
    pub fn needs_tangents(&self) -> bool {
        matches!(
            &self.normal_map,
            Some(NormalMap::Height { .. })
                | Some(NormalMap::Normals {
                    space: NormalSpace::Tangent,
                    ..
                })
        )
    }

    /// Every texture the material samples.
    pub fn maps(&self) -> impl Iterator<Item = &TextureRef> {
        let nm = match &self.normal_map {
            Some(NormalMap::Normals { map, .. }) | Some(NormalMap::Height { map, .. }) => Some(map),
            None => None,
        };
        [
            self.map_ka.as_ref(),
            self.map_kd.as_ref(),
            self.map_ks.as_ref(),
            self.map_ke.as_ref(),
            self.map_ns.as_ref(),
            self.map_d.as_ref(),
            nm,
        ]
        .into_iter()
        .flatten()
    }
}
