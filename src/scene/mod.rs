//! From a scene file to a loaded `Scene`: `desc` (the TOML as data),
//! `overrides` (`--set`), `build` (resolve paths, load assets, defaults),
//! `materials` (file materials to renderer materials).

pub mod animation;
pub mod build;
pub mod camera;
pub mod desc;
pub mod light;
pub mod material;
pub mod materials;
pub mod overrides;

use std::path::PathBuf;
use std::sync::Arc;

use glam::{Mat4, Vec3};

use crate::assets::mesh::Mesh;
pub use animation::Animation;
pub use camera::Camera;
use desc::{
    AddressMode, AoMethod, Background, CullMode, DepthMode, ShadingMode, ShadowMethod,
    TextureFilter, Tonemap,
};
pub use light::Light;
pub use material::Material;

/// Everything that decides how a frame is rasterized and shaded.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub shading: ShadingMode,
    pub texture_filter: TextureFilter,
    pub max_anisotropy: f32,
    pub address: AddressMode,
    pub cull: CullMode,
    pub depth: DepthMode,
    pub tonemap: Tonemap,
    pub exposure: f32,
    pub background: Background,
    pub ambient: Vec3,
    /// How lights with `shadows = true` cast them (default pcf).
    pub shadows: ShadowMethod,
    /// Shadow map size in texels, per side (default 2048).
    pub shadow_map_size: u32,
    pub shadow_bias: ShadowBias,
    pub ao: AoSettings,
    /// Samples per pixel: 1, 2, 4, 8 or 16 (standard D3D positions).
    pub msaa: u32,
    /// Supersampling factor per axis (1: off).
    pub ssaa: u32,
}

/// Shadow-map bias, in texels of the map at the receiver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowBias {
    /// Depth bias (default 1).
    pub constant: f32,
    /// Depth bias times the tangent of the angle between normal and light
    /// (default 0.5; the tangent is capped at 10).
    pub slope: f32,
    /// Lookup point moved along the geometric normal, times the sine of
    /// the angle between normal and light (default 1).
    pub normal: f32,
}

impl Default for ShadowBias {
    fn default() -> ShadowBias {
        ShadowBias {
            constant: 1.0,
            slope: 0.5,
            normal: 1.0,
        }
    }
}

/// `render.ao`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AoSettings {
    pub method: AoMethod,
    /// Occluders within this distance count; None (raytraced only): rays of
    /// unbounded length. SSAO without a radius uses a fifth of the scene's
    /// bounding radius.
    pub radius: Option<f32>,
    /// Rays per pixel (raytraced) or depth-buffer reads per pixel (ssao).
    pub samples: u32,
}

#[derive(Debug, Clone, PartialEq)]
pub struct OutputSettings {
    pub dir: PathBuf,
    /// File stem pattern with `{scene}`, `{camera}`, `{frame}` (`{frame:04}`
    /// pads with zeros).
    pub name: String,
    pub color: bool,
    /// `<name>_depth.exr`, channel `Z`.
    pub depth: bool,
    /// `<name>_ao.exr`, channel `AO`.
    pub ao: bool,
    /// The GIF's file name (in `dir`; `{camera}`, or `_<camera>` added
    /// before the extension when the scene has several cameras).
    pub gif: Option<String>,
    pub gif_delay_ms: u32,
    pub gif_dither: desc::GifDither,
}

#[derive(Debug, Clone)]
pub struct Model {
    pub name: String,
    pub mesh: Arc<Mesh>,
    pub materials: Vec<Material>,
    /// Placement at rest (before any turntable turn).
    pub world_from_object: Mat4,
}

#[derive(Debug, Clone)]
pub struct Scene {
    pub file: PathBuf,
    /// The scene file's stem, for `{scene}` and the default output dir.
    pub stem: String,
    pub settings: RenderSettings,
    pub output: OutputSettings,
    pub models: Vec<Model>,
    /// Empty: every camera gets a headlight (a directional light along its view).
    pub lights: Vec<Light>,
    pub cameras: Vec<Camera>,
    pub animation: Animation,
    /// World-space bounding sphere of all models at rest.
    pub bounds_center: Vec3,
    pub bounds_radius: f32,
    /// Every decoded texture; `Texture::id` indexes this list.
    pub textures: Vec<Arc<crate::assets::texture::Texture>>,
    /// What loading ignored (optional glTF extensions, line primitives...),
    /// for the command line to show.
    pub warnings: Vec<String>,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.models.iter().map(|m| m.mesh.triangles.len()).sum()
    }

    /// The file stem for a camera and frame, from the output name pattern.
    pub fn file_stem(&self, camera: &str, frame: u32) -> String {
        expand_pattern(&self.output.name, &self.stem, camera, frame)
    }
}

/// Expands `{scene}`, `{camera}`, `{frame}` and `{frame:0N}`.
pub fn expand_pattern(pattern: &str, scene: &str, camera: &str, frame: u32) -> String {
    let mut out = String::new();
    let mut rest = pattern;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let Some(close) = rest[open..].find('}') else {
            out.push_str(&rest[open..]);
            return out;
        };
        let field = &rest[open + 1..open + close];
        let (name, fmt) = field.split_once(':').unwrap_or((field, ""));
        match name {
            "scene" => out.push_str(scene),
            "camera" => out.push_str(camera),
            "frame" => {
                let width: usize = fmt.trim_start_matches('0').parse().unwrap_or(0);
                out.push_str(&format!("{frame:0width$}"));
            }
            _ => out.push_str(&rest[open..=open + close]),
        }
        rest = &rest[open + close + 1..];
    }
    out.push_str(rest);
    out
}

/// Fields a pattern may name; anything else is an error at load time.
pub fn check_pattern(pattern: &str) -> Result<(), String> {
    let mut rest = pattern;
    while let Some(open) = rest.find('{') {
        let close = rest[open..]
            .find('}')
            .ok_or_else(|| format!("unclosed `{{` in `{pattern}`"))?;
        let field = &rest[open + 1..open + close];
        let (name, fmt) = field.split_once(':').unwrap_or((field, ""));
        let fmt_ok = fmt.is_empty() || (name == "frame" && fmt.chars().all(|c| c.is_ascii_digit()));
        if !matches!(name, "scene" | "camera" | "frame") || !fmt_ok {
            return Err(format!(
                "unknown field `{{{field}}}` in `{pattern}`: expected {{scene}}, {{camera}}, {{frame}} or {{frame:04}}"
            ));
        }
        rest = &rest[open + close + 1..];
    }
    if pattern.contains('/') || pattern.contains('\\') {
        return Err(format!(
            "`{pattern}` must be a file stem, without directories"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_expand() {
        assert_eq!(
            expand_pattern("{camera}_{frame:04}", "s", "front", 7),
            "front_0007"
        );
        assert_eq!(
            expand_pattern("{scene}-{frame}", "melina", "c", 12),
            "melina-12"
        );
        assert!(check_pattern("{camera}_{frame:04}").is_ok());
        assert!(check_pattern("{cam}").is_err());
        assert!(check_pattern("a/{frame}").is_err());
        assert!(check_pattern("{frame").is_err());
    }
}
