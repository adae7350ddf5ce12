//! Screen-space refraction: what a transmissive surface shows of the
//! scene behind it, as the glTF viewers render KHR_materials_transmission
//! and KHR_materials_volume (Khronos glTF-Sample-Viewer, three.js,
//! Filament).
//!
//! The frame's opaque surfaces are shaded first; their linear colour,
//! with a box-filtered mip chain, is the `OpaqueFrame`. A transmissive
//! fragment then:
//!
//! - bends the view ray into the surface by Snell's law (`ior`, from
//!   KHR_materials_ior; 1.5 without it);
//! - follows it for the volume's `thickness` (model units; 0 is a thin
//!   wall: no offset) to the point where it leaves;
//! - reads the opaque frame where that point projects, at the level of
//!   detail log2(frame size) x roughness x clamp(2 ior - 2, 0, 1) (the
//!   sample viewer's blur by roughness);
//! - where the point leaves the screen, lies behind the camera or lands
//!   on a background that shows the environment, reads the environment
//!   along the bent ray, blurred by the transmitted lobe's spread
//!   (`spread_through`), with the lights taken out of the image put back
//!   (the frame's border colour without an environment).
//!
//! The shading then multiplies this by the surface's transmittance (base
//! colour, 1 - reflection, Beer's law along the thickness). What lies
//! behind is the opaque frame only: other blended or transmissive
//! surfaces do not show through a transmissive one, as in the viewers.
//!
//! `method = "sampled"` traces the refracted ray instead (`traced`).

use glam::{Mat4, Vec2, Vec3, Vec4, Vec4Swizzles};
use rayon::prelude::*;

use super::env::bounce::Scene;
use super::env::sampled::{alpha, frame, ggx_sample_aniso, point, position_hash};
use super::env::{Disc, EnvLight};

/// The shaded opaque frame and its mip chain (linear RGB), its depth, and
/// the camera that maps world points to its pixels.
#[derive(Debug)]
pub struct OpaqueFrame {
    /// Level 0 is the frame; each next level halves it (sizes round up).
    levels: Vec<Level>,
    /// Level 0's distance along the view axis (+inf: background).
    depth: Vec<f32>,
    camera: Camera,
    /// The background shows the environment sharp: a ray that lands on
    /// it reads the environment (`spread_through`), as where it leaves the
    /// screen.
    sky: bool,
    /// The lights taken out of the environment image, put back where the
    /// environment is read.
    discs: Vec<Disc>,
}

/// What `OpaqueFrame` needs of the frame's camera.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    pub clip_from_world: Mat4,
    pub eye: Vec3,
    /// Unit view axis.
    pub forward: Vec3,
}

#[derive(Debug)]
struct Level {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

impl Level {
    #[inline]
    fn at(&self, x: usize, y: usize) -> Vec3 {
        self.texels[y.min(self.height - 1) * self.width + x.min(self.width - 1)]
    }

    /// Bilinear at (x, y) in this level's pixels (centres at +0.5),
    /// clamped to the edges.
    fn bilinear(&self, x: f32, y: f32) -> Vec3 {
        let (fx, fy) = ((x - 0.5).max(0.0), (y - 0.5).max(0.0));
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let (x0, y0) = (x0 as usize, y0 as usize);
        let top = self.at(x0, y0).lerp(self.at(x0 + 1, y0), tx);
        let bottom = self.at(x0, y0 + 1).lerp(self.at(x0 + 1, y0 + 1), tx);
        top.lerp(bottom, ty)
    }

    /// The next level: 2x2 boxes (an odd edge repeats its last texel).
    fn half(&self) -> Level {
        let (width, height) = (self.width.div_ceil(2), self.height.div_ceil(2));
        let mut texels = vec![Vec3::ZERO; width * height];
        texels
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, t) in row.iter_mut().enumerate() {
                    let (sx, sy) = (2 * x, 2 * y);
                    let sum = self.at(sx, sy)
                        + self.at(sx + 1, sy)
                        + self.at(sx, sy + 1)
                        + self.at(sx + 1, sy + 1);
                    *t = sum * 0.25;
                }
            });
        Level {
            width,
            height,
            texels,
        }
    }
}

