//! The fragments of a band whose materials are shaded four at a time
//! (`ShadeContext::shade_lanes`): queued per draw while the band's quads
//! are walked, then gathered into groups of four of one draw and shaded
//! together. Each fragment's result is what the one-fragment path gives
//! it, so the band resolves its pixels in the same order with the same
//! values either way.

// Loops over the four lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Vec3, Vec4};

use super::band::FrameData;
use crate::assets::texture::Footprint;
use crate::shade::blinn_phong4::{Lanes, MAX_SIZES};
use crate::shade::lanes::V3;

/// A fragment waiting for its lane.
#[derive(Clone, Copy)]
pub(super) struct Pending {
    /// Triangle id.
    pub id: u32,
    /// The pixel the result goes to (its index in the band), or a marker
    /// the caller chose for results it collects by slot.
    pub pixel: u32,
    /// Barycentrics at the shading point, and w there.
    pub lambda: Vec3,
    pub w: f32,
    /// Filter footprints per texture size (`LaneMaterial::footprints`).
    pub footprints: [Footprint; MAX_SIZES],
    pub ao: f32,
}

/// A band's queued fragments, and per draw the ones of that draw.
pub(super) struct LaneQueue {
    pending: Vec<Pending>,
    by_draw: Vec<Vec<u32>>,
}

impl LaneQueue {
    pub fn new(draws: usize) -> LaneQueue {
        LaneQueue {
            pending: Vec::new(),
            by_draw: vec![Vec::new(); draws],
        }
    }

    /// Queues `p` (of draw `draw`) in the next slot.
    #[inline]
    pub fn push(&mut self, draw: u32, p: Pending) {
        let slot = self.pending.len() as u32;
        self.pending.push(p);
        self.by_draw[draw as usize].push(slot);
    }

    /// Fragments queued so far (the next slot).
    pub fn len(&self) -> u32 {
        self.pending.len() as u32
    }

    pub fn is_empty(&self) -> bool {
        self.pending.is_empty()
    }

    /// Shades every queued fragment and hands `done(slot, pixel, colour,
    /// view depth)` each result: linear colour, zero where not finite (as
    /// the one-fragment path has it).
    pub fn shade(&self, data: &FrameData, mut done: impl FnMut(u32, u32, Vec3, f32)) {
        for (draw, slots) in self.by_draw.iter().enumerate() {
            let Some(lm) = data.lane_material(draw) else {
                continue;
            };
            for group in slots.chunks(4) {
                // A short last group repeats its last fragment.
                let at = |k: usize| &self.pending[group[k.min(group.len() - 1)] as usize];
                let frags = [at(0), at(1), at(2), at(3)];
                let (lanes, depth) = data.gather(draw, &frags);
                let c = data.ctx.shade_lanes(lm, &lanes);
                for (k, &slot) in group.iter().enumerate() {
                    let c = c.lane(k);
                    let c = if c.is_finite() { c } else { Vec3::ZERO };
                    done(slot, frags[k].pixel, c, depth[k]);
                }
            }
        }
    }
}

impl FrameData<'_> {
    /// Four queued fragments of draw `draw` as the lanes take them (each
    /// lane interpolated as `point` and `surface` interpolate one
    /// fragment, in the same order), and their view depths.
    fn gather(&self, draw: usize, frags: &[&Pending; 4]) -> (Lanes, [f32; 4]) {
        let d = self.draws[draw];
        let model = &self.fs.scene.models[d.model];
        let mesh = &model.mesh;
        let mv = &self.verts[d.model];
        let ctx = &self.ctx;
        let mut position = [Vec3::ZERO; 4];
        let mut normal = [Vec3::ZERO; 4];
        let mut geo_normal = [Vec3::ZERO; 4];
        let mut depth = [0.0f32; 4];
        let mut u = [0.0f32; 4];
        let mut v = [0.0f32; 4];
        let mut tangent = [Vec3::ZERO; 4];
        let mut sign = [0.0f32; 4];
        let mut color = [Vec3::ONE; 4];
        let mut ao = [1.0f32; 4];
        let mut footprints = [[Footprint::Lod(0.0); 4]; MAX_SIZES];
        for (k, f) in frags.iter().enumerate() {
            let t = &self.tris[f.id as usize];
            let idx = mesh.triangles[t.prim as usize].map(|i| i as usize);
            let l = f.lambda;
            let lerp3 = |a: &[Vec3]| a[idx[0]] * l.x + a[idx[1]] * l.y + a[idx[2]] * l.z;
            let p = lerp3(&mv.world);
            position[k] = p;
            depth[k] = if ctx.orthographic {
                (p - ctx.eye).dot(ctx.forward)
            } else {
                f.w
            };
            let n = lerp3(&mv.normal).normalize_or(Vec3::Y);
            let n = if t.front { n } else { -n };
            normal[k] = n;
            geo_normal[k] = if self.geo_normal {
                let [a, b, c] = idx.map(|i| mv.world[i]);
                let g = (b - a).cross(c - a).normalize_or(n);
                if g.dot(ctx.view_vector(p)) < 0.0 {
                    -g
                } else {
                    g
                }
            } else {
                n
            };
            let uv = &mesh.uvs;
            if !uv.is_empty() {
                let t = uv[idx[0]] * l.x + uv[idx[1]] * l.y + uv[idx[2]] * l.z;
                (u[k], v[k]) = (t.x, t.y);
            }
            if !mesh.colors.is_empty() {
                let c = &mesh.colors;
                color[k] = (c[idx[0]] * l.x + c[idx[1]] * l.y + c[idx[2]] * l.z).truncate();
            }
            if !mv.tangent.is_empty() {
                let c = t.prim as usize * 3;
                let tt = &mv.tangent;
                tangent[k] = (tt[c] * l.x + tt[c + 1] * l.y + tt[c + 2] * l.z).truncate();
                sign[k] = tt[c].w;
            }
            ao[k] = f.ao;
            for (s, fp) in footprints.iter_mut().enumerate() {
                fp[k] = f.footprints[s];
            }
        }
        let lanes = Lanes {
            position: V3::from_lanes(position),
            normal: V3::from_lanes(normal),
            u: Vec4::from(u),
            v: Vec4::from(v),
            tangent: V3::from_lanes(tangent),
            sign: Vec4::from(sign),
            color: (!mesh.colors.is_empty()).then(|| V3::from_lanes(color)),
            geo_normal,
            ao: Vec4::from(ao),
            footprints,
        };
        (lanes, depth)
    }
}
