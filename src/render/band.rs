//! One band of the frame: visibility (depth test, with the alpha test of
//! cutout materials), then shading of each visible pixel in 2x2 quads, then
//! the blended (transparent) triangles, back to front, over the result.
//!
//! Quads give texture-coordinate derivatives the way a GPU does: each
//! triangle present in a quad is interpolated at all four of its pixel
//! centers (extrapolated where it does not cover them, "helper lanes"), and
//! the differences across the quad's top row and left column are d/dx and
//! d/dy ("coarse" derivatives).
//!
//! With MSAA, coverage and depth are per sample and each triangle present
//! in a pixel is shaded once there: at the pixel center when the center is
//! inside it, otherwise at the centroid of the samples it covers. The
//! resolve averages the fragments' linear colors weighted by their sample
//! counts, before tone mapping.

use glam::{Vec3, Vec4};

use super::display::PlainBackground;
use super::fragment::{BandInputs, LANE_SLOT, PixelShare, Sink, resolve};
use super::lanes::{LaneBatches, Pending, QuadAt};
use super::surface::FragmentLighting;
use crate::assets::texture::Gradients;
use crate::raster::bin::TileRect;
use crate::raster::coverage::{
    MAX_SAMPLES, NO_TRIANGLE, Visibility, in_front, raster_samples, raster_triangle,
};
use crate::raster::interp::{Fragment, Interpolator};
use crate::raster::setup::Tri;
use crate::scene::material::AlphaMode;
use crate::shade::ao::GPixel;
use crate::shade::lanes::{Footprints, LaneMaterial};
use crate::shade::light::LightMask;

/// A worker thread's buffers for `shade_visible`, kept from band to band
/// (grown anew in each band, they cost 1% of an MSAA frame's
/// instructions): the lane results kept by slot, and the pixels resolved
/// after the lanes, with their fragments.
#[derive(Default)]
struct Scratch {
    shaded: Vec<(Vec3, f32)>,
    deferred: Vec<(usize, smallvec::SmallVec<[PixelShare; 4]>)>,
}

thread_local! {
    static SCRATCH: std::cell::Cell<Scratch> = std::cell::Cell::new(Scratch::default());
}

impl<'a> BandInputs<'a> {
    /// Visibility of band `ti` (pixels `rect`): the nearest opaque or
    /// alpha-tested triangle per pixel, and the blended triangles to
    /// composite over them. `bins`: per setup chunk, its per-band triangle
    /// lists and the index of its first triangle.
    pub fn visibility(
        &self,
        rect: TileRect,
        ti: usize,
        bins: &[(&[Vec<u32>], u32)],
    ) -> (Visibility, Vec<u32>) {
        let mut vis = Visibility::new(rect, self.reverse, self.pattern);
        let mut blended = Vec::new();
        for (b, off) in bins {
            for &i in &b[ti] {
                let id = off + i;
                let t = &self.tris[id as usize];
                match self.alpha[t.draw as usize] {
                    AlphaMode::Opaque => self.draw_opaque(&mut vis, t, id),
                    AlphaMode::Mask(cutoff) => {
                        let it = Interpolator::new(t);
                        let keep = |px: i32, py: i32, (ox, oy): (i8, i8)| {
                            let f = if (ox, oy) == (0, 0) {
                                it.at_pixel(px, py)
                            } else {
                                it.at(
                                    px as f64 + 0.5 + ox as f64 / 16.0,
                                    py as f64 + 0.5 + oy as f64 / 16.0,
                                )
                            };
                            let (m, uv, color) = self.material_uv(t, f.lambda);
                            self.ctx.opacity_at(m, uv, color) >= cutoff
                        };
                        if self.reverse {
                            vis.draw_if::<true>(t, id, keep);
                        } else {
                            vis.draw_if::<false>(t, id, keep);
                        }
                    }
                    AlphaMode::Blend => blended.push(id),
                }
            }
        }
        (vis, blended)
    }

