//! The ground shadow catcher (`[ground] shadow = true`): an invisible plane
//! under the models that shows only what they take from it, composited over
//! the background: the shadows of shadow-casting lights and a soft contact
//! occlusion. It is not an object: depth and the other buffers do not see
//! it. Per background pixel whose view ray meets the plane:
//!
//!   factor = (sum_i E_i v_i + E_a ao) / (sum_i E_i + E_a)
//!
//! with E_i the light's irradiance on the plane and v_i its visibility (a
//! ray through the scene's BVHs per pixel, the open share of a cone of
//! rays for a light with a disc (`shade::soft_shadow`); 1 for lights that
//! cast no shadows), E_a the irradiance of the environment from above (or of
//! `[ambient]`), and ao the unoccluded fraction of 16 cosine-weighted rays
//! within half the models' radius: a soft contact shadow, computed per
//! frame on a 96x96 grid over the plane within 1.5 radii of the models'
//! center (1 beyond), blurred (`smoothed`) and interpolated bilinearly.
//! The catcher fades out between 2 and 3 radii from the center. Without
//! lights, where each pixel meets the plane is kept while the camera
//! stays (`GroundView`).

use std::sync::{Arc, OnceLock};

use glam::{Vec2, Vec3, Vec4};

use super::draw_list::DrawList;
use super::rays::{CameraRays, ViewCache};
use crate::raytrace::Tracer;
use crate::scene::Light;
use crate::scene::light::LightKind;
use crate::scene::settings::Background;
use crate::shade::ShadeContext;
use crate::shade::ao::{for_each_ray, pixel_hash};
use crate::shade::light::{Incidence, incidence};
use crate::shade::soft_shadow::open_share;

/// Rays of contact occlusion per grid point.
const AO_SAMPLES: u32 = 16;
/// Grid points of contact occlusion per side.
const AO_GRID: usize = 96;
/// The grid's half size, in models' radii.
const AO_EXTENT: f32 = 1.5;

pub(super) struct Ground<'a> {
    rays: CameraRays,
    height: f32,
    center: Vec3,
    radius: f32,
    lights: &'a [Light],
    tracer: &'a Tracer<'a>,
    /// Luminance of the light from above that is not a light.
    ambient: f32,
    /// Contact occlusion on the grid, rows along +Z.
    ao: Vec<f32>,
    /// Without lights, the pixels (first and last column, first and last
    /// row) outside which the catcher keeps all the light: the contact
    /// grid's shadowed part seen through the camera (`open_outside`).
    /// None: no such bounds.
    open_outside: Option<[i32; 4]>,
    transparent: bool,
    /// Without lights, where each pixel of the grid's view meets the
    /// plane (`GroundView`), when the renderer keeps it for this view.
    view: Option<Arc<GroundView>>,
}

/// Where a pixel's view ray meets the plane, as the catcher reads it
/// without lights: the fade there (0: no plane point shown) and the
/// contact grid's cell (None: outside the grid, no contact shadow).
#[derive(Clone, Copy)]
struct Spot {
    fade: f32,
    cell: Option<Cell>,
}

/// The bytes of one pixel's `Spot` (the memory estimate's).
pub(super) const SPOT_BYTES: u64 = std::mem::size_of::<Spot>() as u64;

/// A plane point's place in the contact grid: the corners of its cell
/// (column and row of the first and second) and the blend weights.
#[derive(Clone, Copy)]
struct Cell {
    x: [u8; 2],
    z: [u8; 2],
    f: [f32; 2],
}

/// Every pixel's `Spot` within the bounds of the whole contact grid
/// seen through the camera (the pixels beyond see no grid point, so
/// without lights they keep the background). The same for every frame
/// of a camera: the plane does not move.
pub(super) struct GroundView {
    /// First column and row, width and height.
    at: [i32; 4],
    spots: Vec<Spot>,
}

