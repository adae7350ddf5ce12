//! Environment images for image-based lighting: equirectangular (2:1
//! latitude-longitude) linear radiance, from Radiance `.hdr` (flat and RLE)
//! or OpenEXR (`R`, `G`, `B` of the first layer), top row = up (+Y).

use std::path::Path;

use glam::Vec3;

use crate::error::Error;

/// Linear RGB radiance, row-major from the top; `width == 2 * height`.
#[derive(Debug, Clone)]
pub struct EnvImage {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

impl EnvImage {
    /// Reads an `.hdr` or `.exr` environment. A file that is not 2:1, has
    /// fewer than 8 rows, or holds negative or non-finite radiance is
    /// refused, naming the file.
    pub fn load(path: &Path) -> Result<EnvImage, Error> {
        let bad = |message: String| Error::asset(path, None, message);
        if !path.is_file() {
            return Err(bad("environment file not found".into()));
        }
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let (width, height, texels) = match ext.as_str() {
            "hdr" => read_hdr(path).map_err(bad)?,
            "exr" => read_exr(path).map_err(bad)?,
            _ => {
                return Err(bad(format!(
                    "an environment is a .hdr or .exr file, not .{ext}"
                )));
            }
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
    pub fn studio() -> EnvImage {
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

fn read_hdr(path: &Path) -> Result<Texels, String> {
    let img = image::ImageReader::open(path)
        .map_err(|e| format!("cannot read the environment: {e}"))?
        .with_guessed_format()
        .map_err(|e| format!("cannot read the environment: {e}"))?
        .decode()
        .map_err(|e| format!("not a readable Radiance HDR image: {e}"))?
        .into_rgb32f();
    let (w, h) = img.dimensions();
    let texels = img.pixels().map(|p| Vec3::from(p.0)).collect();
    Ok((w, h, texels))
}

fn read_exr(path: &Path) -> Result<Texels, String> {
    use exr::prelude::read_first_rgba_layer_from_file;
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![Vec3::ZERO; size.width() * size.height()]),
        |(w, px): &mut (usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
        },
    )
    .map_err(|e| format!("not a readable OpenEXR RGB image: {e}"))?;
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
}