    /// Shades a band's visible pixels into its rows of the frame, then
    /// composites its blended triangles. `ao`: the band's ambient
    /// occlusion per pixel, when the scene asks for it. `known`: what the
    /// band's rows already hold, where the last frame rendered into them
    /// left plain background (pixels of that colour and infinite depth
    /// outside its columns), which then need no filling again. Returns,
    /// where it is known, the flat background: its colour and the columns
    /// outside which every pixel of the band holds exactly that colour
    /// and infinite depth.
    pub fn shade_band(
        &self,
        vis: &Visibility,
        blended: Vec<u32>,
        ao: Option<&[f32]>,
        known: Option<PlainBackground>,
        color: &mut [Vec4],
        depth: &mut [f32],
    ) -> Option<PlainBackground> {
        let plain = self.shade_visible(vis, ao, known, color, depth);
        if !blended.is_empty() {
            self.blend(vis, blended, color);
            // Blended layers may lie anywhere.
            return None;
        }
        plain
    }

    /// The geometry buffer of a band: view depth, interpolated normal and
    /// geometric normal (both facing the camera) and position per pixel;
    /// depth +inf where nothing is visible.
    /// With MSAA: of the triangle covering most samples of the pixel, at
    /// its shading point.
    pub fn gbuffer(&self, vis: &Visibility, out: &mut [GPixel]) {
        let rect = vis.rect;
        let tw = rect.width();
        let n = vis.samples();
        let mut cache = InterpolatorCache::default();
        for (i, g) in out.iter_mut().enumerate() {
            let (id, mask) = if n == 1 {
                (vis.id()[i], 1)
            } else {
                fragments(&vis.id()[i * n..(i + 1) * n])
                    .into_iter()
                    .filter(|f| f.0 != NO_TRIANGLE)
                    .fold((NO_TRIANGLE, 0u32), |best, f| {
                        if f.1.count_ones() > best.1.count_ones() {
                            f
                        } else {
                            best
                        }
                    })
            };
            if id == NO_TRIANGLE {
                *g = GPixel::EMPTY;
                continue;
            }
            let t = &self.tris[id as usize];
            let it = cache.get(id, t);
            let (px, py) = (rect.x0 + (i % tw) as i32, rect.y0 + (i / tw) as i32);
            let frag = self.shading_point(it, px, py, mask);
            let p = self.point(t, frag);
            *g = GPixel {
                depth: p.view_depth,
                position: p.position,
                normal: p.normal,
                geo_normal: p.geo_normal,
                roughness: self.roughness_factor(t.draw as usize),
            };
        }
    }

    /// The perceptual roughness of draw `draw`'s material where it is one
    /// factor for the whole surface (shaded as metallic-roughness, no
    /// roughness map); -1 otherwise.
    fn roughness_factor(&self, draw: usize) -> f32 {
        let d = self.draws[draw];
        let m = &self.setup.scene.models[d.model].materials[d.material];
        crate::shade::env::reflect::pass_roughness(self.ctx.mode, m).unwrap_or(-1.0)
    }

    #[inline]
    fn draw_opaque(&self, vis: &mut Visibility, t: &Tri, id: u32) {
        if self.reverse {
            vis.draw::<true>(t, id);
        } else {
            vis.draw::<false>(t, id);
        }
    }