/// One transmissive fragment's refraction inputs (world space).
#[derive(Debug, Clone, Copy)]
pub struct RefractedRay {
    /// The surface point.
    pub position: Vec3,
    /// The shading normal (unit), on the side the eye sees.
    pub normal: Vec3,
    /// Unit vector from the point towards the eye.
    pub view: Vec3,
    /// Index of refraction of the volume.
    pub ior: f32,
    /// KHR_materials_dispersion: 20 / the Abbe number (0: none).
    pub dispersion: f32,
    /// The volume's thickness (0: thin wall).
    pub thickness: f32,
    /// Perceptual roughness of the surface.
    pub roughness: f32,
}

impl RefractedRay {
    /// What `seen(ior)` gives at the volume's index (1.5 where it is not a
    /// number of at least 1). With dispersion, in a volume, red bends
    /// least and blue most: each channel is read through its own index,
    /// (ior - 1) / 40 x dispersion either side of green's (the extension's
    /// sample viewer).
    fn per_channel(&self, seen: impl Fn(f32) -> Vec3) -> Vec3 {
        let ior = if self.ior.is_finite() && self.ior >= 1.0 {
            self.ior
        } else {
            1.5
        };
        let solid = self.thickness > 0.0 && self.thickness.is_finite();
        if self.dispersion > 0.0 && self.dispersion.is_finite() && solid {
            let half = (ior - 1.0) * 0.025 * self.dispersion;
            let red = seen((ior - half).max(1.0));
            let green = seen(ior);
            let blue = seen(ior + half);
            return Vec3::new(red.x, green.y, blue.z);
        }
        seen(ior)
    }
}

/// Where a point or direction lands in the frame.
enum Landing {
    /// On screen, at these level-0 pixel coordinates.
    On(f32, f32),
    /// Off screen; the nearest point of the frame towards it.
    Off(f32, f32),
}

