//! Traced light for the prefiltered environment: reflections
//! (`environment.reflections`) and light bounced once between surfaces
//! (`environment.bounces = 1`).
//!
//! The split sum lights every point as if nothing stood between it and
//! the environment. A path tracer's sphere beside another shows its
//! neighbour, dark or lit, in its reflection; a metal disc under another
//! shows the other's back; a Cornell box's walls light each other.
//!
//! - **Reflections.** One ray per point, along the direction the split
//!   sum reads the environment, finds the surface met (`bounce::
//!   Surfaces`); where it meets one, what that surface sends back
//!   replaces the prefiltered environment, whatever the lobe's roughness
//!   (a fade towards the prefiltered light for rough lobes, 1 - r^2, was
//!   further from Cycles on 14 frames of the set and closer on 2).
//! - **Bounced light.** `GATHER_RAYS` cosine-weighted rays per point; the
//!   irradiance is the environment's E(n), less what the rays that meet a
//!   surface would have brought from it (pi times the environment
//!   along the ray prefiltered at `HIDDEN_ROUGHNESS`, a smooth stand-in
//!   for its radiance), plus what those surfaces send back. The
//!   frame casts them once per pixel before shading and filters what they
//!   change (`BounceScreen`, from `render::bounce_pass`); a point off its
//!   pixel's surface casts its own.
//!
//! A surface met is lit as the prefiltered method lights an open point:
//! its Lambertian colour times the irradiance E(n) / pi and the scene's
//! lights (the lights taken out of the image among them), its specular
//! colour times the split sum along its own mirror direction plus each
//! light's highlight (`highlight`), and (for the reflections) its
//! emission, unless it is one of the emitters, whose area light's
//! highlight shows it already (`Bounce::lamp`). With the bounce on, the
//! lights are tested for shadow at the point met (the CornellBox in the
//! studio against Cycles, eight rays: 0.121 unshadowed, 0.106 shadowed),
//! and the bounce's second gathering adds the first's bounce to its
//! irradiance where the frame shows it (`gathered_change`'s `prior`);
//! without it the reflections light their surfaces unshadowed, which measured
//! closer to Cycles where nothing else brings the walls' light (the
//! CornellBox 0.180 against 0.183). The bounce leaves out the emission
//! (the emitters light the point as area lights already) and clamps what
//! a surface sends to `bounce::INDIRECT_CLAMP`, as the sampled bounce
//! does.

use std::sync::OnceLock;

use glam::{Mat4, Vec3, Vec4};

use super::EnvLight;
use super::bounce::{Bounce, Surfaces, clamped};
use super::pattern::{point, position_hash};
use crate::raytrace::Tracer;
use crate::scene::light::{Light, LightKind};
use crate::shade::ao::cosine_direction;
use crate::shade::ggx::{MIN_ALPHA, d_vis};
use crate::shade::light::incidence;
use crate::simd::{Lane, Mask, V3};

/// Rays per shaded point of the bounced light (the CornellBox under the
/// studio HDRI against Cycles: 1: 0.121, 2: 0.113, 4: 0.109, 8: 0.108,
/// 16: 0.107).
pub const GATHER_RAYS: u32 = 4;

/// The perceptual roughness at which a gathering ray that meets a
/// surface reads the environment it hides. E along the ray (a cosine's
/// blur) stood in for it first; over a hemisphere mostly hidden, E about
/// the normal less E along the rays left the sky's colour where the
/// opening shows the ground (a Cornell box's floor went lavender in the
/// courtyard). 0.3, 0.5 and 0.7 measured alike against Cycles (the
/// CornellBox 0.123 / 0.098), 1.0 and E further (0.128, 0.127).
const HIDDEN_ROUGHNESS: f32 = 0.5;

/// Rays per pixel of the rough reflections' pass (`reflected_lobe`),
/// drawn over the lobe.
pub const GLOSSY_RAYS: u32 = 8;