    /// Blended triangles, farthest first (by mean depth; ties in submission
    /// order), each pixel in front of the opaque surface composited over it.
    /// With MSAA a triangle is shaded once per pixel over the samples where
    /// it is in front of the opaque surface and composited over each of
    /// those samples, which start as the pixel's opaque colour (exact where
    /// the surface behind is one color); the pixel is then their mean. So
    /// two triangles that share an edge inside a pixel cover it once
    /// between them: composited over the whole pixel by their shares, the
    /// surface behind would show through the edge twice.
    pub(super) fn blend(&self, vis: &Visibility, mut ids: Vec<u32>, color: &mut [Vec4]) {
        let far_key = |id: &u32| {
            let z = self.tris[*id as usize].z;
            let mean = (z[0] + z[1] + z[2]) / 3.0;
            // Larger key = farther.
            if self.reverse { -mean } else { mean }
        };
        ids.sort_by(|a, b| far_key(b).total_cmp(&far_key(a)).then(a.cmp(b)));
        let n = vis.samples();
        let full = if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
        // With MSAA, the pixels some layer covers in part (`split`, in the
        // order they were reached), their samples' colours (n per pixel in
        // `samples`) and per pixel of the band its place in `split`.
        const NONE: u32 = u32::MAX;
        let (mut split, mut samples) = (Vec::new(), Vec::new());
        let mut slot = if n > 1 {
            vec![NONE; color.len()]
        } else {
            Vec::new()
        };
        let over = |dst: Vec4, (add, through, a): (Vec3, Vec3, f32)| {
            (add + dst.truncate() * through).extend(a + dst.w * (1.0 - a))
        };
        let (mut frags, mut masks, mut layers) = (Vec::new(), Vec::new(), Vec::new());
        for id in ids {
            let t = &self.tris[id as usize];
            let it = Interpolator::new(t);
            let lm = self.lane_material(t.draw as usize);
            frags.clear();
            masks.clear();
            self.layer_fragments(vis, (t, &it, id), lm, (&mut frags, &mut masks));
            layers.clear();
            self.layers(t, &frags, &mut layers);
            for ((f, &mask), &layer) in frags.iter().zip(&masks).zip(&layers) {
                // A layer whose shading is not finite (degenerate input)
                // is skipped.
                if !(layer.0.is_finite() && layer.1.is_finite()) {
                    continue;
                }
                let i = f.pixel as usize;
                // Until a layer covers part of a pixel, its samples are
                // all the pixel's colour: a whole pixel is composited as one.
                if n == 1 || (mask == full && slot[i] == NONE) {
                    color[i] = over(color[i], layer);
                    continue;
                }
                if slot[i] == NONE {
                    slot[i] = split.len() as u32;
                    split.push(i);
                    samples.extend(std::iter::repeat_n(color[i], n));
                }
                let k = slot[i] as usize;
                for (s, dst) in samples[k * n..(k + 1) * n].iter_mut().enumerate() {
                    if mask & (1 << s) != 0 {
                        *dst = over(*dst, layer);
                    }
                }
            }
        }
        let inv_n = 1.0 / n as f32;
        for (&i, px) in split.iter().zip(samples.chunks_exact(n.max(1))) {
            color[i] = px.iter().fold(Vec4::ZERO, |acc, s| acc + *s) * inv_n;
        }
    }

    /// The fragments of the blended triangle `t` (id `id`) in front of the
    /// opaque surface, in raster order: per pixel its shading point, the
    /// fraction of the pixel's samples it covers there (`count`) and its
    /// filter footprints for its material `lm`; and in `masks`, the
    /// samples it covers (bit s: sample s; 1 without MSAA).
    fn layer_fragments(
        &self,
        vis: &Visibility,
        (t, it, id): (&Tri, &Interpolator, u32),
        lm: &LaneMaterial,
        (out, masks): (&mut Vec<Pending>, &mut Vec<u32>),
    ) {
        let rect = vis.rect;
        let tw = rect.width();
        let n = vis.samples();
        let mut quad: Option<((i32, i32), Footprints, [Gradients; 2])> = None;
        let mut push = |px: i32, py: i32, frag: Fragment, count: f32| {
            let q0 = (px & !1, py & !1);
            let (footprints, grads) = match quad {
                Some((q, f, g)) if q == q0 => (f, g),
                _ => {
                    let g = self.lane_gradients(lm, t, it, q0);
                    let f = lm.footprints(&self.ctx, g);
                    quad = Some((q0, f, g));
                    (f, g)
                }
            };
            out.push(Pending {
                id,
                pixel: ((py - rect.y0) as usize * tw + (px - rect.x0) as usize) as u32,
                count,
                lambda: frag.lambda,
                w: frag.w,
                footprints,
                grads,
                ao: 1.0,
                // Blended fragments may lie in front of the tile's visible
                // depths: every light.
                lights: LightMask::ALL,
                edge: self.edge_distance(it, px, py, frag.lambda),
            });
        };
        if n == 1 {
            raster_triangle(t, rect, |px, py, z| {
                let i = (py - rect.y0) as usize * tw + (px - rect.x0) as usize;
                if in_front(z, vis.depth()[i], self.reverse) {
                    push(px, py, it.at_pixel(px, py), 1.0);
                    masks.push(1);
                }
            });
            return;
        }
        raster_samples(t, rect, self.pattern, |px, py, mask, z| {
            let i = (py - rect.y0) as usize * tw + (px - rect.x0) as usize;
            let mut m = 0u32;
            for (s, &zs) in z.iter().enumerate().take(n) {
                if mask & (1 << s) != 0 && in_front(zs, vis.depth()[i * n + s], self.reverse) {
                    m |= 1 << s;
                }
            }
            if m != 0 {
                let frag = self.shading_point(it, px, py, m);
                push(px, py, frag, m.count_ones() as f32 / n as f32);
                masks.push(m);
            }
        });
    }

