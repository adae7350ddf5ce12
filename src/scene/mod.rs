//! The loaded scene: what a scene file describes, with its assets loaded
//! and every default filled in. `desc` is the file's shape (serde structs
//! with spans, for errors), `overrides` edits the text for `--set`, `build`
//! turns a `desc` into a `Scene` (the defaults live there), and the rest
//! are the runtime types the renderer reads: `settings`, `camera`,
//! `light`, `material`, `animation`. Nothing here knows how a frame is
//! rendered, and the renderer never writes into a `Scene`.

pub mod animation;
pub mod assemble;
pub mod camera;
mod desc;
pub mod emitters;
pub mod environment;
pub mod light;
pub mod material;
pub mod overrides;
pub mod settings;

use std::path::PathBuf;
use std::sync::Arc;

use glam::{Mat4, Vec3};

use crate::assets::mesh::Mesh;
pub use animation::Animation;
pub use assemble::LoadOptions;
pub use camera::Camera;
pub use desc::parse_size;
pub use light::Light;
pub use material::Material;
pub use settings::{AoSettings, OutputSettings, RenderSettings, ShadowBias};

/// A model of the scene: its mesh, materials and placement.
#[derive(Debug, Clone)]
pub struct Model {
    /// `[[model]] name`, else the file's stem.
    pub name: String,
    /// Its mesh (models may share one).
    pub mesh: Arc<Mesh>,
    /// Its materials; the mesh's groups index them.
    pub materials: Vec<Material>,
    /// Placement at rest (before any turntable turn).
    pub world_from_object: Mat4,
    /// Every edge shared by exactly two faces in opposite directions
    /// (`Mesh::is_closed`): `render.cull = "auto"` culls its back faces.
    pub closed: bool,
    /// `model.animation`: the glTF clip it plays.
    pub playback: Option<Arc<animation::Playback>>,
    /// With a clip: a sample of the (object-space) points its vertices
    /// reach over the frames, the extremes along each axis included, for
    /// bounds and framing.
    pub motion_points: Vec<Vec3>,
}

impl Model {
    /// Ids the object-id pass gives the model: one per mesh part (glTF
    /// nodes), at least one.
    pub fn object_count(&self) -> u32 {
        self.mesh.parts.len().max(1) as u32
    }

    /// The object-id pass's names of the model's parts: the model's name,
    /// and `name/part` per part where the mesh has parts.
    pub fn object_names(&self) -> Vec<String> {
        if self.mesh.parts.is_empty() {
            return vec![self.name.clone()];
        }
        self.mesh
            .parts
            .iter()
            .map(|p| format!("{}/{p}", self.name))
            .collect()
    }

    /// Every point the model's vertices take (object space): at rest, and
    /// over its clip.
    pub fn reach(&self) -> impl Iterator<Item = &Vec3> {
        self.mesh.positions.iter().chain(&self.motion_points)
    }
}

/// A loaded scene: models with their meshes, materials and textures,
/// lights, cameras, environment and settings. Load one with `Scene::load`
/// (a scene file or a model file) or `Scene::from_text`, then render it with
/// `render::Renderer`.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The scene file (a model file's path for a one-line scene).
    pub file: PathBuf,
    /// The scene file's stem, for `{scene}` and the default output dir.
    pub stem: String,
    /// How frames are rendered (`[render]`, the output size).
    pub settings: RenderSettings,
    /// What files each frame writes (`[output]`).
    pub output: OutputSettings,
    /// The models, in the file's order.
    pub models: Vec<Model>,
    /// Empty, and no environment (a model imported no lights it asked
    /// for): every camera gets a headlight (a directional light along its
    /// view). A scene that names no light gets the studio environment.
    pub lights: Vec<Light>,
    /// Lights that follow the animated nodes of their glTF file.
    pub node_lights: Vec<animation::NodeLight>,
    /// Image-based lighting (`[environment]`).
    pub environment: Option<environment::Environment>,
    /// The emissive pieces that light the scene as area lights
    /// (`environment.emitters`; `DrawList` places them each frame).
    pub emitters: Vec<emitters::Patch>,
    /// The shadow catcher under the models (`[ground] shadow = true`).
    pub ground: Option<GroundPlane>,
    /// The cameras, in the file's order (a fitted camera when none is
    /// given).
    pub cameras: Vec<Camera>,
    /// `[animation]`.
    pub animation: Animation,
    /// World-space bounding sphere of all models at rest.
    pub bounds_center: Vec3,
    /// The bounding sphere's radius.
    pub bounds_radius: f32,
    /// Every decoded texture; `Texture::id` indexes this list.
    pub textures: Vec<Arc<crate::assets::texture::Texture>>,
    /// What loading ignored (optional glTF extensions, line primitives...),
    /// for the command line to show.
    pub warnings: Vec<String>,
}

/// The plane of the ground shadow catcher: horizontal (+Y up) at the
/// models' lowest point at rest, around their center.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundPlane {
    /// Its height (y).
    pub height: f32,
    /// The models' center at rest (the catcher's middle).
    pub center: Vec3,
    /// The models' bounding radius: the catcher fades out between 2 and 3
    /// of them from the center.
    pub radius: f32,
}

impl Scene {
    /// Triangles over every model.
    pub fn triangle_count(&self) -> usize {
        self.models.iter().map(|m| m.mesh.triangles.len()).sum()
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
                // check_pattern refuses wider fields; the cap keeps
                // `format!` in range whatever it is handed.
                let width: usize = fmt.trim_start_matches('0').parse().unwrap_or(0).min(9);
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
        if name == "frame" && fmt.len() > 1 {
            let width: usize = fmt.trim_start_matches('0').parse().unwrap_or(usize::MAX);
            if width > 9 {
                return Err(format!(
                    "`{{{field}}}` in `{pattern}`: a frame number has at most 9 digits (u32); use a width of 1 to 9, e.g. {{frame:04}}"
                ));
            }
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
        assert!(check_pattern("{frame:09}").is_ok());
        assert!(check_pattern("{frame:010}").is_err());
        assert!(check_pattern("{frame:070000}").is_err());
        assert!(check_pattern("{frame:0999999999999999999999}").is_err());
        assert_eq!(expand_pattern("{frame:070000}", "s", "c", 7), "000000007");
    }
}
