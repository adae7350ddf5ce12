//! The fragments of a band whose materials are shaded a lane group at a
//! time (`ShadeContext::shade_lanes`, 1, 4 or 8 lanes: `Renderer`'s
//! lane width): queued per draw while the band's quads are walked, then
//! gathered into groups of one draw and shaded together; a quad covered
//! by one triangle is shaded at once (with eight lanes, two such quads of
//! one draw together). A blended triangle's fragments are shaded as
//! layers (colour and opacity), a lane group at a time, before the band
//! composites them in order. Each fragment's result is the same bits at
//! every width, so the band resolves its pixels in the same order with
//! the same values whatever the width.

use glam::{Vec2, Vec3, Vec4};

use super::fragment::{BandInputs, Sink};
use crate::assets::texture::Footprint;
use crate::assets::texture::Gradients;
use crate::raster::interp::Interpolator;
use crate::raster::setup::Tri;
use crate::scene::settings::ShadingMode;
use crate::shade::lanes::LaneMaterial;
use crate::shade::lanes::{Coords, Footprints, Lanes, Layer, MAX_LANES, MAX_SIZES};
use crate::shade::light::LightMask;
use crate::simd::{F8, Lane, V3, lerp3};

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
    /// Filter footprints per slot, and the bump map's step
    /// (`LaneMaterial::footprints`).
    pub footprints: Footprints,
    /// Texture-coordinate derivatives of its quad (sets 0 and 1): the
    /// footprints of a material's slots past `MAX_SIZES` come from them.
    pub grads: [Gradients; 2],
    pub ao: f32,
    /// The lights that may reach its tile.
    pub lights: LightMask,
    /// Wireframe: its distance to its triangle's nearest edge, in
    /// pixels (`BandInputs::edge_distance`).
    pub edge: f32,
}

/// A band's lane fragments waiting for their group: per draw, up to one
/// less than the lane width; the last shades the group at once.
pub(super) struct LaneBatches {
    waiting: Vec<Waiting>,
    /// The slot of the next fragment.
    next: u32,
    /// The corners of the band's recent triangles.
    pub corners: CornerCache,
    /// Lanes per group: 1, 4 or 8.
    width: usize,
    /// With eight lanes: a quad of one triangle waiting for a second of
    /// its draw, with its triangle's corners, the band pixels its
    /// results go to and their samples, where `quad_waits`. Written over
    /// in place, never moved: it is over a kilobyte.
    quad: WaitingQuad,
    quad_waits: bool,
    /// A queued group as the lanes take it (`shade_group`).
    prepared: Prepared,
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
    fn fill(&mut self, data: &BandInputs, draw: usize, id: u32, t: &Tri) {
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
    pub fn get(&mut self, data: &BandInputs, draw: usize, id: u32, t: &Tri) -> &Corners {
        self.fill(data, draw, id, t);
        &self.corners[Self::slot(id)]
    }
}

/// Up to a group of fragments of one draw, with their slots.
#[derive(Clone, Copy)]
struct Waiting {
    group: [Pending; MAX_LANES],
    slots: [u32; MAX_LANES],
    len: usize,
}

impl Pending {
    const NONE: Pending = Pending {
        id: 0,
        pixel: 0,
        count: 1.0,
        lambda: Vec3::ZERO,
        w: 0.0,
        footprints: Footprints::NONE,
        grads: [Gradients::ZERO; 2],
        ao: 1.0,
        lights: LightMask::NONE,
        edge: f32::INFINITY,
    };
}

impl LaneBatches {
    /// Batches for `draws` draws, shading `width` lanes at a time (1, 4
    /// or 8).
    pub fn new(draws: usize, width: usize) -> LaneBatches {
        LaneBatches {
            waiting: vec![
                Waiting {
                    group: [Pending::NONE; MAX_LANES],
                    slots: [0; MAX_LANES],
                    len: 0,
                };
                draws
            ],
            next: 0,
            corners: CornerCache::new(),
            width,
            quad: WaitingQuad::NONE,
            quad_waits: false,
            prepared: Prepared::EMPTY,
        }
    }

