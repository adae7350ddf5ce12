//! Camera paths: keys at frames, interpolated in between (Catmull-Rom
//! through the keys' eyes and targets, or straight lines), held before the
//! first key and after the last. A frame on a key is that key exactly.

use glam::Vec3;

use super::camera::{Camera, Projection, fitted_planes};

/// `camera.interpolation`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// Catmull-Rom (a cubic Hermite whose tangents come from the
    /// neighbouring keys, scaled by their spacing in frames).
    #[default]
    Smooth,
    Linear,
}

#[derive(Debug, Clone, PartialEq)]
pub struct CameraKey {
    pub frame: u32,
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Perspective cameras only; None keeps the camera's.
    pub fov: Option<f32>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct CameraPath {
    /// At least one, frames strictly increasing.
    pub keys: Vec<CameraKey>,
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

    fn key(frame: u32, x: f32) -> CameraKey {
        CameraKey {
            frame,
            eye: Vec3::new(x, 1.0, 5.0),
            target: Vec3::new(x, 0.0, 0.0),
            up: Vec3::Y,
            fov: Some(40.0 + x),
        }
    }

    fn base() -> Camera {
        Camera::framing("c".into(), Vec3::ZERO, 1.0, 45.0)
    }

    fn path(interpolation: Interpolation) -> CameraPath {
        CameraPath {
            keys: vec![key(10, 0.0), key(20, 4.0), key(40, 6.0)],
            interpolation,
            fit_planes: None,
            projection: Projection::Perspective { fov_y: 45.0 },
        }
    }

    #[test]
    fn keys_are_exact_held_at_the_ends_and_interpolated_between() {
        for interp in [Interpolation::Smooth, Interpolation::Linear] {
            let p = path(interp);
            for k in &p.keys {
                let c = p.at(&base(), k.frame);
                assert_eq!((c.eye, c.target), (k.eye, k.target));
                assert_eq!(
                    c.projection,
                    Projection::Perspective {
                        fov_y: k.fov.unwrap()
                    }
                );
            }
            assert_eq!(p.at(&base(), 0).eye, p.keys[0].eye);
            assert_eq!(p.at(&base(), 99).eye, p.keys[2].eye);
            // Linear halfway: the midpoint; fov linear in both.
            let mid = p.at(&base(), 15);
            assert_eq!(mid.projection, Projection::Perspective { fov_y: 42.0 });
            if interp == Interpolation::Linear {
                assert!((mid.eye.x - 2.0).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn smooth_paths_have_no_corner_at_a_key() {
        // The velocity just before key 20 equals the velocity just after.
        let p = path(Interpolation::Smooth);
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
            keys: vec![key(0, 0.0), key(10, 1.0), key(20, 2.0), key(30, 3.0)],
            interpolation: Interpolation::Smooth,
            fit_planes: None,
            projection: Projection::Perspective { fov_y: 45.0 },
        };
        for f in 0..30 {
            let x = even.at(&base(), f).eye.x;
            assert!((x - f as f32 / 10.0).abs() < 1e-5, "frame {f}: {x}");
        }
    }
}
