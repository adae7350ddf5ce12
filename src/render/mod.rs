//! One frame, as a short list of passes over the frame's draw list
//! (`DrawList`):
//!
//! 1. `vertex`: every model's vertices placed for the frame;
//! 2. `shadow_pass`: a depth map per shadow-casting light, or the BVHs for
//!    ray-traced shadows;
//! 3. Gouraud only: light summed at the vertices (`shade::gouraud`);
//! 4. `geometry`: clip, set up and bin every triangle;
//! 5. textures: the mip chains of the textures this frame minifies;
//! 6. per band of rows (`band`): visibility with the depth test, then
//!    (with AO on) the geometry buffer of every band, `ao_pass` over the
//!    whole frame, and shading of each visible pixel once (`lanes`: 1, 4
//!    or 8 fragments at a time; `fragment`: the data every band reads and
//!    the sink that takes shaded fragments to their pixels; `aovs`: the
//!    data passes);
//! 7. `frame`: with supersampling, the box filter down to the output size.
//!
//! Each band owns its rows: no locks, no shared writes, and the same frame
//! whatever the number of threads.
//!
//! `Renderer` is the render state of one scene, which it borrows and
//! never writes to, kept across its frames: the BVH of each mesh, built on
//! the first frame that needs it (the mip chains are kept with the
//! textures). `Renderer::render` of a `Shot` (camera and frame) is the
//! one entry for a frame.

mod ao_pass;
mod aovs;
mod backdrop;
mod band;
mod bounce;
mod bounce_pass;
pub mod display;
mod draw_list;
mod emitters;
mod env_cache;
mod exposure;
mod fragment;
mod frame;
mod geometry;
mod ground;
mod lanes;
mod light_tiles;
mod lines;
pub mod memory;
mod rays;
mod shadow_pass;
mod surface;
mod vertex;

use std::sync::{Arc, OnceLock};

use glam::Vec3;
use rayon::prelude::*;

pub use display::{Image8, resolve};
pub use draw_list::DrawList;
pub use frame::{AovPixel, Frame, FrameSequence};

use crate::assets::mesh::Mesh;
use crate::assets::mip;
use crate::assets::texture::Level;
use crate::error::Error;
use crate::raster::coverage::{Visibility, sample_pattern};
use crate::raster::setup::Viewport;
use crate::raytrace::bvh::Bvh;
use crate::raytrace::{Cutout, Placed, Tracer};
use crate::scene::camera::Projection;
use crate::scene::environment::{Bounces, EnvMethod};
use crate::scene::material::{Native, roughness_from_ns};
use crate::scene::settings::{AoMethod, Background, ShadingMode, ShadowMethod, TextureFilter};
use crate::scene::{Light, Scene};
use crate::shade::ao::GPixel;
use crate::shade::env::EnvLight;
use crate::shade::env::bounce::Surfaces;
use crate::shade::env::emitters::Emitters;
use crate::shade::env::reflect::{GLOSSY_FROM, Reflections, pass_roughness};
use crate::shade::env::sampled::{EnvSampler, Sampled};
use crate::shade::refraction::{self, OpaqueFrame};
use crate::shade::shadow::Shadows;
use crate::shade::{ShadeContext, gouraud};
use geometry::Geometry;

/// Where `render.msaa = samples` samples each pixel: offsets from the
/// pixel's center in 1/16 pixel, x right and y down, the standard
/// Direct3D (and Vulkan) positions for 1, 2, 4, 8 and 16 samples; None for
/// other counts. For checking coverage against a known shape.
pub fn msaa_sample_positions(samples: u32) -> Option<&'static [(i8, i8)]> {
    sample_pattern(samples)
}

/// The lane widths this build shades with (each frame is the same bytes at
/// every one): 1, 4 and 8 where it targets AVX (x86-64-v3, the default
/// x86-64 build), else 1 and 4.
pub fn lane_widths() -> &'static [usize] {
    crate::simd::widths()
}

/// The lane width the `SOFTRASTER_LANES` variable forces (1, 4 or 8, for
/// tests and bug reports), or None without it. A width this build lacks
/// is an `Error::Argument` naming the variable and the widths it has.
pub fn forced_lane_width() -> Result<Option<usize>, Error> {
    crate::simd::lane_width().map_err(Error::Argument)
}