    /// Where draw `draw`'s next fragment goes: filled in there, then
    /// added by `commit`.
    #[inline]
    pub fn next(&mut self, draw: u32) -> &mut Pending {
        let w = &mut self.waiting[draw as usize];
        &mut w.group[w.len]
    }

    /// Adds the fragment written at `next(draw)` as the next slot, which
    /// it returns; a full group of its draw is shaded into `sink`.
    #[inline]
    pub fn commit(&mut self, data: &BandInputs, draw: u32, sink: &mut Sink) -> u32 {
        let slot = self.next;
        self.next += 1;
        let w = &mut self.waiting[draw as usize];
        w.slots[w.len] = slot;
        w.len += 1;
        if w.len == self.width {
            shade_group(
                data,
                draw as usize,
                w,
                (&mut self.corners, &mut self.prepared),
                sink,
                self.width,
            );
            w.len = 0;
        }
        slot
    }

    /// Shades every group that is not full (its last fragment repeated),
    /// and a quad still waiting.
    pub fn finish(&mut self, data: &BandInputs, sink: &mut Sink) {
        self.flush_quad(data, sink.color, sink.depth);
        for (draw, w) in self.waiting.iter_mut().enumerate() {
            if w.len > 0 {
                for k in w.len..MAX_LANES {
                    w.group[k] = w.group[w.len - 1];
                }
                shade_group(
                    data,
                    draw,
                    w,
                    (&mut self.corners, &mut self.prepared),
                    sink,
                    self.width,
                );
                w.len = 0;
            }
        }
    }

    /// Shades the quad `q` of one triangle (band pixels `pixels`, `n`
    /// samples each, all covered) into the band's `color` and `depth`: at
    /// once, or with eight lanes when a second quad of its draw comes (or
    /// the band ends: `finish`).
    pub fn quad(
        &mut self,
        data: &BandInputs,
        q: QuadAt,
        pixels: [usize; 4],
        (color, depth): (&mut [glam::Vec4], &mut [f32]),
        n: usize,
    ) {
        let (draw, id) = (q.t.draw as usize, q.id);
        let c = self.corners.get(data, draw, id, q.t);
        if self.width != 8 {
            let mut p = Prepared::EMPTY;
            data.prepare_quad_into(&q, c, &mut p, 0);
            let out = data.shade_prepared(&p, &[c; MAX_LANES], &[], self.width);
            put_quad(&out[..4], pixels, color, depth, n);
            return;
        }
        let w = &mut self.quad;
        if self.quad_waits && w.prepared.draw == draw {
            // The second quad goes into the first's lanes 4 .. 8.
            data.prepare_quad_into(&q, c, &mut w.prepared, 4);
            let a = &w.corners;
            let refs = [a, a, a, a, c, c, c, c];
            let out = data.shade_prepared(&w.prepared, &refs, &[], 8);
            put_quad(&out[..4], w.pixels, color, depth, w.samples);
            put_quad(&out[4..], pixels, color, depth, n);
            self.quad_waits = false;
            return;
        }
        // A quad of another draw waiting is shaded alone; this one is
        // written over it and waits.
        if self.quad_waits {
            w.shade(data, color, depth);
        }
        data.prepare_quad_into(&q, c, &mut w.prepared, 0);
        (w.corners, w.pixels, w.samples) = (*c, pixels, n);
        self.quad_waits = true;
    }

    /// Shades a quad still waiting for a second.
    fn flush_quad(&mut self, data: &BandInputs, color: &mut [glam::Vec4], depth: &mut [f32]) {
        if self.quad_waits {
            self.quad.shade(data, color, depth);
        }
        self.quad_waits = false;
    }
}

/// A quad of one triangle waiting for a second of its draw (eight
/// lanes).
struct WaitingQuad {
    prepared: Prepared,
    corners: Corners,
    pixels: [usize; 4],
    samples: usize,
}

impl WaitingQuad {
    /// None waiting (`LaneBatches::quad_waits` false).
    const NONE: WaitingQuad = WaitingQuad {
        prepared: Prepared::EMPTY,
        corners: Corners::NONE,
        pixels: [0; 4],
        samples: 0,
    };

