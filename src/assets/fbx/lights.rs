//! An FBX file's lights and cameras as glTF's (`model.lights`,
//! `model.cameras`), placed by their nodes in Y-up metres.
//!
//! FBX lights carry no physical unit: the intensity ufbx reports is taken
//! as candela for point and spot lights and as lux for directional ones.
//! (Blender's exporter writes a 1000 W point light as 1000; its glTF
//! exporter writes the same light as 54,351 cd, P / 4 pi x 683.) Spot cones: the file's inner and outer angles are full
//! angles; glTF's are half. Area and volume lights are left out, with a
//! warning. Cameras look along their node's +X with +Y up (FBX's
//! convention), with the file's vertical field of view.

use glam::Vec3;

use super::{matrix, vec3};
use crate::assets::gltf::{GltfCamera, GltfLight, GltfLightKind, GltfProjection};

/// The lights of `scene`, placed; a warning for each that is left out.
pub(super) fn lights(scene: &ufbx::Scene, warnings: &mut Vec<String>) -> Vec<GltfLight> {
    let mut out = Vec::new();
    for node in scene.nodes.iter() {
        let Some(l) = &node.light else { continue };
        let kind = match l.type_ {
            ufbx::LightType::Point => GltfLightKind::Point,
            ufbx::LightType::Directional => GltfLightKind::Directional,
            ufbx::LightType::Spot => {
                let outer = (l.outer_angle as f32 * 0.5).to_radians();
                let inner = (l.inner_angle as f32 * 0.5).to_radians().min(outer);
                GltfLightKind::Spot {
                    inner_cone_angle: inner.max(0.0),
                    outer_cone_angle: outer.clamp(1e-4, std::f32::consts::FRAC_PI_2),
                }
            }
            other => {
                warnings.push(format!(
                    "light {}: {other:?} lights are not read",
                    node.element.name
                ));
                continue;
            }
        };
        let world = matrix(&node.node_to_world);
        let color = vec3(&l.color);
        let intensity = l.intensity as f32;
        if !color.is_finite() || !intensity.is_finite() || intensity < 0.0 {
            warnings.push(format!(
                "light {}: its colour or intensity is not a number; it is left out",
                node.element.name
            ));
            continue;
        }
        out.push(GltfLight {
            kind,
            color,
            intensity,
            range: None,
            position: world.transform_point3(Vec3::ZERO),
            direction: world
                .transform_vector3(vec3(&l.local_direction))
                .try_normalize()
                .unwrap_or(Vec3::NEG_Y),
        });
    }
    out
}

/// The cameras of `scene`, placed.
pub(super) fn cameras(scene: &ufbx::Scene) -> Vec<GltfCamera> {
    let mut out = Vec::new();
    for node in scene.nodes.iter() {
        let Some(c) = &node.camera else { continue };
        let world = matrix(&node.node_to_world);
        // FBX cameras look along their node's +X, up its +Y.
        let dir = |v: Vec3, fallback: Vec3| {
            world
                .transform_vector3(v)
                .try_normalize()
                .unwrap_or(fallback)
        };
        let forward = dir(Vec3::X, Vec3::NEG_Z);
        let up = dir(Vec3::Y, Vec3::Y);
        let projection = match c.projection_mode {
            ufbx::ProjectionMode::Orthographic => GltfProjection::Orthographic {
                height: (c.orthographic_size.y as f32).max(1e-6),
            },
            ufbx::ProjectionMode::Perspective => GltfProjection::Perspective {
                fov_y: (c.field_of_view_deg.y as f32).clamp(0.1, 179.0),
            },
        };
        let finite = |v: f64| (v.is_finite() && v > 0.0).then_some(v as f32);
        out.push(GltfCamera {
            name: node.element.name.to_string(),
            eye: world.transform_point3(Vec3::ZERO),
            forward,
            up,
            projection,
            near: finite(c.near_plane).unwrap_or(0.01),
            far: finite(c.far_plane),
        });
    }
    out
}
