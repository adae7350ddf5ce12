//! Environment images for image-based lighting: equirectangular (2:1
//! latitude-longitude) linear radiance, from Radiance `.hdr` (flat and RLE)
//! or OpenEXR (`R`, `G`, `B` of the first layer), top row = up (+Y).

use std::path::Path;

use glam::Vec3;

use super::input::Input;
use crate::error::Error;

/// Linear RGB radiance, row-major from the top; `width == 2 * height`.
#[derive(Debug, Clone)]
pub struct EnvImage {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// The radiance, row-major from the top.
    pub texels: Vec<Vec3>,
}

/// A bright region taken out of an image (`EnvImage::extract_sun`,
/// `extract_lights`) as a directional light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TakenLight {
    /// The unit vector its light travels along (environment space).
    pub direction: Vec3,
    /// Irradiance (RGB) on a surface facing it: what the texels lost.
    pub irradiance: Vec3,
    /// Angular radius in radians of a uniform disc with the same spread.
    pub angle: f32,
}

/// A light's peak (4x4 box) is at least this many times the image's mean.
const PEAK_OVER_MEAN: f32 = 20.0;
/// `extract_lights`: the level, as a fraction of the peak, texels are
/// lowered to.
const LIGHT_LEVEL: f32 = 0.02;
/// `extract_lights`: the half angle in degrees of the cone a light is
/// taken from.
const LIGHT_CONE: f32 = 12.0;

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl EnvImage {
    /// Reads an `.hdr` or `.exr` environment. A file that is not 2:1, has
    /// fewer than 8 rows, or holds negative or non-finite radiance is
    /// refused, naming the file.
    pub fn load(path: &Path, input: &Input) -> Result<EnvImage, Error> {
        let bad = |message: String| Error::asset(path, None, message);
        if std::fs::symlink_metadata(path).is_err() {
            return Err(bad("environment file not found".into()));
        }
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if !matches!(ext.as_str(), "hdr" | "exr") {
            return Err(bad(format!(
                "an environment is a .hdr or .exr file, not .{ext}"
            )));
        }
        let bytes = input.read(path, None, None)?;
        let (width, height, texels) = if ext == "hdr" {
            read_hdr(&bytes, path, input)?
        } else {
            read_exr(&bytes, path, input)?
        };
        EnvImage::new(width, height, texels).map_err(bad)
    }

    /// An environment from texels; `width` must be twice `height` (>= 8).
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Result<EnvImage, String> {
        if width != 2 * height || height < 8 {
            return Err(format!(
                "an environment is an equirectangular image, twice as wide as high (at least 16x8); this one is {width}x{height}"
            ));
        }
        if texels.len() != (width * height) as usize {
            return Err(format!("{} texels for {width}x{height}", texels.len()));
        }
        if let Some(i) = texels
            .iter()
            .position(|t| !t.is_finite() || t.min_element() < 0.0)
        {
            return Err(format!(
                "texel ({}, {}) holds {} : radiance must be finite and non-negative",
                i as u32 % width,
                i as u32 / width,
                texels[i]
            ));
        }
        Ok(EnvImage {
            width,
            height,
            texels,
        })
    }

    /// The built-in studio (`preset = "studio"`), made by code: a neutral
    /// grey room (ceiling 0.35, walls 0.3 at the horizon, floor 0.12 as
    /// the floor's bounce), a large soft key panel above front-left
    /// (radiance 3), a fill panel front-right (1), a rim strip behind the
    /// model, above (2), and a top light (0.75): a white Lambertian
    /// surface facing the key reflects about 0.9. Soft edges everywhere: no
    /// texel-sharp step for the prefilter to ring on.
    ///
    /// Made once per process: every scene of the default look shares it.
    pub fn studio() -> std::sync::Arc<EnvImage> {
        static STUDIO: std::sync::OnceLock<std::sync::Arc<EnvImage>> = std::sync::OnceLock::new();
        STUDIO
            .get_or_init(|| std::sync::Arc::new(EnvImage::make_studio()))
            .clone()
    }

    /// `studio`, made.
    fn make_studio() -> EnvImage {
        let (w, h) = (512u32, 256u32);
        // (toward the panel, angular radius, softness, radiance); the
        // camera looks down -Z from +Z, so "front" is +Z.
        let panels = [
            (Vec3::new(-0.55, 0.55, 0.63), 0.45f32, 0.25f32, 3.0f32),
            (Vec3::new(0.75, 0.2, 0.63), 0.5, 0.3, 1.0),
            (Vec3::new(0.15, 0.45, -0.88), 0.3, 0.2, 2.0),
            (Vec3::new(0.0, 1.0, 0.0), 0.5, 0.4, 0.75),
        ];
        let smooth = |e0: f32, e1: f32, x: f32| {
            let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        };
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let theta = (y as f32 + 0.5) / h as f32 * std::f32::consts::PI;
                let phi = ((x as f32 + 0.5) / w as f32 - 0.5) * std::f32::consts::TAU;
                let d = Vec3::new(
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    -theta.sin() * phi.cos(),
                );
                let room = if d.y >= 0.0 {
                    0.3 + 0.05 * d.y
                } else {
                    0.3 - 0.18 * smooth(0.0, 0.15, -d.y)
                };
                let mut c = room;
                for (dir, radius, soft, radiance) in panels {
                    let angle = d.dot(dir.normalize()).clamp(-1.0, 1.0).acos();
                    c += radiance * (1.0 - smooth(radius - soft * 0.5, radius + soft * 0.5, angle));
                }
                Vec3::splat(c)
            })
            .collect();
        EnvImage {
            width: w,
            height: h,
            texels,
        }
    }

    /// Takes the sun out of the image: the texels within 8 degrees of the
    /// brightest one (on a 4x smaller copy) that are brighter than a
    /// quarter of it are lowered to that quarter, and what they lose is
    /// returned as a directional light. None for an image without a clear
    /// peak (its peak under 20 times the mean).
    pub fn extract_sun(&mut self) -> Option<TakenLight> {
        let (peak, at) = self.box_peak();
        if peak < PEAK_OVER_MEAN * self.mean_luminance() || peak <= 0.0 {
            return None;
        }
        self.take(at, 0.25 * peak, 8f32.to_radians().cos())
    }

    /// Takes up to `max` lights out of the image (`environment.lights`),
    /// brightest first: while the peak of a 4x smaller copy is at least 20
    /// times the image's mean, the texels within 12 degrees of it that
    /// are brighter than 2% of it are lowered to that level, and what
    /// they lose becomes a directional light with the spread of what was
    /// taken. Small bright sources (lamps, softboxes, a sun) then light
    /// the scene through the light loop, with shadows, and the image keeps
    /// the rest.
    pub fn extract_lights(&mut self, max: usize) -> Vec<TakenLight> {
        let mean = self.mean_luminance();
        let mut out = Vec::new();
        while out.len() < max {
            let (peak, at) = self.box_peak();
            if peak < PEAK_OVER_MEAN * mean || peak <= 0.0 {
                break;
            }
            match self.take(at, LIGHT_LEVEL * peak, LIGHT_CONE.to_radians().cos()) {
                Some(l) => out.push(l),
                None => break,
            }
        }
        out
    }

    /// Unit direction toward texel (x, y)'s center.
    fn direction(&self, x: usize, y: usize) -> Vec3 {
        use std::f32::consts::PI;
        let theta = (y as f32 + 0.5) / self.height as f32 * PI;
        let phi = ((x as f32 + 0.5) / self.width as f32 - 0.5) * 2.0 * PI;
        Vec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        )
    }

    /// Solid angle of a texel of row y.
    fn texel_solid_angle(&self, y: usize) -> f32 {
        use std::f32::consts::PI;
        let h = self.height as f32;
        (2.0 * PI / self.width as f32) * (PI / h) * ((y as f32 + 0.5) / h * PI).sin()
    }

    /// Mean luminance over the texels.
    fn mean_luminance(&self) -> f32 {
        self.texels.iter().map(|c| luminance(*c)).sum::<f32>() / self.texels.len() as f32
    }

    /// The brightest 4x4 box (one hot texel is not a light): its mean
    /// luminance and the texel at its center.
    fn box_peak(&self) -> (f32, (usize, usize)) {
        let (w, h) = (self.width as usize, self.height as usize);
        let (mut best, mut at) = (0.0f32, (0, 0));
        for by in 0..h / 4 {
            for bx in 0..w / 4 {
                let mut s = 0.0;
                for k in 0..16 {
                    s += luminance(self.texels[(by * 4 + k / 4) * w + bx * 4 + k % 4]);
                }
                if s > best {
                    (best, at) = (s, (bx * 4 + 2, by * 4 + 2));
                }
            }
        }
        (best / 16.0, at)
    }

    /// Lowers the texels within the cone (`cos_max`) around texel `at`
    /// that are brighter than `threshold` to that luminance; what they
    /// lose is the light. Its direction is the luminance-weighted mean of
    /// the directions taken, and its angular radius that of a uniform
    /// disc with the same mean resultant length R (cos = 2R - 1).
    fn take(&mut self, at: (usize, usize), threshold: f32, cos_max: f32) -> Option<TakenLight> {
        let center = self.direction(at.0, at.1);
        let (w, h) = (self.width as usize, self.height as usize);
        let (mut energy, mut weighted, mut weight) = (Vec3::ZERO, Vec3::ZERO, 0.0f32);
        for y in 0..h {
            let omega = self.texel_solid_angle(y);
            for x in 0..w {
                let d = self.direction(x, y);
                let t = self.texels[y * w + x];
                let l = luminance(t);
                if d.dot(center) < cos_max || l <= threshold {
                    continue;
                }
                let kept = t * (threshold / l);
                let taken = (t - kept) * omega;
                energy += taken;
                weighted += d * luminance(taken);
                weight += luminance(taken);
                self.texels[y * w + x] = kept;
            }
        }
        let toward = weighted.try_normalize()?;
        let r = (weighted.length() / weight).min(1.0);
        Some(TakenLight {
            direction: -toward,
            irradiance: energy,
            angle: (2.0 * r - 1.0).clamp(-1.0, 1.0).acos(),
        })
    }

    /// A uniform environment of radiance `c`.
    pub fn uniform(c: Vec3) -> EnvImage {
        EnvImage {
            width: 32,
            height: 16,
            texels: vec![c; 32 * 16],
        }
    }
}

