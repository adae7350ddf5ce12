//! Cameras: placement, projection, and the matrices named `a_from_b`.
//!
//! Clip space is Direct3D/Vulkan style: x and y in [-w, w], z in [0, w].
//! Reverse-Z maps the near plane to depth 1 and the far plane to 0 (the
//! floating-point precision then follows the perspective division), standard
//! maps near to 0 and far to 1.

use glam::{Mat4, Vec3, Vec4};

use crate::raster::DepthMode;

/// How a camera projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// A pinhole camera.
    Perspective {
        /// Vertical field of view in degrees.
        fov_y: f32,
    },
    /// Parallel rays.
    Orthographic {
        /// Height of the view volume in world units.
        height: f32,
    },
}

/// A camera as loaded: where it stands at rest, and its path if it has keys.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Its name (unique in the scene; output file names use it).
    pub name: String,
    /// Where it stands.
    pub eye: Vec3,
    /// Where it looks.
    pub target: Vec3,
    /// Which way is up (need not be orthogonal to the view).
    pub up: Vec3,
    /// Perspective or orthographic.
    pub projection: Projection,
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (> near).
    pub far: f32,
    /// Keys the camera follows over the animation (`[[camera.keys]]`).
    pub path: Option<std::sync::Arc<CameraPath>>,
}

impl Camera {
    /// The camera at `frame`: itself, or where its path puts it.
    pub fn at_frame(&self, frame: u32) -> Camera {
        match &self.path {
            Some(p) => p.at(self, frame),
            None => self.clone(),
        }
    }

