//! The turntable: frame i turns by i * degrees / frames about an axis through
//! the models' bounding-box center, so the last frame is one step short of the
//! first and the loop is seamless. And glTF clips played on a model
//! (`Playback`): frame i poses it at time i / fps of the clip, which loops.

use std::sync::Arc;

use glam::{Mat4, Quat, Vec3, Vec4};

use crate::assets::keyframes::Clip;
use crate::assets::mesh::Mesh;
use crate::assets::rig::{NodePose, Parts, Posed, Rig};
use crate::scene::light::Light;

/// A glTF clip played on one model.
#[derive(Debug)]
pub struct Playback {
    /// The file's nodes and skins.
    pub rig: Arc<Rig>,
    /// The clip played.
    pub clip: Clip,
    /// The clip's index in the file.
    pub index: usize,
    /// The model's per-corner tangents in source space (`Rig::source_tangents`).
    pub tangents: Vec<Vec4>,
}

impl Playback {
    /// The file's nodes at animation time `t` seconds.
    pub fn nodes_at(&self, t: f64) -> NodePose {
        self.rig
            .node_pose(Some((&self.clip, self.clip.local_time(t))))
    }

    /// The model's mesh as the clip poses it at animation time `t`.
    pub fn pose(&self, mesh: &Mesh, t: f64, parts: Parts) -> Posed {
        self.rig
            .place(&self.nodes_at(t), mesh, &self.tangents, parts)
    }
}

/// A light of a glTF file (`model.lights = true`) whose model plays a
/// clip: it follows its node.
#[derive(Debug, Clone)]
pub struct NodeLight {
    /// Index in `Scene::lights`.
    pub light: usize,
    /// The model whose file holds the light (index in `Scene::models`).
    pub model: usize,
    /// The node the light hangs on, in its file.
    pub node: usize,
    /// The light in its node's space (at the origin, shining down -Z).
    pub local: Light,
}

/// What a turntable turns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TurntableTarget {
    /// The models, about the pivot; camera and lights stay.
    #[default]
    Models,
    /// The cameras, about the pivot; models and lights stay.
    Camera,
}

/// `[animation] turntable`: the turn spread over the frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Turntable {
    /// The axis of the turn, unit (default +Y).
    pub axis: Vec3,
    /// The whole turn in degrees over the animation (default 360); frame i
    /// turns by i * degrees / frames, so a loop is seamless.
    pub degrees: f32,
    /// What turns.
    pub rotate: TurntableTarget,
    /// Degrees above the plane of the turn the cameras look from (their
    /// orbit is a cone); None leaves them where they are.
    pub elevation: Option<f32>,
}

/// `[animation]`: frames, their rate and the turntable.
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    /// Frames in the animation (default 1).
    pub frames: u32,
    /// Frame i is at time i / fps seconds.
    pub fps: f32,
    /// None: nothing turns.
    pub turntable: Option<Turntable>,
    /// Bounding-box center of all models at rest (the turntable's pivot).
    pub pivot: Vec3,
}

impl Animation {
    /// The rigid turn of frame `i` about the pivot (identity without turntable).
    pub fn turn(&self, frame: u32) -> Mat4 {
        match &self.turntable {
            None => Mat4::IDENTITY,
            Some(t) => {
                let angle = (frame as f64 * t.degrees as f64 / self.frames as f64).to_radians();
                Mat4::from_translation(self.pivot)
                    * Mat4::from_quat(Quat::from_axis_angle(t.axis, angle as f32))
                    * Mat4::from_translation(-self.pivot)
            }
        }
    }

    /// `eye` moved on its sphere about the pivot to `degrees` above the
    /// plane of the turn (keeping its distance and its direction about the
    /// axis). An eye on the axis stays.
    pub fn raise(&self, eye: Vec3, degrees: f32) -> Vec3 {
        let Some(t) = &self.turntable else {
            return eye;
        };
        let d = eye - self.pivot;
        let radial = d - t.axis * d.dot(t.axis);
        let Some(out) = radial.try_normalize() else {
            return eye;
        };
        let e = degrees.to_radians();
        self.pivot + (out * e.cos() + t.axis * e.sin()) * d.length()
    }

    /// Frame `frame`'s time in seconds.
    pub fn time(&self, frame: u32) -> f64 {
        frame as f64 / self.fps as f64
    }

    /// Whether a turntable turns the models.
    pub fn rotates_models(&self) -> bool {
        matches!(&self.turntable, Some(t) if t.rotate == TurntableTarget::Models)
    }

    /// Whether a turntable turns the cameras.
    pub fn rotates_camera(&self) -> bool {
        matches!(&self.turntable, Some(t) if t.rotate == TurntableTarget::Camera)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seventy_two_frames_step_five_degrees_and_never_repeat_frame_zero() {
        let a = Animation {
            frames: 72,
            turntable: Some(Turntable {
                axis: Vec3::Y,
                degrees: 360.0,
                rotate: TurntableTarget::Models,
                elevation: None,
            }),
            fps: 24.0,
            pivot: Vec3::new(1.0, 0.0, 0.0),
        };
        let p = Vec3::new(2.0, 0.0, 0.0);
        let q = a.turn(18).transform_point3(p);
        // 90 degrees about +Y around (1,0,0): (2,0,0) -> (1,0,-1)
        assert!((q - Vec3::new(1.0, 0.0, -1.0)).length() < 1e-5, "{q}");
        let last = a.turn(71).transform_point3(p);
        assert!((last - p).length() > 1e-3);
        assert!(a.turn(0).abs_diff_eq(Mat4::IDENTITY, 1e-7));
        // Raised 30 degrees: same distance, 30 degrees above the plane.
        let eye = Vec3::new(1.0, 0.0, 4.0);
        let up = a.raise(eye, 30.0);
        let d = up - a.pivot;
        assert!((d.length() - 4.0).abs() < 1e-5);
        assert!((d.y / d.length() - 0.5).abs() < 1e-6, "{up}");
        assert!(d.x.abs() < 1e-6 && d.z > 0.0);
    }
}
