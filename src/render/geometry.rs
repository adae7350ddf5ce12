//! The geometry pass: one draw per model and material group in file
//! order, its triangles clipped (homogeneous, with a guard band), set up
//! (fixed-point edges, culling) and binned into bands of rows, in parallel
//! chunks of triangles merged back in submission order. Each chunk also
//! measures the largest texel density of each texture-coordinate set, from
//! which the frame decides which textures it minifies.

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::draw_list::DrawList;
use super::vertex::{self, ModelVertices};
use crate::assets::mesh::Mesh;
use crate::raster::CullMode;
use crate::raster::bin::{TileGrid, bin};
use crate::raster::clip::{ClipVertex, Clipped, OUTSIDE_PLANES, clip_triangle, outcode};
use crate::raster::setup::{Projected, SUBPIXEL, Tri, Viewport, project, setup, setup_projected};

/// One model's triangles that share a material.
#[derive(Clone, Copy)]
pub(super) struct Draw {
    pub model: usize,
    pub material: usize,
    /// The mesh part (`Group::part`), for the object-id pass.
    pub part: u32,
    pub first: u32,
    pub end: u32,
}

/// Triangles a chunk of a draw sets up at most.
const CHUNK: u32 = 2048;

/// One chunk's output.
pub(super) struct Chunk {
    /// The draw the chunk belongs to.
    pub draw: usize,
    /// Index of its first triangle in `Geometry::tris`.
    pub first: u32,
    /// Per band: indices (from `first`) of the triangles touching it.
    pub bins: Vec<Vec<u32>>,
    /// Largest UV area per pixel area, per texture-coordinate set (0 when
    /// the frame filters without mip maps).
    pub density: [f32; 2],
}

/// The frame's set-up triangles, binned.
pub(super) struct Geometry {
    pub draws: Vec<Draw>,
    pub tris: Vec<Tri>,
    /// Per model, per mesh triangle corner: the world-space tangent and
    /// bitangent sign, filled for the triangles set up here (the only
    /// ones shading reads: at a million triangles most are culled or
    /// cover no pixel center, and turning every corner in the vertex
    /// pass was a tenth of the frame); empty for a model without tangents.
    pub tangents: Vec<Vec<Vec4>>,
    pub chunks: Vec<Chunk>,
    pub grid: TileGrid,
}

impl Geometry {
    /// Per chunk: its per-band triangle lists and the index of its first
    /// triangle (what visibility walks, band by band).
    pub fn bins(&self) -> Vec<(&[Vec<u32>], u32)> {
        self.chunks
            .iter()
            .map(|c| (c.bins.as_slice(), c.first))
            .collect()
    }
}

