//! The fragments of a band whose materials are shaded four at a time
//! (`ShadeContext::shade_lanes`): queued per draw while the band's quads
//! are walked, then gathered into groups of four of one draw and shaded
//! together. Each fragment's result is what the one-fragment path gives
//! it, so the band resolves its pixels in the same order with the same
//! values either way.

// Loops over the four lanes index several per-lane arrays at once.
#![allow(clippy::needless_range_loop)]

use glam::{Vec2, Vec3, Vec4};

use super::fragment::{FrameData, Sink};
use crate::assets::texture::Footprint;
use crate::assets::texture::Gradients;
use crate::raster::interp::Interpolator;
use crate::raster::setup::Tri;
use crate::shade::lanes::LaneMaterial;
use crate::shade::lanes::{Lanes, MAX_SIZES};
use crate::shade::light::LightMask;
use crate::simd::{V3, lanes4, lerp3};

/// A fragment waiting for its lane.
#[derive(Clone, Copy)]
pub(super) struct Pending {
    /// Triangle id.
    pub id: u32,
    /// The pixel the result goes to (its index in the band), or a marker
    /// the caller chose for results it collects by slot.
    pub pixel: u32,
    /// The samples of the pixel it covers (all of them, where it goes to
    /// its pixel).
    pub count: f32,
    /// Barycentrics at the shading point, and w there.
    pub lambda: Vec3,
    pub w: f32,
    /// Filter footprints per texture size (`LaneMaterial::footprints`).
    pub footprints: [Footprint; MAX_SIZES],
    pub ao: f32,
    /// The lights that may reach its tile.
    pub lights: LightMask,
}

/// A band's lane fragments waiting for their group of four: per draw, up
/// to three of them; the fourth shades the group at once.
pub(super) struct LaneBatches {
    waiting: Vec<Waiting>,
    /// The slot of the next fragment.
    next: u32,
    /// The corners of the band's recent triangles.
    pub corners: CornerCache,
}

/// How many triangles' corners a band keeps at hand.
const CACHED: usize = 16;

/// The corners of recently shaded triangles, by triangle id (slot: id
/// mod 16): the quads and groups of a band come back to the same few
/// triangles, whose corners are then gathered from the mesh once instead
/// of once per quad or group.
pub(super) struct CornerCache {
    ids: [u32; CACHED],
    corners: [Corners; CACHED],
}

impl CornerCache {
    fn new() -> CornerCache {
        CornerCache {
            // No triangle has this id: every slot starts empty.
            ids: [u32::MAX; CACHED],
            corners: [Corners::NONE; CACHED],
        }
    }

    /// Triangle `id`'s slot.
    #[inline(always)]
    fn slot(id: u32) -> usize {
        id as usize % CACHED
    }

    /// Puts the corners of triangle `id` (`t`, of draw `draw`) in its slot
    /// unless they are there.
    #[inline]
    fn fill(&mut self, data: &FrameData, draw: usize, id: u32, t: &Tri) {
        let k = Self::slot(id);
        if self.ids[k] != id {
            self.corners[k] = data.corners(draw, t);
            self.ids[k] = id;
        }
    }

    /// The corners of triangle `id` if they are in its slot.
    #[inline(always)]
    fn peek(&self, id: u32) -> Option<&Corners> {
        let k = Self::slot(id);
        (self.ids[k] == id).then(|| &self.corners[k])
    }

    /// The corners of triangle `id` (`t`, of draw `draw`).
    #[inline]
    pub fn get(&mut self, data: &FrameData, draw: usize, id: u32, t: &Tri) -> &Corners {
        self.fill(data, draw, id, t);
        &self.corners[Self::slot(id)]
    }
}

/// Up to four fragments of one draw, with their slots.
#[derive(Clone, Copy)]
struct Waiting {
    group: [Pending; 4],
    slots: [u32; 4],
    len: usize,
}

impl Pending {
    const NONE: Pending = Pending {
        id: 0,
        pixel: 0,
        count: 1.0,
        lambda: Vec3::ZERO,
        w: 0.0,
        footprints: [Footprint::Lod(0.0); MAX_SIZES],
        ao: 1.0,
        lights: LightMask::NONE,
    };
}

impl LaneBatches {
    pub fn new(draws: usize) -> LaneBatches {
        LaneBatches {
            waiting: vec![
                Waiting {
                    group: [Pending::NONE; 4],
                    slots: [0; 4],
                    len: 0,
                };
                draws
            ],
            next: 0,
            corners: CornerCache::new(),
        }
    }

