//! What a frame's bands share and how a fragment's result reaches its
//! pixel: the frame's data (`BandInputs`, built once per frame: set-up,
//! shading context, vertices, draws, per-draw lane materials, the
//! backgrounds) and the sink that takes shaded fragments
//! (`Sink`, `PixelShare`, `resolve`). The band loop (`band`) and the lane
//! shading (`lanes`) both build on it; it depends on neither.

use glam::{Vec3, Vec4};

use super::backdrop::EnvBackground;
use super::draw_list::DrawList;
use super::geometry::{Draw, Geometry};
use super::ground::Ground;
use super::light_tiles::Culling;
use super::vertex::ModelVertices;
use crate::raster::setup::Tri;
use crate::raytrace::Tracer;
use crate::scene::material::AlphaMode;
use crate::scene::settings::{AoMethod, DepthMode, ShadingMode};
use crate::shade::lanes::LaneMaterial;
use crate::shade::{ShadeContext, background};

/// What every band of one frame reads.
pub(super) struct BandInputs<'a> {
    pub setup: &'a DrawList<'a>,
    pub ctx: ShadeContext<'a>,
    pub verts: &'a [ModelVertices],
    pub draws: &'a [Draw],
    /// Per draw.
    pub alpha: Vec<AlphaMode>,
    pub tris: &'a [Tri],
    /// Per model, per mesh triangle corner: tangents (`Geometry::tangents`).
    pub tangents: &'a [Vec<Vec4>],
    /// Sample offsets in 1/16 pixel; one entry without MSAA.
    pub pattern: &'static [(i8, i8)],
    pub reverse: bool,
    pub bg: Vec4,
    /// The environment seen through the camera, where the background
    /// shows it.
    pub env_bg: Option<EnvBackground<'a>>,
    /// The ground shadow catcher, over the background.
    pub ground: Option<Ground<'a>>,
    /// Texture filtering needs derivatives (trilinear, anisotropic).
    pub grads: bool,
    /// Shading reads the triangle's plane normal (flat shading, shadows,
    /// AO); otherwise it is not computed.
    pub geo_normal: bool,
    /// Per draw: its material prepared for shading a lane group at a
    /// time.
    pub lanes: Vec<LaneMaterial<'a>>,
    /// Per-tile light culling, where some light can be culled.
    pub culling: Option<Culling>,
    /// Lanes per lane call: 1, 4 or 8 (the same pixels at every width).
    pub lane_width: usize,
}

/// How a frame shades (the same pixels either way; the switches are for
/// tests that compare them).
#[derive(Debug, Clone, Copy)]
pub(super) struct Paths {
    /// Skip per tile the lights that cannot reach it.
    pub light_culling: bool,
    /// Lanes per lane call (1, 4 or 8).
    pub lane_width: usize,
}

impl<'a> BandInputs<'a> {
    /// `verts` and `geo`: the frame's vertex and geometry passes.
    /// `pattern`: the sample offsets; `grads`: the texture filter reads
    /// derivatives (trilinear, anisotropic). `paths`: the lane width,
    /// and whether to skip lights per tile (`light_tiles`).
    pub fn new(
        setup: &'a DrawList<'a>,
        ctx: ShadeContext<'a>,
        (verts, geo): (&'a [ModelVertices], &'a Geometry),
        (pattern, grads): (&'static [(i8, i8)], bool),
        tracer: Option<&'a Tracer<'a>>,
        paths: Paths,
    ) -> BandInputs<'a> {
        let s = &setup.scene.settings;
        let alpha = geo
            .draws
            .iter()
            .map(|d| setup.scene.models[d.model].materials[d.material].alpha)
            .collect();
        let geo_normal = s.shading == ShadingMode::Flat
            || !ctx.shadows.lights.is_empty()
            || s.ao.method != AoMethod::Off
            || ctx.env_sampled.is_some();
        let lanes = geo
            .draws
            .iter()
            .map(|d| {
                let model = &setup.scene.models[d.model];
                let (uvs, tangents) = mesh_inputs(model, &geo.tangents[d.model]);
                LaneMaterial::new(&ctx, &model.materials[d.material], uvs, tangents)
            })
            .collect();
        let culling = paths
            .light_culling
            .then(|| {
                Culling::new(
                    ctx.lights,
                    setup.clip_from_world,
                    geo.grid.width,
                    geo.grid.height,
                )
            })
            .flatten();
        BandInputs {
            setup,
            verts,
            draws: &geo.draws,
            alpha,
            tris: &geo.tris,
            tangents: &geo.tangents,
            pattern,
            reverse: s.depth == DepthMode::ReverseZ,
            bg: background(s.background),
            env_bg: EnvBackground::new(setup, ctx.env, geo.grid.width, geo.grid.height),
            ground: Ground::new(setup, &ctx, tracer, geo.grid.width, geo.grid.height),
            grads,
            geo_normal,
            lanes,
            culling,
            lane_width: paths.lane_width,
            ctx,
        }
    }