/// `densities`: whether to measure texel densities (filters with mip maps).
pub(super) fn setup_and_bin(
    setup: &DrawList,
    verts: &[ModelVertices],
    vp: Viewport,
    densities: bool,
) -> Geometry {
    let scene = setup.scene;
    let mut draws = Vec::new();
    for (mi, m) in scene.models.iter().enumerate() {
        for g in &m.mesh.groups {
            draws.push(Draw {
                model: mi,
                material: g.material,
                part: g.part,
                first: g.triangles.start,
                end: g.triangles.end,
            });
        }
    }
    let mut ranges = Vec::new();
    for (di, d) in draws.iter().enumerate() {
        let mut start = d.first;
        while start < d.end {
            let end = (start + CHUNK).min(d.end);
            ranges.push((di, start, end));
            start = end;
        }
    }
    let grid = TileGrid::bands(vp.width, vp.height);
    let corners = corners_all(verts, vp);
    let mut tangents: Vec<Vec<Vec4>> = (0..verts.len())
        .map(|m| vec![Vec4::ZERO; vertex::tangent_source(setup, m).len()])
        .collect();
    let models: Vec<usize> = ranges.iter().map(|r| draws[r.0].model).collect();
    let spans: Vec<(u32, u32)> = ranges.iter().map(|r| (r.1, r.2)).collect();
    let slices = split_spans(&mut tangents, &models, &spans);
    let owned: Vec<bool> = (0..verts.len())
        .map(|m| (0..slices.len()).any(|k| models[k] == m && slices[k].is_some()))
        .collect();
    let per_chunk: Vec<(Vec<Tri>, Chunk)> = ranges
        .par_iter()
        .zip(slices)
        .map(|(&(di, start, end), tangent_out)| {
            let d = draws[di];
            let material = &scene.models[d.model].materials[d.material];
            let model = &scene.models[d.model];
            let cull = scene.settings.cull.resolve(
                material.double_sided,
                material.native == crate::scene::material::Native::Pbr,
                model.closed,
            );
            let measure = densities && material.maps().next().is_some();
            let mv = &verts[d.model];
            let (tris, density) = setup_range(
                setup,
                (mv, &corners[d.model]),
                (d, di),
                start..end,
                vp,
                cull,
                measure,
            );
            if let Some(out) = tangent_out {
                // Each mesh triangle's corners once, however many
                // triangles its clipped polygon became.
                let source = vertex::tangent_source(setup, d.model);
                let mut last = None;
                for t in &tris {
                    if last != Some(t.prim) {
                        let k = (t.prim - start) as usize * 3;
                        let corner: &mut [Vec4; 3] = (&mut out[k..k + 3])
                            .try_into()
                            .expect("three corners per triangle");
                        mv.turn_tangents(source, t.prim, corner);
                        last = Some(t.prim);
                    }
                }
            }
            let bins = bin(&tris, &grid, vp.msaa);
            let chunk = Chunk {
                draw: di,
                first: 0,
                bins,
                density,
            };
            (tris, chunk)
        })
        .collect();
    let mut tris = Vec::new();
    let mut chunks = Vec::with_capacity(per_chunk.len());
    for (t, mut c) in per_chunk {
        c.first = tris.len() as u32;
        tris.extend(t);
        chunks.push(c);
    }
    for (m, (mv, t)) in verts.iter().zip(&mut tangents).enumerate() {
        if !owned[m] && !t.is_empty() {
            // Groups that overlap: every corner.
            let source = vertex::tangent_source(setup, m);
            t.par_chunks_mut(3).enumerate().for_each(|(prim, out)| {
                if let Ok(out) = <&mut [Vec4; 3]>::try_from(out) {
                    mv.turn_tangents(source, prim as u32, out);
                }
            });
        }
    }
    Geometry {
        draws,
        tris,
        tangents,
        chunks,
        grid,
    }
}

/// For each chunk `k` (model `models[k]`, mesh triangles `spans[k]`), the
/// part of that model's per-corner buffer in `buffers` that holds its
/// triangles' corners; None where the model has no such buffer (empty)
/// or where its chunks overlap or reach past it (no chunk owns those
/// triangles: `setup_and_bin` fills such a model's corners whole).
fn split_spans<'a>(
    buffers: &'a mut [Vec<Vec4>],
    models: &[usize],
    spans: &[(u32, u32)],
) -> Vec<Option<&'a mut [Vec4]>> {
    let mut out: Vec<Option<&'a mut [Vec4]>> = (0..spans.len()).map(|_| None).collect();
    for (m, buffer) in buffers.iter_mut().enumerate() {
        if buffer.is_empty() {
            continue;
        }
        let mut mine: Vec<usize> = (0..spans.len()).filter(|&k| models[k] == m).collect();
        mine.sort_by_key(|&k| spans[k].0);
        let disjoint = mine.windows(2).all(|w| spans[w[0]].1 <= spans[w[1]].0);
        let inside = mine
            .iter()
            .all(|&k| spans[k].1 as usize * 3 <= buffer.len());
        if !(disjoint && inside) {
            continue;
        }
        let mut rest: &'a mut [Vec4] = buffer.as_mut_slice();
        let mut at = 0usize;
        for k in mine {
            let (lo, hi) = (spans[k].0 as usize * 3, spans[k].1 as usize * 3);
            let (_, tail) = std::mem::take(&mut rest).split_at_mut(lo - at);
            let (part, tail) = tail.split_at_mut(hi - lo);
            out[k] = Some(part);
            rest = tail;
            at = hi;
        }
    }
    out
}

/// A vertex as every triangle around it sees it: its outcode against
/// the clip planes and its projection to the viewport.
#[derive(Debug, Clone, Copy, Default)]
struct Corner {
    code: u8,
    screen: Projected,
}

/// Bytes per vertex of the frame's `Corner`s (for the memory estimate).
pub(super) const CORNER_BYTES: usize = std::mem::size_of::<Corner>();

