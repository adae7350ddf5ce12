//! The camera's ray through each pixel center, for what is seen where no
//! triangle is: the environment behind the models and the ground catcher;
//! and the cache of what such a view computes per pixel (`ViewCache`).

use std::sync::{Arc, Mutex};

use glam::Vec3;

use crate::scene::camera::{Camera, Projection};

#[derive(Clone, PartialEq)]
pub(super) struct CameraRays {
    eye: Vec3,
    forward: Vec3,
    /// Half the view's extent along x and y: per unit of depth
    /// (perspective) or in world units (orthographic).
    right: Vec3,
    up: Vec3,
    orthographic: bool,
    size: (f32, f32),
}

impl CameraRays {
    pub fn new(cam: &Camera, width: u32, height: u32) -> CameraRays {
        let forward = cam.forward();
        let side = forward.cross(cam.up).normalize_or(Vec3::X);
        let up = side.cross(forward);
        let aspect = width as f32 / height as f32;
        let (half_h, orthographic) = match cam.projection {
            Projection::Perspective { fov_y } => ((fov_y.to_radians() * 0.5).tan(), false),
            Projection::Orthographic { height } => (height * 0.5, true),
        };
        CameraRays {
            eye: cam.eye,
            forward,
            right: side * (half_h * aspect),
            up: up * half_h,
            orthographic,
            size: (width as f32, height as f32),
        }
    }

    /// The image's height in pixels.
    pub fn height(&self) -> u32 {
        self.size.1 as u32
    }

    /// The image's width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.size.0 as u32, self.size.1 as u32)
    }

    /// Origin and unit direction of the ray through pixel (px, py)'s center.
    pub fn ray(&self, px: i32, py: i32) -> (Vec3, Vec3) {
        let x = (px as f32 + 0.5) / self.size.0 * 2.0 - 1.0;
        let y = 1.0 - (py as f32 + 0.5) / self.size.1 * 2.0;
        let offset = self.right * x + self.up * y;
        if self.orthographic {
            (self.eye + offset, self.forward)
        } else {
            (self.eye, (self.forward + offset).normalize())
        }
    }

    /// Where the ray through a pixel center meets world point `q`: its
    /// pixel coordinates (centers at k + 1/2, as `ray` places them);
    /// None behind the camera.
    pub fn pixel_of(&self, q: Vec3) -> Option<(f32, f32)> {
        let d = q - self.eye;
        let depth = d.dot(self.forward);
        if !self.orthographic && depth <= 0.0 {
            return None;
        }
        let per = if self.orthographic { 1.0 } else { depth };
        // `ray`'s offset is right x + up y, and right and up are
        // orthogonal to the view: their components give x and y back.
        let x = d.dot(self.right) / (self.right.length_squared() * per);
        let y = d.dot(self.up) / (self.up.length_squared() * per);
        Some(((x + 1.0) * 0.5 * self.size.0, (1.0 - y) * 0.5 * self.size.1))
    }
}

/// The last per-pixel result a renderer computed for a view (a backdrop,
/// where the ground meets each pixel). A camera that stays put sees the
/// same every frame (a turntable turns the models, not the camera): the
/// first frame of a view only remembers its key and computes what it
/// needs itself; the second computes the whole, which it and every later
/// frame of the view read.
pub(super) struct ViewCache<K, V> {
    last: Mutex<Option<(K, Option<Arc<V>>)>>,
}

impl<K, V> Default for ViewCache<K, V> {
    fn default() -> Self {
        ViewCache {
            last: Mutex::new(None),
        }
    }
}

impl<K: PartialEq, V> ViewCache<K, V> {
    /// The whole for `key` where the previous frame had the same key
    /// (`build` makes it on the second frame of a view); None otherwise,
    /// and the key is remembered.
    pub fn get(&self, key: K, build: impl FnOnce() -> V) -> Option<Arc<V>> {
        // A poisoned lock (a panic in another frame) only loses the cache.
        let Ok(mut last) = self.last.lock() else {
            return None;
        };
        match &mut *last {
            Some((k, kept)) if *k == key => {
                Some(kept.get_or_insert_with(|| Arc::new(build())).clone())
            }
            _ => {
                *last = Some((key, None));
                None
            }
        }
    }

    /// What is kept, if anything.
    #[cfg(test)]
    pub fn kept(&self) -> Option<Arc<V>> {
        self.last
            .lock()
            .ok()
            .and_then(|l| l.as_ref().and_then(|(_, v)| v.clone()))
    }
}