/// What one call renders: a camera of the scene (its index in
/// `Scene::cameras`), a frame of its animation, and the exposure its
/// display image takes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Shot {
    /// The camera's index in `Scene::cameras`.
    pub camera: usize,
    /// The frame of the animation, from 0.
    pub frame: u32,
    /// Stops (`2^exposure` scales the radiance before the tone map); None:
    /// the scene's `render.exposure` (`Renderer::exposure`).
    pub exposure: Option<f32>,
}

impl Shot {
    /// Camera `camera` at frame `frame`, at the scene's exposure.
    pub fn new(camera: usize, frame: u32) -> Shot {
        Shot {
            camera,
            frame,
            exposure: None,
        }
    }

    /// The same shot at `stops` of exposure.
    pub fn with_exposure(self, stops: f32) -> Shot {
        Shot {
            exposure: Some(stops),
            ..self
        }
    }
}

/// The renderer of one scene: it borrows the scene, which it never
/// writes to, and keeps what its frames share: the BVH of each mesh
/// (built on the first frame that traces rays), the environment's
/// prefiltered lighting, the last shadow maps and backdrop. The mip chains
/// are kept with the textures themselves (`Texture::mip_chain`), so a
/// renderer for another setting of the same scene reuses them. Another
/// scene, or the same scene changed, takes a renderer of its own.
pub struct Renderer<'s> {
    scene: &'s Scene,
    /// The scene's distinct meshes (models may share one).
    meshes: Vec<&'s Arc<Mesh>>,
    /// Per model: its mesh's index in `meshes`.
    model_mesh: Vec<usize>,
    /// Per mesh: its object-space BVH and bounds, built on first need.
    bvhs: Vec<OnceLock<(Bvh, (Vec3, Vec3))>>,
    /// The environment's prefiltered lighting (built on the first frame).
    env: OnceLock<Option<Arc<EnvLight>>>,
    /// `method = "sampled"`: the environment's sampling tables.
    env_sampler: OnceLock<Option<EnvSampler>>,
    /// The last frame's shadow maps (reused while nothing they depend on
    /// moves).
    shadow_maps: shadow_pass::MapCache,
    /// The last camera's environment backdrop (reused while the view
    /// stays).
    backdrops: backdrop::BackdropCache,
    /// The last camera's ground view (`ground::GroundView`).
    grounds: ground::GroundCache,
    /// Skip, per tile, the lights that cannot reach it (`light_tiles`);
    /// off only to compare.
    light_culling: bool,
    /// Lanes per lane call: 1, 4 or 8 (`simd::lane_width`).
    lane_width: usize,
    /// `render.exposure = "auto"`, computed on first need.
    auto_exposure: OnceLock<f32>,
}

impl<'s> Renderer<'s> {
    /// The renderer of `scene`; it builds nothing until a frame needs it.
    pub fn new(scene: &'s Scene) -> Renderer<'s> {
        let mut meshes: Vec<&Arc<Mesh>> = Vec::new();
        let model_mesh = scene
            .models
            .iter()
            .map(
                |m| match meshes.iter().position(|k| Arc::ptr_eq(k, &m.mesh)) {
                    Some(i) => i,
                    None => {
                        meshes.push(&m.mesh);
                        meshes.len() - 1
                    }
                },
            )
            .collect();
        Renderer {
            scene,
            bvhs: meshes.iter().map(|_| OnceLock::new()).collect(),
            meshes,
            model_mesh,
            env: OnceLock::new(),
            env_sampler: OnceLock::new(),
            shadow_maps: Default::default(),
            backdrops: Default::default(),
            grounds: Default::default(),
            light_culling: true,
            lane_width: crate::simd::lane_width()
                .ok()
                .flatten()
                .unwrap_or(crate::simd::widest()),
            auto_exposure: OnceLock::new(),
        }
    }

    /// The scene this renderer draws.
    pub fn scene(&self) -> &'s Scene {
        self.scene
    }

    /// The scene's exposure in stops: `render.exposure`, and for "auto"
    /// the one value of the whole sequence (every camera, every frame),
    /// computed here on first need, so a turntable does not flicker and
    /// every shard of a farm run gets the same value. It does not depend
    /// on the renderer's other settings.
    pub fn exposure(&self) -> f32 {
        let s = &self.scene.settings;
        if !s.auto_exposure {
            return s.exposure;
        }
        *self
            .auto_exposure
            .get_or_init(|| exposure::auto_exposure(self.scene))
    }