    /// Shades it alone.
    fn shade(&self, data: &BandInputs, color: &mut [glam::Vec4], depth: &mut [f32]) {
        let c = &self.corners;
        let out = data.shade_prepared(&self.prepared, &[c; MAX_LANES], &[], 8);
        put_quad(&out[..4], self.pixels, color, depth, self.samples);
    }
}

/// A quad's four results to its band pixels (`n` samples each, all of
/// them covered), as the band resolves such pixels.
fn put_quad(
    out: &[(Vec3, f32)],
    pixels: [usize; 4],
    color: &mut [glam::Vec4],
    depth: &mut [f32],
    n: usize,
) {
    let inv_n = 1.0 / n as f32;
    for (k, &i) in pixels.iter().enumerate() {
        (color[i], depth[i]) = super::fragment::resolve(
            &[super::fragment::PixelShare::Queued(0, n as f32)],
            &out[k..k + 1],
            inv_n,
        );
    }
}

/// A quad covered by one triangle, as the band hands it to the lanes.
pub(super) struct QuadAt<'q, 'a> {
    pub t: &'q Tri,
    pub id: u32,
    pub it: &'q Interpolator,
    pub lm: &'q LaneMaterial<'a>,
    /// Its top-left pixel.
    pub q0: (i32, i32),
    pub ao: [f32; 4],
    pub lights: LightMask,
}

/// Shades the group of draw `draw` in `w` (`width` lanes at a time) and
/// hands the fragments it holds to `sink` (linear colour, zero where not
/// finite: degenerate input must not poison the frame).
fn shade_group(
    data: &BandInputs,
    draw: usize,
    w: &Waiting,
    (corners, p): (&mut CornerCache, &mut Prepared),
    sink: &mut Sink,
    width: usize,
) {
    let lm = data.lane_material(draw);
    // (Made in the batches' own, which is reused, not returned and
    // copied: its lanes from `width` on stay empty.)
    data.prepare_group_into(&w.group, width, p);
    p.draw = draw;
    let p = &*p;
    let extra = data.extra_footprints(lm, &w.group, width);
    let id = |k: usize| w.group[k].id;
    let tri = |k: usize| &data.tris[id(k) as usize];
    for k in 0..width {
        corners.fill(data, draw, id(k), tri(k));
    }
    // Two of the lanes' triangles may share a slot; then their corners
    // are gathered here.
    let mut refs: [&Corners; MAX_LANES] = [&Corners::NONE; MAX_LANES];
    let mut cached = true;
    for (k, r) in refs.iter_mut().enumerate().take(width) {
        match corners.peek(id(k)) {
            Some(c) => *r = c,
            None => {
                cached = false;
                break;
            }
        }
    }
    let out = if cached {
        for k in width..MAX_LANES {
            refs[k] = refs[width - 1];
        }
        data.shade_prepared(p, &refs, &extra, width)
    } else {
        let mut own = [Corners::NONE; MAX_LANES];
        for k in 0..width {
            // Neighbouring fragments mostly share a triangle.
            own[k] = if k > 0 && id(k) == id(k - 1) {
                own[k - 1]
            } else {
                data.corners(draw, tri(k))
            };
        }
        let own = &own;
        let refs = std::array::from_fn(|k| &own[k.min(width - 1)]);
        data.shade_prepared(p, &refs, &extra, width)
    };
    for (k, &(c, d)) in out.iter().enumerate().take(w.len) {
        sink.put(w.slots[k], w.group[k].pixel, w.group[k].count, c, d);
    }
}

/// Up to eight fragments of one draw, ready for the lanes: where each
/// lane interpolates its triangle's corners (which come beside it) and
/// what it looks up.
#[derive(Clone, Copy)]
pub(super) struct Prepared {
    draw: usize,
    /// How many lanes hold fragments (the rest repeat the last).
    len: usize,
    /// Per lane: barycentrics and w, AO, footprints.
    lambda: [Vec3; MAX_LANES],
    w: [f32; MAX_LANES],
    ao: [f32; MAX_LANES],
    edge: [f32; MAX_LANES],
    footprints: [[Footprint; MAX_LANES]; MAX_SIZES],
    bump: [Vec2; MAX_LANES],
    lights: LightMask,
}

impl Prepared {
    /// No fragment: filled in by `prepare_quad_into` or `prepare_group`.
    const EMPTY: Prepared = Prepared {
        draw: 0,
        len: 0,
        lambda: [Vec3::ZERO; MAX_LANES],
        w: [0.0; MAX_LANES],
        ao: [1.0; MAX_LANES],
        edge: [f32::INFINITY; MAX_LANES],
        footprints: [[Footprint::Lod(0.0); MAX_LANES]; MAX_SIZES],
        bump: [Vec2::ZERO; MAX_LANES],
        lights: LightMask::NONE,
    };
}

/// A lane call's fragments, their triangles' corners, and the footprints
/// of their material's slots past `MAX_SIZES` (`extra_footprints`).
type Group<'p> = (
    &'p Prepared,
    &'p [&'p Corners; MAX_LANES],
    &'p [[Footprint; MAX_LANES]],
);

