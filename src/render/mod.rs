//! One frame: the per-frame draw list (camera and models turned for this
//! frame, lights in world space), then the stages in order:
//! vertex transform -> clip + setup + binning (parallel over chunks of
//! triangles, merged in submission order) -> per tile (parallel): visibility
//! with the depth test, then shading of each visible pixel once -> `Frame`.
//!
//! Each tile owns its pixels: no locks, no shared writes, and the same frame
//! whatever the number of threads.

use glam::{Mat3, Mat4, Vec3, Vec4};
use rayon::prelude::*;

use crate::raster::bin::{TileGrid, bin};
use crate::raster::clip::{ClipVertex, Clipped, clip_triangle};
use crate::raster::coverage::sample_pattern;
use crate::raster::setup::{SUBPIXEL, Tri, Viewport, setup};
use crate::raytrace::Tracer;
use crate::scene::Scene;
use crate::scene::camera::{Camera, Projection};
use crate::scene::light::{Light, LightKind};
use crate::scene::material::AlphaMode;
use crate::scene::settings::{AoMethod, CullMode, DepthMode, ShadingMode, TextureFilter};
use crate::shade::ao::{self, AoView};
use crate::shade::shadow::Shadows;
use crate::shade::{ShadeContext, background, blinn_phong};

mod band;
mod shadow_pass;

/// A rendered frame in linear space, before tone mapping.
#[derive(Debug, Clone)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Linear RGB and coverage alpha per pixel, row-major from the top.
    /// For the data views (normals, depth, wireframe) RGB is already the
    /// display value.
    pub color: Vec<Vec4>,
    /// Distance along the view axis at the pixel center; +inf where nothing
    /// was drawn.
    pub depth: Vec<f32>,
    /// Ambient occlusion at the pixel center (1: unoccluded, and where
    /// nothing was drawn); empty unless the scene selects an AO method.
    pub ao: Vec<f32>,
}

impl Frame {
    pub fn new(width: u32, height: u32) -> Frame {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            color: vec![Vec4::ZERO; n],
            depth: vec![f32::INFINITY; n],
            ao: Vec::new(),
        }
    }

    fn resize(&mut self, width: u32, height: u32) {
        let n = width as usize * height as usize;
        self.width = width;
        self.height = height;
        self.color.resize(n, Vec4::ZERO);
        self.depth.resize(n, f32::INFINITY);
    }
}

/// The draw list of one frame: everything placed where it is at this frame.
pub struct FrameSetup<'a> {
    pub scene: &'a Scene,
    pub camera: Camera,
    pub world_from_object: Vec<Mat4>,
    pub lights: Vec<Light>,
    pub clip_from_world: Mat4,
}