    /// Shades each triangle visible in a pixel once (one per pixel without
    /// MSAA), quad by quad so that a triangle's texture derivatives are
    /// computed once per quad, and resolves: the fragments' colors weighted
    /// by their sample counts, plus the background over the uncovered
    /// samples. Depth: the nearest fragment's.
    fn shade_visible(
        &self,
        vis: &Visibility,
        ao: Option<&[f32]>,
        known: Option<PlainBackground>,
        color: &mut [Vec4],
        depth: &mut [f32],
    ) -> Option<PlainBackground> {
        let rect = vis.rect;
        let (tw, th) = (rect.width(), rect.height());
        let n = vis.samples();
        let inv_n = 1.0 / n as f32;
        let mut cache = InterpolatorCache::default();
        // One background color for the band (none of the per-pixel kinds).
        let flat_bg = (self.env_bg.is_none() && self.ground.is_none()).then_some(self.bg);
        // The lights that may reach each tile of the band.
        let tiles = self
            .culling
            .as_ref()
            .map(|c| c.tiles(self.ctx.lights, vis, self.tris));
        let lights_at = |x: usize| tiles.as_ref().map_or(LightMask::ALL, |t| t.at(x));
        // Over a flat background: the empty pixels first, in one pass, and
        // quads without a triangle skipped below.
        let filled = flat_bg.is_some();
        let empty_at = |i: usize| empty(vis, i);
        let (spans, drawn) = self.fill_background(vis, filled, known, color, depth);
        let lanes = &mut LaneBatches::new(self.draws.len(), self.lane_width);
        // (Taken, so that a band shaded within this one on the same
        // thread finds none and makes its own.)
        let mut scratch = SCRATCH.take();
        let Scratch { shaded, deferred } = &mut scratch;
        shaded.clear();
        let sink = &mut Sink {
            color: &mut *color,
            depth: &mut *depth,
            shaded,
            inv_n,
        };
        for qy in (0..th).step_by(2) {
            let below = spans.get(qy + 1).copied().unwrap_or((usize::MAX, 0));
            let (x0, x1) = (spans[qy].0.min(below.0), spans[qy].1.max(below.1));
            if x0 >= x1 {
                continue;
            }
            for qx in (x0 & !1..x1).step_by(2) {
                if filled {
                    let at = |x: usize, y: usize| x >= tw || y >= th || empty_at(y * tw + x);
                    if at(qx, qy) && at(qx + 1, qy) && at(qx, qy + 1) && at(qx + 1, qy + 1) {
                        continue;
                    }
                }
                // A quad of one triangle: its four pixels are lanes.
                if qx + 1 < tw && qy + 1 < th {
                    let lights = lights_at(qx);
                    let out = (&mut *sink.color, &mut *sink.depth);
                    if self.lane_quad(vis, (qx, qy), lanes, &mut cache, (ao, lights), out) {
                        continue;
                    }
                }
                // Per triangle present in the quad: its texture-coordinate
                // derivatives and the filter footprints computed from them.
                let mut quad: smallvec::SmallVec<[QuadEntry; 4]> = smallvec::SmallVec::new();
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (x, y) = (qx + dx, qy + dy);
                    if x >= tw || y >= th {
                        continue;
                    }
                    let i = y * tw + x;
                    let ids = &vis.id()[i * n..(i + 1) * n];
                    let (px, py) = (rect.x0 + x as i32, rect.y0 + y as i32);
                    let empty = ids[0] == NO_TRIANGLE && ids.iter().all(|&id| id == NO_TRIANGLE);
                    let bg = match flat_bg {
                        Some(bg) => bg,
                        // Only where the background shows (some sample is
                        // uncovered) is its per-pixel color needed.
                        None if empty || ids.contains(&NO_TRIANGLE) => self.background_at(px, py),
                        None => Vec4::ZERO,
                    };
                    if empty {
                        if filled {
                            continue;
                        }
                        sink.color[i] = bg;
                        sink.depth[i] = f32::INFINITY;
                        continue;
                    }
                    let occlusion = ao.map_or(1.0, |a| a[i]);
                    let q0 = (rect.x0 + qx as i32, rect.y0 + qy as i32);
                    let mut at = FragmentAt {
                        px: (px, py),
                        q0,
                        reach: FragmentLighting {
                            ao: occlusion,
                            lights: lights_at(x),
                        },
                        cache: &mut cache,
                        quad: &mut quad,
                    };
                    if ids[1..].iter().all(|&s| s == ids[0]) {
                        // One fragment over every sample: the lanes write
                        // it.
                        let all = (1u32 << n) - 1;
                        self.fragment(&mut at, (ids[0], all), i as u32, (lanes, sink));
                        continue;
                    }
                    // (Filled where it is kept: a pixel's parts are over a
                    // hundred bytes.)
                    deferred.push((i, smallvec::SmallVec::new()));
                    if let Some((_, parts)) = deferred.last_mut() {
                        self.pixel_parts(&mut at, (ids, bg), (lanes, sink), parts);
                    }
                }
            }
        }
        // The lanes' last groups, then the pixels that wait for them.
        lanes.finish(self, sink);
        for (i, parts) in deferred.drain(..) {
            (sink.color[i], sink.depth[i]) = resolve(&parts, sink.shaded, inv_n);
        }
        SCRATCH.set(scratch);
        // Over a flat background, the pixels outside the drawn columns
        // were filled with it above, and no quad reaches them.
        filled.then_some(PlainBackground {
            color: self.bg,
            columns: drawn,
        })
    }

    /// Shades the quad whose top-left band pixel is (qx, qy) with the
    /// lanes where one triangle covers all its samples (and says so),
    /// into `color` and `depth`.
    fn lane_quad(
        &self,
        vis: &Visibility,
        (qx, qy): (usize, usize),
        b: &mut LaneBatches,
        cache: &mut InterpolatorCache,
        (ao, lights): (Option<&[f32]>, LightMask),
        (color, depth): (&mut [Vec4], &mut [f32]),
    ) -> bool {
        let (rect, n) = (vis.rect, vis.samples());
        let tw = rect.width();
        let i0 = qy * tw + qx;
        let quad = [i0, i0 + 1, i0 + tw, i0 + tw + 1];
        let id = vis.id()[i0 * n];
        let one = |i: usize| vis.id()[i * n..(i + 1) * n].iter().all(|&s| s == id);
        if id == NO_TRIANGLE || !quad.iter().all(|&i| one(i)) {
            return false;
        }
        let t = &self.tris[id as usize];
        let lm = self.lane_material(t.draw as usize);
        if lm.extra_slots() > 0 {
            // Its slots past the footprints a quad carries are computed
            // per fragment (`extra_footprints`).
            return false;
        }
        let q = QuadAt {
            t,
            id,
            it: cache.get(id, t),
            lm,
            q0: (rect.x0 + qx as i32, rect.y0 + qy as i32),
            ao: ao.map_or([1.0; 4], |a| quad.map(|i| a[i])),
            lights,
        };
        b.quad(self, q, quad, (color, depth), n);
        true
    }

    /// The parts of a pixel whose samples hold several fragments `ids`
    /// (the background `bg` where none), into `parts`, the fragments
    /// queued for the lanes (the pixel waits for them).
    fn pixel_parts(
        &self,
        at: &mut FragmentAt,
        (ids, bg): (&[u32], Vec4),
        (lanes, sink): (&mut LaneBatches, &mut Sink),
        parts: &mut smallvec::SmallVec<[PixelShare; 4]>,
    ) {
        for (id, mask) in fragments(ids) {
            let count = mask.count_ones() as f32;
            if id == NO_TRIANGLE {
                parts.push(PixelShare::Shaded(bg, f32::INFINITY, count));
                continue;
            }
            let slot = self.fragment(at, (id, mask), LANE_SLOT, (&mut *lanes, &mut *sink));
            parts.push(PixelShare::Queued(slot, count));
        }
    }

    /// The background at band pixel (px, py): the environment or the
    /// colour, with the ground catcher over it.
    fn background_at(&self, px: i32, py: i32) -> Vec4 {
        let bg = match &self.env_bg {
            Some(e) => e.at(px, py),
            None => self.bg,
        };
        match &self.ground {
            Some(g) => g.over(bg, px, py),
            None => bg,
        }
    }

    /// Over a flat background (`filled`), the band's empty pixels filled
    /// with it (only where `known` says they may hold something else) and
    /// per row the span of pixels some triangle covers; otherwise every
    /// row's whole width. Also the columns drawn into.
    fn fill_background(
        &self,
        vis: &Visibility,
        filled: bool,
        known: Option<PlainBackground>,
        color: &mut [Vec4],
        depth: &mut [f32],
    ) -> (Vec<(usize, usize)>, (usize, usize)) {
        let tw = vis.rect.width();
        let th = vis.rect.height();
        // Per row: the span of pixels some triangle covers (over a flat
        // background only those are visited; the others are filled here).
        let mut spans = vec![(usize::MAX, 0usize); th];
        let drawn = vis.drawn_columns();
        // Columns that may hold something other than this background now.
        let stale = match known {
            Some(k)
                if k.color.to_array().map(f32::to_bits) == self.bg.to_array().map(f32::to_bits) =>
            {
                let hi = k.columns.1.min(tw);
                (k.columns.0.min(hi), hi)
            }
            _ => (0, tw),
        };
        for (y, span) in spans.iter_mut().enumerate() {
            let row = y * tw..(y + 1) * tw;
            if !filled {
                *span = (0, tw);
                continue;
            }
            let (c, d) = (&mut color[row.clone()], &mut depth[row]);
            // Outside the drawn columns every pixel is empty.
            let (lo, hi) = drawn;
            // (Only where it does not hold the background already.)
            for r in [stale.0..lo.min(stale.1), hi.max(stale.0)..stale.1] {
                if r.start < r.end {
                    c[r.clone()].fill(self.bg);
                    d[r].fill(f32::INFINITY);
                }
            }
            for x in lo..hi {
                if empty(vis, y * tw + x) {
                    c[x] = self.bg;
                    d[x] = f32::INFINITY;
                } else {
                    span.0 = span.0.min(x);
                    span.1 = x + 1;
                }
            }
        }
        (spans, drawn)
    }

    /// The fragment of triangle `id` covering samples `mask` of the pixel
    /// `at` describes, added to the lanes with `pixel` as where its result
    /// goes (written in its place there, not copied in); its slot.
    fn fragment(
        &self,
        at: &mut FragmentAt,
        (id, mask): (u32, u32),
        pixel: u32,
        (lanes, sink): (&mut LaneBatches, &mut Sink),
    ) -> u32 {
        let t = &self.tris[id as usize];
        let it = at.cache.get(id, t);
        let lm = self.lane_material(t.draw as usize);
        let quad = &mut *at.quad;
        let (px, py) = at.px;
        // `shading_point`: at the centre where the triangle covers it
        // (`at_pixel`, or the same value kept), else the centroid.
        let point = |centers: &Option<([Fragment; 4], [bool; 4])>| match centers {
            Some((c, covers)) => {
                let k = Interpolator::quad_lane(at.q0, px, py);
                if self.pattern.len() == 1 || covers[k] {
                    c[k]
                } else {
                    self.centroid_point(it, px, py, mask)
                }
            }
            None => self.shading_point(it, px, py, mask),
        };
        // (What a new entry holds is taken from the values made, not read
        // back from the entry just written.)
        let (frag, footprints, grads) = match quad.iter().find(|q| q.id == id) {
            Some(q) => (point(&q.centers), q.footprints, q.grads),
            None => {
                // The triangle at the quad's four centres, kept: the
                // derivatives are taken between the first three, and the
                // pixels it covers are shaded there.
                let centers = self.wants_gradients().then(|| it.at_quad(at.q0.0, at.q0.1));
                let grads = match &centers {
                    Some((c, _)) => self.lane_gradients_at(lm, t, c),
                    None => [Gradients::default(); 2],
                };
                let footprints = lm.footprints(&self.ctx, grads);
                let frag = point(&centers);
                quad.push(QuadEntry {
                    id,
                    grads,
                    footprints,
                    centers,
                });
                (frag, footprints, grads)
            }
        };
        *lanes.next(t.draw) = Pending {
            id,
            pixel,
            count: mask.count_ones() as f32,
            lambda: frag.lambda,
            w: frag.w,
            footprints,
            grads,
            ao: at.reach.ao,
            lights: at.reach.lights,
            edge: self.edge_distance(it, px, py, frag.lambda),
        };
        lanes.commit(self, t.draw, sink)
    }
}