/// One triangle's corners as the lanes interpolate them.
#[derive(Clone, Copy)]
pub(super) struct Corners {
    world: [Vec3; 3],
    normal: [Vec3; 3],
    /// Texture coordinates of sets 0 and 1 (zero without them).
    uv: [[Vec2; 3]; 2],
    /// Per corner, with the bitangent sign in w (zero without tangents).
    tangent: [Vec4; 3],
    color: [Vec4; 3],
    /// Its index in the mesh (Gouraud shading finds its vertices' light).
    prim: u32,
    /// Counter-clockwise as the camera sees it.
    front: bool,
}

impl Corners {
    /// What an empty cache slot holds.
    const NONE: Corners = Corners {
        world: [Vec3::ZERO; 3],
        normal: [Vec3::ZERO; 3],
        uv: [[Vec2::ZERO; 3]; 2],
        tangent: [Vec4::ZERO; 3],
        color: [Vec4::ZERO; 3],
        prim: 0,
        front: false,
    };
}

impl<'a> BandInputs<'a> {
    /// The corners of triangle `t` (of draw `draw`).
    #[inline]
    pub(super) fn corners(&self, draw: usize, t: &Tri) -> Corners {
        let d = self.draws[draw];
        let mesh = &self.setup.scene.models[d.model].mesh;
        let mv = &self.verts[d.model];
        let [i0, i1, i2] = mesh.triangles[t.prim as usize];
        let k = [i0 as usize, i1 as usize, i2 as usize];
        // Written out, not `array::map`: that call is left out of line,
        // and this runs once per triangle a lane group shades.
        #[inline(always)]
        fn pick<T: Copy>(v: &[T], [a, b, c]: [usize; 3]) -> [T; 3] {
            [v[a], v[b], v[c]]
        }
        let uv = |uv: &[Vec2]| {
            if uv.is_empty() {
                [Vec2::ZERO; 3]
            } else {
                pick(uv, k)
            }
        };
        let tt = &self.tangents[d.model];
        let tangent = if tt.is_empty() {
            [Vec4::ZERO; 3]
        } else {
            let c = t.prim as usize * 3;
            [tt[c], tt[c + 1], tt[c + 2]]
        };
        Corners {
            world: pick(&mv.world, k),
            normal: pick(&mv.normal, k),
            uv: [uv(&mesh.uvs), uv(&mesh.uvs1)],
            tangent,
            color: if mesh.colors.is_empty() {
                [Vec4::ONE; 3]
            } else {
                pick(&mesh.colors, k)
            },
            prim: t.prim,
            front: t.front,
        }
    }