impl OpaqueFrame {
    /// `color` and `depth`: the frame's `width` x `height` linear colour
    /// and view-axis distance, row by row from the top.
    pub fn new(
        (color, depth): (&[Vec4], &[f32]),
        width: u32,
        height: u32,
        camera: Camera,
    ) -> OpaqueFrame {
        let (width, height) = (width.max(1) as usize, height.max(1) as usize);
        let full = color.len() == width * height && depth.len() == width * height;
        let mut levels = vec![Level {
            width: if full { width } else { 1 },
            height: if full { height } else { 1 },
            texels: if full {
                color.par_iter().map(|c| c.xyz()).collect()
            } else {
                vec![Vec3::ZERO]
            },
        }];
        while let Some(last) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            let next = last.half();
            levels.push(next);
        }
        OpaqueFrame {
            levels,
            depth: if full {
                depth.to_vec()
            } else {
                vec![f32::INFINITY]
            },
            camera,
            sky: false,
            discs: Vec::new(),
        }
    }

    /// The frame's background is the environment itself (`output.background
    /// = "environment"`): rays landing on it read the environment, blurred
    /// by roughness as a path tracer's rough glass blurs it, rather than
    /// the frame's pixels, whose blur by the mip chain differs from it and
    /// would show the screen's edge as a seam.
    pub fn sky_behind(mut self, sky: bool) -> OpaqueFrame {
        self.sky = sky;
        self
    }

    /// The lights taken out of the environment image: rays that read the
    /// environment see them too (a lamp through clear glass).
    pub fn image_lights(mut self, discs: Vec<Disc>) -> OpaqueFrame {
        self.discs = discs;
        self
    }

    /// Trilinear read at (x, y) in level-0 pixels, level of detail `lod`.
    fn read(&self, x: f32, y: f32, lod: f32) -> Vec3 {
        let top = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, top);
        let l0 = lod.floor() as usize;
        let t = lod - l0 as f32;
        let at = |l: usize| {
            let s = 1.0 / (1u32 << l) as f32;
            self.levels[l].bilinear(x * s, y * s)
        };
        if t <= 0.0 || l0 + 1 >= self.levels.len() {
            at(l0)
        } else {
            at(l0).lerp(at(l0 + 1), t)
        }
    }

    /// Where homogeneous world point `p` (w = 0: a direction) lands.
    fn land(&self, p: Vec4) -> Landing {
        let l0 = &self.levels[0];
        let (w, h) = (l0.width as f32, l0.height as f32);
        let clip = self.camera.clip_from_world * p;
        if clip.w <= 1e-6 {
            // Behind the camera: the frame's centre is as good as any.
            return Landing::Off(w * 0.5, h * 0.5);
        }
        let (nx, ny) = (clip.x / clip.w, clip.y / clip.w);
        let pixel = |nx: f32, ny: f32| ((nx * 0.5 + 0.5) * w, (0.5 - ny * 0.5) * h);
        if nx.abs() <= 1.0 && ny.abs() <= 1.0 {
            let (x, y) = pixel(nx, ny);
            Landing::On(x, y)
        } else {
            let (x, y) = pixel(nx.clamp(-1.0, 1.0), ny.clamp(-1.0, 1.0));
            Landing::Off(x, y)
        }
    }

    /// The view-axis distance of the opaque surface at `p`'s pixel
    /// (+inf: background or off screen).
    fn depth_behind(&self, p: Vec3) -> f32 {
        match self.land(p.extend(1.0)) {
            Landing::On(x, y) => self.depth_at(x, y),
            Landing::Off(..) => f32::INFINITY,
        }
    }

    /// The view-axis distance at level-0 pixel (x, y).
    fn depth_at(&self, x: f32, y: f32) -> f32 {
        let w = self.levels[0].width;
        let (x, y) = (x as usize, y as usize);
        self.depth[y.min(self.levels[0].height - 1) * w + x.min(w - 1)]
    }

    /// What the fragment sees through itself: the opaque frame where the
    /// refracted ray meets the surface behind, blurred by roughness, or
    /// the environment where it leaves the screen.
    pub fn through(&self, r: &RefractedRay, env: Option<&EnvLight>) -> Vec3 {
        r.per_channel(|ior| self.through_at(r, ior, env))
    }

    /// `through` at index of refraction `ior`.
    fn through_at(&self, r: &RefractedRay, ior: f32, env: Option<&EnvLight>) -> Vec3 {
        let (exit, out) = bend(r, ior);
        let l0 = &self.levels[0];
        let blur = r.roughness.clamp(0.0, 1.0) * (2.0 * ior - 2.0).clamp(0.0, 1.0);
        let lod = (l0.width.max(l0.height) as f32).log2() * blur;
        let rough = spread_through(r, ior);
        // The opaque surface behind the fragment, taken as a plane facing
        // the camera at its depth; the background lies at infinity.
        let (eye, forward) = (self.camera.eye, self.camera.forward);
        let depth = self.depth_behind(r.position);
        let along = out.dot(forward);
        let target = if depth.is_finite() && along > 1e-4 {
            let s = ((depth - (exit - eye).dot(forward)) / along).max(0.0);
            (exit + out * s).extend(1.0)
        } else {
            out.extend(0.0)
        };
        match (self.land(target), env) {
            (Landing::On(x, y), Some(env)) if self.sky && self.depth_at(x, y).is_infinite() => {
                env.seen(out, rough, &self.discs)
            }
            (Landing::On(x, y), _) => self.read(x, y, lod),
            (Landing::Off(..), Some(env)) => env.seen(out, rough, &self.discs),
            (Landing::Off(x, y), None) => self.read(x, y, lod),
        }
    }
}