    /// Shades `width` lanes at a time (1, 4 or 8; a width this build
    /// lacks (`simd::widths`) takes the widest it has). The frames are
    /// the same bytes at every width (tests compare them).
    pub fn with_lane_width(mut self, width: usize) -> Renderer<'s> {
        self.lane_width = if crate::simd::widths().contains(&width) {
            width
        } else {
            crate::simd::widest()
        };
        self
    }

    /// With `on = false`, every fragment is shaded with every light, not
    /// only those that can reach its tile. The frames are the same either
    /// way (tests compare them bit for bit).
    pub fn with_light_culling(mut self, on: bool) -> Renderer<'s> {
        self.light_culling = on;
        self
    }

    /// Renders `shot` into `out`, reusing its buffers (resized to the
    /// scene's output size); every pixel is written. With supersampling
    /// the frame is rendered `ssaa` times the size per axis and
    /// box-filtered down. A camera the scene does not have is an error
    /// naming it.
    pub fn render(&self, shot: Shot, out: &mut Frame) -> Result<(), Error> {
        self.render_frame(self.setup(shot, out)?, out, None);
        Ok(())
    }

    /// `render`, and `*image = resolve(out, &scene.settings)`: the display
    /// bytes of each band are made as soon as the band is shaded (while
    /// its colour is in the cache) unless a later pass (the line overlay,
    /// supersampling's filter) still changes the frame.
    pub fn render_display(
        &self,
        shot: Shot,
        out: &mut Frame,
        image: &mut Image8,
    ) -> Result<(), Error> {
        self.render_frame(self.setup(shot, out)?, out, Some(image));
        Ok(())
    }

    /// `render_display` (with `image`) or `render` of the next shot of a
    /// sequence into `seq`: the band rows the last frame left as plain
    /// background are not filled again (the same frames and bytes).
    pub fn render_next(
        &self,
        shot: Shot,
        seq: &mut FrameSequence,
        image: Option<&mut Image8>,
    ) -> Result<(), Error> {
        let (out, known) = seq.parts();
        let setup = self.setup(shot, out)?;
        let s = &self.scene.settings;
        if (out.width, out.height) != (s.width, s.height) || s.ssaa.max(1) > 1 {
            // Another size, or a filter over a larger frame: nothing of
            // the buffer is known.
            known.clear();
        }
        if s.ssaa.max(1) > 1 {
            self.render_frame(setup, out, image);
        } else {
            self.render_at(&setup, s.width, s.height, out, image, Some(known));
        }
        Ok(())
    }

    /// The frame's draw list for `shot` (and `out`'s exposure, the shot's),
    /// or an error naming a camera the scene does not have.
    fn setup(&self, shot: Shot, out: &mut Frame) -> Result<DrawList<'s>, Error> {
        let n = self.scene.cameras.len();
        if shot.camera >= n {
            return Err(Error::Argument(format!(
                "camera {}: the scene has {n} camera(s), 0..{n}",
                shot.camera
            )));
        }
        out.exposure = shot.exposure.unwrap_or_else(|| self.exposure());
        Ok(DrawList::new(self.scene, shot.camera, shot.frame))
    }

    /// `render`, and with `display` `render_display`.
    fn render_frame(&self, setup: DrawList, out: &mut Frame, display: Option<&mut Image8>) {
        let (s, k) = (&self.scene.settings, self.scene.settings.ssaa.max(1));
        if k == 1 {
            self.render_at(&setup, s.width, s.height, out, display, None);
            return;
        }
        let mut big = Frame::new(0, 0);
        self.render_at(&setup, s.width * k, s.height * k, &mut big, None, None);
        frame::downsample(&big, k, out);
        if let Some(image) = display {
            display::resolve_into(out, s, image);
        }
    }

    /// Builds every texture's mip chain now (a benchmark counts them as
    /// loading). Frames still read a chain only where they minify.
    pub fn build_all_mips(&self) {
        self.scene.textures.par_iter().for_each(|t| {
            t.mip_chain(mip::build_chain);
        });
    }

    /// Prefilters the scene's environment now rather than at the first
    /// frame (for timing it apart from frames); nothing without one.
    pub fn build_environment(&self) {
        let _ = self.env_light();
    }

    /// Builds now what frames otherwise build on first need: every
    /// texture's mip chain, the environment's lighting and sampling
    /// tables, and, when the scene traces rays, every mesh's BVH. For
    /// timing frames apart from loading; the frames are the same either
    /// way.
    pub fn prepare(&self) {
        self.build_all_mips();
        let _ = self.env_light();
        // The emissive pieces' area lights cast shadows too.
        let emitter_rays = self.scene.settings.shadows == ShadowMethod::Raytraced
            && !self.scene.emitters.is_empty();
        if self.traces_rays(&self.scene.lights) || emitter_rays {
            self.meshes.par_iter().zip(&self.bvhs).for_each(|(m, b)| {
                b.get_or_init(|| bvh_of(m));
            });
        }
    }

    /// The environment's lighting, prefiltered once per process
    /// (`env_cache`).
    fn env_light(&self) -> Option<&EnvLight> {
        self.env
            .get_or_init(|| {
                let e = self.scene.environment.as_ref()?;
                let params = (e.intensity, e.rotation, e.prefilter_size);
                Some(env_cache::env_light(
                    (&e.image, e.backdrop.as_ref()),
                    params,
                    self.phong_roughness(),
                ))
            })
            .as_deref()
    }

    /// Prefilters the scene's environment as the first frame of a process
    /// does, but past the process's cache of prefiltered lighting, and
    /// returns the seconds it took (0 without an environment): for
    /// charting `prefilter_size` against time. The renderer's frames are
    /// unchanged.
    pub fn time_environment_prefilter(&self) -> f64 {
        let Some(e) = &self.scene.environment else {
            return 0.0;
        };
        let t = std::time::Instant::now();
        let light = EnvLight::with_size(&e.image, e.intensity, e.rotation, e.prefilter_size)
            .with_phong_roughness(self.phong_roughness());
        let seconds = t.elapsed().as_secs_f64();
        drop(light);
        seconds
    }

    /// The roughness of every Blinn-Phong exponent that may meet the
    /// environment.
    fn phong_roughness(&self) -> Vec<f32> {
        let scene = self.scene;
        let all = scene.settings.shading == ShadingMode::BlinnPhong;
        scene
            .models
            .iter()
            .flat_map(|m| &m.materials)
            .filter(|m| (all || m.native == Native::BlinnPhong) && m.illum > 0)
            .map(|m| roughness_from_ns(m.ns))
            .collect()
    }

    /// `method = "sampled"`: the sampling tables (built once), the
    /// sample count and whether light bounces.
    fn env_sampler(&self) -> Option<(&EnvSampler, u32, bool)> {
        let e = self.scene.environment.as_ref()?;
        let EnvMethod::Sampled { samples, bounces } = e.method else {
            return None;
        };
        let sampler = self
            .env_sampler
            .get_or_init(|| Some(EnvSampler::new(&e.image, e.intensity, e.rotation)))
            .as_ref()?;
        Some((sampler, samples, bounces > 0))
    }

    /// Whether frames lit by `lights` trace rays through the BVHs:
    /// ray-traced shadows of a light that casts them, ray-traced AO, the
    /// sampled environment or the ground's shadow catcher.
    /// Whether the prefiltered environment's reflections are traced
    /// (`environment.reflections`).
    /// Whether the prefiltered environment traces reflections and
    /// gathers bounced light (`shade::env::reflect`).
    fn traced_env(&self) -> (bool, Bounces) {
        self.scene
            .environment
            .as_ref()
            .map_or((false, Bounces::Off), |e| (e.reflections, e.bounce))
    }

    /// Whether a frame of `setup` at `size` gathers bounced light under
    /// the prefiltered environment: where the scene asks for it, or
    /// leaves it unset under an image and the camera looks into an
    /// enclosure (`bounce_pass::enclosed_share`).
    fn gathers_bounce(
        &self,
        setup: &DrawList,
        (width, height): (u32, u32),
        tracer: Option<&Tracer>,
        surfaces: &dyn Surfaces,
    ) -> bool {
        match (self.traced_env().1, tracer) {
            (Bounces::On, _) => true,
            (Bounces::WhereEnclosed, Some(t)) => {
                let rays = rays::CameraRays::new(&setup.camera, width, height);
                bounce_pass::enclosed_share(&rays, t, surfaces) >= bounce_pass::ENCLOSED_FROM
            }
            _ => false,
        }
    }

    /// Whether some material is shaded as metallic-roughness with one
    /// roughness factor of at least `GLOSSY_FROM` (no roughness map): the
    /// rough reflections' pass has pixels to trace.
    fn has_rough_factor_materials(&self) -> bool {
        let mode = self.scene.settings.shading;
        self.scene
            .models
            .iter()
            .flat_map(|m| &m.materials)
            .any(|m| pass_roughness(mode, m).is_some_and(|r| r >= GLOSSY_FROM))
    }

    fn traces_rays(&self, lights: &[Light]) -> bool {
        let s = &self.scene.settings;
        (s.shadows == ShadowMethod::Raytraced && lights.iter().any(|l| l.shadows))
            || s.ao.method == AoMethod::Raytraced
            || self.env_sampler().is_some()
            || self.scene.ground.is_some()
            || self.traced_env() != (false, Bounces::Off)
    }

    /// The frame's meshes as placed, for rays. `posed`: the BVHs of this
    /// frame's posed models (`posed_bvhs`).
    fn tracer<'a>(
        &'a self,
        setup: &DrawList,
        posed: &'a [Option<(Bvh, (Vec3, Vec3))>],
        cutouts: &'a [Option<bounce::ModelCutout<'a>>],
    ) -> Tracer<'a> {
        let placed = self
            .model_mesh
            .iter()
            .zip(&setup.world_from_object)
            .zip(posed)
            .enumerate()
            .map(|(i, ((&k, &world_from_object), posed))| {
                let (bvh, bounds) = match posed {
                    Some(b) => b,
                    None => self.bvhs[k].get_or_init(|| bvh_of(self.meshes[k])),
                };
                Placed {
                    bvh,
                    cutout: cutouts
                        .get(i)
                        .and_then(|c| c.as_ref())
                        .map(|c| c as &dyn Cutout),
                    bounds: *bounds,
                    world_from_object,
                }
            });
        Tracer::new(placed, setup.scene.bounds_radius)
    }

    /// Per model: the BVH of its vertices as this frame poses them, the
    /// kept BVH of its rest pose refitted (None for models at rest, whose
    /// BVH the renderer keeps).
    fn posed_bvhs(&self, setup: &DrawList) -> Vec<Option<(Bvh, (Vec3, Vec3))>> {
        setup
            .scene
            .models
            .par_iter()
            .zip(&self.model_mesh)
            .zip(&setup.posed)
            .map(|((m, &k), p)| {
                let (p, _) = p.as_ref()?;
                let bounds = p.positions.iter().fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), q| (lo.min(*q), hi.max(*q)),
                );
                let (rest, _) = self.bvhs[k].get_or_init(|| bvh_of(self.meshes[k]));
                Some((rest.refit(&p.positions, &m.mesh.triangles), bounds))
            })
            .collect()
    }

    /// Renders the frame at `width` x `height` pixels: the passes in order;
    /// with `display`, resolved into it too.
    fn render_at(
        &self,
        setup: &DrawList,
        width: u32,
        height: u32,
        out: &mut Frame,
        mut display: Option<&mut Image8>,
        known: Option<&mut Vec<Option<display::PlainBackground>>>,
    ) {
        let s = &setup.scene.settings;
        out.resize(width, height);
        let pattern = sample_pattern(s.msaa).unwrap_or(&[(0, 0)]);
        let vp = Viewport {
            width,
            height,
            msaa: pattern.len() > 1,
        };
        let sampled = self.env_sampler();
        let traced = self.traces_rays(&setup.lights);
        let posed_bvhs = if traced {
            self.posed_bvhs(setup)
        } else {
            Vec::new()
        };
        let cutouts: Vec<Option<bounce::ModelCutout>> = if traced {
            let wrap = s.address.into();
            setup
                .scene
                .models
                .iter()
                .map(|m| bounce::ModelCutout::of(m, wrap))
                .collect()
        } else {
            Vec::new()
        };
        let tracer = traced.then(|| self.tracer(setup, &posed_bvhs, &cutouts));

        let mut verts = vertex::transform_all(setup);
        let shadows = shadow_pass::shadows(setup, &verts, tracer.as_ref(), &self.shadow_maps);
        let env = self.env_light();
        if s.shading == ShadingMode::Gouraud {
            let ctx = shade_context(setup, &[], &shadows, env);
            for (m, mv) in setup.scene.models.iter().zip(&mut verts) {
                mv.light = gouraud::vertex_light(&ctx, m, &mv.world, &mv.normal);
            }
        }
        let filtered = matches!(
            s.texture_filter,
            TextureFilter::Trilinear | TextureFilter::Anisotropic
        ) && !self.scene.textures.is_empty();
        let geo = geometry::setup_and_bin(setup, &verts, vp, filtered);
        let mips = self.frame_mips(setup, &geo);

        let emitters = match sampled {
            Some(_) => emitters::emitters(setup, &verts),
            None => Emitters::default(),
        };
        let surfaces = bounce::FrameSurfaces {
            setup,
            verts: &verts,
        };
        let mut ctx = shade_context(setup, &mips, &shadows, env);
        ctx.env_sampled =
            sampled
                .zip(tracer.as_ref())
                .map(|((sampler, samples, bounces), tracer)| Sampled {
                    env: sampler,
                    tracer,
                    emitters: &emitters,
                    samples,
                    surfaces: bounces.then_some(&surfaces as &dyn Surfaces),
                    light: env,
                });
        let mirror = self.traced_env().0;
        let bounce = self.gathers_bounce(setup, (width, height), tracer.as_ref(), &surfaces);
        // The bounce pass's and the rough reflections' pass's results,
        // once they ran (`bands`).
        let screen = std::sync::OnceLock::new();
        let glossy_screen = std::sync::OnceLock::new();
        let glossy = mirror && self.has_rough_factor_materials();
        ctx.env_reflections = match (env, tracer.as_ref()) {
            (Some(light), Some(tracer)) if mirror || bounce => Some(Reflections {
                tracer,
                surfaces: &surfaces,
                light,
                lights: &setup.lights,
                mirror,
                bounce,
                screen: bounce.then_some(&screen),
                glossy: glossy.then_some(&glossy_screen),
            }),
            _ => None,
        };
        // Wireframe lines keep their width in output pixels.
        ctx.pixel_scale = width as f32 / s.width as f32;
        let mut data = fragment::BandInputs::new(
            setup,
            ctx,
            (&verts, &geo),
            (pattern, filtered),
            tracer.as_ref(),
            fragment::Paths {
                light_culling: self.light_culling,
                lane_width: self.lane_width,
            },
        );
        if let Some(bg) = &mut data.env_bg {
            bg.attach(&self.backdrops);
        }
        if let Some(g) = &mut data.ground {
            g.attach(&self.grounds);
        }
        let overlay = !s.shading.is_data_view() && lines::any(setup);
        let fused = if overlay {
            None
        } else {
            display.as_deref_mut()
        };
        let mut none = Vec::new();
        let known = known.unwrap_or(&mut none);
        self.bands(&data, &geo, tracer.as_ref(), out, fused, known);
        if overlay {
            // Lines may cross the plain background anywhere.
            known.clear();
            lines::draw(setup, &verts, width as f32 / s.width as f32, out);
            if let Some(image) = display {
                display::resolve_into(out, s, image);
            }
        }
    }

    /// What refracting surfaces see: the opaque surfaces shaded into
    /// `out`.
    fn opaque_frame(data: &fragment::BandInputs, out: &Frame) -> OpaqueFrame {
        let camera = refraction::Camera {
            clip_from_world: data.setup.clip_from_world,
            eye: data.ctx.eye,
            forward: data.ctx.forward,
        };
        let sky = data.setup.scene.settings.background == Background::Environment;
        OpaqueFrame::new((&out.color, &out.depth), out.width, out.height, camera)
            .sky_behind(sky)
            .image_lights(backdrop::image_discs(data.setup))
    }

    /// Visibility, AO and shading, band by band, into `out`; with
    /// `display`, each band's display bytes as soon as it is shaded.
    /// Every band is a task of its own (`with_max_len(1)`): bands differ in
    /// cost (a model across some, background in others), and a thread done
    /// early takes the next band instead of waiting while the other
    /// finishes a run of them.
    fn bands(
        &self,
        data: &fragment::BandInputs,
        geo: &Geometry,
        tracer: Option<&Tracer>,
        out: &mut Frame,
        display: Option<&mut Image8>,
        known: &mut Vec<Option<display::PlainBackground>>,
    ) {
        let bins = geo.bins();
        let grid = &geo.grid;
        let band = (grid.tile_w * grid.tile_h) as usize;
        // The data passes: a buffer the bands fill beside their colour, or
        // an empty chunk per band.
        let aovs = data.setup.scene.output.writes_aovs();
        if aovs {
            out.aov.resize(out.color.len(), AovPixel::EMPTY);
        } else {
            out.aov.clear();
        }
        let bands = out.color.len().div_ceil(band);
        let width = out.width as usize;
        // What the last frame left per band (nothing where it was not
        // rendered into this buffer at this size).
        known.resize(bands, None);
        // The display image in band-sized chunks, or an empty chunk per
        // band without one.
        let (encoder, mut bytes): (_, Vec<&mut [u8]>) = match display {
            Some(image) => {
                let e = display::Encoder::new(&data.setup.scene.settings, out.exposure);
                e.shape(out.width, out.height, image);
                (
                    Some(e),
                    image.data.chunks_mut(band * e.channels()).collect(),
                )
            }
            None => (None, (0..bands).map(|_| Default::default()).collect()),
        };
        // A band's display bytes, from its colour just shaded.
        let show = |color: &[glam::Vec4], plain, bytes: &mut [u8]| {
            if let Some(e) = &encoder {
                e.band(color, width, plain, bytes);
            }
        };
        // With transmissive surfaces, a band's blended triangles wait until
        // every band's opaque surfaces are shaded: they refract that frame.
        let refracts = data.refracts();
        let first = |(vis, blended): (Visibility, Vec<u32>),
                     ao: Option<&[f32]>,
                     known: &mut Option<display::PlainBackground>,
                     (color, depth): (&mut [glam::Vec4], &mut [f32]),
                     bytes: &mut [u8]| {
            if refracts && !blended.is_empty() {
                data.shade_band(&vis, Vec::new(), ao, *known, color, depth);
                *known = None;
                return Some((vis, blended));
            }
            let plain = data.shade_band(&vis, blended, ao, *known, color, depth);
            *known = plain;
            show(color, plain, bytes);
            None
        };
        let ao_on = data.setup.scene.settings.ao.method != AoMethod::Off;
        let bounce_pass = data.ctx.env_reflections.is_some_and(|r| r.has_passes());
        let later: Vec<_> = if !ao_on && !bounce_pass {
            out.ao.clear();
            let chunks = aov_chunks(&mut out.aov, band, bands);
            out.color
                .par_chunks_mut(band)
                .zip(out.depth.par_chunks_mut(band))
                .zip(chunks)
                .zip(bytes.par_iter_mut())
                .zip(known.par_iter_mut())
                .enumerate()
                .with_max_len(1)
                .map(|(ti, ((((color, depth), aov), bytes), known))| {
                    let visible = data.visibility(grid.rect(ti), ti, &bins);
                    if !aov.is_empty() {
                        data.aovs(&visible.0, aov);
                    }
                    first(visible, None, known, (color, depth), bytes)
                })
                .collect()
        } else {
            // With ambient occlusion or the bounce pass: visibility and
            // the geometry buffer of every band, the AO and the bounce of
            // the whole frame, then shading.
            let mut gbuf = vec![GPixel::EMPTY; out.color.len()];
            let visible: Vec<_> = gbuf
                .par_chunks_mut(band)
                .enumerate()
                .with_max_len(1)
                .map(|(ti, g)| {
                    let (vis, blended) = data.visibility(grid.rect(ti), ti, &bins);
                    data.gbuffer(&vis, g);
                    (vis, blended)
                })
                .collect();
            whole_frame_passes(data, &gbuf, tracer, out);
            let ao_chunks: Vec<Option<&[f32]>> = if ao_on {
                out.ao.chunks(band).map(Some).collect()
            } else {
                vec![None; bands]
            };
            let chunks = aov_chunks(&mut out.aov, band, bands);
            out.color
                .par_chunks_mut(band)
                .zip(out.depth.par_chunks_mut(band))
                .zip(ao_chunks)
                .zip(visible)
                .zip(chunks)
                .zip(bytes.par_iter_mut())
                .zip(known.par_iter_mut())
                .with_max_len(1)
                .map(|((((((color, depth), ao), visible), aov), bytes), known)| {
                    if !aov.is_empty() {
                        data.aovs(&visible.0, aov);
                    }
                    first(visible, ao, known, (color, depth), bytes)
                })
                .collect()
        };
        if refracts {
            // One `bands` call per frame's inputs: set here only.
            let _ = data.ctx.refraction.set(Self::opaque_frame(data, out));
            out.color
                .par_chunks_mut(band)
                .zip(later)
                .zip(bytes.par_iter_mut())
                .with_max_len(1)
                .for_each(|((color, later), bytes)| {
                    if let Some((vis, blended)) = later {
                        data.blend(&vis, blended, color);
                        show(color, None, bytes);
                    }
                });
        }
    }

    /// Per texture: the mip chain this frame may read, built on the first
    /// frame that needs it, or None. A texture gets its chain where some
    /// triangle's footprint reaches half a texel (the level of detail can
    /// pass 0 there); the others read level 0 only, so a frame's pixels do
    /// not depend on which frames came before.
    fn frame_mips(&self, setup: &DrawList, geo: &Geometry) -> Vec<Option<&'s [Level]>> {
        let mut needed = vec![false; self.scene.textures.len()];
        for c in &geo.chunks {
            let d = geo.draws[c.draw];
            for map in setup.scene.models[d.model].materials[d.material].maps() {
                let t = &map.texture;
                let texels = c.density[(map.texcoord as usize).min(1)]
                    * t.width as f32
                    * t.height as f32
                    * map.transform.matrix2.determinant().abs();
                if texels > 0.25 {
                    needed[t.id] = true;
                }
            }
        }
        self.scene
            .textures
            .par_iter()
            .zip(&needed)
            .map(|(t, &need)| need.then(|| t.mip_chain(mip::build_chain)))
            .collect()
    }
}