impl<'a> FrameSetup<'a> {
    pub fn new(scene: &'a Scene, camera: usize, frame: u32) -> FrameSetup<'a> {
        let turn = scene.animation.turn(frame);
        let mut cam = scene.cameras[camera].clone();
        if scene.animation.rotates_camera() {
            cam.eye = turn.transform_point3(cam.eye);
            cam.target = turn.transform_point3(cam.target);
            cam.up = turn.transform_vector3(cam.up);
        }
        let world_from_object = scene
            .models
            .iter()
            .map(|m| {
                if scene.animation.rotates_models() {
                    turn * m.world_from_object
                } else {
                    m.world_from_object
                }
            })
            .collect();
        let lights = if scene.lights.is_empty() {
            // Headlight: a directional light travelling along the view.
            vec![Light {
                kind: LightKind::Directional {
                    direction: cam.forward(),
                    irradiance: 1.0,
                },
                color: Vec3::ONE,
                shadows: false,
                range: None,
            }]
        } else {
            scene.lights.clone()
        };
        let s = &scene.settings;
        let aspect = s.width as f32 / s.height as f32;
        let clip_from_world = cam.clip_from_view(aspect, s.depth) * cam.view_from_world();
        FrameSetup {
            scene,
            camera: cam,
            world_from_object,
            lights,
            clip_from_world,
        }
    }
}

/// Vertices of one model after the vertex stage.
struct ModelVertices {
    world: Vec<Vec3>,
    normal: Vec<Vec3>,
    clip: Vec<Vec4>,
    /// Gouraud only: per-vertex (diffuse, specular) light sums.
    light: Vec<(Vec3, Vec3)>,
    /// Per triangle corner: world-space tangent and bitangent sign (empty
    /// when the mesh has no tangents).
    tangent: Vec<Vec4>,
    normal_from_object: Mat3,
}

/// One model's triangles that share a material.
#[derive(Clone, Copy)]
struct Draw {
    model: usize,
    material: usize,
    first: u32,
    end: u32,
}

const CHUNK: u32 = 2048;

/// Per chunk of triangles: set-up triangles, per-band triangle lists and
/// the largest texel density in each texture-coordinate set.
type ChunkOut = (Vec<Tri>, Vec<Vec<u32>>, [f32; 2]);

pub fn render_frame(scene: &Scene, camera: usize, frame: u32) -> Frame {
    let fs = FrameSetup::new(scene, camera, frame);
    render_setup(&fs)
}

pub fn render_setup(fs: &FrameSetup) -> Frame {
    let mut frame = Frame::new(0, 0);
    render_into(fs, &mut frame);
    frame
}

/// Renders into `frame`, reusing its buffers (resized to the scene's
/// output size); every pixel is written. With supersampling the frame is
/// rendered at `ssaa` times the size per axis and box-filtered down.
pub fn render_into(fs: &FrameSetup, frame: &mut Frame) {
    let s = &fs.scene.settings;
    let k = s.ssaa.max(1);
    if k == 1 {
        render_at(fs, s.width, s.height, frame);
        return;
    }
    let mut big = Frame::new(0, 0);
    render_at(fs, s.width * k, s.height * k, &mut big);
    downsample(&big, k, frame);
}

/// Box filter of `k` x `k` blocks: the mean color (linear, before tone
/// mapping) and AO, the nearest depth.
fn downsample(big: &Frame, k: u32, out: &mut Frame) {
    let (w, h) = (big.width / k, big.height / k);
    out.resize(w, h);
    let k = k as usize;
    let bw = big.width as usize;
    let inv = 1.0 / (k * k) as f32;
    let has_ao = !big.ao.is_empty();
    if has_ao {
        out.ao.resize(w as usize * h as usize, 1.0);
    } else {
        out.ao.clear();
    }
    let w = w as usize;
    out.color
        .par_chunks_mut(w)
        .zip(out.depth.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (color, depth))| {
            for x in 0..w {
                let mut c = Vec4::ZERO;
                let mut d = f32::INFINITY;
                for sy in 0..k {
                    let row = (y * k + sy) * bw + x * k;
                    for sx in 0..k {
                        c += big.color[row + sx];
                        d = d.min(big.depth[row + sx]);
                    }
                }
                color[x] = c * inv;
                depth[x] = d;
            }
        });
    if has_ao {
        out.ao.par_chunks_mut(w).enumerate().for_each(|(y, ao)| {
            for (x, a) in ao.iter_mut().enumerate() {
                let mut sum = 0.0;
                for sy in 0..k {
                    let row = (y * k + sy) * bw + x * k;
                    sum += big.ao[row..row + k].iter().sum::<f32>();
                }
                *a = sum * inv;
            }
        });
    }
}