/// `method = "sampled"` (with `bounces = 1`): what a transmissive
/// fragment sees through itself, traced. The view ray refracts into the
/// surface; in a volume (thickness > 0) it is followed to the surface
/// where it leaves (one that transmits), refracted out (totally
/// reflected inside, up to 8 times, where Snell's law allows no exit),
/// and what it then meets is counted as the bounce counts it: the
/// environment, or the light a surface reflects. An opaque surface
/// inside the volume (a bulb's filament) is seen where the ray meets it.
/// A thin wall lets the ray straight through. A rough surface turns each
/// of `samples` paths by a microfacet normal drawn from its GGX lobe (at
/// entry and exit). With dispersion, each
/// channel takes its own index, as `through` does.
pub fn traced(scene: &Scene, r: &RefractedRay, samples: u32) -> Vec3 {
    r.per_channel(|ior| traced_at(scene, r, ior, samples))
}

/// `traced` at index of refraction `ior`: the mean over its paths.
fn traced_at(scene: &Scene, r: &RefractedRay, ior: f32, samples: u32) -> Vec3 {
    let rough = r.roughness.clamp(0.0, 1.0);
    // Smooth glass sends every path the same way, but what a path
    // meets is itself a Monte Carlo estimate (`Scene::seen`): all of
    // them average it.
    let paths = samples.clamp(1, 256);
    let shift = position_hash(r.position);
    let a = alpha(rough);
    let sum: Vec3 = (0..paths)
        .map(|i| traced_path(scene, r, (ior, a, rough > 0.0), point(i, paths, shift)))
        .sum();
    sum / paths as f32
}

/// One path of `traced_at`: (ior, GGX alpha, rough) and the path's two
/// numbers in [0, 1).
fn traced_path(
    scene: &Scene,
    r: &RefractedRay,
    (ior, a, rough): (f32, f32, bool),
    xi: Vec2,
) -> Vec3 {
    let eps = scene.tracer.epsilon;
    let facet = |n: Vec3, u: Vec2| {
        if rough {
            ggx_sample_aniso(frame(n), a, a, u)
        } else {
            n
        }
    };
    let (n, v) = (r.normal, r.view);
    if r.thickness <= 0.0 || !r.thickness.is_finite() {
        return scene.seen(r.position - n * eps, -v, xi);
    }
    let mut d = refract(-v, facet(n, xi), 1.0 / ior);
    if d.dot(n) >= 0.0 {
        // The drawn facet sent the ray back out: straight on instead.
        d = -v;
    }
    let mut o = r.position - n * eps;
    let turn = Vec2::new(xi.y, xi.x);
    for _ in 0..8 {
        let Some(hit) = scene.tracer.nearest(o, d, f32::INFINITY) else {
            return scene.sampler.radiance(d);
        };
        let Some(b) = scene.surfaces.at(hit, o, d) else {
            return Vec3::ZERO;
        };
        if b.transmission < 0.5 {
            return scene.leaving(&b, -d, xi, true);
        }
        // The normal met faces the inside, where the ray comes from.
        let out = refract(d, facet(b.normal, turn), ior);
        if out.dot(b.normal) > 0.0 {
            // Totally reflected: on inside.
            o = b.position + b.geometric * eps;
            d = out;
            continue;
        }
        return scene.seen(b.position - b.geometric * eps, out, xi);
    }
    Vec3::ZERO
}

