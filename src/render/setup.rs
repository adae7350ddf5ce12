//! The draw list of one frame: the camera and the models where the
//! animation puts them at this frame, the lights in world space (a
//! headlight when the scene has none), and clip-from-world.

use glam::{Mat4, Vec3};

use crate::scene::Scene;
use crate::scene::camera::Camera;
use crate::scene::light::{Light, LightKind};

/// Everything placed where it is at one frame.
pub struct FrameSetup<'a> {
    pub scene: &'a Scene,
    pub camera: Camera,
    /// Per model, this frame's placement.
    pub world_from_object: Vec<Mat4>,
    pub lights: Vec<Light>,
    pub clip_from_world: Mat4,
}

impl<'a> FrameSetup<'a> {
    pub fn new(scene: &'a Scene, camera: usize, frame: u32) -> FrameSetup<'a> {
        let turn = scene.animation.turn(frame);
        let mut cam = scene.cameras[camera].at_frame(frame);
        if scene.animation.rotates_camera() {
            cam.eye = turn.transform_point3(cam.eye);
            cam.target = turn.transform_point3(cam.target);
            cam.up = turn.transform_vector3(cam.up);
        }
        let world_from_object = scene
            .models
            .iter()
            .map(|m| {
                if scene.animation.rotates_models() {
                    turn * m.world_from_object
                } else {
                    m.world_from_object
                }
            })
            .collect();
        let lights = if scene.lights.is_empty() && scene.environment.is_none() {
            // Headlight: a directional light travelling along the view.
            vec![Light {
                kind: LightKind::Directional {
                    direction: cam.forward(),
                    irradiance: 1.0,
                },
                color: Vec3::ONE,
                shadows: false,
                range: None,
            }]
        } else {
            scene.lights.clone()
        };
        let s = &scene.settings;
        let aspect = s.width as f32 / s.height as f32;
        let clip_from_world = cam.clip_from_view(aspect, s.depth) * cam.view_from_world();
        FrameSetup {
            scene,
            camera: cam,
            world_from_object,
            lights,
            clip_from_world,
        }
    }
}