impl GroundView {
    fn spot(&self, px: i32, py: i32) -> Option<&Spot> {
        let [x0, y0, w, h] = self.at;
        let (x, y) = (px - x0, py - y0);
        if x < 0 || y < 0 || x >= w || y >= h {
            return None;
        }
        self.spots.get((y * w + x) as usize)
    }
}

/// What a ground view depends on: the view rays and the plane (its
/// height, center and radius, as bits).
#[derive(PartialEq)]
pub(super) struct ViewKey {
    rays: CameraRays,
    plane: [u32; 5],
}

/// The last ground view a renderer read, kept while its camera stays.
pub(super) type GroundCache = ViewCache<ViewKey, GroundView>;

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl<'a> Ground<'a> {
    /// The frame's catcher, when the scene asks for one.
    pub fn new(
        setup: &'a DrawList<'a>,
        ctx: &ShadeContext<'a>,
        tracer: Option<&'a Tracer<'a>>,
        width: u32,
        height: u32,
    ) -> Option<Ground<'a>> {
        let plane = setup.scene.ground.as_ref()?;
        let tracer = tracer?;
        if setup.scene.settings.shading.is_data_view() {
            return None;
        }
        let ambient = match ctx.env {
            Some(env) => luminance(env.irradiance(Vec3::Y)),
            None => luminance(ctx.ambient) * std::f32::consts::PI,
        };
        let ao = if ambient > 0.0 {
            smoothed(&contact_grid(
                tracer,
                plane.height,
                plane.center,
                plane.radius,
            ))
        } else {
            Vec::new()
        };
        let mut ground = Ground {
            rays: CameraRays::new(&setup.camera, width, height),
            height: plane.height,
            center: plane.center,
            radius: plane.radius,
            lights: &setup.lights,
            tracer,
            ambient,
            ao,
            open_outside: None,
            transparent: setup.scene.settings.background == Background::Transparent,
            view: None,
        };
        ground.open_outside = ground.open_outside();
        Some(ground)
    }

    /// `open_outside`'s bounds: where there are no lights, those of the
    /// contact grid's shadowed part (its points below 1, two cells wider:
    /// beyond them every lookup blends four 1s, and the factor is 1) seen
    /// through the camera.
    fn open_outside(&self) -> Option<[i32; 4]> {
        const NOWHERE: Option<[i32; 4]> = Some([1, 1, 0, 0]);
        if !self.lights.is_empty() {
            return None;
        }
        // Grid points other than 1 (NaN included), by column and row.
        let mut cells = (0..self.ao.len()).filter(|&k| self.ao[k] != 1.0);
        let Some(first) = cells.next() else {
            // No contact shadow (or no light from above): nothing to show.
            return NOWHERE;
        };
        let at = |k: usize| ((k % AO_GRID) as f32, (k / AO_GRID) as f32);
        let (mut glo, mut ghi) = (Vec2::from(at(first)), Vec2::from(at(first)));
        for k in cells {
            glo = glo.min(Vec2::from(at(k)));
            ghi = ghi.max(Vec2::from(at(k)));
        }
        self.seen_bounds(glo, ghi)
    }

    /// The pixels (first and last column, first and last row) that see
    /// the grid's points from `glo` to `ghi` (column, row), two cells
    /// wider, with two pixels for rounding: the rectangle's corners seen
    /// through the camera, all in front of it (the rectangle, convex,
    /// then lies within their bounds). None where a corner is not.
    fn seen_bounds(&self, glo: Vec2, ghi: Vec2) -> Option<[i32; 4]> {
        let half = AO_EXTENT * self.radius;
        let step = 2.0 * half / AO_GRID as f32;
        // Grid point (i, j) lies at center - half + (i + 1/2) step.
        let world = |g: Vec2| {
            Vec2::new(self.center.x, self.center.z) - Vec2::splat(half)
                + (g + Vec2::splat(0.5)) * step
        };
        let (wlo, whi) = (world(glo - Vec2::splat(2.0)), world(ghi + Vec2::splat(2.0)));
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for (x, z) in [
            (wlo.x, wlo.y),
            (whi.x, wlo.y),
            (wlo.x, whi.y),
            (whi.x, whi.y),
        ] {
            let (x, y) = self.rays.pixel_of(Vec3::new(x, self.height, z))?;
            lo = lo.min(Vec2::new(x, y));
            hi = hi.max(Vec2::new(x, y));
        }
        // Pixel k's center is at k + 1/2; two pixels cover rounding.
        let (lo, hi) = (lo - Vec2::splat(2.5), hi + Vec2::splat(1.5));
        (lo.is_finite() && hi.is_finite() && hi.max_element() < 1e9 && lo.min_element() > -1e9)
            .then(|| {
                [
                    lo.x.floor() as i32,
                    lo.y.floor() as i32,
                    hi.x.ceil() as i32,
                    hi.y.ceil() as i32,
                ]
            })
    }

    /// Without lights, reads where each pixel meets the plane from
    /// `cache` where the previous frame had the same camera (computing
    /// it on the second frame of a camera).
    pub fn attach(&mut self, cache: &GroundCache) {
        if !self.lights.is_empty() || self.ambient <= 0.0 {
            return;
        }
        let key = ViewKey {
            rays: self.rays.clone(),
            plane: [
                self.height.to_bits(),
                self.center.x.to_bits(),
                self.center.y.to_bits(),
                self.center.z.to_bits(),
                self.radius.to_bits(),
            ],
        };
        self.view = cache.get(key, || self.view_of_grid());
    }

    /// Every pixel's `Spot` within the bounds of the whole grid seen
    /// through the camera, clipped to the frame; rows in parallel.
    fn view_of_grid(&self) -> GroundView {
        use rayon::prelude::*;
        let last = Vec2::splat((AO_GRID - 1) as f32);
        let Some([x0, y0, x1, y1]) = self.seen_bounds(Vec2::ZERO, last) else {
            return GroundView {
                at: [0; 4],
                spots: Vec::new(),
            };
        };
        let (w, h) = self.rays.size();
        let (x0, y0) = (x0.max(0), y0.max(0));
        let (x1, y1) = (x1.min(w as i32 - 1), y1.min(h as i32 - 1));
        let (vw, vh) = ((x1 - x0 + 1).max(0), (y1 - y0 + 1).max(0));
        let none = Spot {
            fade: 0.0,
            cell: None,
        };
        let mut spots = vec![none; (vw * vh) as usize];
        spots
            .par_chunks_mut(vw.max(1) as usize)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, s) in row.iter_mut().enumerate() {
                    let (px, py) = (x0 + x as i32, y0 + y as i32);
                    if let Some((p, fade)) = self.plane_point(px, py) {
                        *s = Spot {
                            fade,
                            cell: self.cell(p),
                        };
                    }
                }
            });
        GroundView {
            at: [x0, y0, vw, vh],
            spots,
        }
    }

    /// `bg` with the catcher at pixel (px, py) composited over it: darkened
    /// by the catcher's factor, or, over a transparent background, black
    /// with the shadow's opacity as alpha.
    #[inline]
    pub fn over(&self, bg: Vec4, px: i32, py: i32) -> Vec4 {
        if let Some([x0, y0, x1, y1]) = self.open_outside
            && (px < x0 || px > x1 || py < y0 || py > y1)
        {
            // Factor 1 or none: `bg` either way (over a transparent
            // background, black with alpha 0, which is `bg` there).
            return bg;
        }
        self.over_inside(bg, px, py)
    }

    /// `over` where the pixel is not known to keep `bg`.
    #[inline(never)]
    fn over_inside(&self, bg: Vec4, px: i32, py: i32) -> Vec4 {
        let Some(f) = self.factor(px, py) else {
            return bg;
        };
        if self.transparent {
            Vec4::new(0.0, 0.0, 0.0, 1.0 - f)
        } else {
            (bg.truncate() * f).extend(bg.w)
        }
    }

    /// The share of light the plane keeps at the pixel (1: none taken).
    fn factor(&self, px: i32, py: i32) -> Option<f32> {
        if let Some(spot) = self.view.as_ref().and_then(|v| v.spot(px, py)) {
            return self.factor_seen(spot);
        }
        let (p, fade) = self.plane_point(px, py)?;
        let (mut total, mut kept) = (self.ambient, 0.0);
        for light in self.lights {
            let Some((e, inc)) = self.reaching(light, p) else {
                continue;
            };
            total += e;
            kept += e * self.visibility(light, p, inc);
        }
        if self.ambient > 0.0 {
            kept += self.ambient * self.contact(p);
        }
        share(total, kept, fade)
    }

    /// `factor` without lights, from the view's spot: the same operations
    /// on the same values.
    fn factor_seen(&self, spot: &Spot) -> Option<f32> {
        if spot.fade <= 0.0 {
            return None;
        }
        let mut kept = 0.0;
        if self.ambient > 0.0 {
            kept += self.ambient * spot.cell.as_ref().map_or(1.0, |c| self.blend(c));
        }
        share(self.ambient, kept, spot.fade)
    }

    /// The plane point pixel (px, py) sees, and the catcher's fade there;
    /// None where it sees none the catcher shows.
    fn plane_point(&self, px: i32, py: i32) -> Option<(Vec3, f32)> {
        let (o, d) = self.rays.ray(px, py);
        if d.y.abs() < 1e-6 {
            return None;
        }
        let t = (self.height - o.y) / d.y;
        if t <= 0.0 {
            return None;
        }
        let p = o + d * t;
        let r = Vec3::new(p.x - self.center.x, 0.0, p.z - self.center.z).length() / self.radius;
        let fade = 1.0 - smoothstep(2.0, 3.0, r);
        (fade > 0.0).then_some((p, fade))
    }

    /// The luminance of `light`'s irradiance on the plane at `p`, and its
    /// incidence; None where it brings none.
    fn reaching(&self, light: &Light, p: Vec3) -> Option<(f32, Incidence)> {
        let inc = incidence(light, p)?;
        let e = luminance(inc.e) * inc.l.y.max(0.0);
        (e > 0.0).then_some((e, inc))
    }

    /// How much of `light` (arriving as `inc`) plane point `p` sees: a
    /// ray, or the open share of a disc's cone; 1 for a light that casts
    /// no shadows.
    fn visibility(&self, light: &Light, p: Vec3, inc: Incidence) -> f32 {
        if !light.shadows {
            return 1.0;
        }
        let origin = p + Vec3::Y * self.tracer.epsilon;
        let t_max = if light.kind_is_directional() {
            f32::INFINITY
        } else {
            1.0
        };
        let dir = if t_max.is_finite() {
            light.position_or(p) - origin
        } else {
            inc.l
        };
        match light.kind {
            LightKind::Directional { angle, .. } if angle > 0.0 => {
                open_share(self.tracer, angle, p, Vec3::Y, inc.l)
            }
            _ => f32::from(u8::from(!self.tracer.occluded(origin, dir, t_max))),
        }
    }
}