/// The ray through the volume: into it at the surface by Snell's law,
/// across a sphere of diameter `thickness` touching the surface there (the
/// local shape of a closed volume: exact for a sphere of that size), and
/// out of it again. Returns where it leaves and its direction then. A
/// thin wall (thickness 0) bends it in and out by the same angle: it goes
/// straight on.
fn bend(r: &RefractedRay, ior: f32) -> (Vec3, Vec3) {
    let (n, v) = (r.normal, r.view);
    if r.thickness <= 0.0 || !r.thickness.is_finite() {
        return (r.position, -v);
    }
    let d = refract(-v, n, 1.0 / ior);
    let cos = (-d.dot(n)).max(0.0);
    // The chord across the sphere, and the outward normal where it ends.
    let exit = r.position + d * (r.thickness * cos);
    let n_exit = n + d * (2.0 * cos);
    (exit, refract(d, -n_exit, ior))
}

/// The roughness at which the environment is read through a rough
/// volume: the width of the transmitted lobe in the units of a reflected
/// one. A facet tilted by d turns a reflected ray by 2d, a refracted one
/// by e d, where e = 1 - cos(in) / (eta cos(out)) at each face. Through a
/// ball (the shape `bend` assumes), the exit face turns the ray by
/// e_exit d and the entry face's turn reaches the exit at about half its
/// size, so the spread is sqrt((e_entry / 2)^2 + e_exit^2) d (0.53 d
/// head-on at ior 1.5, 1.5 d at 60 degrees), and GGX alpha scales by
/// that over 2 (perceptual roughness by its square root; at most 1). A
/// thin wall reads at the surface's roughness.
fn spread_through(r: &RefractedRay, ior: f32) -> f32 {
    let rough = r.roughness.clamp(0.0, 1.0);
    if r.thickness <= 0.0 || !r.thickness.is_finite() || rough == 0.0 {
        return rough;
    }
    let cos_i = r.normal.dot(r.view).clamp(1e-3, 1.0);
    let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (ior * ior)).max(0.0).sqrt();
    let entry = 1.0 - cos_i / (ior * cos_t).max(1e-3);
    // The exit face meets the ray at the entry's refracted angle and
    // sends it out at the entry's incident one.
    let exit = 1.0 - ior * cos_t / cos_i;
    let spread = ((0.5 * entry).powi(2) + exit * exit).sqrt();
    (rough * (spread / 2.0).min(1.0).sqrt()).min(1.0)
}