    /// Whether some blended draw transmits light (KHR_materials_transmission
    /// shaded as metallic-roughness): it refracts the opaque frame, so the
    /// frame's blended triangles wait for every band's opaque surfaces.
    pub(super) fn refracts(&self) -> bool {
        self.draws.iter().zip(&self.alpha).any(|(d, a)| {
            let m = &self.setup.scene.models[d.model].materials[d.material];
            *a == AlphaMode::Blend && m.pbr.transmission.is_some() && self.ctx.shades_pbr(m)
        })
    }

    /// Draw `draw`'s material prepared for the lanes, if it is.
    #[inline]
    pub(super) fn lane_material(&self, draw: usize) -> &LaneMaterial<'a> {
        &self.lanes[draw]
    }

    /// Whether draw `draw`'s mesh has texture coordinates of sets 0 and
    /// 1, and tangents.
    pub(super) fn mesh_inputs(&self, draw: usize) -> ([bool; 2], bool) {
        let model = self.draws[draw].model;
        mesh_inputs(&self.setup.scene.models[model], &self.tangents[model])
    }
}

/// Whether `model`'s mesh has texture coordinates of sets 0 and 1, and
/// tangents (`tangents`: its tangents this frame).
fn mesh_inputs(model: &crate::scene::Model, tangents: &[Vec4]) -> ([bool; 2], bool) {
    let mesh = &model.mesh;
    (
        [!mesh.uvs.is_empty(), !mesh.uvs1.is_empty()],
        !tangents.is_empty(),
    )
}

/// The pixel of a lane result that is resolved from its slot, after the
/// lanes (MSAA pixels with several fragments).
pub(super) const LANE_SLOT: u32 = u32::MAX;

/// Where lane results go: one-sample pixels straight to the band's
/// colour and depth, the others by slot for their pixels' resolve.
pub(super) struct Sink<'s> {
    pub color: &'s mut [Vec4],
    pub depth: &'s mut [f32],
    pub shaded: &'s mut Vec<(Vec3, f32)>,
    pub inv_n: f32,
}

impl Sink<'_> {
    /// The result of slot `slot` for `pixel`: linear colour, view depth.
    #[inline]
    pub fn put(&mut self, slot: u32, pixel: u32, count: f32, c: Vec3, d: f32) {
        if pixel == LANE_SLOT {
            let slot = slot as usize;
            if self.shaded.len() <= slot {
                self.shaded.resize(slot + 1, (Vec3::ZERO, 0.0));
            }
            self.shaded[slot] = (c, d);
        } else {
            let i = pixel as usize;
            (self.color[i], self.depth[i]) =
                resolve(&[PixelShare::Queued(0, count)], &[(c, d)], self.inv_n);
        }
    }
}

/// One fragment's share of a pixel: shaded already (linear RGBA, view
/// depth, sample count) or queued for the lanes (slot, sample count).
pub(super) enum PixelShare {
    Shaded(Vec4, f32, f32),
    Queued(u32, f32),
}

/// A pixel's colour and depth from its fragments in order: their colours
/// weighted by sample counts over `1 / inv_n` samples, the nearest depth.
/// `shaded`: the lane results by slot.
pub(super) fn resolve(parts: &[PixelShare], shaded: &[(Vec3, f32)], inv_n: f32) -> (Vec4, f32) {
    let mut acc = Vec4::ZERO;
    let mut nearest = f32::INFINITY;
    for p in parts {
        let (c, d, count) = match *p {
            PixelShare::Shaded(c, d, count) => (c, d, count),
            PixelShare::Queued(slot, count) => {
                let (c, d) = shaded[slot as usize];
                (c.extend(1.0), d, count)
            }
        };
        acc += c * count;
        nearest = nearest.min(d);
    }
    (acc * inv_n, nearest)
}

/// A surface point as the rasterizer sees it.
pub(super) struct Point {
    pub position: Vec3,
    /// Interpolated unit normal, on the side the camera sees.
    pub normal: Vec3,
    /// The triangle's plane normal, on the side the camera sees.
    pub geo_normal: Vec3,
    pub view_depth: f32,
}