impl Ground<'_> {
    /// Contact occlusion at plane point `p`, from the grid.
    fn contact(&self, p: Vec3) -> f32 {
        self.cell(p).map_or(1.0, |c| self.blend(&c))
    }

    /// Where plane point `p` falls in the grid; None outside it.
    fn cell(&self, p: Vec3) -> Option<Cell> {
        let half = AO_EXTENT * self.radius;
        let n = AO_GRID as f32;
        let gx = (p.x - self.center.x + half) / (2.0 * half) * n - 0.5;
        let gz = (p.z - self.center.z + half) / (2.0 * half) * n - 0.5;
        if !(gx > -0.5 && gz > -0.5 && gx < n - 0.5 && gz < n - 0.5) {
            return None;
        }
        let (gx, gz) = (gx.clamp(0.0, n - 1.0), gz.clamp(0.0, n - 1.0));
        // Within [0, 95]: the casts are exact.
        let (x0, z0) = (gx as u8, gz as u8);
        let last = (AO_GRID - 1) as u8;
        Some(Cell {
            x: [x0, (x0 + 1).min(last)],
            z: [z0, (z0 + 1).min(last)],
            f: [gx - f32::from(x0), gz - f32::from(z0)],
        })
    }

    /// The grid's occlusion blended over `c`.
    fn blend(&self, c: &Cell) -> f32 {
        let at = |x: u8, z: u8| self.ao[z as usize * AO_GRID + x as usize];
        let ([x0, x1], [z0, z1], [fx, fz]) = (c.x, c.z, c.f);
        let a = at(x0, z0) + (at(x1, z0) - at(x0, z0)) * fx;
        let b = at(x0, z1) + (at(x1, z1) - at(x0, z1)) * fx;
        a + (b - a) * fz
    }
}

