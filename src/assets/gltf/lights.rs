//! KHR_lights_punctual lights and glTF cameras, placed by their nodes.

use super::*;

/// A KHR_lights_punctual light placed by its node (in the file's space).
#[derive(Debug, Clone)]
pub struct GltfLight {
    pub kind: GltfLightKind,
    /// Linear RGB.
    pub color: Vec3,
    /// Candela (point, spot) or lux (directional).
    pub intensity: f32,
    /// Point and spot: the distance where the light ends (None: unlimited).
    pub range: Option<f32>,
    pub position: Vec3,
    /// Unit direction the light travels along (the node's -Z).
    pub direction: Vec3,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GltfLightKind {
    Directional,
    Point,
    /// Cone angles in radians from the axis.
    Spot {
        inner_cone_angle: f32,
        outer_cone_angle: f32,
    },
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GltfProjection {
    /// Vertical field of view in degrees.
    Perspective { fov_y: f32 },
    /// Full height of the view volume.
    Orthographic { height: f32 },
}

/// A camera placed by its node: it looks down the node's -Z, up +Y.
#[derive(Debug, Clone)]
pub struct GltfCamera {
    pub name: String,
    pub eye: Vec3,
    pub forward: Vec3,
    pub up: Vec3,
    pub projection: GltfProjection,
    pub near: f32,
    /// None: infinite (perspective without zfar).
    pub far: Option<f32>,
}

impl GltfLight {
    /// The light at a node whose world transform is `world`: at its
    /// origin, shining down its -Z.
    pub fn placed(&self, world: Mat4) -> GltfLight {
        GltfLight {
            position: world.transform_point3(Vec3::ZERO),
            direction: world
                .transform_vector3(Vec3::NEG_Z)
                .try_normalize()
                .unwrap_or(Vec3::NEG_Z),
            ..self.clone()
        }
    }
}

pub(super) fn light(l: &gltf::khr_lights_punctual::Light, world: Mat4) -> GltfLight {
    use gltf::khr_lights_punctual::Kind;
    GltfLight {
        kind: match l.kind() {
            Kind::Directional => GltfLightKind::Directional,
            Kind::Point => GltfLightKind::Point,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => GltfLightKind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            },
        },
        color: Vec3::from(l.color()),
        intensity: l.intensity(),
        range: l.range(),
        position: Vec3::ZERO,
        direction: Vec3::NEG_Z,
    }
    .placed(world)
}

pub(super) fn camera(c: &gltf::Camera, node: &gltf::Node, world: Mat4, n: usize) -> GltfCamera {
    let eye = world.transform_point3(Vec3::ZERO);
    let forward = world
        .transform_vector3(Vec3::NEG_Z)
        .try_normalize()
        .unwrap_or(Vec3::NEG_Z);
    let up = world
        .transform_vector3(Vec3::Y)
        .try_normalize()
        .unwrap_or(Vec3::Y);
    let (projection, near, far) = match c.projection() {
        gltf::camera::Projection::Perspective(p) => (
            GltfProjection::Perspective {
                fov_y: p.yfov().to_degrees(),
            },
            p.znear(),
            p.zfar(),
        ),
        gltf::camera::Projection::Orthographic(o) => (
            GltfProjection::Orthographic {
                height: 2.0 * o.ymag().abs(),
            },
            o.znear(),
            Some(o.zfar()),
        ),
    };
    GltfCamera {
        name: c
            .name()
            .or(node.name())
            .map(str::to_string)
            .unwrap_or_else(|| format!("gltf_camera{n}")),
        eye,
        forward,
        up,
        projection,
        near,
        far,
    }
}
