//! One frame: the per-frame draw list (camera and models turned for this
//! frame, lights in world space), then the stages in order:
//! vertex transform -> clip + setup + binning (parallel over chunks of
//! triangles, merged in submission order) -> per tile (parallel): visibility
//! with the depth test, then shading of each visible pixel once -> `Frame`.
//!
//! Each tile owns its pixels: no locks, no shared writes, and the same frame
//! whatever the number of threads.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use rayon::prelude::*;

use crate::raster::bin::{TileGrid, bin};
use crate::raster::clip::{ClipVertex, Clipped, clip_triangle};
use crate::raster::coverage::{NO_TRIANGLE, Visibility};
use crate::raster::interp::Interpolator;
use crate::raster::setup::{Tri, Viewport, setup};
use crate::scene::Scene;
use crate::scene::camera::{Camera, Projection};
use crate::scene::desc::{DepthMode, ShadingMode};
use crate::scene::light::{Light, LightKind};
use crate::shade::{ShadeContext, Surface, background, blinn_phong};

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
}

impl Frame {
    pub fn new(width: u32, height: u32) -> Frame {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            color: vec![Vec4::ZERO; n],
            depth: vec![f32::INFINITY; n],
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
/// output size); every pixel is written.
pub fn render_into(fs: &FrameSetup, frame: &mut Frame) {
    let scene = fs.scene;
    let s = &scene.settings;
    frame.resize(s.width, s.height);
    let vp = Viewport {
        width: s.width,
        height: s.height,
    };

    // Vertex stage.
    let verts: Vec<ModelVertices> = scene
        .models
        .iter()
        .zip(&fs.world_from_object)
        .map(|(m, world)| vertex_stage(fs, m, *world))
        .collect();

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
    let grid = TileGrid::bands(s.width, s.height);
    let (gx, gy) = vp.guard_band();
    let cull = s.cull;
    let per_chunk: Vec<(Vec<Tri>, Vec<Vec<u32>>)> = chunks
        .par_iter()
        .map(|&(di, start, end)| {
            let d = draws[di];
            let mesh = &scene.models[d.model].mesh;
            let clip = &verts[d.model].clip;
            let mut tris = Vec::with_capacity((end - start) as usize);
            for prim in start..end {
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
            }
            let bins = bin(&tris, &grid);
            (tris, bins)
        })
        .collect();
    let mut offsets = Vec::with_capacity(per_chunk.len());
    let mut total = 0u32;
    for (t, _) in &per_chunk {
        offsets.push(total);
        total += t.len() as u32;
    }
    let tris: Vec<Tri> = per_chunk
        .iter()
        .flat_map(|(t, _)| t.iter().copied())
        .collect();

    let ctx = shade_context(fs);
    let bg = background(s.background);
    let reverse = s.depth == DepthMode::ReverseZ;
    // Each band owns its rows of the frame: visibility, then shading
    // straight into the frame buffer.
    let band = (grid.tile_w * grid.tile_h) as usize;
    frame
        .color
        .par_chunks_mut(band)
        .zip(frame.depth.par_chunks_mut(band))
        .enumerate()
        .for_each(|(ti, (color, depth))| {
            let rect = grid.rect(ti);
            let mut vis = Visibility::new(rect, reverse);
            for ((_, bins), off) in per_chunk.iter().zip(&offsets) {
                for &i in &bins[ti] {
                    let id = off + i;
                    if reverse {
                        vis.draw::<true>(&tris[id as usize], id);
                    } else {
                        vis.draw::<false>(&tris[id as usize], id);
                    }
                }
            }
            shade_tile(fs, &ctx, &verts, &draws, &tris, &vis, bg, color, depth);
        });
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
    let mut light = Vec::new();
    if fs.scene.settings.shading == ShadingMode::Gouraud {
        // Each vertex lit with the exponent of a material that uses it.
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
        let ctx = shade_context(fs);
        light = (0..n)
            .into_par_iter()
            .map(|i| {
                let v = ctx.view_vector(world[i]);
                blinn_phong::light_sums(world[i], normal[i], v, ns[i], spec[i], &fs.lights)
            })
            .collect();
    }
    ModelVertices {
        world,
        normal,
        clip,
        light,
    }
}

fn shade_context<'a>(fs: &'a FrameSetup) -> ShadeContext<'a> {
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
        address: s.address,
        depth_range: (lo, hi),
    }
}