/// The perceptual roughness from which a point of a material with one
/// roughness factor reads its reflection from the rough reflections'
/// pass (`Reflections::glossy`) instead of one ray along the lobe's
/// dominant direction: one ray draws the edge of what it meets as a hard
/// line across a lobe that is wide. On the Cycles set (`docs/cycles.md`)
/// lobes of 0.15 and 0.25 (the iridescent and the specular-ior spheres,
/// which mirror each other) came out closer with their one ray.
pub const GLOSSY_FROM: f32 = 0.3;

/// The roughness the rough reflections' pass traces for material `m`
/// (shaded in `mode`): its perceptual roughness factor, clamped to 0..1,
/// where it is shaded as metallic-roughness without a roughness map;
/// None elsewhere (the pass reads no textures).
pub fn pass_roughness(
    mode: crate::scene::settings::ShadingMode,
    m: &crate::scene::Material,
) -> Option<f32> {
    let p = &m.pbr;
    let mapped = p.metallic_roughness_map.is_some() || p.roughness_map.is_some();
    (crate::shade::shades_pbr(mode, m) && !mapped).then(|| p.roughness.clamp(0.0, 1.0))
}

/// What the traced light reads: the frame's rays and surfaces, the
/// prefiltered environment and the scene's lights, and which of the two
/// it traces.
#[derive(Clone, Copy)]
pub struct Reflections<'a> {
    pub tracer: &'a Tracer<'a>,
    pub surfaces: &'a dyn Surfaces,
    pub light: &'a EnvLight,
    pub lights: &'a [Light],
    /// Trace the specular lobes' dominant directions.
    pub mirror: bool,
    /// Gather light bounced once.
    pub bounce: bool,
    /// Where the frame gathers the bounce per pixel before shading (the
    /// bounce pass, `render::bounce_pass`), filled once the pass ran;
    /// the points it shows read it, the others gather their own.
    pub screen: Option<&'a OnceLock<BounceScreen>>,
    /// Where the frame traces the rough lobes' reflections per pixel
    /// before shading (`render::bounce_pass::glossy`), filled once the
    /// pass ran: what they change in the prefiltered light, filtered
    /// across the surface, for the points it shows whose roughness is
    /// at least `GLOSSY_FROM`; the others trace their one ray.
    pub glossy: Option<&'a OnceLock<BounceScreen>>,
}

/// The light bounced once, gathered at every pixel's surface and
/// filtered across the surface (`ao::edge_aware_blur`): four rays a point
/// are grain, which a path tracer's denoiser removes and one pixel's own
/// rays cannot.
pub struct BounceScreen {
    pub width: usize,
    pub height: usize,
    /// Per pixel: the filtered irradiance change (what the gathering rays
    /// bring, less the environment's irradiance they stand in for); for
    /// the rough reflections' pass, what its rays brought (`met_share`).
    pub delta: Vec<Vec3>,
    /// Per pixel: its surface's view depth (+inf: nothing) and unit
    /// geometric normal, facing the camera.
    pub depth: Vec<f32>,
    pub geo_normal: Vec<Vec3>,
    /// Per pixel of a grid coarser than the frame's (the rough
    /// reflections' pass): its sample's position, whose tangent plane a
    /// point must lie on; empty on the frame's own grid, where the view
    /// depth is checked.
    pub position: Vec<Vec3>,
    /// Per pixel of the rough reflections' pass: the filtered share of
    /// the lobe (by n.l) whose rays met a surface; `delta` then holds
    /// what those rays brought, over the whole lobe's weight. Empty for
    /// the bounce.
    pub met_share: Vec<f32>,
    pub clip_from_world: Mat4,
    pub eye: Vec3,
    pub forward: Vec3,
}

