//! Drawing directions from an environment image in proportion to its
//! luminance (times the solid angle of each texel), with the density of
//! any direction: the environment's half of `method = "sampled"`'s
//! multiple importance sampling, and the bounce's.

use std::f32::consts::PI;

use glam::{Mat3, Vec2, Vec3};

use super::{direction_to_uv, uv_to_direction};
use crate::assets::environment::EnvImage;

/// Luminance-proportional sampling of an environment image.
#[derive(Debug, Clone)]
pub struct EnvSampler {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
    /// Per row: the cumulative weight of the rows above and including it.
    rows: Vec<f32>,
    /// Per texel: the cumulative weight within its row.
    cols: Vec<f32>,
    /// Per texel: its sampling weight (luminance plus a floor, times sin).
    weight: Vec<f32>,
    total: f32,
    env_from_world: Mat3,
    world_from_env: Mat3,
    intensity: f32,
}

pub(super) fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl EnvSampler {
    pub fn new(image: &EnvImage, intensity: f32, rotation_deg: f32) -> EnvSampler {
        let (w, h) = (image.width as usize, image.height as usize);
        let mean = image.texels.iter().map(|c| luminance(*c)).sum::<f32>() / (w * h) as f32;
        // A floor of a tenth of the mean: no direction has zero density.
        let floor = 0.1 * mean.max(1e-6);
        let mut weight = vec![0.0f32; w * h];
        let mut cols = vec![0.0f32; w * h];
        let mut rows = vec![0.0f32; h];
        let mut total = 0.0f32;
        for (y, row_end) in rows.iter_mut().enumerate() {
            let sin = ((y as f32 + 0.5) / h as f32 * PI).sin();
            let mut acc = 0.0f32;
            for x in 0..w {
                let i = y * w + x;
                weight[i] = (luminance(image.texels[i]) + floor) * sin;
                acc += weight[i];
                cols[i] = acc;
            }
            total += acc;
            *row_end = total;
        }
        let world_from_env = Mat3::from_rotation_y(rotation_deg.to_radians());
        EnvSampler {
            width: w,
            height: h,
            texels: image.texels.clone(),
            rows,
            cols,
            weight,
            total,
            env_from_world: world_from_env.transpose(),
            world_from_env,
            intensity,
        }
    }

    /// The texel a direction (environment space) falls in.
    fn texel(&self, d: Vec3) -> usize {
        let uv = direction_to_uv(d);
        let x = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        y * self.width + x
    }

    /// Radiance from world direction `d`.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        self.texels[self.texel(self.env_from_world * d)] * self.intensity
    }

    /// Density (per steradian) of drawing world direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let i = self.texel(self.env_from_world * d);
        let y = i / self.width;
        let sin = ((y as f32 + 0.5) / self.height as f32 * PI).sin();
        let texel_omega = (2.0 * PI / self.width as f32) * (PI / self.height as f32) * sin;
        if texel_omega <= 0.0 {
            return 0.0;
        }
        self.weight[i] / self.total / texel_omega
    }

    /// A world direction drawn from `xi` (uniform in [0, 1)^2).
    pub fn sample(&self, xi: Vec2) -> Vec3 {
        let t = xi.y * self.total;
        let y = self.rows.partition_point(|&r| r <= t).min(self.height - 1);
        let row = &self.cols[y * self.width..(y + 1) * self.width];
        let before = if y == 0 { 0.0 } else { self.rows[y - 1] };
        let row_total = row[self.width - 1].max(1e-30);
        let tx = (xi.x * row_total).min(row_total * 0.999_999);
        let x = row.partition_point(|&c| c <= tx).min(self.width - 1);
        // Where within the texel: the leftover of each choice.
        let start = if x == 0 { 0.0 } else { row[x - 1] };
        let fx = ((tx - start) / self.weight[y * self.width + x].max(1e-30)).clamp(0.0, 1.0);
        let fy = ((t - before) / (row_total)).clamp(0.0, 1.0);
        let uv = Vec2::new(
            (x as f32 + fx) / self.width as f32,
            (y as f32 + fy) / self.height as f32,
        );
        self.world_from_env * uv_to_direction(uv)
    }
}
