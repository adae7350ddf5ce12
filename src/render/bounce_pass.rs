//! The bounce pass: under `prefiltered` with `environment.bounces = 1`,
//! the light bounced once is gathered at every pixel's surface (the
//! geometry buffer's point and normal) and filtered across the surface
//! before shading, which reads it where a point lies on its pixel's
//! surface (`reflect::BounceScreen`) and gathers its own elsewhere.
//!
//! Four rays a point leave grain: a pixel whose one ray meets the floor
//! under a lamp is bright, its neighbour dark. The filter is an
//! edge-aware tent à trous (`ao::edge_aware_blur`, a 3x3 tent with its
//! taps 1, 2, 4 and 8 pixels apart), which does not cross depth edges or
//! creases. It filters what the rays change, not the irradiance: the
//! environment's part stays sharp per pixel, about each pixel's own
//! (normal-mapped) normal.

use glam::Vec3;
use rayon::prelude::*;

use super::draw_list::DrawList;
use super::rays::CameraRays;
use crate::raytrace::Tracer;
use crate::shade::ao::{AoView, Blurred, GPixel, cosine_direction, edge_aware_blur};
use crate::shade::env::bounce::Surfaces;
use crate::shade::env::pattern::{point, position_hash};
use crate::shade::env::reflect::{BounceScreen, GLOSSY_FROM, Reflections};

/// The filter's weights along each axis, and the steps of its passes in
/// pixels: 36 taps a pixel, 31 pixels wide (the CornellBox under the
/// studio HDRI against Cycles: 0.0999 FLIP, as with a 5x5 tent at steps
/// 1, 2 and 4, at half the taps).
const TENT: [f32; 3] = [1.0, 2.0, 1.0];
const STEPS: [i32; 4] = [1, 2, 4, 8];

/// The bounce at the pixels of `gbuf` (`width` x `height`; every other
/// one in each direction where the frame's shorter side has at least
/// twice `HALF_FROM` pixels), gathered by `with` and filtered, twice:
/// the second gathering lights the surfaces its rays meet with the
/// first's bounce where the frame shows them (`Reflections::
/// gathered_change`); `(eye, forward)`: the camera's position and unit
/// view axis.
///
/// Lit as open points, the surfaces met in a box's corner shone with
/// the whole sky that their own neighbours hide: the CornellBox against
/// Cycles 0.111 / 0.095 (courtyard / studio) with one gathering, 0.106
/// / 0.084 with two, 0.1056 / 0.0816 with three.
pub(super) fn bounce(
    setup: &DrawList,
    with: &Reflections,
    gbuf: &[GPixel],
    size: (u32, u32),
    camera: (Vec3, Vec3),
) -> BounceScreen {
    let (points, grid, coarse) = samples(gbuf, size, |_| true);
    let gathering = |prior: Option<&BounceScreen>| {
        let raw = per_pixel(&points, grid.0, |g| {
            with.gathered_change(g.position, [g.geo_normal, g.normal], prior)
        });
        let mut screen = filtered(setup, &points, grid, camera, raw);
        if coarse {
            screen.position = points.iter().map(|g| g.position).collect();
        }
        screen
    };
    let first = gathering(None);
    gathering(Some(&first))
}

/// The shorter side, in samples, from which the passes take every other
/// pixel. The rough reflections' pass on a frame of 160x120, on a grid
/// of 80x60, lost the lower discs' gradients (the anisotropy discs
/// against Cycles, 0.123 -> 0.137 FLIP), while at 700x700 the full
/// grid's filter doubled the CornellBox's frame; the bounce at 700x700
/// took 0.4-0.5 s more a frame on every pixel (one gathering), 0.2-0.3 s
/// on every other one (two gatherings).
const HALF_FROM: usize = 240;