    /// Adds `p` (of draw `draw`) as the next slot, which it returns; a
    /// full group of its draw is shaded into `sink`.
    #[inline]
    pub fn push(&mut self, data: &FrameData, draw: u32, p: Pending, sink: &mut Sink) -> u32 {
        let slot = self.next;
        self.next += 1;
        let w = &mut self.waiting[draw as usize];
        w.group[w.len] = p;
        w.slots[w.len] = slot;
        w.len += 1;
        if w.len == 4 {
            shade_group(data, draw as usize, w, &mut self.corners, sink);
            w.len = 0;
        }
        slot
    }

    /// Shades every group that is not full (its last fragment repeated).
    pub fn finish(&mut self, data: &FrameData, sink: &mut Sink) {
        for (draw, w) in self.waiting.iter_mut().enumerate() {
            if w.len > 0 {
                for k in w.len..4 {
                    w.group[k] = w.group[w.len - 1];
                }
                shade_group(data, draw, w, &mut self.corners, sink);
                w.len = 0;
            }
        }
    }
}

/// Shades the four fragments of draw `draw` in `w` and hands those it
/// holds to `sink` (linear colour, zero where not finite as the
/// one-fragment path has it).
fn shade_group(
    data: &FrameData,
    draw: usize,
    w: &Waiting,
    corners: &mut CornerCache,
    sink: &mut Sink,
) {
    let Some(lm) = data.lane_material(draw) else {
        return;
    };
    let (lanes, depth) = data.gather(draw, &w.group, corners);
    let c = data.ctx.shade_lanes(lm, &lanes);
    for k in 0..w.len {
        let c = c.lane(k);
        let c = if c.is_finite() { c } else { Vec3::ZERO };
        sink.put(w.slots[k], w.group[k].pixel, w.group[k].count, c, depth[k]);
    }
}

/// One triangle's corners as the lanes interpolate them.
#[derive(Clone, Copy)]
pub(super) struct Corners {
    world: [Vec3; 3],
    normal: [Vec3; 3],
    uv: [Vec2; 3],
    /// Per corner, with the bitangent sign in w (zero without tangents).
    tangent: [Vec4; 3],
    color: [Vec4; 3],
    /// Counter-clockwise as the camera sees it.
    front: bool,
}

impl Corners {
    /// What an empty cache slot holds.
    const NONE: Corners = Corners {
        world: [Vec3::ZERO; 3],
        normal: [Vec3::ZERO; 3],
        uv: [Vec2::ZERO; 3],
        tangent: [Vec4::ZERO; 3],
        color: [Vec4::ZERO; 3],
        front: false,
    };
}

/// Corner `j`'s `f` of four triangles, one per lane.
#[inline(always)]
fn corner3(c: &[&Corners; 4], j: usize, f: impl Fn(&Corners) -> [Vec3; 3]) -> V3 {
    V3::from_lanes([f(c[0])[j], f(c[1])[j], f(c[2])[j], f(c[3])[j]])
}

/// Corner `j`'s `f` (a 4-vector, of which xyz) of four triangles.
#[inline(always)]
fn corner4(c: &[&Corners; 4], j: usize, f: impl Fn(&Corners) -> [Vec4; 3]) -> V3 {
    V3::from_lanes([
        f(c[0])[j].truncate(),
        f(c[1])[j].truncate(),
        f(c[2])[j].truncate(),
        f(c[3])[j].truncate(),
    ])
}

impl<'a> FrameData<'a> {
    /// The corners of triangle `t` (of draw `draw`).
    #[inline]
    pub(super) fn corners(&self, draw: usize, t: &Tri) -> Corners {
        let d = self.draws[draw];
        let mesh = &self.fs.scene.models[d.model].mesh;
        let mv = &self.verts[d.model];
        let idx = mesh.triangles[t.prim as usize].map(|i| i as usize);
        let tt = &self.tangents[d.model];
        let tangent = if tt.is_empty() {
            [Vec4::ZERO; 3]
        } else {
            let c = t.prim as usize * 3;
            [tt[c], tt[c + 1], tt[c + 2]]
        };
        Corners {
            world: idx.map(|i| mv.world[i]),
            normal: idx.map(|i| mv.normal[i]),
            uv: if mesh.uvs.is_empty() {
                [Vec2::ZERO; 3]
            } else {
                idx.map(|i| mesh.uvs[i])
            },
            tangent,
            color: if mesh.colors.is_empty() {
                [Vec4::ONE; 3]
            } else {
                idx.map(|i| mesh.colors[i])
            },
            front: t.front,
        }
    }