/// What the gathering rays at a point found.
struct Gathered {
    /// What the surfaces they meet send back, times pi / `GATHER_RAYS`.
    met: Vec3,
    /// pi times the environment along those that meet a surface
    /// (prefiltered at `HIDDEN_ROUGHNESS`), over `GATHER_RAYS`.
    hidden: Vec3,
    /// The summed distance to the surfaces met that could be read, and
    /// their count.
    distance: f32,
    hits: u32,
}

impl BounceScreen {
    /// The change at world point `p` with unit geometric normal `ng`
    /// (either side), where `p` lies on the surface its pixel shows (its
    /// view depth within 1%, the triangles' planes within 37 degrees);
    /// None elsewhere.
    pub fn at(&self, p: Vec3, ng: Vec3) -> Option<Vec3> {
        self.index(p, ng).map(|i| self.delta[i])
    }

    /// The rough reflections' pass at `p` (as `at`): what the rays that
    /// met a surface brought, and the share of the lobe they hold.
    pub fn lobe_at(&self, p: Vec3, ng: Vec3) -> Option<(Vec3, f32)> {
        self.index(p, ng)
            .map(|i| (self.delta[i], self.met_share.get(i).copied().unwrap_or(0.0)))
    }

    /// The sample `at` reads for `p`.
    fn index(&self, p: Vec3, ng: Vec3) -> Option<usize> {
        let clip = self.clip_from_world * p.extend(1.0);
        if clip.w <= 1e-6 {
            return None;
        }
        let (nx, ny) = (clip.x / clip.w, clip.y / clip.w);
        let x = (nx * 0.5 + 0.5) * self.width as f32;
        let y = (0.5 - ny * 0.5) * self.height as f32;
        if !(x >= 0.0 && y >= 0.0 && x < self.width as f32 && y < self.height as f32) {
            return None;
        }
        let (x, y) = (x as usize, y as usize);
        let depth = (p - self.eye).dot(self.forward);
        let on = |i: usize| {
            let d = self.depth[i];
            let near = if self.position.is_empty() {
                (depth - d).abs() <= 0.01 * d
            } else {
                d.is_finite() && (p - self.position[i]).dot(self.geo_normal[i]).abs() <= 0.01 * d
            };
            near && ng.dot(self.geo_normal[i]).abs() > 0.8
        };
        if self.position.is_empty() {
            let i = y * self.width + x;
            return on(i).then_some(i);
        }
        // On the coarser grid a point lies between the samples of its
        // cell and of the cells after it: the first on its surface.
        [(0, 0), (1, 0), (0, 1), (1, 1)]
            .into_iter()
            .map(|(dx, dy)| (x + dx, y + dy))
            .filter(|&(x, y)| x < self.width && y < self.height)
            .map(|(x, y)| y * self.width + x)
            .find(|&i| on(i))
    }
}

/// The traced light at a group of points: their positions and geometric
/// normals.
#[derive(Clone, Copy)]
pub struct At<'a, L: Lane> {
    pub with: &'a Reflections<'a>,
    pub position: V3<L>,
    pub geo_normal: &'a [Vec3],
}

