//! Lights as the scene places them: punctual lights in world space, and
//! how a placement moves them. What a light delivers to a shaded point is
//! shading's business (`shade::light`).

use glam::{Mat4, Vec3};

/// What a light is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightKind {
    /// Radiant intensity `intensity` (times `color`) from `position`.
    Point {
        /// Where it stands.
        position: Vec3,
        /// Radiant intensity: irradiance = intensity * cos / r^2.
        intensity: f32,
    },
    /// Irradiance `irradiance` on a surface facing the light; `direction` is
    /// the unit vector the light travels along.
    Directional {
        /// The unit vector the light travels along.
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: f32,
        /// Angular radius of the disc the light comes from, in radians:
        /// 0 (a point) for the scene's and the glTF files' lights, > 0
        /// only for lights taken out of the environment image
        /// (`environment.lights`). Such a light widens highlights, softens
        /// ray-traced shadows, and lights Blinn-Phong surfaces as the
        /// image did (`blinn_phong::image_light`).
        angle: f32,
    },
    /// A point light limited to a cone around `direction` (unit), with the
    /// KHR_lights_punctual smooth falloff between the cone angles.
    Spot {
        /// Where it stands.
        position: Vec3,
        /// The cone's axis, unit, the way the light travels.
        direction: Vec3,
        /// Radiant intensity on the axis.
        intensity: f32,
        /// Cosine of the angle inside which the light is full.
        cos_inner: f32,
        /// Cosine of the angle outside which there is no light.
        cos_outer: f32,
    },
    /// An emissive surface of the scene taken as a light
    /// (`environment.emitters`): from a disc of radius `radius` at
    /// `position`, radiant intensity `along * |cos| + around` towards a
    /// direction at angle cos to `axis` (a flat two-sided emitter of area
    /// A and radiance 1 has along = A, around = 0), times `color`.
    Area {
        /// The centre of the emitting surface.
        position: Vec3,
        /// Unit normal of its main plane (either side).
        axis: Vec3,
        /// Radiant intensity along the axis, less `around`.
        along: f32,
        /// Radiant intensity every way (the share of a surface that is
        /// not flat).
        around: f32,
        /// Radius of the disc of the surface's area: what softens its
        /// ray-traced shadows.
        radius: f32,
    },
}

/// A light of the scene (`[[light]]`, or a glTF file's lights).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Light {
    /// Its kind and geometry.
    pub kind: LightKind,
    /// Linear RGB colour multiplying its intensity.
    pub color: Vec3,
    /// Whether it casts shadows (`render.shadows` says how).
    pub shadows: bool,
    /// Point and spot: distance beyond which the light has no effect, with
    /// the KHR_lights_punctual smooth window clamp(1 - (r/range)^4, 0, 1)^2
    /// on the inverse square law. None: unlimited.
    pub range: Option<f32>,
}

impl Light {
    /// Whether it is a directional light.
    pub fn kind_is_directional(&self) -> bool {
        matches!(self.kind, LightKind::Directional { .. })
    }

    /// A point or spot light's position, or `otherwise`.
    pub fn position_or(&self, otherwise: Vec3) -> Vec3 {
        match self.kind {
            LightKind::Point { position, .. }
            | LightKind::Spot { position, .. }
            | LightKind::Area { position, .. } => position,
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
                angle,
            } => LightKind::Directional {
                direction: dir(direction),
                irradiance,
                angle,
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
            LightKind::Area {
                position,
                axis,
                along,
                around,
                radius,
            } => LightKind::Area {
                position: m.transform_point3(position),
                axis: dir(axis),
                along,
                around,
                radius,
            },
        };
        Light { kind, ..*self }
    }
}