/// The catcher's factor from the light's total and kept luminance, and
/// the fade; None without light.
fn share(total: f32, kept: f32, fade: f32) -> Option<f32> {
    if total <= 0.0 {
        return None;
    }
    Some(1.0 - fade * (1.0 - kept / total))
}

/// Contact occlusion on the grid: rays of half a radius from farther than
/// 1.5 radii cannot meet the models, so the grid covers the rest. Each
/// point casts `occlusion_at`'s rays (their directions depend only on the
/// point's place in the grid, so they are made once per process); a point
/// whose rays cannot reach any model's bounds is open without casting.
fn contact_grid(tracer: &Tracer, height: f32, center: Vec3, radius: f32) -> Vec<f32> {
    use rayon::prelude::*;
    let half = AO_EXTENT * radius;
    let step = 2.0 * half / AO_GRID as f32;
    let t_max = radius * 0.5;
    // The rays' directions are unit to within a few ulps: 1% is room.
    let reach = t_max * 1.01 + tracer.epsilon;
    let dirs = contact_rays();
    let mut grid = vec![1.0f32; AO_GRID * AO_GRID];
    grid.par_chunks_mut(AO_GRID)
        .enumerate()
        .for_each(|(z, row)| {
            for (x, v) in row.iter_mut().enumerate() {
                let p = Vec3::new(
                    center.x - half + (x as f32 + 0.5) * step,
                    height + tracer.epsilon,
                    center.z - half + (z as f32 + 0.5) * step,
                );
                if !tracer.any_within(p, reach) {
                    continue;
                }
                let at = (z * AO_GRID + x) * AO_SAMPLES as usize;
                let rays = &dirs[at..at + AO_SAMPLES as usize];
                let open = rays
                    .iter()
                    .filter(|&&d| !tracer.occluded(p, d, t_max))
                    .count();
                // As `occlusion_at` divides.
                *v = open as u32 as f32 / AO_SAMPLES as f32;
            }
        });
    grid
}