impl<L: Lane> At<'_, L> {
    /// `light` (the prefiltered environment along `r`, for lobes of
    /// perceptual `roughness`), replaced by what a ray along `r` meets
    /// where it meets a surface; a lobe at least `GLOSSY_FROM` rough, at a
    /// point the rough reflections' pass shows, takes what the pass's
    /// rays brought plus `light` times the share of the lobe they did not
    /// meet instead.
    #[inline]
    pub fn blend(&self, light: V3<L>, r: V3<L>, roughness: L) -> V3<L> {
        if !self.with.mirror {
            return light;
        }
        let glossy = self.with.glossy.and_then(OnceLock::get);
        let rough = roughness.cmpge(L::splat(GLOSSY_FROM));
        let Some(screen) = glossy.filter(|_| rough.any()) else {
            return self.with.along(self.position, self.geo_normal, r, light);
        };
        let mut out = light;
        let mut own = false;
        let mut changed = [None; crate::simd::MAX_WIDTH];
        for (k, c) in changed.iter_mut().enumerate().take(L::WIDTH) {
            if roughness.lane(k) >= GLOSSY_FROM {
                *c = screen.lobe_at(self.position.lane(k), self.geo_normal[k]);
            }
            own |= c.is_none();
        }
        if own {
            out = self.with.along(self.position, self.geo_normal, r, light);
        }
        V3::from_fn(|k| match changed[k] {
            Some((met, share)) => light.lane(k) * (1.0 - share) + met,
            None => out.lane(k),
        })
    }

    /// The irradiance `e` (the environment's, about unit normals `n`)
    /// with the light bounced once in place of what the surfaces around
    /// hide, where the scene gathers it; else `e`.
    #[inline]
    pub fn irradiance(&self, e: V3<L>, n: V3<L>) -> V3<L> {
        if !self.with.bounce {
            return e;
        }
        let screen = self.with.screen.and_then(OnceLock::get);
        V3::from_fn(|k| {
            let (p, nk, ek) = (self.position.lane(k), n.lane(k), e.lane(k));
            match screen.and_then(|s| s.at(p, self.geo_normal[k])) {
                Some(delta) => (ek + delta).max(Vec3::ZERO),
                None => self.with.gather(p, self.geo_normal[k], nk, ek),
            }
        })
    }
}