/// Renders the frame at `width` x `height` pixels.
fn render_at(fs: &FrameSetup, width: u32, height: u32, frame: &mut Frame) {
    let scene = fs.scene;
    let s = &scene.settings;
    frame.resize(width, height);
    let pattern = sample_pattern(s.msaa).unwrap_or(&[(0, 0)]);
    let msaa = pattern.len() > 1;
    let vp = Viewport {
        width,
        height,
        msaa,
    };

    // Vertex stage, then the shadow pass over the placed vertices.
    let mut verts: Vec<ModelVertices> = scene
        .models
        .iter()
        .zip(&fs.world_from_object)
        .map(|(m, world)| vertex_stage(fs, m, *world))
        .collect();
    let shadows = shadow_pass::shadows(fs, &verts);
    if s.shading == ShadingMode::Gouraud {
        for (m, mv) in scene.models.iter().zip(&mut verts) {
            mv.light = vertex_light(fs, m, mv, &shadows);
        }
    }

    // Draw list: one draw per model and material group, in file order.
    let mut draws = Vec::new();
    for (mi, m) in scene.models.iter().enumerate() {
        for g in &m.mesh.groups {
            draws.push(Draw {
                model: mi,
                material: g.material,
                first: g.triangles.start,
                end: g.triangles.end,
            });
        }
    }
    let mut chunks = Vec::new();
    for (di, d) in draws.iter().enumerate() {
        let mut start = d.first;
        while start < d.end {
            let end = (start + CHUNK).min(d.end);
            chunks.push((di, start, end));
            start = end;
        }
    }

    // Clip, set up and bin, chunk by chunk; merged in submission order.
    let grid = TileGrid::bands(width, height);
    let (gx, gy) = vp.guard_band();
    let cull = s.cull;
    let filtered = matches!(
        s.texture_filter,
        TextureFilter::Trilinear | TextureFilter::Anisotropic
    ) && !scene.textures.is_empty();
    let per_chunk: Vec<ChunkOut> = chunks
        .par_iter()
        .map(|&(di, start, end)| {
            let d = draws[di];
            let mesh = &scene.models[d.model].mesh;
            let clip = &verts[d.model].clip;
            // glTF doubleSided materials are never culled.
            let cull = if scene.models[d.model].materials[d.material].double_sided {
                CullMode::None
            } else {
                cull
            };
            let mut tris = Vec::with_capacity((end - start) as usize);
            let density = filtered
                && scene.models[d.model].materials[d.material]
                    .maps()
                    .next()
                    .is_some();
            let mut max_density = [0.0f32; 2];
            for prim in start..end {
                let before = tris.len();
                let idx = mesh.triangles[prim as usize];
                let v = idx.map(|i| clip[i as usize]);
                let base = |k: usize, b: Vec3| ClipVertex { pos: v[k], bary: b };
                match clip_triangle(v, gx, gy) {
                    Clipped::Rejected => {}
                    Clipped::Inside => {
                        let tri = [base(0, Vec3::X), base(1, Vec3::Y), base(2, Vec3::Z)];
                        tris.extend(setup(tri, vp, cull, di as u32, prim));
                    }
                    Clipped::Polygon(p) => {
                        let p = p.as_slice();
                        for k in 1..p.len() - 1 {
                            tris.extend(setup([p[0], p[k], p[k + 1]], vp, cull, di as u32, prim));
                        }
                    }
                }
                if density {
                    for t in &tris[before..] {
                        for (set, uvs) in [&mesh.uvs, &mesh.uvs1].into_iter().enumerate() {
                            if !uvs.is_empty() {
                                max_density[set] = max_density[set].max(uv_density(t, uvs, idx));
                            }
                        }
                    }
                }
            }
            let bins = bin(&tris, &grid, msaa);
            (tris, bins, max_density)
        })
        .collect();
    let mut offsets = Vec::with_capacity(per_chunk.len());
    let mut total = 0u32;
    for (t, _, _) in &per_chunk {
        offsets.push(total);
        total += t.len() as u32;
    }
    let tris: Vec<Tri> = per_chunk
        .iter()
        .flat_map(|(t, _, _)| t.iter().copied())
        .collect();

    // Mip chains for the textures this frame minifies (built once, on the
    // first frame that needs them); the others read level 0 only, so a
    // frame's pixels do not depend on which frames came before.
    let mut mips = vec![false; scene.textures.len()];
    for (&(di, _, _), (_, _, density)) in chunks.iter().zip(&per_chunk) {
        let d = draws[di];
        for map in scene.models[d.model].materials[d.material].maps() {
            let t = &map.texture;
            let texels = density[(map.texcoord as usize).min(1)]
                * t.width as f32
                * t.height as f32
                * map.transform.matrix2.determinant().abs();
            // Footprints of half a texel and up: the level-of-detail can
            // pass 0 somewhere in such a triangle.
            if texels > 0.25 {
                mips[t.id] = true;
            }
        }
    }
    scene
        .textures
        .par_iter()
        .filter(|t| mips[t.id])
        .for_each(|t| t.ensure_mips());

    let mut ctx = shade_context(fs, &mips, &shadows);
    // Wireframe lines keep their width in output pixels.
    ctx.pixel_scale = width as f32 / s.width as f32;
    let alpha: Vec<AlphaMode> = draws
        .iter()
        .map(|d| scene.models[d.model].materials[d.material].alpha)
        .collect();
    let data = band::FrameData {
        fs,
        ctx,
        verts: &verts,
        draws: &draws,
        alpha: &alpha,
        tris: &tris,
        pattern,
        reverse: s.depth == DepthMode::ReverseZ,
        bg: background(s.background),
        grads: filtered,
        geo_normal: s.shading == ShadingMode::Flat
            || !shadows.lights.is_empty()
            || s.ao.method != AoMethod::Off,
    };
    let bins: Vec<(&[Vec<u32>], u32)> = per_chunk
        .iter()
        .zip(&offsets)
        .map(|((_, b, _), off)| (b.as_slice(), *off))
        .collect();
    // Each band owns its rows of the frame: visibility, then shading
    // straight into the frame buffer.
    let band = (grid.tile_w * grid.tile_h) as usize;
    if s.ao.method == AoMethod::Off {
        frame.ao.clear();
        frame
            .color
            .par_chunks_mut(band)
            .zip(frame.depth.par_chunks_mut(band))
            .enumerate()
            .for_each(|(ti, (color, depth))| {
                let (vis, blended) = data.visibility(grid.rect(ti), ti, &bins);
                data.shade_band(&vis, blended, None, color, depth);
            });
        return;
    }
    // With ambient occlusion: visibility and the geometry buffer of every
    // band, the AO of the whole frame, then shading.
    let mut gbuf = vec![ao::GPixel::EMPTY; frame.color.len()];
    let visible: Vec<_> = gbuf
        .par_chunks_mut(band)
        .enumerate()
        .map(|(ti, g)| {
            let (vis, blended) = data.visibility(grid.rect(ti), ti, &bins);
            data.gbuffer(&vis, g);
            (vis, blended)
        })
        .collect();
    let view = AoView::new(&fs.camera, width, height);
    frame.ao = match s.ao.method {
        AoMethod::Raytraced => {
            // Ray-traced shadows already placed the scene for this frame.
            let own;
            let tracer = match &shadows.tracer {
                Some(t) => t,
                None => {
                    own = Tracer::new(scene, &fs.world_from_object);
                    &own
                }
            };
            ao::raytraced(tracer, &gbuf, width, s.ao.samples, s.ao.radius)
        }
        _ => {
            let radius = s.ao.radius.unwrap_or(scene.bounds_radius * 0.2);
            ao::ssao(&gbuf, &view, radius, s.ao.samples)
        }
    };
    frame
        .color
        .par_chunks_mut(band)
        .zip(frame.depth.par_chunks_mut(band))
        .zip(frame.ao.par_chunks(band))
        .zip(visible)
        .for_each(|(((color, depth), ao), (vis, blended))| {
            data.shade_band(&vis, blended, Some(ao), color, depth);
        });
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

fn vertex_stage(
    fs: &FrameSetup,
    m: &crate::scene::Model,
    world_from_object: Mat4,
) -> ModelVertices {
    let mesh = &m.mesh;
    let normal_from_object = Mat3::from_mat4(world_from_object).inverse().transpose();
    let n = mesh.positions.len();
    let mut world = vec![Vec3::ZERO; n];
    let mut normal = vec![Vec3::ZERO; n];
    let mut clip = vec![Vec4::ZERO; n];
    const V_CHUNK: usize = 8192;
    world
        .par_chunks_mut(V_CHUNK)
        .zip(normal.par_chunks_mut(V_CHUNK))
        .zip(clip.par_chunks_mut(V_CHUNK))
        .enumerate()
        .for_each(|(c, ((w, nn), cl))| {
            let base = c * V_CHUNK;
            for i in 0..w.len() {
                let p = world_from_object.transform_point3(mesh.positions[base + i]);
                w[i] = p;
                nn[i] = (normal_from_object * mesh.normals[base + i]).normalize_or(Vec3::Y);
                cl[i] = fs.clip_from_world * p.extend(1.0);
            }
        });
    // Tangents follow the surface (not the inverse transpose); a mirroring
    // transform flips the bitangent.
    let m3 = Mat3::from_mat4(world_from_object);
    let flip = if m3.determinant() < 0.0 { -1.0 } else { 1.0 };
    let tangent = mesh
        .tangents
        .par_iter()
        .map(|t| (m3 * t.truncate()).normalize_or(Vec3::X).extend(t.w * flip))
        .collect();
    ModelVertices {
        world,
        normal,
        clip,
        light: Vec::new(),
        tangent,
        normal_from_object,
    }
}

/// Gouraud: per-vertex (diffuse, specular) light sums, each vertex lit with
/// the exponent of a material that uses it and shadowed at the vertex.
fn vertex_light(
    fs: &FrameSetup,
    m: &crate::scene::Model,
    mv: &ModelVertices,
    shadows: &Shadows,
) -> Vec<(Vec3, Vec3)> {
    let mesh = &m.mesh;
    let n = mesh.positions.len();
    let mut ns = vec![32.0f32; n];
    let mut spec = vec![false; n];
    for g in &mesh.groups {
        let mat = &m.materials[g.material];
        for t in &mesh.triangles[g.triangles.start as usize..g.triangles.end as usize] {
            for &i in t {
                ns[i as usize] = mat.ns;
                spec[i as usize] = mat.illum >= 2;
            }
        }
    }
    let ctx = shade_context(fs, &[], shadows);
    (0..n)
        .into_par_iter()
        .map(|i| {
            let (p, nn) = (mv.world[i], mv.normal[i]);
            let v = ctx.view_vector(p);
            let shadow = |k: usize, l: Vec3| shadows.visibility(k, p, nn, l);
            blinn_phong::light_sums(p, nn, v, ns[i], spec[i], &fs.lights, &shadow)
        })
        .collect()
}

fn shade_context<'a>(
    fs: &'a FrameSetup,
    mips: &'a [bool],
    shadows: &'a Shadows<'a>,
) -> ShadeContext<'a> {
    let s = &fs.scene.settings;
    let cam = &fs.camera;
    let forward = cam.forward();
    let dist = (fs.scene.bounds_center - cam.eye).dot(forward);
    let r = fs.scene.bounds_radius;
    let lo = (dist - r).max(cam.near);
    let hi = (dist + r).max(lo + 1e-6);
    ShadeContext {
        mode: s.shading,
        lights: &fs.lights,
        ambient: s.ambient,
        eye: cam.eye,
        forward,
        orthographic: matches!(cam.projection, Projection::Orthographic { .. }),
        filter: s.texture_filter,
        max_anisotropy: s.max_anisotropy,
        address: s.address,
        mips,
        depth_range: (lo, hi),
        shadows,
        pixel_scale: 1.0,
    }
}
