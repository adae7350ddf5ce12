//! The environment behind the models (`output.background = "environment"`
//! or `"blurred"`): the radiance along each pixel center's view ray, sharp
//! or prefiltered.
//!
//! A camera that stays put sees the same backdrop every frame (a
//! turntable turns the models, not the camera), so the renderer keeps
//! the last one (`BackdropCache`): the first frame of a camera looks up
//! only the pixels where the background shows; when the next frame has
//! the same camera, size, blur and environment, the whole image is
//! computed once and read by every frame after it. The values are the
//! lookups' own, so frames are the same bytes with or without it.

use std::sync::Arc;

use glam::Vec4;
use rayon::prelude::*;

use super::draw_list::DrawList;
use super::rays::{CameraRays, ViewCache};
use crate::scene::light::LightKind;
use crate::scene::settings::Background;
use crate::shade::env::{Disc, EnvLight};

/// The environment seen through the camera, where the background shows
/// it.
pub(super) struct EnvBackground<'a> {
    env: &'a EnvLight,
    /// The lights taken out of the image (`environment.lights`): their
    /// unit direction towards them, irradiance and angular radius, added
    /// back to the blurred background.
    discs: Vec<Disc>,
    /// Prefiltering roughness; 0: the image itself.
    blur: f32,
    rays: CameraRays,
    width: u32,
    /// Every pixel's value, when the cache holds them for this view.
    cached: Option<Image>,
}

/// What a backdrop depends on: the view rays, the blur and the
/// environment's lighting (by address: one renderer's, built once).
#[derive(PartialEq)]
pub(super) struct Key {
    rays: CameraRays,
    blur: u32,
    env: usize,
}

impl<'a> EnvBackground<'a> {
    /// The backdrop of the frame `setup` at `width` x `height` pixels, or
    /// None where the background is not the environment.
    pub fn new(
        setup: &DrawList,
        env: Option<&'a EnvLight>,
        width: u32,
        height: u32,
    ) -> Option<EnvBackground<'a>> {
        let blur = match setup.scene.settings.background {
            Background::Environment => 0.0,
            Background::Blurred(b) => b,
            _ => return None,
        };
        // The data views show values, not radiance: no environment there.
        if setup.scene.settings.shading.is_data_view() {
            return None;
        }
        Some(EnvBackground {
            env: env?,
            discs: image_discs(setup),
            blur,
            rays: CameraRays::new(&setup.camera, width, height),
            width,
            cached: None,
        })
    }

    /// The radiance behind pixel (px, py), opaque.
    #[inline]
    pub fn at(&self, px: i32, py: i32) -> Vec4 {
        if let Some(c) = &self.cached {
            return c[py as usize * self.width as usize + px as usize];
        }
        self.look_up(px, py)
    }

    fn look_up(&self, px: i32, py: i32) -> Vec4 {
        let (_, d) = self.rays.ray(px, py);
        self.env.seen(d, self.blur, &self.discs).extend(1.0)
    }

    fn key(&self) -> Key {
        Key {
            rays: self.rays.clone(),
            blur: self.blur.to_bits(),
            env: self.env as *const EnvLight as usize,
        }
    }

    /// Every pixel's `look_up`, rows in parallel.
    fn image(&self) -> Vec<Vec4> {
        let w = self.width as usize;
        let h = self.rays.height() as usize;
        let mut out = vec![Vec4::ZERO; w * h];
        out.par_chunks_mut(w.max(1))
            .enumerate()
            .for_each(|(y, row)| {
                for (x, o) in row.iter_mut().enumerate() {
                    *o = self.look_up(x as i32, y as i32);
                }
            });
        out
    }
}

/// The lights the frame took out of its environment image (directional
/// lights with a disc), as `EnvLight::seen` puts them back.
pub(super) fn image_discs(setup: &DrawList) -> Vec<Disc> {
    setup
        .lights
        .iter()
        .filter_map(|l| match l.kind {
            LightKind::Directional {
                direction,
                irradiance,
                angle,
            } if angle > 0.0 => Some((-direction, l.color * irradiance, angle)),
            _ => None,
        })
        .collect()
}

/// A whole backdrop, rows of the frame's width.
type Image = Arc<Vec<Vec4>>;

/// The last backdrop a renderer drew, kept while its view stays.
pub(super) type BackdropCache = ViewCache<Key, Vec<Vec4>>;

impl EnvBackground<'_> {
    /// Reads the whole image from `cache` where the previous frame had the
    /// same view (computing it on the second frame of a view).
    pub fn attach(&mut self, cache: &BackdropCache) {
        self.cached = cache.get(self.key(), || self.image());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::environment::EnvImage;
    use crate::scene::camera::Camera;
    use glam::Vec3;

    fn backdrop<'a>(env: &'a EnvLight, eye: Vec3, blur: f32) -> EnvBackground<'a> {
        let cam = Camera {
            eye,
            ..Camera::framing("c".into(), Vec3::ZERO, 1.0, 40.0)
        };
        EnvBackground {
            env,
            discs: Vec::new(),
            blur,
            rays: CameraRays::new(&cam, 37, 23),
            width: 37,
            cached: None,
        }
    }

    #[test]
    fn the_kept_image_is_every_lookup_bit_for_bit() {
        let env = EnvLight::with_size(&EnvImage::studio(), 1.0, 30.0, 32);
        let cache = BackdropCache::default();
        for blur in [0.0, 0.5] {
            let eye = Vec3::new(1.0, 0.5, 3.0);
            // First frame of the view: nothing kept.
            let mut first = backdrop(&env, eye, blur);
            first.attach(&cache);
            assert!(first.cached.is_none());
            // Second: the whole image, equal to the lookups.
            let mut second = backdrop(&env, eye, blur);
            second.attach(&cache);
            assert!(second.cached.is_some());
            assert_eq!(cache.kept().map(|i| i.len()), Some(37 * 23));
            for y in 0..23 {
                for x in 0..37 {
                    let (a, b) = (second.at(x, y), first.at(x, y));
                    assert_eq!(
                        a.to_array().map(f32::to_bits),
                        b.to_array().map(f32::to_bits)
                    );
                }
            }
            // Another view is not served the kept image.
            let mut moved = backdrop(&env, eye + Vec3::X * 0.01, blur);
            moved.attach(&cache);
            assert!(moved.cached.is_none());
        }
    }
}