    /// The fragments of `p` as `L`'s lanes take them (lanes `at` ..
    /// `at + L::WIDTH`), interpolated as `point` and `surface`
    /// interpolate one fragment (the same operations in the same order,
    /// lane by lane); and their view depths.
    #[inline(always)]
    fn lanes<'p, L: Lane>(
        &self,
        lm: &LaneMaterial,
        (p, corners, extra): Group<'p>,
        at: usize,
    ) -> (Lanes<L>, Coords<'p, L>, L) {
        let d = self.draws[p.draw];
        let mesh = &self.setup.scene.models[d.model].mesh;
        let ctx = &self.ctx;
        let l = V3::<L>::from_fn(|k| p.lambda[at + k]);
        // Whether each quad of lanes holds one triangle's corners (a
        // quad's pixels): then each value is loaded once per quad.
        let by_quad = (0..L::QUADS).all(|q| {
            let first = corners[at + 4 * q];
            (1..L::WIDTH.min(4)).all(|k| std::ptr::eq(first, corners[at + 4 * q + k]))
        });
        let of = (corners, at, by_quad);
        let corner3 = |j: usize, f: fn(&Corners) -> [Vec3; 3]| V3::<L> {
            x: lanes_of(of, |c| f(c)[j].x),
            y: lanes_of(of, |c| f(c)[j].y),
            z: lanes_of(of, |c| f(c)[j].z),
        };
        let lerp =
            |f: fn(&Corners) -> [Vec3; 3]| lerp3(corner3(0, f), corner3(1, f), corner3(2, f), l);
        let position = lerp(|k| k.world);
        let w = L::from_fn(|k| p.w[at + k]);
        let depth = if ctx.orthographic {
            (position - V3::splat(ctx.eye)).dot(V3::splat(ctx.forward))
        } else {
            w
        };
        let raw = lerp(|k| k.normal);
        let n = raw.normalize_or(V3::splat(Vec3::Y));
        let front = lanes_of::<L>(of, |c| c.front as u32 as f32).cmpgt(L::splat(0.0));
        let normal = V3::select(front, n, -n);
        // The triangles' normals facing the viewer (`ShadeContext::
        // view_vector`), all lanes at once.
        let geo = if self.geo_normal {
            let a = corner3(0, |k| k.world);
            let g = (corner3(1, |k| k.world) - a)
                .cross(corner3(2, |k| k.world) - a)
                .normalize_or(normal);
            let away = V3::splat(-ctx.forward);
            let view = if ctx.orthographic {
                away
            } else {
                (V3::splat(ctx.eye) - position).normalize_or(away)
            };
            V3::select(g.dot(view).cmplt(L::splat(0.0)), -g, g)
        } else {
            normal
        };
        let mut geo_normal = [Vec3::ZERO; MAX_LANES];
        for (k, g) in geo_normal.iter_mut().enumerate().take(L::WIDTH) {
            *g = geo.lane(k);
        }
        let uv = |set: usize| {
            let at = |j: usize| {
                let u = lanes_of::<L>(of, |c| c.uv[set][j].x);
                (u, lanes_of::<L>(of, |c| c.uv[set][j].y))
            };
            let ((u0, v0), (u1, v1), (u2, v2)) = (at(0), at(1), at(2));
            (
                u0 * l.x + u1 * l.y + u2 * l.z,
                v0 * l.x + v1 * l.y + v2 * l.z,
            )
        };
        let uv0 = uv(0);
        let uv1 = if lm.reads_set1() { uv(1) } else { uv0 };
        let tangent = lerp(|k| k.tangent.map(|t| t.truncate()));
        let color = (!mesh.colors.is_empty()).then(|| lerp(|k| k.color.map(|c| c.truncate())));
        // Flat shading: the triangles' normals (as `surface` has them).
        let normal = if ctx.mode == ShadingMode::Flat {
            V3::from_fn(|k| geo_normal[k])
        } else {
            normal
        };
        let lanes = Lanes {
            position,
            normal,
            color,
            geo_normal,
            ao: L::from_fn(|k| p.ao[at + k]),
            depth,
            edge: L::from_fn(|k| p.edge[at + k]),
            lights: p.lights,
            vertex_light: self.vertex_light(p.draw, corners, at, l),
        };
        let coords = Coords {
            uv: lm.coords([uv0, uv1]),
            tangent,
            sign: lanes_of::<L>(of, |c| c.tangent[0].w),
            normal_from_object: self.verts[d.model].normal_from_object,
            back: normal.dot(raw).cmplt(L::splat(0.0)),
            footprints: &p.footprints,
            first: at,
            extra,
            sets: [uv0, uv1],
            bump: &p.bump,
        };
        (lanes, coords, depth)
    }

    /// Gouraud shading: the lanes' light sums (diffuse, specular)
    /// interpolated from their triangles' vertices (`surface`'s
    /// `vertex_light`); None in the other modes.
    #[inline(always)]
    fn vertex_light<L: Lane>(
        &self,
        draw: usize,
        corners: &[&Corners; MAX_LANES],
        at: usize,
        l: V3<L>,
    ) -> Option<(V3<L>, V3<L>)> {
        let d = self.draws[draw];
        let light = &self.verts[d.model].light;
        if light.is_empty() {
            return None;
        }
        let triangles = &self.setup.scene.models[d.model].mesh.triangles;
        let corner = |j: usize, specular: bool| {
            V3::<L>::from_fn(|k| {
                let v = triangles[corners[at + k].prim as usize][j] as usize;
                if specular { light[v].1 } else { light[v].0 }
            })
        };
        let sum = |s: bool| lerp3(corner(0, s), corner(1, s), corner(2, s), l);
        Some((sum(false), sum(true)))
    }

    /// Shades the fragments of `p`, `width` lanes at a time: per lane,
    /// the linear colour (zero where not finite) and view depth.
    pub(super) fn shade_prepared(
        &self,
        p: &Prepared,
        corners: &[&Corners; MAX_LANES],
        extra: &[[Footprint; MAX_LANES]],
        width: usize,
    ) -> [(Vec3, f32); MAX_LANES] {
        let mut out = [(Vec3::ZERO, 0.0); MAX_LANES];
        let lm = self.lane_material(p.draw);
        let mut at = 0;
        while at < p.len {
            match width {
                8 => self.shade_at::<F8>(lm, (p, corners, extra), at, &mut out),
                4 => self.shade_at::<Vec4>(lm, (p, corners, extra), at, &mut out),
                _ => self.shade_at::<f32>(lm, (p, corners, extra), at, &mut out),
            }
            at += width;
        }
        out
    }

    /// `shade_prepared` of lanes `at` .. `at + L::WIDTH`.
    #[inline(never)]
    fn shade_at<L: Lane>(
        &self,
        lm: &LaneMaterial<'a>,
        group: Group,
        at: usize,
        out: &mut [(Vec3, f32); MAX_LANES],
    ) {
        let (lanes, coords, depth) = self.lanes::<L>(lm, group, at);
        let c = self.ctx.shade_lanes(lm, &lanes, &coords);
        for (k, o) in out[at..at + L::WIDTH].iter_mut().enumerate() {
            let c = c.lane(k);
            *o = (if c.is_finite() { c } else { Vec3::ZERO }, depth.lane(k));
        }
    }

    /// The fragments `frags` of the blended triangle `t`, whose material
    /// the lanes shade as layers (`LaneMaterial::layers`), a lane group
    /// at a time: per fragment, in order, what it adds, the share of the
    /// colour behind it lets through, and its opacity
    /// (`ShadeContext::layer_lanes`) into `out`.
    pub(super) fn layers(&self, t: &Tri, frags: &[Pending], out: &mut Vec<Layer>) {
        let draw = t.draw as usize;
        let lm = self.lane_material(draw);
        let c = self.corners(draw, t);
        let corners = [&c; MAX_LANES];
        let width = self.lane_width;
        let mut res = [(Vec3::ZERO, Vec3::ZERO, 0.0); MAX_LANES];
        for chunk in frags.chunks(width) {
            let mut group = [chunk[chunk.len() - 1]; MAX_LANES];
            group[..chunk.len()].copy_from_slice(chunk);
            let mut p = self.prepare_group(&group, width);
            p.draw = draw;
            let extra = self.extra_footprints(lm, &group, width);
            let g = (&p, &corners, &extra[..]);
            match width {
                8 => self.layer_at::<F8>(lm, g, &mut res),
                4 => self.layer_at::<Vec4>(lm, g, &mut res),
                _ => self.layer_at::<f32>(lm, g, &mut res),
            }
            out.extend_from_slice(&res[..chunk.len()]);
        }
    }

    /// `layers` of the lanes of `p`.
    #[inline(never)]
    fn layer_at<L: Lane>(&self, lm: &LaneMaterial<'a>, group: Group, out: &mut [Layer; MAX_LANES]) {
        let (p, corners, _) = group;
        let (lanes, coords, _) = self.lanes::<L>(lm, group, 0);
        // The vertex colours' alpha (exactly 1 without them).
        let mesh = &self.setup.scene.models[self.draws[p.draw].model].mesh;
        let alpha = if mesh.colors.is_empty() {
            L::splat(1.0)
        } else {
            let l = V3::<L>::from_fn(|k| p.lambda[k]);
            let a = |j: usize| L::from_fn(|k| corners[k].color[j].w);
            a(0) * l.x + a(1) * l.y + a(2) * l.z
        };
        self.ctx.layer_lanes(lm, &lanes, &coords, alpha, out);
    }

    /// The data passes of the fragments `frags` (`width` of them, the
    /// last repeated where fewer wait; of draw `draw`, whose material
    /// `LaneMaterial::for_aovs` prepared as `lm`), per lane into `out`:
    /// shading normal, albedo, position (`ShadeContext::aov_lanes`).
    pub(super) fn aov_group(
        &self,
        (draw, lm): (usize, &LaneMaterial<'a>),
        frags: &[Pending; MAX_LANES],
        width: usize,
        out: &mut [[Vec3; 3]; MAX_LANES],
    ) {
        let mut p = self.prepare_group(frags, width);
        p.draw = draw;
        let extra = self.extra_footprints(lm, frags, width);
        let mut own = [Corners::NONE; MAX_LANES];
        for k in 0..width {
            own[k] = if k > 0 && frags[k].id == frags[k - 1].id {
                own[k - 1]
            } else {
                self.corners(draw, &self.tris[frags[k].id as usize])
            };
        }
        let refs = std::array::from_fn(|k| &own[k.min(width - 1)]);
        let g = (&p, &refs, &extra[..]);
        match width {
            8 => self.aov_at::<F8>(lm, g, out),
            4 => self.aov_at::<Vec4>(lm, g, out),
            _ => self.aov_at::<f32>(lm, g, out),
        }
    }

    /// `aov_group` of the lanes of `group`.
    #[inline(never)]
    fn aov_at<L: Lane>(
        &self,
        lm: &LaneMaterial<'a>,
        group: Group,
        out: &mut [[Vec3; 3]; MAX_LANES],
    ) {
        let (lanes, coords, _) = self.lanes::<L>(lm, group, 0);
        let (n, albedo) = self.ctx.aov_lanes(lm, &lanes, &coords);
        for (k, o) in out.iter_mut().enumerate().take(L::WIDTH) {
            *o = [n.lane(k), albedo.lane(k), lanes.position.lane(k)];
        }
    }

    /// The four pixels of the quad `q`, all of one triangle, one sample
    /// each, in reading order, ready for the lanes, written into `out`:
    /// at `at` 0, into lanes 0 .. 4 (lanes 4 .. 8 repeat them); at 4,
    /// into lanes 4 .. 8 after a quad of the same draw (`out` then holds
    /// eight). The quad's texture derivatives are its lanes' differences
    /// (what `gradients0_at` computes).
    #[inline(always)]
    pub(super) fn prepare_quad_into(
        &self,
        q: &QuadAt,
        corners: &Corners,
        out: &mut Prepared,
        at: usize,
    ) {
        let (it, t) = (q.it, q.t);
        let (x, y) = q.q0;
        let px = [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)];
        let (centers, covered) = it.at_quad(x, y);
        // With MSAA the shading point leaves a center the triangle does not
        // cover (`shading_point`); the derivatives stay the centers'.
        let f = if self.pattern.len() == 1 || covered == [true; 4] {
            centers
        } else {
            // `shading_point`: the center where the triangle covers it
            // (computed above), else the covered samples' centroid.
            let all = (1u32 << self.pattern.len()) - 1;
            [0, 1, 2, 3].map(|k| {
                let (x, y) = px[k];
                if covered[k] {
                    centers[k]
                } else {
                    self.shading_point(it, x, y, all)
                }
            })
        };
        let grads = |set: usize| {
            if !self.grads || (set == 1 && !q.lm.reads_set1()) {
                return Gradients::default();
            }
            let uv = |k: usize| {
                let c = &corners.uv[set];
                let l = centers[k].lambda;
                c[0] * l.x + c[1] * l.y + c[2] * l.z
            };
            let a = uv(0);
            Gradients {
                dx: uv(1) - a,
                dy: uv(2) - a,
            }
        };
        let grads = [grads(0), grads(1)];
        let fp = q.lm.footprints(&self.ctx, grads);
        // Lane k takes the quad's pixel k - at (the last past the fourth).
        let lanes = if at == 0 { 0..MAX_LANES } else { at..at + 4 };
        for k in lanes {
            let j = (k - at).min(3);
            out.lambda[k] = f[j].lambda;
            out.w[k] = f[j].w;
            out.ao[k] = q.ao[j];
            out.edge[k] = self.edge_distance(it, px[j].0, px[j].1, f[j].lambda);
            for (s, fs) in out.footprints.iter_mut().enumerate() {
                fs[k] = fp.slots[s];
            }
            out.bump[k] = fp.bump;
        }
        if at == 0 {
            (out.draw, out.len, out.lights) = (t.draw as usize, 4, q.lights);
        } else {
            out.len = at + 4;
            out.lights = out.lights.union(q.lights);
        }
    }

    /// The queued fragments `frags` (`width` of them, the last repeated
    /// where fewer wait), ready for the lanes.
    #[inline(always)]
    fn prepare_group(&self, frags: &[Pending; MAX_LANES], width: usize) -> Prepared {
        let mut p = Prepared::EMPTY;
        self.prepare_group_into(frags, width, &mut p);
        p
    }

    /// `prepare_group` into `p`, whose lanes from `width` on are left as
    /// they are.
    #[inline(always)]
    fn prepare_group_into(&self, frags: &[Pending; MAX_LANES], width: usize, p: &mut Prepared) {
        (p.len, p.lights) = (width, LightMask::NONE);
        for (k, f) in frags.iter().enumerate().take(width) {
            p.lambda[k] = f.lambda;
            p.w[k] = f.w;
            p.ao[k] = f.ao;
            p.edge[k] = f.edge;
            for (s, fp) in p.footprints.iter_mut().enumerate() {
                fp[k] = f.footprints.slots[s];
            }
            p.bump[k] = f.footprints.bump;
            p.lights = p.lights.union(f.lights);
        }
    }

    /// The footprints of `lm`'s slots past `MAX_SIZES`
    /// (`LaneMaterial::extra_slots`) for the queued fragments `frags`
    /// (`width` of them): per slot, per lane; empty without such slots.
    fn extra_footprints(
        &self,
        lm: &LaneMaterial,
        frags: &[Pending; MAX_LANES],
        width: usize,
    ) -> Vec<[Footprint; MAX_LANES]> {
        (MAX_SIZES..MAX_SIZES + lm.extra_slots())
            .map(|s| {
                let mut fp = [Footprint::Lod(0.0); MAX_LANES];
                for (k, f) in frags.iter().enumerate().take(width) {
                    fp[k] = lm.slot_footprint(&self.ctx, s, f.grads);
                }
                fp
            })
            .collect()
    }
}

/// Lanes `at` .. `at + L::WIDTH` of a value of their triangles' corners
/// (`g`): loaded once per quad where each quad holds one triangle's
/// (`by_quad`), else lane by lane. The same values either way.
#[inline(always)]
fn lanes_of<L: Lane>(
    (corners, at, by_quad): (&[&Corners; MAX_LANES], usize, bool),
    g: impl Fn(&Corners) -> f32,
) -> L {
    if by_quad {
        L::from_quads(|q| Vec4::splat(g(corners[at + 4 * q])))
    } else {
        L::from_fn(|k| g(corners[at + k]))
    }
}