impl Reflections<'_> {
    /// Whether the frame runs a pass over its geometry buffer for them
    /// (the bounce, the rough reflections) before shading.
    pub fn has_passes(&self) -> bool {
        self.screen.is_some() || self.glossy.is_some()
    }

    /// Per lane: the radiance arriving at `p` along unit `r` from the
    /// surface the ray meets, or `open` where it meets nothing. `ng`: the
    /// geometric normals, toward the viewer (the rays' offset).
    pub fn along<L: Lane>(&self, p: V3<L>, ng: &[Vec3], r: V3<L>, open: V3<L>) -> V3<L> {
        V3::from_fn(|k| {
            let d = r.lane(k);
            let n = ng[k];
            let off = if n.dot(d) < 0.0 { -n } else { n };
            self.incoming(p.lane(k) + off * self.tracer.epsilon, d)
                .unwrap_or_else(|| open.lane(k))
        })
    }

    /// Irradiance `e` at `p` about unit `n` (`ng`: the geometric normal),
    /// less the environment each gathering ray that meets a surface
    /// hides (`HIDDEN_ROUGHNESS`), plus pi /
    /// `GATHER_RAYS` times what that surface sends back.
    pub fn gather(&self, p: Vec3, ng: Vec3, n: Vec3, e: Vec3) -> Vec3 {
        let g = self.gathered(p, ng, n, None);
        (e - g.hidden).max(Vec3::ZERO) + g.met
    }

    /// What `gather` changes at `p` (what the rays bring less the
    /// environment's irradiance they stand in for, before the clamp at
    /// zero), and the mean distance to the surfaces they meet (+inf where
    /// they meet none): the change varies over about that distance.
    /// `[ng, n]`: the geometric and the shading normal. `prior`: an
    /// earlier gathering's bounce, which lights the surfaces met where
    /// it shows them (light bounced twice), else they are lit as open
    /// points.
    pub fn gathered_change(
        &self,
        p: Vec3,
        [ng, n]: [Vec3; 2],
        prior: Option<&BounceScreen>,
    ) -> (Vec3, f32) {
        let g = self.gathered(p, ng, n, prior);
        let reach = if g.hits > 0 {
            g.distance / g.hits as f32
        } else {
            f32::INFINITY
        };
        (g.met - g.hidden, reach)
    }

    /// What `GLOSSY_RAYS` rays over the GGX lobe of perceptual
    /// `roughness` about unit `n`, seen from unit `v` (towards the
    /// viewer), find at `p`: in xyz, what the rays that meet a surface
    /// bring, weighted by n.l, over all the rays' weights; in w, the
    /// share of that weight they hold (the shading keeps its own
    /// prefiltered light for the rest: `At::blend`); and the mean
    /// distance to the surfaces they meet (+inf where they meet none).
    /// `ng`: the geometric normal.
    ///
    /// A lobe whose rays all meet surfaces so shows exactly what they
    /// bring. A change to the point's light (each ray's radiance less the
    /// environment along it, prefiltered again at the lobe's roughness)
    /// was a blur of a blur: where the lobe faced a bright sky it stood
    /// lower than the lobe's own light, and the difference stayed (a
    /// Cornell box's floor reflected the sky its ceiling hides: 0.127 ->
    /// 0.111 FLIP against Cycles in the courtyard, with the bounce);
    /// less the lobe's own light along the isotropic dominant direction,
    /// it missed the bent normal of an anisotropic lobe (the discs in the
    /// courtyard 0.1010, with the share 0.0992).
    pub fn reflected_lobe(&self, p: Vec3, [ng, n, v]: [Vec3; 3], roughness: f32) -> (Vec4, f32) {
        let off = if ng.dot(v) < 0.0 { -ng } else { ng };
        let o = p + off * self.tracer.epsilon;
        let a2 = (roughness * roughness).max(MIN_ALPHA).powi(2);
        let (shift, (tx, ty)) = (position_hash(p), n.any_orthonormal_pair());
        let (mut met, mut weight) = (Vec3::ZERO, 0.0);
        let (mut distance, mut hits) = (0.0, 0);
        let mut met_weight = 0.0;
        for i in 0..GLOSSY_RAYS {
            let xi = point(i, GLOSSY_RAYS, shift);
            // A GGX half vector: cos^2 = (1 - u) / (1 + (a^2 - 1) u).
            let cos2 = (1.0 - xi.x) / (1.0 + (a2 - 1.0) * xi.x);
            let (cos, sin) = (cos2.sqrt(), (1.0 - cos2).max(0.0).sqrt());
            let phi = std::f32::consts::TAU * xi.y;
            let h = tx * (sin * phi.cos()) + ty * (sin * phi.sin()) + n * cos;
            let l = h * (2.0 * v.dot(h)) - v;
            let ndl = n.dot(l);
            if ndl <= 0.0 || l.dot(off) <= 0.0 {
                continue;
            }
            weight += ndl;
            let Some(b) = self.met(o, l) else {
                continue;
            };
            let sent = match b {
                Some(b) => {
                    distance += (b.position - o).length();
                    hits += 1;
                    let lit = self.lit(&b, -l, self.bounce);
                    if b.lamp { lit } else { lit + b.emitted }
                }
                None => Vec3::ZERO,
            };
            met += sent * ndl;
            met_weight += ndl;
        }
        if weight <= 0.0 {
            return (Vec4::ZERO, f32::INFINITY);
        }
        let reach = if hits > 0 {
            distance / hits as f32
        } else {
            f32::INFINITY
        };
        ((met / weight).extend(met_weight / weight), reach)
    }

    /// The gathering rays at `p` about unit `n` (`prior`: as
    /// `gathered_change`).
    fn gathered(&self, p: Vec3, ng: Vec3, n: Vec3, prior: Option<&BounceScreen>) -> Gathered {
        let off = if ng.dot(n) < 0.0 { -ng } else { ng };
        let o = p + off * self.tracer.epsilon;
        let (shift, pair) = (position_hash(p), n.any_orthonormal_pair());
        let (mut met, mut hidden) = (Vec3::ZERO, Vec3::ZERO);
        let (mut distance, mut hits) = (0.0, 0);
        for i in 0..GATHER_RAYS {
            let xi = point(i, GATHER_RAYS, shift);
            let d = cosine_direction(n, pair, (xi.x, xi.y));
            if d.dot(off) <= 0.0 {
                continue;
            }
            let Some(b) = self.met(o, d) else {
                continue;
            };
            hidden += self.light.prefiltered(d, HIDDEN_ROUGHNESS) * std::f32::consts::PI;
            if let Some(b) = b {
                met += clamped(self.lit_with(&b, -d, true, prior));
                distance += (b.position - o).length();
                hits += 1;
            }
        }
        let rays = GATHER_RAYS as f32;
        Gathered {
            met: met * (std::f32::consts::PI / rays),
            hidden: hidden / rays,
            distance,
            hits,
        }
    }

    /// The radiance along the ray `o + t d` from the first surface that
    /// reflects (`met`); None where it leaves the scene.
    fn incoming(&self, o: Vec3, d: Vec3) -> Option<Vec3> {
        Some(match self.met(o, d)? {
            Some(b) if b.lamp => self.lit(&b, -d, self.bounce),
            Some(b) => self.lit(&b, -d, self.bounce) + b.emitted,
            None => Vec3::ZERO,
        })
    }

    /// The first surface along the ray `o + t d` that reflects, through
    /// up to 8 that mostly transmit (as thin walls): None where the ray
    /// leaves the scene, Some(None) where the surface cannot be read or
    /// the ray goes no further (counted as dark).
    fn met(&self, mut o: Vec3, d: Vec3) -> Option<Option<Bounce>> {
        for _ in 0..8 {
            let hit = self.tracer.nearest(o, d, f32::INFINITY)?;
            let Some(b) = self.surfaces.at(hit, o, d) else {
                return Some(None);
            };
            if b.transmission >= 0.5 {
                o = b.position - b.geometric * self.tracer.epsilon;
                continue;
            }
            return Some(Some(b));
        }
        Some(None)
    }

    /// What surface `b` reflects towards unit `wo`, lit as an open point
    /// (without its emission); `shadowed`: the lights tested for shadow.
    fn lit(&self, b: &Bounce, wo: Vec3, shadowed: bool) -> Vec3 {
        self.lit_with(b, wo, shadowed, None)
    }

    /// `lit`, its irradiance with the bounce of `prior` where that shows
    /// the surface.
    fn lit_with(&self, b: &Bounce, wo: Vec3, shadowed: bool, prior: Option<&BounceScreen>) -> Vec3 {
        let env = self.light;
        let n = b.normal;
        let ndv = n.dot(wo).clamp(1e-4, 1.0);
        let o = b.position + b.geometric * self.tracer.epsilon;
        let mut e = env.irradiance(n);
        if let Some(delta) = prior.and_then(|s| s.at(b.position, b.geometric)) {
            e = (e + delta).max(Vec3::ZERO);
        }
        let mut diffuse_light = e / std::f32::consts::PI;
        let mut glossy = Vec3::ZERO;
        for light in self.lights {
            if let Some(i) = incidence(light, b.position) {
                let cos = n.dot(i.l);
                if cos > 0.0 && (!shadowed || self.reaches(light, o, i.l)) {
                    diffuse_light += i.e * (cos / std::f32::consts::PI);
                    glossy += i.e * cos * highlight(b, light, wo, i.l);
                }
            }
        }
        let mirror = n * (2.0 * n.dot(wo)) - wo;
        let ab = env.brdf(ndv, b.roughness);
        let specular = env.prefiltered(mirror, b.roughness) * (b.specular * ab.x + ab.y);
        b.diffuse * diffuse_light + specular + glossy
    }

    /// Whether `light` reaches `o` (already off its surface) along unit
    /// `l`: past what a shadow ray meets, for lights that cast shadows.
    /// An area light's centre lies on its own surface: the ray stops just
    /// short of it, as the shaded points' rays do (`open_share_to`). Taken
    /// as reaching, the floor behind the CornellBox's tall box, in the
    /// lamp's shadow, lit the bounce of the corner beside it as if it
    /// were not: 2.5 times Cycles' light there.
    fn reaches(&self, light: &Light, o: Vec3, l: Vec3) -> bool {
        let t_max = match light.kind {
            _ if !light.shadows => return true,
            LightKind::Area { position, .. } => (position - o).length() * (1.0 - 1e-3),
            LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
                (position - o).length() * (1.0 - 1e-4)
            }
            LightKind::Directional { .. } => f32::INFINITY,
        };
        self.tracer.transmittance(o, l, t_max) > 0.5
    }
}

