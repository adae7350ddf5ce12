//! The environment's prefiltered lighting, shared by every renderer of
//! the process: a batch of inputs lit by one environment (the studio of
//! the default look, mostly) prefilters it once, not once per input (over
//! 100 ms each, most of a thumbnail's time).
//!
//! An entry is found by the image's content (a hash, then the texels
//! compared), intensity, rotation, prefilter size and the Blinn-Phong
//! roughnesses it blends levels for; the same inputs give the same
//! lighting, so a frame is the same bytes whether its lighting was made
//! for it or found here. The last `KEEP` entries are kept.

use std::sync::{Arc, Mutex};

use crate::assets::environment::EnvImage;
use crate::shade::env::EnvLight;

/// How many lightings are kept (each a few MB to a few tens of MB).
const KEEP: usize = 4;

#[derive(PartialEq, Eq)]
struct Key {
    hash: u64,
    intensity: u32,
    rotation: u32,
    size: u32,
    phong: Vec<u32>,
    /// `content_hash` of the backdrop (0: none).
    backdrop: u64,
}

struct Entry {
    key: Key,
    image: Arc<EnvImage>,
    light: Arc<EnvLight>,
}

static CACHE: Mutex<Vec<Entry>> = Mutex::new(Vec::new());

/// `EnvLight::with_size(image, intensity, rotation, size)
/// .with_phong_roughness(phong)`, made once per process for each distinct
/// set of inputs.
pub fn env_light(
    (image, backdrop): (&Arc<EnvImage>, Option<&Arc<EnvImage>>),
    (intensity, rotation, size): (f32, f32, u32),
    phong: Vec<f32>,
) -> Arc<EnvLight> {
    // The same image (the studio, mostly) is found without hashing it.
    let params = |k: &Key| {
        k.intensity == intensity.to_bits()
            && k.rotation == rotation.to_bits()
            && k.size == size
            && k.backdrop == backdrop.map_or(0, |b| content_hash(b))
            && k.phong
                .iter()
                .copied()
                .eq(phong.iter().map(|r| r.to_bits()))
    };
    if let Some(e) = lock()
        .iter()
        .find(|e| Arc::ptr_eq(&e.image, image) && params(&e.key))
    {
        return e.light.clone();
    }
    let key = Key {
        hash: content_hash(image),
        intensity: intensity.to_bits(),
        rotation: rotation.to_bits(),
        size,
        phong: phong.iter().map(|r| r.to_bits()).collect(),
        backdrop: backdrop.map_or(0, |b| content_hash(b)),
    };
    let same = |e: &Entry| {
        e.key == key
            && (Arc::ptr_eq(&e.image, image)
                || (e.image.width == image.width && e.image.texels == image.texels))
    };
    if let Some(e) = lock().iter().find(|e| same(e)) {
        return e.light.clone();
    }
    // Made without the lock: other renderers go on meanwhile.
    let mut light =
        EnvLight::with_size(image, intensity, rotation, size).with_phong_roughness(phong);
    if let Some(b) = backdrop {
        light = light.with_backdrop(b);
    }
    let light = Arc::new(light);
    let mut cache = lock();
    if !cache.iter().any(same) {
        if cache.len() == KEEP {
            cache.remove(0);
        }
        cache.push(Entry {
            key,
            image: image.clone(),
            light: light.clone(),
        });
    }
    light
}

/// The cache, whatever a panicking holder left (entries are pushed whole).
fn lock() -> std::sync::MutexGuard<'static, Vec<Entry>> {
    CACHE.lock().unwrap_or_else(|p| p.into_inner())
}

/// A hash of the image's size and texels' bits.
fn content_hash(image: &EnvImage) -> u64 {
    const K: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut h = (image.width as u64) << 32 | image.height as u64;
    for t in &image.texels {
        for c in [t.x, t.y, t.z] {
            h = (h ^ c.to_bits() as u64).wrapping_mul(K).rotate_left(29);
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The same inputs find the lighting made first; a different texel,
    /// intensity or roughness list makes its own.
    #[test]
    fn the_same_environment_is_prefiltered_once() {
        let texels = |v: f32| vec![Vec3::splat(v); 32 * 16];
        let a = Arc::new(EnvImage::new(32, 16, texels(0.25)).unwrap());
        let a2 = Arc::new(EnvImage::new(32, 16, texels(0.25)).unwrap());
        let mut other = texels(0.25);
        other[100].y = 0.5;
        let b = Arc::new(EnvImage::new(32, 16, other).unwrap());
        let first = env_light((&a, None), (1.0, 0.0, 16), vec![0.5]);
        assert!(Arc::ptr_eq(
            &first,
            &env_light((&a2, None), (1.0, 0.0, 16), vec![0.5])
        ));
        for (image, params, phong) in [
            ((&b, None), (1.0, 0.0, 16), vec![0.5]),
            ((&a, None), (2.0, 0.0, 16), vec![0.5]),
            ((&a, None), (1.0, 0.0, 16), vec![0.25]),
            // The same lighting with another backdrop.
            ((&a, Some(&b)), (1.0, 0.0, 16), vec![0.5]),
        ] {
            assert!(!Arc::ptr_eq(&first, &env_light(image, params, phong)));
        }
    }
}