/// A mesh's object-space BVH and bounds.
fn bvh_of(m: &Mesh) -> (Bvh, (Vec3, Vec3)) {
    (Bvh::build(&m.positions, &m.triangles), m.bounds())
}

/// The passes over the whole frame's geometry buffer `gbuf` before
/// shading: its AO into `out.ao` (empty without AO), and the bounce into
/// the slot the shading reads it from (`bounce_pass`).
fn whole_frame_passes(
    data: &fragment::BandInputs,
    gbuf: &[GPixel],
    tracer: Option<&Tracer>,
    out: &mut Frame,
) {
    if data.setup.scene.settings.ao.method != AoMethod::Off {
        out.ao = ao_pass::occlusion(data.setup, gbuf, out.width, out.height, tracer);
    } else {
        out.ao.clear();
    }
    let screen = data
        .ctx
        .env_reflections
        .as_ref()
        .and_then(|r| r.screen.map(|s| (r, s)));
    let size = (out.width, out.height);
    let camera = (data.ctx.eye, data.ctx.forward);
    if let Some((with, slot)) = screen {
        // One `bands` call per frame's inputs: set here only.
        let _ = slot.set(bounce_pass::bounce(data.setup, with, gbuf, size, camera));
    }
    let glossy = data
        .ctx
        .env_reflections
        .as_ref()
        .and_then(|r| r.glossy.map(|s| (r, s)));
    if let Some((with, slot)) = glossy {
        let view = |p: Vec3| data.ctx.view_vector(p);
        let pass = bounce_pass::glossy(data.setup, with, gbuf, size, (camera, &view));
        let _ = slot.set(pass);
    }
}