/// The specular lobe's f(wo, l) of surface `b` for `light` from unit `l`:
/// GGX with Schlick's Fresnel from its specular colour, widened by the
/// disc the light is seen as (a light taken out of the image, an
/// emitter's area), as the shaded points' own highlights are
/// (`PbrColor::widened`). The prefiltered levels no longer hold the
/// image's lamps and sky patches: without it a metal met by a reflection
/// ray showed none of them.
fn highlight(b: &Bounce, light: &Light, wo: Vec3, l: Vec3) -> Vec3 {
    let alpha = (b.roughness * b.roughness).max(MIN_ALPHA);
    let widen = match light.kind {
        LightKind::Directional { angle, .. } => (0.5 * angle.tan()).powi(2),
        LightKind::Area {
            position, radius, ..
        } => (0.5 * radius / (position - b.position).length().max(1e-6)).powi(2),
        _ => 0.0,
    };
    let a2 = (alpha * alpha + widen).min(1.0);
    let h = (l + wo).normalize_or_zero();
    let fresnel = b.specular + (Vec3::ONE - b.specular) * (1.0 - wo.dot(h).abs()).powi(5);
    let dv = d_vis::<f32>(b.normal.into(), wo.into(), h.into(), b.normal.dot(l), a2);
    fresnel * dv
}