/// The pixels of `gbuf` (`width` x `height`) a pass samples: every one,
/// or every other one in each direction where the shorter side has at
/// least twice `HALF_FROM`; those `keep` refuses are left empty. With the
/// grid's size, and whether it is the coarser one.
fn samples(
    gbuf: &[GPixel],
    (width, height): (u32, u32),
    keep: impl Fn(&GPixel) -> bool,
) -> (Vec<GPixel>, (u32, u32), bool) {
    let (w, h) = (width as usize, height as usize);
    let step = if w.min(h) >= 2 * HALF_FROM { 2 } else { 1 };
    let grid = (w.div_ceil(step), h.div_ceil(step));
    let points = (0..grid.0 * grid.1)
        .map(|i| {
            let g = &gbuf[(i / grid.0) * step * w + (i % grid.0) * step];
            if keep(g) { *g } else { GPixel::EMPTY }
        })
        .collect();
    (points, (grid.0 as u32, grid.1 as u32), step > 1)
}

/// The rough reflections' pass: at the pixels of `gbuf` (`width` x
/// `height`, sampled as `samples` does) whose material has one roughness
/// factor of at least `GLOSSY_FROM`, what `GLOSSY_RAYS` rays over its
/// lobe bring from the surfaces they meet and the share of the lobe
/// those hold (`Reflections::reflected_lobe`), filtered across the
/// surface as
/// the bounce is (a rough lobe's reflection changes slowly across the
/// surface); `view`: the unit vector from a point towards the eye. The
/// other pixels are left out of the filter and show nothing.
pub(super) fn glossy(
    setup: &DrawList,
    with: &Reflections,
    gbuf: &[GPixel],
    size: (u32, u32),
    (camera, view): ((Vec3, Vec3), &(dyn Fn(Vec3) -> Vec3 + Sync)),
) -> BounceScreen {
    let (rough, grid, _) = samples(gbuf, size, |g| g.roughness >= GLOSSY_FROM);
    let raw = per_pixel(&rough, grid.0, |g| {
        let normals = [g.geo_normal, g.normal, view(g.position)];
        with.reflected_lobe(g.position, normals, g.roughness)
    });
    let lobe = blurred(setup, &rough, grid, raw);
    let mut screen = screen(
        setup,
        &rough,
        grid,
        camera,
        lobe.iter().map(|v| v.truncate()).collect(),
    );
    screen.met_share = lobe.iter().map(|v| v.w).collect();
    screen.position = rough.iter().map(|g| g.position).collect();
    screen
}

/// `f` of every drawn pixel of `gbuf` (rows of `width`); (0, +inf)
/// elsewhere.
fn per_pixel<T: Copy + Default + Send>(
    gbuf: &[GPixel],
    width: u32,
    f: impl Fn(&GPixel) -> (T, f32) + Sync,
) -> Vec<(T, f32)> {
    let w = width as usize;
    let mut raw = vec![(T::default(), f32::INFINITY); gbuf.len()];
    raw.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let g = &gbuf[y * w + x];
            if g.depth.is_finite() {
                *o = f(g);
            }
        }
    });
    raw
}

/// The changes and reaches `raw` of the pixels of `gbuf`, filtered
/// (`TENT` at `STEPS`), as the screen shading reads them.
fn filtered(
    setup: &DrawList,
    gbuf: &[GPixel],
    size: (u32, u32),
    camera: (Vec3, Vec3),
    raw: Vec<(Vec3, f32)>,
) -> BounceScreen {
    let delta = blurred(setup, gbuf, size, raw);
    screen(setup, gbuf, size, camera, delta)
}

/// The values and reaches `raw` of the pixels of `gbuf`, filtered
/// (`TENT` at `STEPS`).
fn blurred<T: Blurred>(
    setup: &DrawList,
    gbuf: &[GPixel],
    (width, height): (u32, u32),
    raw: Vec<(T, f32)>,
) -> Vec<T> {
    let (values, reach): (Vec<T>, Vec<f32>) = raw.into_iter().unzip();
    let view = AoView::new(&setup.camera, width, height);
    STEPS.iter().fold(values, |d, &step| {
        edge_aware_blur(gbuf, &view, &d, (&TENT, step), Some(&reach), T::default())
    })
}