    /// The camera that frames a bounding sphere from +Z (the default camera).
    /// Distance so that the sphere fills the vertical field of view; near and
    /// far leave room for the sphere (and anything turning inside it).
    pub fn framing(name: String, center: Vec3, radius: f32, fov_y: f32) -> Camera {
        let radius = radius.max(1e-6);
        let dist = radius / (fov_y.to_radians() * 0.5).sin();
        let eye = center + Vec3::new(0.0, 0.0, dist);
        let (near, far) = fitted_planes(dist, radius);
        Camera {
            name,
            eye,
            target: center,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y },
            near,
            far,
            path: None,
        }
    }

    /// The camera that fits `points` tightly: it looks at them from
    /// direction `toward_eye` (unit, from the points to the eye), up +Y
    /// (or -Z when looking straight down), with the points' projection
    /// filling `fill` (0.95: a 5% margin) of the frame's width or height at
    /// aspect `aspect` and centred on it. Perspective cameras move as close
    /// as that allows; orthographic ones set their height. Near and far
    /// planes bracket the points' depths.
    pub fn fitted(
        name: String,
        points: &[Vec3],
        toward_eye: Vec3,
        projection: Projection,
        aspect: f32,
        fill: f32,
    ) -> Camera {
        let back = toward_eye.normalize_or(Vec3::Z);
        let up0 = if back.cross(Vec3::Y).length() < 1e-3 {
            -Vec3::Z
        } else {
            Vec3::Y
        };
        let right = up0.cross(back).normalize();
        let up = back.cross(right);
        // Coordinates in the camera's basis; z grows toward the eye.
        let coords = points
            .iter()
            .map(|p| (p.dot(right), p.dot(up), p.dot(back)));
        let (ex, ey, ez, projection) = match projection {
            Projection::Perspective { fov_y } => {
                let ty = (fov_y.to_radians() * 0.5).tan() * fill;
                let tx = ty * aspect;
                // Each side: the eye must satisfy |x - ex| <= t (ez - z).
                let (mut a_pos, mut a_neg, mut b_pos, mut b_neg) =
                    (f32::MIN, f32::MIN, f32::MIN, f32::MIN);
                for (x, y, z) in coords {
                    a_pos = a_pos.max(x + tx * z);
                    a_neg = a_neg.max(-x + tx * z);
                    b_pos = b_pos.max(y + ty * z);
                    b_neg = b_neg.max(-y + ty * z);
                }
                let ez = ((a_pos + a_neg) / (2.0 * tx)).max((b_pos + b_neg) / (2.0 * ty));
                (
                    (a_pos - a_neg) * 0.5,
                    (b_pos - b_neg) * 0.5,
                    ez,
                    Projection::Perspective { fov_y },
                )
            }
            Projection::Orthographic { .. } => {
                let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
                for (x, y, z) in coords {
                    lo = lo.min(Vec3::new(x, y, z));
                    hi = hi.max(Vec3::new(x, y, z));
                }
                let ext = (hi - lo).max(Vec3::splat(1e-6));
                let height = (ext.y.max(ext.x / aspect) / fill).max(1e-6);
                let ez = hi.z + ext.length().max(1e-3);
                (
                    (lo.x + hi.x) * 0.5,
                    (lo.y + hi.y) * 0.5,
                    ez,
                    Projection::Orthographic { height },
                )
            }
        };
        let eye = right * ex + up * ey + back * ez;
        let (mut near, mut far) = (f32::MAX, 0.0f32);
        for p in points {
            let d = (eye - *p).dot(back);
            near = near.min(d);
            far = far.max(d);
        }
        let far = (far * 1.25).max(1e-5);
        let near = (near * 0.8).max(far * 1e-4);
        let mid = ((near + far) * 0.5).max(1e-6);
        Camera {
            name,
            eye,
            target: eye - back * mid,
            up,
            projection,
            near,
            far: far.max(near * 2.0),
            path: None,
        }
    }

    /// The unit view direction, from eye to target.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.eye).normalize()
    }

    /// World -> camera space (right-handed, looking down -Z).
    pub fn view_from_world(&self) -> Mat4 {
        let f = self.forward();
        let s = f.cross(self.up).normalize();
        let u = s.cross(f);
        Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(self.eye), -u.dot(self.eye), f.dot(self.eye), 1.0),
        )
    }

    /// Camera -> clip space for an image of `aspect` (width / height), with
    /// the depth mapping `depth` (reverse-Z by default).
    pub fn clip_from_view(&self, aspect: f32, depth: DepthMode) -> Mat4 {
        let (n, f) = (self.near, self.far);
        // Depth as a function of view-space z (negative in front):
        // z_clip = a * z_view + b, w_clip = -z_view (perspective) or 1 (ortho).
        match self.projection {
            Projection::Perspective { fov_y } => {
                let t = 1.0 / (fov_y.to_radians() * 0.5).tan();
                let (a, b) = match depth {
                    // near -> 0, far -> 1
                    DepthMode::Standard => (f / (n - f), n * f / (n - f)),
                    // near -> 1, far -> 0
                    DepthMode::ReverseZ => (n / (f - n), n * f / (f - n)),
                };
                Mat4::from_cols(
                    Vec4::new(t / aspect, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, t, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, a, -1.0),
                    Vec4::new(0.0, 0.0, b, 0.0),
                )
            }
            Projection::Orthographic { height } => {
                let sy = 2.0 / height;
                let (a, b) = match depth {
                    DepthMode::Standard => (-1.0 / (f - n), -n / (f - n)),
                    DepthMode::ReverseZ => (1.0 / (f - n), f / (f - n)),
                };
                Mat4::from_cols(
                    Vec4::new(sy / aspect, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, sy, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, a, 0.0),
                    Vec4::new(0.0, 0.0, b, 1.0),
                )
            }
        }
    }
}

/// Near and far planes around a bounding sphere at distance `dist` from the
/// eye: they enclose the sphere with a margin, and the near plane never gets
/// closer than 1/1000 of the far one (the eye may be inside the sphere).
pub fn fitted_planes(dist: f32, radius: f32) -> (f32, f32) {
    let far = dist + radius * 1.5;
    let near = (dist - radius * 1.5).max(far * 1e-3);
    (near, far)
}

// ---------------------------------------------------------------------------
// Camera paths: keys at frames, interpolated in between (Catmull-Rom
// through the keys' eyes and targets, or straight lines), held before the
// first key and after the last. A frame on a key is that key exactly.

/// `camera.interpolation`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// Catmull-Rom (a cubic Hermite whose tangents come from the
    /// neighbouring keys, scaled by their spacing in frames).
    #[default]
    Smooth,
    /// Straight lines between keys.
    Linear,
}

/// One key of a camera path (`[[camera.keys]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct CameraKey {
    /// The frame it holds at.
    pub frame: u32,
    /// Where the camera stands.
    pub eye: Vec3,
    /// Where it looks.
    pub target: Vec3,
    /// Which way is up.
    pub up: Vec3,
    /// Perspective cameras only; None keeps the camera's.
    pub fov: Option<f32>,
}