/// The data-pass buffer in band-sized chunks, or an empty chunk per band
/// when the frame has none.
fn aov_chunks(aov: &mut [AovPixel], band: usize, bands: usize) -> Vec<&mut [AovPixel]> {
    if aov.is_empty() {
        (0..bands).map(|_| Default::default()).collect()
    } else {
        aov.chunks_mut(band).collect()
    }
}

fn shade_context<'a>(
    setup: &'a DrawList,
    mips: &'a [Option<&'a [Level]>],
    shadows: &'a Shadows<'a>,
    env: Option<&'a EnvLight>,
) -> ShadeContext<'a> {
    let s = &setup.scene.settings;
    let cam = &setup.camera;
    let forward = cam.forward();
    let dist = (setup.scene.bounds_center - cam.eye).dot(forward);
    let r = setup.scene.bounds_radius;
    let lo = (dist - r).max(cam.near);
    let hi = (dist + r).max(lo + 1e-6);
    ShadeContext {
        mode: s.shading,
        lights: &setup.lights,
        ambient: s.ambient,
        eye: cam.eye,
        forward,
        orthographic: matches!(cam.projection, Projection::Orthographic { .. }),
        filter: s.texture_filter,
        max_anisotropy: s.max_anisotropy,
        specular_aa: s.specular_aa,
        address: s.address,
        mips,
        depth_range: (lo, hi),
        shadows,
        env,
        env_sampled: None,
        env_reflections: None,
        pixel_scale: 1.0,
        refraction: Default::default(),
    }
}