type Texels = (u32, u32, Vec<Vec3>);

/// What a texel takes while loading: the decoded RGB floats, the texels
/// kept, and the prefiltered levels made from them (a third more).
const ENV_TEXEL_BYTES: u64 = 12 + 12 + 4;

fn read_hdr(bytes: &[u8], path: &Path, input: &Input) -> Result<Texels, Error> {
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| Error::asset(path, None, format!("cannot read the environment: {e}")))?;
    let img = crate::assets::texture::decode_within(
        reader,
        input,
        path,
        "the environment",
        ENV_TEXEL_BYTES,
    )?
    .into_rgb32f();
    let (w, h) = img.dimensions();
    let texels = img.pixels().map(|p| Vec3::from(p.0)).collect();
    Ok((w, h, texels))
}

fn read_exr(bytes: &[u8], path: &Path, input: &Input) -> Result<Texels, Error> {
    use exr::prelude::{ReadChannels, ReadLayers};
    let bad = |e: exr::error::Error| {
        Error::asset(path, None, format!("not a readable OpenEXR RGB image: {e}"))
    };
    // The size from the header, before the pixels are allocated.
    let meta =
        exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).map_err(bad)?;
    let largest = meta
        .headers
        .iter()
        .map(|h| h.layer_size.width() as u64 * h.layer_size.height() as u64)
        .max()
        .unwrap_or(0);
    // The channels decoded as floats (at most four) and the texels kept.
    input.check_file(
        path,
        "the environment",
        largest.saturating_mul(16 + ENV_TEXEL_BYTES),
    )?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size: exr::math::Vec2<usize>, _: &exr::prelude::RgbaChannels| {
                (size.width(), vec![Vec3::ZERO; size.width() * size.height()])
            },
            |(w, px): &mut (usize, Vec<Vec3>),
             pos: exr::math::Vec2<usize>,
             (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(bad)?;
    let size = image.layer_data.size;
    let (_, texels) = image.layer_data.channel_data.pixels;
    Ok((size.width() as u32, size.height() as u32, texels))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_is_not_an_equirectangular_radiance_map() {
        assert!(EnvImage::new(16, 16, vec![Vec3::ONE; 256]).is_err());
        assert!(EnvImage::new(16, 8, vec![Vec3::ONE; 100]).is_err());
        let mut t = vec![Vec3::ONE; 128];
        t[5] = Vec3::new(f32::NAN, 0.0, 0.0);
        let e = EnvImage::new(16, 8, t).unwrap_err();
        assert!(e.contains("(5, 0)"), "{e}");
        assert!(EnvImage::new(16, 8, vec![Vec3::ONE; 128]).is_ok());
    }

    #[test]
    fn the_sun_leaves_the_image_as_a_light_of_the_same_energy() {
        use std::f32::consts::PI;
        let (w, h) = (256u32, 128u32);
        // A 4x4-texel sun around u = 0.75, v = 0.25: toward +X, 45 degrees up.
        let texels: Vec<Vec3> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if (190..194).contains(&x) && (30..34).contains(&y) {
                    Vec3::splat(5000.0)
                } else {
                    Vec3::splat(0.1)
                }
            })
            .collect();
        let omega = |y: u32| {
            (2.0 * PI / w as f32) * (PI / h as f32) * ((y as f32 + 0.5) / h as f32 * PI).sin()
        };
        let total = |t: &[Vec3]| -> f32 {
            t.iter()
                .enumerate()
                .map(|(i, c)| c.x * omega(i as u32 / w))
                .sum()
        };
        let mut img = EnvImage::new(w, h, texels).unwrap();
        let before = total(&img.texels);
        let sun = img.extract_sun().unwrap();
        let (toward, e) = (-sun.direction, sun.irradiance);
        let want = Vec3::new(1.0, 1.0, 0.0).normalize();
        assert!(toward.dot(want) > 0.999, "{toward}");
        // Energy is moved, not made: the image keeps the rest.
        assert!(
            (total(&img.texels) + e.x - before).abs() < 1e-3 * before,
            "{e}"
        );
        assert!(img.texels.iter().all(|c| c.x <= 5000.0 * 0.25 + 1e-3));
        // No clear peak, no sun.
        assert!(EnvImage::uniform(Vec3::ONE).extract_sun().is_none());
    }

    #[test]
    fn lamps_leave_the_image_as_lights_of_their_energy_direction_and_size() {
        let (w, h) = (512u32, 256u32);
        let mut img = EnvImage::new(w, h, vec![Vec3::splat(0.2); (w * h) as usize]).unwrap();
        // Two round lamps: 5 degrees across toward +X, level; 8 degrees
        // across straight up, half as bright, warm.
        let lamps = [
            (Vec3::X, 5f32.to_radians(), Vec3::splat(400.0)),
            (Vec3::Y, 8f32.to_radians(), Vec3::new(200.0, 150.0, 100.0)),
        ];
        let mut painted = [Vec3::ZERO; 2];
        for y in 0..h as usize {
            for x in 0..w as usize {
                let d = img.direction(x, y);
                for (k, (dir, r, c)) in lamps.into_iter().enumerate() {
                    if d.dot(dir) >= r.cos() {
                        img.texels[y * w as usize + x] += c;
                        painted[k] += c * img.texel_solid_angle(y);
                    }
                }
            }
        }
        let power = |img: &EnvImage| -> Vec3 {
            (0..(w * h) as usize)
                .map(|i| img.texels[i] * img.texel_solid_angle(i / w as usize))
                .sum()
        };
        let before = power(&img);
        let lights = img.extract_lights(4);
        assert_eq!(lights.len(), 2, "{lights:?}");
        for ((l, (dir, r, _)), want) in lights.iter().zip(lamps).zip(painted) {
            assert!((-l.direction).dot(dir) > 0.9995, "{l:?}");
            // Nearly all of the lamp: what is left is 2% of its peak.
            let got = l.irradiance;
            assert!(
                (got / want - Vec3::ONE).abs().max_element() < 0.03,
                "{got} against {want}"
            );
            assert!((l.angle / r - 1.0).abs() < 0.1, "{} against {r}", l.angle);
        }
        // Moved, not made.
        let after = power(&img) + lights.iter().map(|l| l.irradiance).sum::<Vec3>();
        assert!((after / before - Vec3::ONE).abs().max_element() < 1e-3);
        // An even sky has no lights; max bounds the count.
        assert!(EnvImage::uniform(Vec3::ONE).extract_lights(4).is_empty());
        let mut again = EnvImage::new(w, h, vec![Vec3::splat(0.2); (w * h) as usize]).unwrap();
        again.texels[100 * w as usize + 100] = Vec3::splat(1e5);
        assert_eq!(again.extract_lights(0).len(), 0);
    }

    #[test]
    fn the_built_in_studio_keeps_its_soft_panels() {
        // Its panels peak under 20 times its mean: no lights, no shadows.
        let mut studio = (*EnvImage::studio()).clone();
        assert!(studio.extract_lights(4).is_empty());
    }
}
