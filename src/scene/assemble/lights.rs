//! `[[light]]` tables and the lights of glTF files (`model.lights = true`)
//! to `Light`: the file's lights first, in file order, then each model's
//! imported ones placed with the model.

use glam::{Mat4, Vec3};

use super::get;
use crate::assets::gltf::{GltfLight, GltfLightKind};
use crate::scene::desc;
use crate::scene::light::{Light, LightKind};

/// Defaults: a point light at the origin of intensity 10, white; a
/// directional light of irradiance 1 travelling down -Y; spot cones of 20
/// and 30 degrees; no shadows; no range.
pub(super) fn from_desc(l: &desc::LightDesc) -> Light {
    let color = Vec3::from(get(&l.color, [1.0; 3]));
    let position = Vec3::from(get(&l.position, [0.0; 3]));
    let direction = Vec3::from(get(&l.direction, [0.0, -1.0, 0.0])).normalize();
    let intensity = get(&l.intensity, 10.0);
    let kind = match l.kind.as_ref().map(|k| *k.get_ref()) {
        None | Some(desc::LightKind::Point) => LightKind::Point {
            position,
            intensity,
        },
        Some(desc::LightKind::Directional) => LightKind::Directional {
            direction,
            irradiance: get(&l.irradiance, 1.0),
            angle: 0.0,
        },
        Some(desc::LightKind::Spot) => LightKind::Spot {
            position,
            direction,
            intensity,
            cos_inner: get(&l.inner_angle, 20.0).to_radians().cos(),
            cos_outer: get(&l.outer_angle, 30.0).to_radians().cos(),
        },
    };
    Light {
        kind,
        color,
        shadows: get(&l.shadows, false),
        range: l.range.as_ref().map(|r| *r.get_ref()),
    }
}

/// A glTF light placed by `world_from_file` (the model's placement).
/// KHR_lights_punctual's intensities are candela and lux, which are the
/// radiometric intensity and irradiance here; lights cast no shadows.
pub(super) fn from_gltf(g: &GltfLight, world_from_file: Mat4) -> Light {
    let (position, direction, intensity) = (g.position, g.direction, g.intensity);
    let kind = match g.kind {
        GltfLightKind::Directional => LightKind::Directional {
            direction,
            irradiance: intensity,
            angle: 0.0,
        },
        GltfLightKind::Point => LightKind::Point {
            position,
            intensity,
        },
        GltfLightKind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => LightKind::Spot {
            position,
            direction,
            intensity,
            cos_inner: inner_cone_angle.cos(),
            cos_outer: outer_cone_angle.cos(),
        },
    };
    Light {
        kind,
        color: g.color,
        shadows: false,
        range: g.range,
    }
    .transformed(world_from_file)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn light_defaults() {
        let d = desc::SceneDesc::parse(
            Path::new("s.toml"),
            "[[model]]\npath = \"m.obj\"\n[[light]]\n[[light]]\nkind = \"directional\"\n\
             [[light]]\nkind = \"spot\"\n",
        )
        .unwrap();
        let l: Vec<Light> = d.lights.iter().map(|l| from_desc(l.get_ref())).collect();
        assert_eq!(
            l[0].kind,
            LightKind::Point {
                position: Vec3::ZERO,
                intensity: 10.0
            }
        );
        assert_eq!(
            l[1].kind,
            LightKind::Directional {
                direction: -Vec3::Y,
                irradiance: 1.0,
                angle: 0.0,
            }
        );
        let LightKind::Spot {
            cos_inner,
            cos_outer,
            ..
        } = l[2].kind
        else {
            panic!("{:?}", l[2].kind)
        };
        assert!((cos_inner - 20f32.to_radians().cos()).abs() < 1e-6);
        assert!((cos_outer - 30f32.to_radians().cos()).abs() < 1e-6);
        assert!(
            l.iter()
                .all(|l| !l.shadows && l.color == Vec3::ONE && l.range.is_none())
        );
    }

    #[test]
    fn gltf_lights_follow_their_model() {
        let g = GltfLight {
            kind: GltfLightKind::Point,
            color: Vec3::ONE,
            intensity: 5.0,
            range: Some(3.0),
            position: Vec3::X,
            direction: Vec3::NEG_Z,
        };
        let l = from_gltf(&g, Mat4::from_translation(Vec3::Y));
        assert_eq!(
            l.kind,
            LightKind::Point {
                position: Vec3::new(1.0, 1.0, 0.0),
                intensity: 5.0
            }
        );
        assert_eq!(l.range, Some(3.0));
    }
}