/// The keys a camera follows over the animation.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraPath {
    /// At least one, frames strictly increasing.
    pub keys: Vec<CameraKey>,
    /// How the keys are joined.
    pub interpolation: Interpolation,
    /// Near and far follow the eye (fitted to the models' bounding sphere,
    /// center and radius) unless the camera gives them.
    pub fit_planes: Option<(Vec3, f32)>,
    /// The camera's own projection, for keys without a `fov`.
    pub projection: Projection,
}

impl CameraPath {
    /// `base` (the camera's projection, planes and name) placed at `frame`.
    pub fn at(&self, base: &Camera, frame: u32) -> Camera {
        let mut cam = base.clone();
        let keys = &self.keys;
        let i = keys.partition_point(|k| k.frame <= frame);
        let (eye, target, up, fov) = if i == 0 {
            let k = &keys[0];
            (k.eye, k.target, k.up, k.fov)
        } else if i == keys.len() || keys[i - 1].frame == frame {
            let k = &keys[i - 1];
            (k.eye, k.target, k.up, k.fov)
        } else {
            let (a, b) = (&keys[i - 1], &keys[i]);
            let t = (frame - a.frame) as f32 / (b.frame - a.frame) as f32;
            let pos = |get: fn(&CameraKey) -> Vec3| match self.interpolation {
                Interpolation::Linear => get(a).lerp(get(b), t),
                Interpolation::Smooth => {
                    let prev = if i >= 2 { Some(&keys[i - 2]) } else { None };
                    let next = keys.get(i + 1);
                    hermite(prev, a, b, next, get, t)
                }
            };
            let up = a.up.lerp(b.up, t).try_normalize().unwrap_or(a.up);
            let fov = match (a.fov, b.fov) {
                (Some(x), Some(y)) => Some(x + (y - x) * t),
                (x, y) => x.or(y),
            };
            (pos(|k| k.eye), pos(|k| k.target), up, fov)
        };
        cam.eye = eye;
        cam.target = target;
        cam.up = up;
        cam.projection = match (fov, self.projection) {
            (Some(f), Projection::Perspective { .. }) => Projection::Perspective { fov_y: f },
            (_, p) => p,
        };
        if let Some((center, radius)) = self.fit_planes {
            let (near, far) = fitted_planes((center - eye).length(), radius);
            cam.near = near;
            cam.far = far.max(near * 2.0);
        }
        cam
    }
}