#[allow(clippy::too_many_arguments)]
fn shade_tile(
    fs: &FrameSetup,
    ctx: &ShadeContext,
    verts: &[ModelVertices],
    draws: &[Draw],
    tris: &[Tri],
    vis: &Visibility,
    bg: Vec4,
    color: &mut [Vec4],
    depth: &mut [f32],
) {
    let rect = vis.rect;
    let tw = rect.width();
    color.fill(bg);
    depth.fill(f32::INFINITY);
    let mode = ctx.mode;
    let ortho = ctx.orthographic;
    // Runs of pixels from one triangle share its interpolator.
    let mut current = NO_TRIANGLE;
    let mut it: Option<Interpolator> = None;
    for (i, &id) in vis.id.iter().enumerate() {
        if id == NO_TRIANGLE {
            continue;
        }
        let px = rect.x0 + (i % tw) as i32;
        let py = rect.y0 + (i / tw) as i32;
        let t = &tris[id as usize];
        if id != current {
            current = id;
            it = Some(Interpolator::new(t));
        }
        let Some(it) = &it else { continue };
        let frag = it.at_pixel(px, py);
        let d = draws[t.draw as usize];
        let model = &fs.scene.models[d.model];
        let mv = &verts[d.model];
        let idx = model.mesh.triangles[t.prim as usize].map(|v| v as usize);
        let l = frag.lambda;
        let lerp3 = |a: &[Vec3]| a[idx[0]] * l.x + a[idx[1]] * l.y + a[idx[2]] * l.z;
        let position = lerp3(&mv.world);
        let raw_normal = lerp3(&mv.normal);
        let view_depth = if ortho {
            (position - ctx.eye).dot(ctx.forward)
        } else {
            frag.w
        };
        let normal = if mode == ShadingMode::Flat {
            let [a, b, c] = idx.map(|k| mv.world[k]);
            (b - a).cross(c - a).normalize_or(raw_normal)
        } else {
            raw_normal.normalize_or(Vec3::Y)
        };
        // Light the side the camera sees.
        let normal = if t.front { normal } else { -normal };
        let uv = model.mesh.has_uvs().then(|| {
            let uv = &model.mesh.uvs;
            uv[idx[0]] * l.x + uv[idx[1]] * l.y + uv[idx[2]] * l.z
        });
        let vertex_light = (!mv.light.is_empty()).then(|| {
            let g = |k: usize| mv.light[idx[k]];
            let (a, b, c) = (g(0), g(1), g(2));
            (
                a.0 * l.x + b.0 * l.y + c.0 * l.z,
                a.1 * l.x + b.1 * l.y + c.1 * l.z,
            )
        });
        let edge_distance = if mode == ShadingMode::Wireframe {
            edge_distance(it, px, py, l)
        } else {
            f32::INFINITY
        };
        let surface = Surface {
            material: &model.materials[d.material],
            position,
            normal,
            raw_normal,
            uv,
            view_depth,
            vertex_light,
            edge_distance,
        };
        let c = ctx.shade(&surface);
        // A NaN from degenerate input must not poison the frame.
        color[i] = if c.is_finite() {
            c.extend(1.0)
        } else {
            Vec4::W
        };
        depth[i] = view_depth;
    }
}

/// Screen-space distance (pixels) from the pixel center to the nearest edge
/// of the original triangle: each barycentric over the length of its
/// screen-space gradient.
fn edge_distance(it: &Interpolator, px: i32, py: i32, l: Vec3) -> f32 {
    let dx = it.at_pixel(px + 1, py).lambda - l;
    let dy = it.at_pixel(px, py + 1).lambda - l;
    let mut best = f32::INFINITY;
    for k in 0..3 {
        let g = Vec2::new(dx[k], dy[k]).length();
        if g > 0.0 {
            best = best.min(l[k] / g);
        }
    }
    best
}
