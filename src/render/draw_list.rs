//! The draw list of one frame: the camera and the models where the
//! animation puts them at this frame (turned, and posed by their glTF
//! clips), the lights in world space (a headlight when the scene has none;
//! lights of animated glTF nodes where their node is), and
//! clip-from-world.

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use crate::assets::rig::{Parts, Posed};
use crate::scene::Scene;
use crate::scene::camera::Camera;
use crate::scene::light::{Light, LightKind};

/// Everything placed where it is at one frame.
pub struct DrawList<'a> {
    /// The scene drawn.
    pub scene: &'a Scene,
    /// The camera as it stands at this frame (path, turntable).
    pub camera: Camera,
    /// Per model, this frame's placement.
    pub world_from_object: Vec<Mat4>,
    /// Per model that plays a clip: its vertices posed for this frame, and
    /// the clip time they are posed at.
    pub posed: Vec<Option<(Posed, f32)>>,
    /// The lights as they stand at this frame.
    pub lights: Vec<Light>,
    /// The camera's projection times its view.
    pub clip_from_world: Mat4,
}

impl<'a> DrawList<'a> {
    /// The draw list of frame `frame` seen by camera `camera` (an index
    /// the caller has checked: `Renderer::render` does).
    pub fn new(scene: &'a Scene, camera: usize, frame: u32) -> DrawList<'a> {
        let turn = scene.animation.turn(frame);
        let mut cam = scene.cameras[camera].at_frame(frame);
        if scene.animation.rotates_camera() {
            cam.eye = turn.transform_point3(cam.eye);
            cam.target = turn.transform_point3(cam.target);
            cam.up = turn.transform_vector3(cam.up);
        }
        let world_from_object: Vec<Mat4> = scene
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
        let time = scene.animation.time(frame);
        let nodes: Vec<_> = scene
            .models
            .par_iter()
            .map(|m| m.playback.as_ref().map(|p| p.nodes_at(time)))
            .collect();
        let posed = scene
            .models
            .iter()
            .zip(&nodes)
            .map(|(m, n)| {
                let (p, n) = (m.playback.as_ref()?, n.as_ref()?);
                let mut posed = p.rig.place(n, &m.mesh, &p.tangents, Parts::All);
                keep_in_range(&mut posed, &m.mesh.positions, &m.mesh.normals);
                Some((posed, p.clip.local_time(time)))
            })
            .collect();
        let mut lights = if scene.lights.is_empty() && scene.environment.is_none() {
            // Headlight: a directional light travelling along the view.
            vec![Light {
                kind: LightKind::Directional {
                    direction: cam.forward(),
                    irradiance: 1.0,
                    angle: 0.0,
                },
                color: Vec3::ONE,
                shadows: false,
                range: None,
            }]
        } else {
            let mut lights = scene.lights.clone();
            for nl in &scene.node_lights {
                if let (Some(Some(n)), Some(l)) = (nodes.get(nl.model), lights.get_mut(nl.light)) {
                    let node = n.worlds.get(nl.node).copied().unwrap_or(Mat4::IDENTITY);
                    let placed = nl
                        .local
                        .transformed(scene.models[nl.model].world_from_object * node);
                    if placed_ok(&placed) {
                        *l = placed;
                    }
                }
            }
            lights
        };
        // The emissive pieces' area lights, placed with their models.
        lights.extend(
            scene
                .emitters
                .iter()
                .map(|p| p.light(world_from_object[p.model]))
                .filter(placed_ok),
        );
        let s = &scene.settings;
        let aspect = s.width as f32 / s.height as f32;
        let clip_from_world = cam.clip_from_view(aspect, s.depth) * cam.view_from_world();
        DrawList {
            scene,
            camera: cam,
            world_from_object,
            posed,
            lights,
            clip_from_world,
        }
    }
}

/// Largest coordinate a pose may give (as the loader's bound).
const MAX_COORDINATE: f32 = 1e18;

/// Vertices a pose throws out of range (non-finite, or beyond the
/// loader's bound) stay where the mesh has them at rest.
fn keep_in_range(posed: &mut Posed, rest: &[Vec3], rest_normals: &[Vec3]) {
    for (i, p) in posed.positions.iter_mut().enumerate() {
        if !(p.is_finite() && p.abs().max_element() <= MAX_COORDINATE) {
            *p = rest[i];
            if let (Some(n), Some(r)) = (posed.normals.get_mut(i), rest_normals.get(i)) {
                *n = *r;
            }
        }
    }
}

/// Whether a light a node places is usable (finite position and direction).
fn placed_ok(l: &Light) -> bool {
    match l.kind {
        LightKind::Point { position, .. } => position.is_finite(),
        LightKind::Area { position, axis, .. } => position.is_finite() && axis.is_finite(),
        LightKind::Directional { direction, .. } => direction.is_finite(),
        LightKind::Spot {
            position,
            direction,
            ..
        } => position.is_finite() && direction.is_finite(),
    }
}