/// The screen the shading reads `delta` of the pixels of `gbuf` from.
fn screen(
    setup: &DrawList,
    gbuf: &[GPixel],
    (width, height): (u32, u32),
    (eye, forward): (Vec3, Vec3),
    delta: Vec<Vec3>,
) -> BounceScreen {
    BounceScreen {
        width: width as usize,
        height: height as usize,
        delta,
        depth: gbuf.iter().map(|g| g.depth).collect(),
        geo_normal: gbuf.iter().map(|g| g.geo_normal).collect(),
        position: Vec::new(),
        met_share: Vec::new(),
        clip_from_world: setup.clip_from_world,
        eye,
        forward,
    }
}

/// The `enclosed_share` from which a frame gathers bounced light where
/// the scene leaves `environment.bounces` unset. The CornellBox seen
/// through its open side measures 0.85, at 45 degrees (half its inside
/// seen, half an outer wall) 0.38-0.42, from behind 0; the Cycles set's
/// objects in the open 0 to 0.085 (FlightHelmet).
pub(super) const ENCLOSED_FROM: f32 = 0.25;

/// Camera rays per side of the grid `enclosed_share` casts (its shorter
/// side; the longer one in proportion).
const PROBE_GRID: u32 = 24;
/// Rays `enclosed_share` casts from each point a camera ray meets, and
/// how many of them must meet a surface for the point to count as
/// enclosed.
const PROBE_RAYS: u32 = 8;
const ENCLOSED_RAYS: u32 = 5;

/// How much of what the camera sees is enclosed: over a grid of camera
/// rays, the share of the points they meet from which at least
/// `ENCLOSED_RAYS` of `PROBE_RAYS` cosine-weighted rays (off the side
/// facing the camera) meet a surface. 0 where the camera sees nothing.
///
/// The mean share of hidden rays over all the points (the first
/// measure) called a box seen at 45 degrees open (0.34-0.36): a
/// turntable dropped the bounce there, and the box's floor went back to
/// the sky's colour between two frames that had it.
pub(super) fn enclosed_share(rays: &CameraRays, tracer: &Tracer, surfaces: &dyn Surfaces) -> f32 {
    let (w, h) = rays.size();
    let (gw, gh) = if w >= h {
        ((PROBE_GRID * w).div_ceil(h), PROBE_GRID)
    } else {
        (PROBE_GRID, (PROBE_GRID * h).div_ceil(w))
    };
    let (mut enclosed, mut seen) = (0u32, 0u32);
    for gy in 0..gh {
        for gx in 0..gw {
            let px = ((gx * 2 + 1) * w / (2 * gw)) as i32;
            let py = ((gy * 2 + 1) * h / (2 * gh)) as i32;
            let (o, d) = rays.ray(px, py);
            let Some(b) = tracer
                .nearest(o, d, f32::INFINITY)
                .and_then(|hit| surfaces.at(hit, o, d))
            else {
                continue;
            };
            let q = b.position + b.geometric * tracer.epsilon;
            let (shift, pair) = (
                position_hash(b.position),
                b.geometric.any_orthonormal_pair(),
            );
            let hidden = (0..PROBE_RAYS)
                .filter(|&i| {
                    let xi = point(i, PROBE_RAYS, shift);
                    let l = cosine_direction(b.geometric, pair, (xi.x, xi.y));
                    tracer.occluded(q, l, f32::INFINITY)
                })
                .count() as u32;
            seen += 1;
            enclosed += u32::from(hidden >= ENCLOSED_RAYS);
        }
    }
    if seen == 0 {
        0.0
    } else {
        enclosed as f32 / seen as f32
    }
}