/// The interpolators of the band's last triangles, one slot per id mod
/// `SLOTS`: consecutive pixels mostly belong to one triangle, and the
/// quads along an edge alternate between two or three.
pub(super) struct InterpolatorCache {
    slots: [Option<(u32, Interpolator)>; InterpolatorCache::SLOTS],
}

impl Default for InterpolatorCache {
    fn default() -> InterpolatorCache {
        InterpolatorCache {
            slots: [const { None }; InterpolatorCache::SLOTS],
        }
    }
}

impl InterpolatorCache {
    const SLOTS: usize = 16;

    #[inline]
    pub(super) fn get(&mut self, id: u32, t: &Tri) -> &Interpolator {
        let slot = &mut self.slots[id as usize % Self::SLOTS];
        if !matches!(slot, Some((k, _)) if *k == id) {
            *slot = None;
        }
        &slot.get_or_insert_with(|| (id, Interpolator::new(t))).1
    }
}

/// A triangle present in a 2x2 quad: its texture-coordinate derivatives
/// (one pair for the quad, as a GPU takes them) and the filter footprints
/// of its material derived from them, shared by the quad's pixels.
struct QuadEntry {
    id: u32,
    grads: [Gradients; 2],
    footprints: Footprints,
    /// The triangle at the quad's four centres and whether it covers
    /// each (`Interpolator::at_quad`), where the derivatives were taken
    /// (their first three).
    centers: Option<([Fragment; 4], [bool; 4])>,
}