/// Every model's `Corner`s, computed once per vertex (a mesh's vertex is
/// a corner of about six triangles), in parallel.
fn corners_all(verts: &[ModelVertices], vp: Viewport) -> Vec<Vec<Corner>> {
    verts
        .iter()
        .map(|mv| corners_all_of(&mv.clip, vp))
        .collect()
}

/// The `Corner`s of clip-space positions `clip`.
fn corners_all_of(clip: &[Vec4], vp: Viewport) -> Vec<Corner> {
    const V_CHUNK: usize = 8192;
    let (gx, gy) = vp.guard_band();
    let mut out = vec![Corner::default(); clip.len()];
    out.par_chunks_mut(V_CHUNK)
        .zip(clip.par_chunks(V_CHUNK))
        .for_each(|(out, clip)| {
            for (o, &p) in out.iter_mut().zip(clip) {
                *o = Corner {
                    code: outcode(p, gx, gy),
                    screen: project(p, vp),
                };
            }
        });
    out
}

/// Clips and sets up triangles `prims` of draw `d` (index `di`); with
/// `measure`, also their largest texel density per coordinate set.
/// Triangles inside every plane (most of them) are set up from their
/// corners' projections, which is what `clip_triangle` and `setup` would
/// give them; only the others are clipped.
fn setup_range(
    setup: &DrawList,
    (mv, corners): (&ModelVertices, &[Corner]),
    (d, di): (Draw, usize),
    prims: std::ops::Range<u32>,
    vp: Viewport,
    cull: CullMode,
    measure: bool,
) -> (Vec<Tri>, [f32; 2]) {
    let mesh = &setup.scene.models[d.model].mesh;
    let mut tris = Vec::with_capacity(prims.len());
    let mut max_density = [0.0f32; 2];
    let mut place = Placer {
        clip: &mv.clip,
        corners,
        vp,
        cull,
        draw: di as u32,
    };
    for prim in prims {
        let before = tris.len();
        let idx = mesh.triangles[prim as usize];
        place.triangle(idx, prim, &mut tris);
        measure_density(measure, &tris[before..], mesh, idx, &mut max_density);
    }
    (tris, max_density)
}

/// What setting up one draw's triangles needs.
struct Placer<'a> {
    clip: &'a [Vec4],
    corners: &'a [Corner],
    vp: Viewport,
    cull: CullMode,
    draw: u32,
}

impl Placer<'_> {
    /// Clips and sets up the mesh triangle `prim` with vertices `idx`,
    /// pushing what is left of it to `tris` (nothing, one triangle, or
    /// the fan of its clipped polygon).
    #[inline]
    fn triangle(&mut self, idx: [u32; 3], prim: u32, tris: &mut Vec<Tri>) {
        let (vp, cull, draw) = (self.vp, self.cull, self.draw);
        let c = idx.map(|i| self.corners[i as usize]);
        if c[0].code | c[1].code | c[2].code == 0 {
            // `clip_triangle` would say Inside, and `setup` would project
            // the corners as they are projected already.
            let bary = [Vec3::X, Vec3::Y, Vec3::Z];
            tris.extend(setup_projected(
                c.map(|c| c.screen),
                bary,
                vp,
                cull,
                draw,
                prim,
            ));
            return;
        }
        if c[0].code & c[1].code & c[2].code & OUTSIDE_PLANES != 0 {
            // All three outside one plane: Rejected.
            return;
        }
        let v = idx.map(|i| self.clip[i as usize]);
        let (gx, gy) = vp.guard_band();
        let base = |k: usize, b: Vec3| ClipVertex { pos: v[k], bary: b };
        match clip_triangle(v, gx, gy) {
            Clipped::Rejected => {}
            Clipped::Inside => {
                let tri = [base(0, Vec3::X), base(1, Vec3::Y), base(2, Vec3::Z)];
                tris.extend(setup(tri, vp, cull, draw, prim));
            }
            Clipped::Polygon(p) => {
                let p = p.as_slice();
                for k in 1..p.len() - 1 {
                    tris.extend(setup([p[0], p[k], p[k + 1]], vp, cull, draw, prim));
                }
            }
        }
    }
}