    /// Four fragments of draw `draw` as the lanes take them: lane k at
    /// barycentrics (`lx`, `ly`, `lz`)[k] and w `w`[k] of the triangle
    /// with `corners[k]`, interpolated as `point` and `surface` interpolate
    /// one fragment (the same operations in the same order, four at a
    /// time); and their view depths.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn lanes(
        &self,
        draw: usize,
        corners: &[&Corners; 4],
        l: V3,
        w: Vec4,
        ao: Vec4,
        footprints: [[Footprint; 4]; MAX_SIZES],
        lights: LightMask,
    ) -> (Lanes, Vec4) {
        let d = self.draws[draw];
        let mesh = &self.fs.scene.models[d.model].mesh;
        let ctx = &self.ctx;
        let world = |k: &Corners| k.world;
        let position = lerp3(
            corner3(corners, 0, world),
            corner3(corners, 1, world),
            corner3(corners, 2, world),
            l,
        );
        let depth = if ctx.orthographic {
            (position - V3::splat(ctx.eye)).dot(V3::splat(ctx.forward))
        } else {
            w
        };
        let nrm = |k: &Corners| k.normal;
        let n = lerp3(
            corner3(corners, 0, nrm),
            corner3(corners, 1, nrm),
            corner3(corners, 2, nrm),
            l,
        )
        .normalize_or(V3::splat(Vec3::Y));
        let front = lanes4(
            corners[0].front as u32 as f32,
            corners[1].front as u32 as f32,
            corners[2].front as u32 as f32,
            corners[3].front as u32 as f32,
        )
        .cmpgt(Vec4::ZERO);
        let normal = V3::select(front, n, -n);
        let mut geo_normal = [Vec3::ZERO; 4];
        for k in 0..4 {
            let n = normal.lane(k);
            geo_normal[k] = if self.geo_normal {
                let [a, b, c] = corners[k].world;
                let g = (b - a).cross(c - a).normalize_or(n);
                if g.dot(ctx.view_vector(position.lane(k))) < 0.0 {
                    -g
                } else {
                    g
                }
            } else {
                n
            };
        }
        let uv = |j: usize| {
            let p = [
                corners[0].uv[j],
                corners[1].uv[j],
                corners[2].uv[j],
                corners[3].uv[j],
            ];
            (
                lanes4(p[0].x, p[1].x, p[2].x, p[3].x),
                lanes4(p[0].y, p[1].y, p[2].y, p[3].y),
            )
        };
        let ((u0, v0), (u1, v1), (u2, v2)) = (uv(0), uv(1), uv(2));
        let tan = |k: &Corners| k.tangent;
        let tangent = lerp3(
            corner4(corners, 0, tan),
            corner4(corners, 1, tan),
            corner4(corners, 2, tan),
            l,
        );
        let color = (!mesh.colors.is_empty()).then(|| {
            let col = |k: &Corners| k.color;
            lerp3(
                corner4(corners, 0, col),
                corner4(corners, 1, col),
                corner4(corners, 2, col),
                l,
            )
        });
        let sign = lanes4(
            corners[0].tangent[0].w,
            corners[1].tangent[0].w,
            corners[2].tangent[0].w,
            corners[3].tangent[0].w,
        );
        let lanes = Lanes {
            position,
            normal,
            u: u0 * l.x + u1 * l.y + u2 * l.z,
            v: v0 * l.x + v1 * l.y + v2 * l.z,
            tangent,
            sign,
            color,
            geo_normal,
            ao,
            footprints,
            lights,
        };
        (lanes, depth)
    }

    /// The four pixels of the quad whose top-left pixel is `q0`, all of
    /// triangle `t` (interpolated by `it`) of lane material `lm`, one
    /// sample each: per pixel in reading order, the linear colour (zero
    /// where not finite) and view depth, as `fragment` and the lanes give
    /// them pixel by pixel. The quad's texture derivatives are its lanes'
    /// differences (what `gradients0` computes).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn shade_quad(
        &self,
        t: &Tri,
        it: &Interpolator,
        lm: &LaneMaterial<'a>,
        q0: (i32, i32),
        ao: [f32; 4],
        lights: LightMask,
        corners: &Corners,
    ) -> [(Vec3, f32); 4] {
        let draw = t.draw as usize;
        let (x, y) = q0;
        let px = [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)];
        let centers = px.map(|(x, y)| it.at_pixel(x, y));
        // With MSAA the shading point leaves a center the triangle does not
        // cover (`shading_point`); the derivatives stay the centers'.
        let f = if self.pattern.len() == 1 {
            centers
        } else {
            // `shading_point`: the center where the triangle covers it
            // (computed above), else the covered samples' centroid.
            let all = (1u32 << self.pattern.len()) - 1;
            [0, 1, 2, 3].map(|k| {
                let (x, y) = px[k];
                if it.covers_center(x, y) {
                    centers[k]
                } else {
                    self.shading_point(it, x, y, all)
                }
            })
        };
        let l = V3::from_lanes([f[0].lambda, f[1].lambda, f[2].lambda, f[3].lambda]);
        let uv = |k: usize| {
            let c = &corners.uv;
            let l = centers[k].lambda;
            c[0] * l.x + c[1] * l.y + c[2] * l.z
        };
        let grads = if self.grads {
            let a = uv(0);
            Gradients {
                dx: uv(1) - a,
                dy: uv(2) - a,
            }
        } else {
            Gradients::default()
        };
        let fp = lm.footprints(&self.ctx, grads);
        let footprints = [[fp[0]; 4], [fp[1]; 4], [fp[2]; 4]];
        let (lanes, depth) = self.lanes(
            draw,
            &[corners; 4],
            l,
            lanes4(f[0].w, f[1].w, f[2].w, f[3].w),
            lanes4(ao[0], ao[1], ao[2], ao[3]),
            footprints,
            lights,
        );
        let c = self.ctx.shade_lanes(lm, &lanes);
        let out = |k: usize| {
            let c = c.lane(k);
            (if c.is_finite() { c } else { Vec3::ZERO }, depth[k])
        };
        [out(0), out(1), out(2), out(3)]
    }

    /// Four queued fragments of draw `draw` as the lanes take them, and
    /// their view depths.
    fn gather(
        &self,
        draw: usize,
        frags: &[Pending; 4],
        cache: &mut CornerCache,
    ) -> (Lanes, [f32; 4]) {
        let tri = |k: usize| &self.tris[frags[k].id as usize];
        for f in frags {
            cache.fill(self, draw, f.id, &self.tris[f.id as usize]);
        }
        // Two of the lanes' triangles may share a slot; then the corners
        // are gathered here.
        let cached = frags.map(|f| cache.peek(f.id));
        if let [Some(a), Some(b), Some(c), Some(d)] = cached {
            return self.gather_from(draw, frags, &[a, b, c, d]);
        }
        let c0 = self.corners(draw, tri(0));
        // Neighbouring fragments mostly share a triangle.
        let c1 = if frags[1].id == frags[0].id {
            c0
        } else {
            self.corners(draw, tri(1))
        };
        let c2 = if frags[2].id == frags[1].id {
            c1
        } else {
            self.corners(draw, tri(2))
        };
        let c3 = if frags[3].id == frags[2].id {
            c2
        } else {
            self.corners(draw, tri(3))
        };
        self.gather_from(draw, frags, &[&c0, &c1, &c2, &c3])
    }

    /// `gather` with the lanes' triangles' corners at hand.
    fn gather_from(
        &self,
        draw: usize,
        frags: &[Pending; 4],
        corners: &[&Corners; 4],
    ) -> (Lanes, [f32; 4]) {
        let mut footprints = [[Footprint::Lod(0.0); 4]; MAX_SIZES];
        for (k, f) in frags.iter().enumerate() {
            for (s, fp) in footprints.iter_mut().enumerate() {
                fp[k] = f.footprints[s];
            }
        }
        let f = |k: usize| &frags[k];
        let (lanes, depth) = self.lanes(
            draw,
            corners,
            V3::from_lanes([f(0).lambda, f(1).lambda, f(2).lambda, f(3).lambda]),
            lanes4(f(0).w, f(1).w, f(2).w, f(3).w),
            lanes4(f(0).ao, f(1).ao, f(2).ao, f(3).ao),
            footprints,
            frags.iter().fold(LightMask::NONE, |m, f| m.union(f.lights)),
        );
        (lanes, depth.to_array())
    }
}
