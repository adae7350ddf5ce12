//! Lights as the scene places them: punctual lights in world space, and
//! how a placement moves them. What a light delivers to a shaded point is
//! shading's business (`shade::light`).

use glam::{Mat4, Vec3};

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightKind {
    /// Radiant intensity `intensity` (times `color`) from `position`.
    Point { position: Vec3, intensity: f32 },
    /// Irradiance `irradiance` on a surface facing the light; `direction` is
    /// the unit vector the light travels along.
    Directional { direction: Vec3, irradiance: f32 },
    /// A point light limited to a cone around `direction` (unit), with the
    /// KHR_lights_punctual smooth falloff between the cone angles.
    Spot {
        position: Vec3,
        direction: Vec3,
        intensity: f32,
        cos_inner: f32,
        cos_outer: f32,
    },
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    pub color: Vec3,
    pub shadows: bool,
    /// Point and spot: distance beyond which the light has no effect, with
    /// the KHR_lights_punctual smooth window clamp(1 - (r/range)^4, 0, 1)^2
    /// on the inverse square law. None: unlimited.
    pub range: Option<f32>,
}

impl Light {
    pub fn kind_is_directional(&self) -> bool {
        matches!(self.kind, LightKind::Directional { .. })
    }

    /// A point or spot light's position, or `otherwise`.
    pub fn position_or(&self, otherwise: Vec3) -> Vec3 {
        match self.kind {
            LightKind::Point { position, .. } | LightKind::Spot { position, .. } => position,
            LightKind::Directional { .. } => otherwise,
        }
    }

    /// The light moved by `m` (positions as points, directions as unit
    /// vectors; intensities unchanged).
    pub fn transformed(&self, m: Mat4) -> Light {
        let dir = |d: Vec3| m.transform_vector3(d).try_normalize().unwrap_or(d);
        let kind = match self.kind {
            LightKind::Directional {
                direction,
                irradiance,
            } => LightKind::Directional {
                direction: dir(direction),
                irradiance,
            },
            LightKind::Point {
                position,
                intensity,
            } => LightKind::Point {
                position: m.transform_point3(position),
                intensity,
            },
            LightKind::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
            } => LightKind::Spot {
                position: m.transform_point3(position),
                direction: dir(direction),
                intensity,
                cos_inner,
                cos_outer,
            },
        };
        Light { kind, ..*self }
    }
}
