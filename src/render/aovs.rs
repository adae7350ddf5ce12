//! The data passes of a band (`output.normal`, `albedo`, `position`,
//! `id`): per pixel, of its nearest fragment (the one the depth comes
//! from), at that fragment's shading point, shaded by the lanes a group
//! of one draw at a time (`ShadeContext::aov_lanes`).

use glam::Vec3;

use super::band::{InterpolatorCache, fragments};
use super::fragment::BandInputs;
use super::frame::AovPixel;
use super::lanes::Pending;
use crate::raster::coverage::{NO_TRIANGLE, Visibility};
use crate::raster::interp::Fragment;
use crate::shade::lanes::{LaneMaterial, MAX_LANES};
use crate::shade::light::LightMask;

impl BandInputs<'_> {
    /// The data passes of a band into `out`; the background and the
    /// ground shadow catcher are `AovPixel::EMPTY`.
    pub fn aovs(&self, vis: &Visibility, out: &mut [AovPixel]) {
        let models = &self.setup.scene.models;
        let base = |count: fn(&crate::scene::Model) -> u32| -> Vec<u32> {
            models
                .iter()
                .scan(0u32, |acc, m| {
                    let base = *acc;
                    *acc += count(m);
                    Some(base)
                })
                .collect()
        };
        let material_base = base(|m| m.materials.len() as u32);
        let object_base = base(crate::scene::Model::object_count);
        let materials: Vec<LaneMaterial> = self
            .draws
            .iter()
            .enumerate()
            .map(|(draw, d)| {
                let (uvs, tangents) = self.mesh_inputs(draw);
                let m = &models[d.model].materials[d.material];
                LaneMaterial::for_aovs(&self.ctx, m, uvs, tangents)
            })
            .collect();
        // Per draw, in pixel order: the nearest fragments.
        let mut queued = self.nearest_fragments(vis, &materials, out);
        queued.sort_by_key(|&(draw, _)| draw);
        let width = self.lane_width;
        let mut res = [[Vec3::ZERO; 3]; MAX_LANES];
        for run in queued.chunk_by(|a, b| a.0 == b.0) {
            let draw = run[0].0 as usize;
            let d = self.draws[draw];
            for chunk in run.chunks(width) {
                let mut group = [chunk[chunk.len() - 1].1; MAX_LANES];
                for (g, c) in group.iter_mut().zip(chunk) {
                    *g = c.1;
                }
                self.aov_group((draw, &materials[draw]), &group, width, &mut res);
                for (c, &[normal, albedo, position]) in chunk.iter().zip(&res) {
                    out[c.1.pixel as usize] = AovPixel {
                        normal,
                        albedo,
                        position,
                        object: object_base[d.model] + d.part + 1,
                        material: material_base[d.model] + d.material as u32 + 1,
                    };
                }
            }
        }
    }

    /// Per covered pixel of the band, its nearest fragment as the lanes
    /// take it (with `materials`' footprints), by draw; the pixels
    /// nothing covers are set to `AovPixel::EMPTY` in `out`.
    fn nearest_fragments(
        &self,
        vis: &Visibility,
        materials: &[LaneMaterial],
        out: &mut [AovPixel],
    ) -> Vec<(u32, Pending)> {
        let rect = vis.rect;
        let tw = rect.width();
        let n = vis.samples();
        let mut cache = InterpolatorCache::default();
        let mut queued = Vec::new();
        for (i, a) in out.iter_mut().enumerate() {
            let (px, py) = (rect.x0 + (i % tw) as i32, rect.y0 + (i / tw) as i32);
            let frags = if n == 1 {
                smallvec::smallvec![(vis.id()[i], 1)]
            } else {
                fragments(&vis.id()[i * n..(i + 1) * n])
            };
            let mut best: Option<(f32, u32, Fragment)> = None;
            for (id, mask) in frags {
                if id == NO_TRIANGLE {
                    continue;
                }
                let it = cache.get(id, &self.tris[id as usize]);
                let frag = self.shading_point(it, px, py, mask);
                let d = self.point(&self.tris[id as usize], frag).view_depth;
                if best.is_none_or(|b| d < b.0) {
                    best = Some((d, id, frag));
                }
            }
            let Some((_, id, frag)) = best else {
                *a = AovPixel::EMPTY;
                continue;
            };
            let t = &self.tris[id as usize];
            let it = cache.get(id, t);
            let lm = &materials[t.draw as usize];
            let grads = self.lane_gradients(lm, t, it, (px & !1, py & !1));
            queued.push((
                t.draw,
                Pending {
                    id,
                    pixel: i as u32,
                    count: 1.0,
                    lambda: frag.lambda,
                    w: frag.w,
                    footprints: lm.footprints(&self.ctx, grads),
                    grads,
                    ao: 1.0,
                    lights: LightMask::ALL,
                    edge: f32::INFINITY,
                },
            ));
        }
        queued
    }
}