/// The grid blurred by [1, 2, 1] / 4 along its rows, then its columns
/// (edge points repeated): 16 rays per point leave a mottle the eye
/// reads as dirt on the floor; the blur keeps a uniform grid as it is
/// and lowers the noise of independent points to 0.375 of its spread.
fn smoothed(grid: &[f32]) -> Vec<f32> {
    let n = AO_GRID;
    let blur = |a: f32, b: f32, c: f32| (a + 2.0 * b + c) * 0.25;
    let mut rows = vec![0.0f32; grid.len()];
    for z in 0..n {
        for x in 0..n {
            let at = |x: usize| grid[z * n + x];
            rows[z * n + x] = blur(at(x.saturating_sub(1)), at(x), at((x + 1).min(n - 1)));
        }
    }
    let mut out = vec![0.0f32; grid.len()];
    for z in 0..n {
        for x in 0..n {
            let at = |z: usize| rows[z * n + x];
            out[z * n + x] = blur(at(z.saturating_sub(1)), at(z), at((z + 1).min(n - 1)));
        }
    }
    out
}

/// Per grid point (rows along +Z), the directions of its contact rays:
/// `occlusion_at`'s, around +Y with the point's `pixel_hash` seed.
fn contact_rays() -> &'static [Vec3] {
    static RAYS: OnceLock<Vec<Vec3>> = OnceLock::new();
    RAYS.get_or_init(|| {
        let mut dirs = Vec::with_capacity(AO_GRID * AO_GRID * AO_SAMPLES as usize);
        for z in 0..AO_GRID {
            for x in 0..AO_GRID {
                let seed = pixel_hash(x as u32, z as u32);
                for_each_ray(Vec3::Y, AO_SAMPLES, seed, |d| dirs.push(d));
            }
        }
        dirs
    })
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raytrace::Placed;
    use crate::raytrace::bvh::Bvh;
    use crate::scene::camera::Camera;
    use crate::shade::ao::occlusion_at;
    use glam::Mat4;

    /// The box from `lo` to `hi` as twelve triangles.
    fn box_bvh(lo: Vec3, hi: Vec3) -> Bvh {
        let corner = |k: u32| {
            Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let positions: Vec<Vec3> = (0..8).map(corner).collect();
        let quads = [
            [0, 1, 3, 2],
            [4, 6, 7, 5],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 5, 7, 3],
        ];
        let triangles: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Bvh::build(&positions, &triangles)
    }

    /// Without lights, the bounds of the contact shadow (`open_outside`)
    /// change no pixel: every pixel the catcher darkens lies within them,
    /// and they are tight (the darkened pixels reach within 12 of each
    /// side inside the frame).
    #[test]
    fn pixels_outside_the_contact_shadow_keep_the_background() {
        let (lo, hi) = (Vec3::new(-0.3, 0.0, -0.2), Vec3::new(0.2, 0.7, 0.3));
        let bvh = box_bvh(lo, hi);
        let tracer = box_tracer(&bvh, lo, hi);
        for transparent in [false, true] {
            let mut ground = box_ground(&tracer, &[]);
            ground.transparent = transparent;
            let bg = if transparent {
                Vec4::ZERO
            } else {
                Vec4::new(0.3, 0.5, 0.7, 1.0)
            };
            let bits = |c: Vec4| c.to_array().map(f32::to_bits);
            let everywhere = ground.pixels(|g, x, y| bits(g.over(bg, x, y)));
            ground.open_outside = ground.open_outside();
            let Some([x0, y0, x1, y1]) = ground.open_outside else {
                panic!("no bounds");
            };
            let bounded = ground.pixels(|g, x, y| bits(g.over(bg, x, y)));
            assert_eq!(bounded, everywhere);
            let mut reach = [i32::MAX, i32::MAX, i32::MIN, i32::MIN];
            for (k, c) in everywhere.iter().enumerate() {
                let (x, y) = ((k % W as usize) as i32, (k / W as usize) as i32);
                if *c != bits(bg) {
                    assert!(x >= x0 && x <= x1 && y >= y0 && y <= y1, "({x}, {y})");
                    reach = [
                        reach[0].min(x),
                        reach[1].min(y),
                        reach[2].max(x),
                        reach[3].max(y),
                    ];
                }
            }
            assert!(reach[0] <= reach[2], "no contact shadow");
            let inside = [
                x0.max(0),
                y0.max(0),
                x1.min(W as i32 - 1),
                y1.min(H as i32 - 1),
            ];
            for k in 0..4 {
                assert!((reach[k] - inside[k]).abs() <= 12, "{reach:?} {inside:?}");
            }
            // Not the whole frame.
            assert!(x0 > 0 || y0 > 0 || x1 < W as i32 - 1 || y1 < H as i32 - 1);
        }
    }

    /// Without lights, the view a renderer keeps for its camera
    /// (`GroundView`, read from the second frame of a camera on) gives
    /// every pixel the bits the catcher computes without it; a moved
    /// camera is not served it, and a catcher with lights takes none.
    #[test]
    fn the_kept_view_is_every_pixel_bit_for_bit() {
        let (lo, hi) = (Vec3::new(-0.3, 0.0, -0.2), Vec3::new(0.2, 0.7, 0.3));
        let bvh = box_bvh(lo, hi);
        let tracer = box_tracer(&bvh, lo, hi);
        let cache = GroundCache::default();
        for transparent in [false, true] {
            let mut ground = box_ground(&tracer, &[]);
            ground.transparent = transparent;
            let bg = Vec4::new(0.3, 0.5, 0.7, 1.0);
            let bits = |c: Vec4| c.to_array().map(f32::to_bits);
            let computed = ground.pixels(|g, x, y| bits(g.over(bg, x, y)));
            // The first frame of the camera keeps nothing, the second
            // does (the transparent round finds the view kept already).
            ground.attach(&cache);
            assert_eq!(ground.view.is_some(), transparent);
            ground.attach(&cache);
            let view = ground.view.as_ref().expect("kept");
            // The view covers the darkened pixels and not the whole frame.
            let [x0, y0, w, h] = view.at;
            assert!(
                w > 10 && h > 10 && (w < W as i32 || h < H as i32),
                "{:?}",
                view.at
            );
            assert!(x0 >= 0 && y0 >= 0);
            let read = ground.pixels(|g, x, y| bits(g.over(bg, x, y)));
            assert_eq!(read, computed);
            assert!(read.iter().any(|c| *c != bits(bg)), "no contact shadow");
        }
        let mut moved = box_ground(&tracer, &[]);
        moved.rays = CameraRays::new(&Camera::framing("m".into(), Vec3::Y, 1.0, 40.0), W, H);
        moved.attach(&cache);
        assert!(moved.view.is_none());
        let lights = [Light {
            kind: LightKind::Directional {
                direction: Vec3::new(0.3, -1.0, 0.2).normalize(),
                irradiance: 1.0,
                angle: 0.0,
            },
            color: Vec3::ONE,
            shadows: true,
            range: None,
        }];
        let mut lit = box_ground(&tracer, &lights);
        lit.attach(&cache);
        lit.attach(&cache);
        assert!(lit.view.is_none());
    }

    /// The contact grid's blur: a uniform grid stays as it is, one dark
    /// point spreads as [1, 2, 1] / 4 by [1, 2, 1] / 4 (edges repeated),
    /// and independent noise keeps its mean and loses most of its spread.
    #[test]
    fn the_blur_keeps_the_level_and_lowers_the_mottle() {
        let n = AO_GRID;
        for v in [1.0f32, 0.5] {
            assert!(smoothed(&vec![v; n * n]).iter().all(|&x| x == v));
        }
        let mut one = vec![0.0f32; n * n];
        one[10 * n + 20] = 1.0;
        let b = smoothed(&one);
        let w = [0.25f32, 0.5, 0.25];
        for dz in 0..3 {
            for dx in 0..3 {
                assert_eq!(b[(9 + dz) * n + 19 + dx], w[dz] * w[dx], "({dx}, {dz})");
            }
        }
        assert_eq!(b.iter().sum::<f32>(), 1.0);
        // A corner point: its weights fold back onto it.
        let mut corner = vec![0.0f32; n * n];
        corner[0] = 1.0;
        assert_eq!(smoothed(&corner)[0], 0.75 * 0.75);
        // Noise: a hash per point in [0, 1).
        let noise: Vec<f32> = (0..n * n)
            .map(|k| pixel_hash(k as u32 % 97, k as u32 / 97).0)
            .collect();
        let stats = |g: &[f32]| {
            let inner: Vec<f32> = (1..n - 1)
                .flat_map(|z| (1..n - 1).map(move |x| z * n + x))
                .map(|k| g[k])
                .collect();
            let mean = inner.iter().sum::<f32>() / inner.len() as f32;
            let var =
                inner.iter().map(|v| (v - mean) * (v - mean)).sum::<f32>() / inner.len() as f32;
            (mean, var.sqrt())
        };
        let ((m0, s0), (m1, s1)) = (stats(&noise), stats(&smoothed(&noise)));
        assert!((m0 - m1).abs() < 0.01, "{m0} {m1}");
        assert!(s1 < 0.45 * s0 && s1 > 0.3 * s0, "{s0} {s1}");
    }

    const W: u32 = 97;
    const H: u32 = 61;

    impl Ground<'_> {
        /// `f` of every pixel, rows from the top.
        fn pixels<T>(&self, mut f: impl FnMut(&Self, i32, i32) -> T) -> Vec<T> {
            let mut out = Vec::new();
            for y in 0..H as i32 {
                for x in 0..W as i32 {
                    out.push(f(self, x, y));
                }
            }
            out
        }
    }

    fn box_tracer(bvh: &Bvh, lo: Vec3, hi: Vec3) -> Tracer<'_> {
        Tracer::new(
            [Placed {
                bvh,
                cutout: None,
                bounds: (lo, hi),
                world_from_object: Mat4::IDENTITY,
            }],
            1.0,
        )
    }

    /// A catcher of radius 0.8 at the origin, seen from above at an angle
    /// (`W` x `H`), without bounds.
    fn box_ground<'a>(tracer: &'a Tracer<'a>, lights: &'a [Light]) -> Ground<'a> {
        let cam = Camera {
            eye: Vec3::new(0.4, 1.6, 2.4),
            ..Camera::framing("c".into(), Vec3::new(0.0, 0.3, 0.0), 1.0, 40.0)
        };
        Ground {
            rays: CameraRays::new(&cam, W, H),
            height: 0.0,
            center: Vec3::ZERO,
            radius: 0.8,
            lights,
            tracer,
            ambient: 0.5,
            ao: contact_grid(tracer, 0.0, Vec3::ZERO, 0.8),
            open_outside: None,
            transparent: false,
            view: None,
        }
    }

    /// The grid (its kept ray table and the skip of points far from every
    /// model) equals `occlusion_at` at every point, bit for bit: a box
    /// standing on the plane off the center, so that some points are near
    /// it, some under its overhang and most far from it.
    #[test]
    fn the_contact_grid_is_occlusion_at_every_point() {
        let (lo, hi) = (Vec3::new(0.2, 0.0, -0.4), Vec3::new(0.9, 0.6, 0.1));
        let bvh = box_bvh(lo, hi);
        let tracer = Tracer::new(
            [Placed {
                bvh: &bvh,
                cutout: None,
                bounds: (lo, hi),
                world_from_object: Mat4::from_rotation_y(0.3),
            }],
            1.0,
        );
        let (height, center, radius) = (0.0, Vec3::new(0.1, 0.0, 0.0), 1.2);
        let grid = contact_grid(&tracer, height, center, radius);
        let half = AO_EXTENT * radius;
        let step = 2.0 * half / AO_GRID as f32;
        let mut shaded = 0;
        for z in 0..AO_GRID {
            for x in 0..AO_GRID {
                let p = Vec3::new(
                    center.x - half + (x as f32 + 0.5) * step,
                    height + tracer.epsilon,
                    center.z - half + (z as f32 + 0.5) * step,
                );
                let seed = pixel_hash(x as u32, z as u32);
                let want = occlusion_at(&tracer, p, Vec3::Y, AO_SAMPLES, radius * 0.5, seed);
                let got = grid[z * AO_GRID + x];
                assert_eq!(got.to_bits(), want.to_bits(), "point ({x}, {z})");
                shaded += (want < 1.0) as u32;
            }
        }
        // The box darkens part of the grid, and not all of it.
        assert!(
            shaded > 100 && shaded < (AO_GRID * AO_GRID) as u32 / 2,
            "{shaded}"
        );
    }
}