#[cfg(test)]
mod tests {
    use super::*;

    fn white_metal(roughness: f32) -> Bounce {
        Bounce {
            position: Vec3::ZERO,
            normal: Vec3::Y,
            geometric: Vec3::Y,
            diffuse: Vec3::ZERO,
            specular: Vec3::ONE,
            roughness,
            transmission: 0.0,
            emitted: Vec3::ZERO,
            lamp: false,
        }
    }

    fn sun(angle: f32) -> Light {
        Light {
            kind: LightKind::Directional {
                direction: -Vec3::Y,
                irradiance: 1.0,
                angle,
            },
            color: Vec3::ONE,
            shadows: false,
            range: None,
        }
    }

    #[test]
    fn a_met_surface_shows_a_light_s_highlight_widened_by_its_disc() {
        // Light and view along the normal: D(1) Vis = 1 / (pi a^2) / 4,
        // times Fresnel 1 (white metal).
        let b = white_metal(0.5);
        let a2 = 0.5f32.powi(4);
        let peak = highlight(&b, &sun(0.0), Vec3::Y, Vec3::Y);
        let expect = 1.0 / (4.0 * std::f32::consts::PI * a2);
        assert!(
            (peak - Vec3::splat(expect)).abs().max_element() < 1e-4 * expect,
            "{peak}"
        );
        // A light seen as a disc (one taken out of the image) widens the
        // lobe: a lower peak, alpha^2 + (tan(angle) / 2)^2.
        let angle = 0.3f32;
        let wide = highlight(&b, &sun(angle), Vec3::Y, Vec3::Y);
        let a2w = a2 + (0.5 * angle.tan()).powi(2);
        let expect = 1.0 / (4.0 * std::f32::consts::PI * a2w);
        assert!(
            (wide - Vec3::splat(expect)).abs().max_element() < 1e-4 * expect,
            "{wide}"
        );
        // Away from the mirror direction it falls off.
        let aside = Vec3::new(0.6, 0.8, 0.0);
        assert!(highlight(&b, &sun(0.0), aside, Vec3::Y).x < 0.2 * peak.x);
    }
}
