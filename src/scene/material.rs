//! Blinn-Phong materials as the renderer uses them: MTL values, scene
//! overrides applied, textures resolved.

use glam::Vec3;

use crate::assets::texture::TextureRef;

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
        }
    }
}