/// With `measure`, raises `max_density` to the texel densities of `tris`
/// (the triangles set up from mesh triangle `idx`).
#[inline]
fn measure_density(
    measure: bool,
    tris: &[Tri],
    mesh: &Mesh,
    idx: [u32; 3],
    max_density: &mut [f32; 2],
) {
    if !measure {
        return;
    }
    for t in tris {
        for (set, uvs) in [&mesh.uvs, &mesh.uvs1].into_iter().enumerate() {
            if !uvs.is_empty() {
                max_density[set] = max_density[set].max(uv_density(t, uvs, idx));
            }
        }
    }
}

/// UV area per pixel area of a set-up triangle (texture units squared per
/// pixel squared), from its barycentrics in the original triangle.
fn uv_density(t: &Tri, uvs: &[glam::Vec2], idx: [u32; 3]) -> f32 {
    let uv = idx.map(|i| uvs[i as usize]);
    let at = |b: Vec3| uv[0] * b.x + uv[1] * b.y + uv[2] * b.z;
    let [a, b, c] = t.bary.map(at);
    let uv_area = (b - a).perp_dot(c - a).abs();
    let px = SUBPIXEL as f64;
    let px_area = t.area2 as f64 / (px * px);
    if px_area <= 0.0 {
        return 0.0;
    }
    let d = (uv_area as f64 / px_area) as f32;
    if d.is_finite() { d } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use crate::testing::xorshift;

    /// The scene `text` loaded as if from a file in `dir`.
    fn scene_in(dir: &std::path::Path, text: &str) -> Scene {
        let opts = crate::scene::assemble::LoadOptions::default();
        Scene::from_text(&dir.join("s.toml"), text, &opts).unwrap()
    }

    /// Frame `setup` transformed, set up and binned at `width` x `height`.
    fn geometry_of(setup: &DrawList, width: u32, height: u32, densities: bool) -> Geometry {
        let verts = super::super::vertex::transform_all(setup);
        let vp = Viewport {
            width,
            height,
            msaa: false,
        };
        setup_and_bin(setup, &verts, vp, densities)
    }

    /// `clip_triangle` then `setup` on every triangle, as before corners
    /// were projected once per vertex.
    fn clip_then_setup(v: [Vec4; 3], vp: Viewport, cull: CullMode, prim: u32) -> Vec<Tri> {
        let (gx, gy) = vp.guard_band();
        let base = |k: usize, b: Vec3| ClipVertex { pos: v[k], bary: b };
        match clip_triangle(v, gx, gy) {
            Clipped::Rejected => Vec::new(),
            Clipped::Inside => {
                let tri = [base(0, Vec3::X), base(1, Vec3::Y), base(2, Vec3::Z)];
                setup(tri, vp, cull, 7, prim).into_iter().collect()
            }
            Clipped::Polygon(p) => {
                let p = p.as_slice();
                (1..p.len() - 1)
                    .filter_map(|k| setup([p[0], p[k], p[k + 1]], vp, cull, 7, prim))
                    .collect()
            }
        }
    }

    fn same(a: &Tri, b: &Tri) -> bool {
        let bits = |t: &Tri| {
            (
                t.x,
                t.y,
                [t.min_x, t.min_y, t.max_x, t.max_y],
                t.z.map(f32::to_bits),
                t.inv_w.map(f32::to_bits),
                t.bary.map(|b| b.to_array().map(f32::to_bits)),
                (t.area2, t.draw, t.prim, t.front),
            )
        };
        bits(a) == bits(b)
    }

    #[test]
    fn spans_get_their_own_corners_and_overlapping_ones_none() {
        let mut buffers = vec![vec![Vec4::ZERO; 15], Vec::new(), vec![Vec4::ZERO; 12]];
        // Model 0: triangles 2..5 and 0..2 (out of order); model 1 has no
        // corners; model 2's spans overlap.
        let models = [0, 0, 1, 2, 2];
        let spans = [(2, 5), (0, 2), (0, 3), (0, 3), (2, 4)];
        let mut slices = split_spans(&mut buffers, &models, &spans);
        let lens: Vec<Option<usize>> = slices.iter().map(|s| s.as_ref().map(|s| s.len())).collect();
        assert_eq!(lens, [Some(9), Some(6), None, None, None]);
        for (k, s) in slices.iter_mut().enumerate() {
            if let Some(s) = s {
                s.fill(Vec4::splat(k as f32 + 1.0));
            }
        }
        let firsts: Vec<f32> = buffers[0].iter().map(|v| v.x).collect();
        assert_eq!(firsts, [[2.0; 6].as_slice(), &[1.0; 9]].concat());
        assert!(buffers[2].iter().all(|v| *v == Vec4::ZERO));
    }

    #[test]
    fn set_up_triangles_get_their_corners_tangents() {
        // A normal-mapped grid in front of the camera and a second group
        // reaching behind it (cut by the near plane into several
        // triangles per mesh triangle), drawn as is and mirrored (the
        // bitangent flips); every triangle set-up keeps must find its
        // corners' tangents turned as the vertex pass turned them.
        let dir = std::env::temp_dir().join(format!("softraster-tangents-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        image::RgbaImage::from_pixel(2, 2, image::Rgba([150, 140, 240, 255]))
            .save(dir.join("nm.png"))
            .unwrap();
        let mut obj = String::from("mtllib m.mtl\nusemtl a\n");
        let n = 8;
        for j in 0..=n {
            for i in 0..=n {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                obj += &format!(
                    "v {} {} {}\nvt {u} {v}\n",
                    4.0 * u - 2.0,
                    4.0 * v - 2.0,
                    u * v
                );
            }
        }
        let at = |i: usize, j: usize| j * (n + 1) + i + 1;
        for j in 0..n {
            for i in 0..n {
                if j == n / 2 && i == 0 {
                    obj += "usemtl b\n";
                }
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                obj += &format!("f {a}/{a} {b}/{b} {c}/{c}\nf {a}/{a} {c}/{c} {d}/{d}\n");
            }
        }
        // Behind the eye (z = 5): cut by the near plane.
        obj += "v 0 0 9\nvt 0.5 0.5\n";
        let e = (n + 1) * (n + 1) + 1;
        obj += &format!(
            "f {e}/{e} {}/{} {}/{}\n",
            at(2, 2),
            at(2, 2),
            at(6, 3),
            at(6, 3)
        );
        std::fs::write(dir.join("g.obj"), obj).unwrap();
        std::fs::write(
            dir.join("m.mtl"),
            "newmtl a\nKd 0.5 0.5 0.5\nnorm nm.png\nnewmtl b\nKd 0.5 0.5 0.5\nnorm nm.png\n",
        )
        .unwrap();
        let text = "[output]\nwidth = 48\nheight = 40\n\
                    [[model]]\npath = \"g.obj\"\n\
                    [[model]]\npath = \"g.obj\"\nscale = [-1.0, 1.0, 1.0]\ntranslate = [0.5, 0.0, 0.0]\n\
                    [[camera]]\neye = [0.3, -0.2, 5.0]\ntarget = [0.0, 0.0, 0.0]\nnear = 0.5\n\
                    [[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, -1.0]\n";
        let scene = scene_in(&dir, text);
        let setup = DrawList::new(&scene, 0, 0);
        let geo = geometry_of(&setup, 48, 40, true);
        let (mut checked, mut cut) = (0, 0);
        for c in &geo.chunks {
            let d = geo.draws[c.draw];
            let m = glam::Mat3::from_mat4(setup.world_from_object[d.model]);
            let flip = if m.determinant() < 0.0 { -1.0 } else { 1.0 };
            let source = super::super::vertex::tangent_source(&setup, d.model);
            let end = geo
                .chunks
                .iter()
                .map(|o| o.first)
                .filter(|&f| f > c.first)
                .min();
            let tris = &geo.tris[c.first as usize..end.map_or(geo.tris.len(), |e| e as usize)];
            for t in tris {
                for k in 0..3 {
                    let s = source[t.prim as usize * 3 + k];
                    let want = (m * s.truncate()).normalize_or(Vec3::X).extend(s.w * flip);
                    let got = geo.tangents[d.model][t.prim as usize * 3 + k];
                    assert_eq!(
                        got.to_array().map(f32::to_bits),
                        want.to_array().map(f32::to_bits)
                    );
                }
                checked += 1;
                // A corner of a cut polygon is not one of the mesh's.
                cut += usize::from(t.bary.iter().any(|b| b.max_element() < 1.0));
            }
        }
        assert!(checked > 100 && cut >= 2, "{checked} {cut}");
        assert_eq!(geo.draws.len(), 4);
    }

    #[test]
    fn projected_corners_set_up_what_clip_and_setup_do() {
        // Vertices inside the view, beyond the screen edges, beyond the
        // guard band, behind the eye and beyond the far plane, on the
        // planes, and broken (NaN, infinite, w = 0): every triangle of
        // them, culled or not, with and without MSAA.
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        let mut clip = Vec::new();
        for i in 0..600 {
            let w = match i % 7 {
                0 => -(next() + 0.1),
                1 => 0.0,
                _ => 0.2 + 4.0 * next(),
            };
            let spread = [1.0, 3.0, 3000.0][i % 3];
            let mut p = Vec4::new(
                (next() * 2.0 - 1.0) * spread * w,
                (next() * 2.0 - 1.0) * spread * w,
                (next() * 1.4 - 0.2) * w,
                w,
            );
            match i % 50 {
                11 => p.x = f32::NAN,
                23 => p.y = f32::INFINITY,
                37 => p.z = p.w,
                41 => p.z = 0.0,
                _ => {}
            }
            clip.push(p);
        }
        let n = clip.len() as u32;
        let (mut checked, mut inside, mut cut) = (0, 0, 0);
        for (vp, cull) in [
            (
                Viewport {
                    width: 64,
                    height: 48,
                    msaa: false,
                },
                CullMode::None,
            ),
            (
                Viewport {
                    width: 700,
                    height: 700,
                    msaa: true,
                },
                CullMode::Back,
            ),
            (
                Viewport {
                    width: 33,
                    height: 17,
                    msaa: false,
                },
                CullMode::Front,
            ),
        ] {
            let corners = corners_all_of(&clip, vp);
            let mut place = Placer {
                clip: &clip,
                corners: &corners,
                vp,
                cull,
                draw: 7,
            };
            for prim in 0..20_000u32 {
                let r = |k: u32| (prim.wrapping_mul(2_654_435_761).rotate_left(k * 11)) % n;
                let idx = [r(0), r(1), r(2)];
                let mut got = Vec::new();
                place.triangle(idx, prim, &mut got);
                let want = clip_then_setup(idx.map(|i| clip[i as usize]), vp, cull, prim);
                assert_eq!(got.len(), want.len(), "{idx:?}");
                assert!(got.iter().zip(&want).all(|(a, b)| same(a, b)), "{idx:?}");
                checked += 1;
                let codes = idx.map(|i| corners[i as usize].code);
                inside += usize::from(codes == [0; 3] && !want.is_empty());
                cut += usize::from(want.len() > 1);
            }
        }
        // Both paths were taken many times.
        assert!(
            checked == 60_000 && inside > 1000 && cut > 100,
            "{inside} {cut}"
        );
    }

    #[test]
    fn a_quad_sets_up_two_triangles_binned_in_the_bands_it_covers() {
        let dir = std::env::temp_dir().join(format!("softraster-geometry-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Rows 1.6..9.6 of a 32x32 frame (band 0 of 2), and a second quad
        // behind the camera.
        let quad = "v -0.5 0.4 0\nv 0.5 0.4 0\nv 0.5 0.9 0\nv -0.5 0.9 0\nf 1 2 3 4\n\
                    v -0.5 0.4 9\nv 0.5 0.4 9\nv 0.5 0.9 9\nv -0.5 0.9 9\nf 5 6 7 8\n";
        std::fs::write(dir.join("quad.obj"), quad).unwrap();
        let text = "[output]\nwidth = 32\nheight = 32\n[[model]]\npath = \"quad.obj\"\n\
                    [[camera]]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n\
                    projection = \"orthographic\"\nheight = 2.0\nnear = 0.1\nfar = 10.0\n";
        let scene = scene_in(&dir, text);
        let setup = DrawList::new(&scene, 0, 0);
        let geo = geometry_of(&setup, 32, 32, false);
        assert_eq!(geo.draws.len(), 1);
        // The quad behind the camera is clipped away.
        assert_eq!(geo.tris.len(), 2);
        assert!(geo.tris.iter().all(|t| t.prim < 2 && t.front));
        let bins = geo.bins();
        assert_eq!(bins.len(), 1);
        assert_eq!(bins[0].0[0], vec![0, 1]);
        assert!(bins[0].0[1].is_empty());
        // Two triangles of half the quad's area: 16 x 8 pixels in all.
        let px = (SUBPIXEL * SUBPIXEL) as f64;
        let area: f64 = geo.tris.iter().map(|t| t.area2 as f64 / px / 2.0).sum();
        assert!((area - 128.0).abs() < 1e-6, "{area}");
    }
}