/// Where `BandInputs::fragment` shades: the pixel's position and its
/// quad's top-left pixel, its AO and lights, and the band's state.
struct FragmentAt<'c> {
    px: (i32, i32),
    q0: (i32, i32),
    reach: FragmentLighting,
    cache: &'c mut InterpolatorCache,
    quad: &'c mut smallvec::SmallVec<[QuadEntry; 4]>,
}

/// The distinct triangle ids among one pixel's samples, each with the mask
/// of the samples it holds, in order of first sample.
pub(super) fn fragments(ids: &[u32]) -> smallvec::SmallVec<[(u32, u32); 4]> {
    let mut out: smallvec::SmallVec<[(u32, u32); 4]> = smallvec::SmallVec::new();
    debug_assert!(ids.len() <= MAX_SAMPLES);
    for (s, &id) in ids.iter().enumerate() {
        match out.iter_mut().find(|f| f.0 == id) {
            Some(f) => f.1 |= 1 << s,
            None => out.push((id, 1 << s)),
        }
    }
    out
}

/// Whether no triangle covers any sample of band pixel `i`.
#[inline]
fn empty(vis: &Visibility, i: usize) -> bool {
    let n = vis.samples();
    if n == 1 {
        vis.id()[i] == NO_TRIANGLE
    } else {
        vis.id()[i * n..(i + 1) * n]
            .iter()
            .all(|&id| id == NO_TRIANGLE)
    }
}