/// The Catmull-Rom segment from `a` to `b` at `t` in [0, 1], keys at
/// uneven frames: the tangent at a key is the slope between its
/// neighbours (one-sided at the ends), in units per frame.
fn hermite(
    prev: Option<&CameraKey>,
    a: &CameraKey,
    b: &CameraKey,
    next: Option<&CameraKey>,
    get: fn(&CameraKey) -> Vec3,
    t: f32,
) -> Vec3 {
    let slope = |x: &CameraKey, y: &CameraKey| (get(y) - get(x)) / (y.frame - x.frame) as f32;
    let ma = prev.map(|p| slope(p, b)).unwrap_or_else(|| slope(a, b));
    let mb = next.map(|n| slope(a, n)).unwrap_or_else(|| slope(a, b));
    let span = (b.frame - a.frame) as f32;
    let (t2, t3) = (t * t, t * t * t);
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    get(a) * h00 + ma * (h10 * span) + get(b) * h01 + mb * (h11 * span)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn depth_of(cam: &Camera, mode: DepthMode, z_view: f32) -> f32 {
        let c = cam.clip_from_view(1.0, mode) * Vec4::new(0.0, 0.0, z_view, 1.0);
        c.z / c.w
    }

    #[test]
    fn depth_ranges_map_near_and_far() {
        for proj in [
            Projection::Perspective { fov_y: 45.0 },
            Projection::Orthographic { height: 2.0 },
        ] {
            let cam = Camera {
                name: "c".into(),
                eye: Vec3::ZERO,
                target: -Vec3::Z,
                up: Vec3::Y,
                projection: proj,
                near: 0.5,
                far: 20.0,
                path: None,
            };
            assert!((depth_of(&cam, DepthMode::Standard, -0.5) - 0.0).abs() < 1e-6);
            assert!((depth_of(&cam, DepthMode::Standard, -20.0) - 1.0).abs() < 1e-6);
            assert!((depth_of(&cam, DepthMode::ReverseZ, -0.5) - 1.0).abs() < 1e-6);
            assert!((depth_of(&cam, DepthMode::ReverseZ, -20.0) - 0.0).abs() < 1e-6);
        }
    }

    #[test]
    fn framing_camera_sees_the_whole_sphere() {
        let cam = Camera::framing("c".into(), Vec3::new(1.0, 2.0, 3.0), 2.0, 45.0);
        let d = (cam.eye - cam.target).length();
        assert!(cam.near < d - 2.0 && cam.far > d + 2.0);
        // The sphere's top tangent is inside the vertical field of view.
        let angle = (2.0f32 / d).asin().to_degrees();
        assert!(angle <= 22.5 + 1e-3);
    }

    fn path_key(frame: u32, x: f32) -> CameraKey {
        CameraKey {
            frame,
            eye: Vec3::new(x, 1.0, 5.0),
            target: Vec3::new(x, 0.0, 0.0),
            up: Vec3::Y,
            fov: Some(40.0 + x),
        }
    }

    fn path_base() -> Camera {
        Camera::framing("c".into(), Vec3::ZERO, 1.0, 45.0)
    }

    fn test_path(interpolation: Interpolation) -> CameraPath {
        CameraPath {
            keys: vec![path_key(10, 0.0), path_key(20, 4.0), path_key(40, 6.0)],
            interpolation,
            fit_planes: None,
            projection: Projection::Perspective { fov_y: 45.0 },
        }
    }

    #[test]
    fn keys_are_exact_held_at_the_ends_and_interpolated_between() {
        for interp in [Interpolation::Smooth, Interpolation::Linear] {
            let p = test_path(interp);
            for k in &p.keys {
                let c = p.at(&path_base(), k.frame);
                assert_eq!((c.eye, c.target), (k.eye, k.target));
                assert_eq!(
                    c.projection,
                    Projection::Perspective {
                        fov_y: k.fov.unwrap()
                    }
                );
            }
            assert_eq!(p.at(&path_base(), 0).eye, p.keys[0].eye);
            assert_eq!(p.at(&path_base(), 99).eye, p.keys[2].eye);
            // Linear halfway: the midpoint; fov linear in both.
            let mid = p.at(&path_base(), 15);
            assert_eq!(mid.projection, Projection::Perspective { fov_y: 42.0 });
            if interp == Interpolation::Linear {
                assert!((mid.eye.x - 2.0).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn smooth_paths_have_no_corner_at_a_key() {
        // The velocity just before key 20 equals the velocity just after.
        let p = test_path(Interpolation::Smooth);
        // Sub-frame samples through the Hermite directly.
        let ks = &p.keys;
        let get: fn(&CameraKey) -> Vec3 = |k| k.eye;
        let eps = 1e-3;
        let before = (hermite(None, &ks[0], &ks[1], Some(&ks[2]), get, 1.0)
            - hermite(None, &ks[0], &ks[1], Some(&ks[2]), get, 1.0 - eps))
            / (eps * 10.0);
        let after = (hermite(Some(&ks[0]), &ks[1], &ks[2], None, get, eps)
            - hermite(Some(&ks[0]), &ks[1], &ks[2], None, get, 0.0))
            / (eps * 20.0);
        assert!((before - after).length() < 1e-2, "{before} {after}");
        // Evenly spaced collinear keys at constant speed stay on the line at
        // constant speed (Catmull-Rom reproduces linear motion).
        let even = CameraPath {
            keys: vec![
                path_key(0, 0.0),
                path_key(10, 1.0),
                path_key(20, 2.0),
                path_key(30, 3.0),
            ],
            interpolation: Interpolation::Smooth,
            fit_planes: None,
            projection: Projection::Perspective { fov_y: 45.0 },
        };
        for f in 0..30 {
            let x = even.at(&path_base(), f).eye.x;
            assert!((x - f as f32 / 10.0).abs() < 1e-5, "frame {f}: {x}");
        }
    }
}