/// Snell's law: `i` (unit, towards the surface) through the unit normal
/// `n` (against `i`) with eta = n1 / n2; total internal reflection
/// reflects.
fn refract(i: Vec3, n: Vec3, eta: f32) -> Vec3 {
    let cos_i = -n.dot(i);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return i + n * (2.0 * cos_i);
    }
    (i * eta + n * (eta * cos_i - k.sqrt())).normalize_or(i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(width: u32, height: u32, f: impl Fn(u32, u32) -> f32) -> Vec<Vec4> {
        (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| Vec4::new(f(x, y), 0.0, 0.0, 1.0))
            .collect()
    }

    #[test]
    fn snell_bends_towards_the_normal_and_keeps_unit_length() {
        // 45 degrees into glass: sin t = sin 45 / 1.5.
        let i = Vec3::new(1.0, -1.0, 0.0).normalize();
        let t = refract(i, Vec3::Y, 1.0 / 1.5);
        let sin_t = t.x;
        assert!((sin_t - (0.5f32.sqrt() / 1.5)).abs() < 1e-6, "{t}");
        assert!((t.length() - 1.0).abs() < 1e-6);
        // Head-on: no bend.
        assert!((refract(-Vec3::Y, Vec3::Y, 0.5) + Vec3::Y).length() < 1e-6);
        // Total internal reflection leaving glass at 60 degrees.
        let i = Vec3::new(3f32.sqrt() / 2.0, -0.5, 0.0);
        let r = refract(i, Vec3::Y, 1.5);
        assert!((r - Vec3::new(i.x, 0.5, 0.0)).length() < 1e-6);
    }

    #[test]
    fn the_mip_chain_keeps_the_mean_and_ends_at_one_texel() {
        let color = frame(6, 3, |x, y| (x + 10 * y) as f32);
        let f = OpaqueFrame::new((&color, &[1.0; 18]), 6, 3, camera());
        let sizes: Vec<_> = f.levels.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(6, 3), (3, 2), (2, 1), (1, 1)]);
        // Level 1's first texel is the mean of the top-left 2x2 block.
        assert_eq!(f.levels[1].texels[0].x, (0.0 + 1.0 + 10.0 + 11.0) / 4.0);
    }

    /// A camera at the origin looking down -Z with a 90 degree square
    /// frustum: (x, y, -1) projects to the frame's (x, y).
    fn camera() -> Camera {
        Camera {
            // x_clip = x, y_clip = y, w_clip = -z (z_clip, unused, 0.1).
            clip_from_world: Mat4::from_cols(
                Vec4::X,
                Vec4::Y,
                Vec4::new(0.0, 0.0, 0.0, -1.0),
                Vec4::Z * 0.1,
            ),
            eye: Vec3::ZERO,
            forward: -Vec3::Z,
        }
    }

    /// A 64 x 64 frame whose pixels hold their column, all at depth 3.
    fn columns() -> OpaqueFrame {
        let color = frame(64, 64, |x, _| x as f32);
        OpaqueFrame::new((&color, &[3.0; 64 * 64]), 64, 64, camera())
    }

    /// The entry point of a ball of radius 0.25 centred at (0, 0, -2),
    /// where its normal is `n`.
    fn on_ball(n: Vec3, thickness: f32, roughness: f32, ior: f32) -> RefractedRay {
        let p = Vec3::new(0.0, 0.0, -2.0) + n * 0.25;
        RefractedRay {
            position: p,
            normal: n,
            view: -p.normalize(),
            ior,
            dispersion: 0.0,
            thickness,
            roughness,
        }
    }

    #[test]
    fn a_thin_wall_shows_the_pixel_behind_it_and_a_ball_flips_the_backdrop() {
        let f = columns();
        let left = Vec3::new(-0.6, 0.0, 0.8);
        // The entry point (-0.15, 0, -1.8) is at pixel x = 32 (1 - 0.15 /
        // 1.8) = 29.33: through a thin wall, the columns around it.
        let thin = f.through(&on_ball(left, 0.0, 0.0, 1.5), None).x;
        assert!((thin - 28.83).abs() < 0.01, "{thin}");
        // Through the whole ball (thickness = its diameter), a point left
        // of its centre sees the backdrop right of it: a ball lens of
        // focal length 0.375 images the backdrop 1 behind it upside down.
        let ball = f.through(&on_ball(left, 0.5, 0.0, 1.5), None).x;
        assert!(ball > 32.5, "{ball}");
        // And a point right of the centre sees the left.
        let right = Vec3::new(0.6, 0.0, 0.8);
        let ball = f.through(&on_ball(right, 0.5, 0.0, 1.5), None).x;
        assert!(ball < 31.5, "{ball}");
        // At ior 1 nothing bends: the pixel behind.
        let clear = f.through(&on_ball(left, 0.5, 0.0, 1.0), None).x;
        assert!((clear - thin).abs() < 0.01, "{clear} vs {thin}");
        // Head-on through the centre: straight on, to the centre column.
        let centre = f.through(&on_ball(Vec3::Z, 0.5, 0.0, 1.5), None).x;
        assert!((centre - 31.5).abs() < 0.01, "{centre}");
    }

    #[test]
    fn roughness_blurs_through_the_chain_and_ior_1_does_not() {
        // A single bright column: sharp through smooth glass, spread
        // through rough glass, sharp again at ior 1 (no refraction, no
        // blur, as in the sample viewer).
        let color = frame(64, 64, |x, _| if x == 40 { 64.0 } else { 0.0 });
        let f = OpaqueFrame::new((&color, &[3.0; 64 * 64]), 64, 64, camera());
        let at = |roughness: f32, ior: f32, x: f32| {
            let p = Vec3::new(x, 0.0, -1.0);
            let r = RefractedRay {
                position: p,
                normal: -p.normalize(),
                view: -p.normalize(),
                ior,
                dispersion: 0.0,
                thickness: 0.0,
                roughness,
            };
            f.through(&r, None).x
        };
        let (on, off) = (40.5 / 32.0 - 1.0, 36.5 / 32.0 - 1.0);
        assert!((at(0.0, 1.5, on) - 64.0).abs() < 1e-3);
        assert_eq!(at(0.0, 1.5, off), 0.0);
        assert!(at(0.5, 1.5, on) < 32.0);
        assert!(at(0.5, 1.5, off) > 0.0);
        assert!((at(0.5, 1.0, on) - 64.0).abs() < 1e-3);
    }

    #[test]
    fn off_screen_without_an_environment_reads_the_nearest_edge() {
        let color = frame(8, 8, |x, _| x as f32);
        let f = OpaqueFrame::new((&color, &[3.0; 64]), 8, 8, camera());
        let p = Vec3::new(5.0, 0.0, -1.0);
        let r = RefractedRay {
            position: p,
            normal: -p.normalize(),
            view: -p.normalize(),
            ior: 1.5,
            dispersion: 0.0,
            thickness: 0.0,
            roughness: 0.0,
        };
        assert_eq!(f.through(&r, None).x, 7.0);
    }

    #[test]
    fn each_channel_takes_the_index_the_extension_gives_it() {
        // ior 1.5, dispersion 4 (Abbe number 5): h = 0.5 / 40 x 4 = 0.05.
        let mut r = on_ball(Vec3::Z, 0.5, 0.0, 1.5);
        r.dispersion = 4.0;
        let got = r.per_channel(Vec3::splat);
        assert!(
            (got - Vec3::new(1.45, 1.5, 1.55)).abs().max_element() < 1e-6,
            "{got}"
        );
        // A thin wall, or no dispersion: one index; a bad one reads 1.5.
        r.thickness = 0.0;
        assert_eq!(r.per_channel(Vec3::splat), Vec3::splat(1.5));
        let mut r = on_ball(Vec3::Z, 0.5, 0.0, f32::NAN);
        r.dispersion = 0.0;
        assert_eq!(r.per_channel(Vec3::splat), Vec3::splat(1.5));
    }

    #[test]
    fn dispersion_sends_each_channel_through_its_own_index() {
        // Every channel holds the column.
        let color: Vec<Vec4> = frame(64, 64, |x, _| x as f32)
            .iter()
            .map(|c| Vec4::new(c.x, c.x, c.x, 1.0))
            .collect();
        let f = OpaqueFrame::new((&color, &[3.0; 64 * 64]), 64, 64, camera());
        let left = Vec3::new(-0.6, 0.0, 0.8);
        let plain = f.through(&on_ball(left, 0.5, 0.0, 1.5), None);
        let mut r = on_ball(left, 0.5, 0.0, 1.5);
        r.dispersion = 4.0;
        let spread = f.through(&r, None);
        // Green keeps the index; red and blue, (1.5 - 1) / 40 x 4 = 0.05
        // below and above it, land on columns of their own.
        assert_eq!(spread.y, plain.y);
        let at = |ior: f32| f.through(&on_ball(left, 0.5, 0.0, ior), None);
        assert!((spread.x - at(1.45).x).abs() < 1e-3, "{spread}");
        assert!((spread.z - at(1.55).z).abs() < 1e-3, "{spread}");
        assert!((spread.x - spread.z).abs() > 0.5, "{spread}");
        // A thin wall does not bend the ray: no spread.
        let mut thin = on_ball(left, 0.0, 0.0, 1.5);
        thin.dispersion = 4.0;
        let t = f.through(&thin, None);
        assert!(t.x == t.y && t.y == t.z, "{t}");
    }
}
