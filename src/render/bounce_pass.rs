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
use crate::shade::ao::{AoView, GPixel, edge_aware_blur};
use crate::shade::env::reflect::{BounceScreen, GLOSSY_FROM, Reflections};

/// The filter's weights along each axis, and the steps of its passes in
/// pixels: 36 taps a pixel, 31 pixels wide (the CornellBox under the
/// studio HDRI against Cycles: 0.0999 FLIP, as with a 5x5 tent at steps
/// 1, 2 and 4, at half the taps).
const TENT: [f32; 3] = [1.0, 2.0, 1.0];
const STEPS: [i32; 4] = [1, 2, 4, 8];

/// The bounce of every pixel of `gbuf` (`width` x `height`), gathered by
/// `with` and filtered; `(eye, forward)`: the camera's position and unit
/// view axis.
pub(super) fn bounce(
    setup: &DrawList,
    with: &Reflections,
    gbuf: &[GPixel],
    size: (u32, u32),
    camera: (Vec3, Vec3),
) -> BounceScreen {
    let raw = per_pixel(gbuf, size.0, |g| {
        with.gathered_change(g.position, g.geo_normal, g.normal)
    });
    filtered(setup, gbuf, size, camera, raw)
}

/// The shorter side, in samples, from which the rough reflections' pass
/// takes every other pixel: a frame of 160x120 on a grid of 80x60 lost
/// the lower discs' gradients (the anisotropy discs against Cycles,
/// 0.123 -> 0.137 FLIP), while at 700x700 the full grid's filter
/// doubled the CornellBox's frame.
const GLOSSY_HALF_FROM: usize = 240;

/// The rough reflections' pass: at the pixels of `gbuf` (`width` x
/// `height`) whose material has one roughness factor of at least
/// `GLOSSY_FROM` (every other one in each direction where the frame's
/// shorter side has at least twice `GLOSSY_HALF_FROM` pixels), what
/// `GLOSSY_RAYS` rays over its lobe change in the prefiltered light
/// (`Reflections::reflected_change`), filtered across the surface as
/// the bounce is (a rough lobe's reflection changes slowly across the
/// surface); `view`: the unit vector from a point towards the eye. The
/// other pixels are left out of the filter and show nothing.
pub(super) fn glossy(
    setup: &DrawList,
    with: &Reflections,
    gbuf: &[GPixel],
    (width, height): (u32, u32),
    (camera, view): ((Vec3, Vec3), &(dyn Fn(Vec3) -> Vec3 + Sync)),
) -> BounceScreen {
    let (w, h) = (width as usize, height as usize);
    let step = if w.min(h) >= 2 * GLOSSY_HALF_FROM {
        2
    } else {
        1
    };
    let half = (w.div_ceil(step), h.div_ceil(step));
    let rough: Vec<GPixel> = (0..half.0 * half.1)
        .map(|i| {
            let g = &gbuf[(i / half.0) * step * w + (i % half.0) * step];
            if g.roughness >= GLOSSY_FROM {
                *g
            } else {
                GPixel::EMPTY
            }
        })
        .collect();
    let raw = per_pixel(&rough, half.0 as u32, |g| {
        let normals = [g.geo_normal, g.normal, view(g.position)];
        with.reflected_change(g.position, normals, g.roughness)
    });
    let size = (half.0 as u32, half.1 as u32);
    let mut screen = filtered(setup, &rough, size, camera, raw);
    screen.position = rough.iter().map(|g| g.position).collect();
    screen
}

/// `f` of every drawn pixel of `gbuf` (rows of `width`); (0, +inf)
/// elsewhere.
fn per_pixel(
    gbuf: &[GPixel],
    width: u32,
    f: impl Fn(&GPixel) -> (Vec3, f32) + Sync,
) -> Vec<(Vec3, f32)> {
    let w = width as usize;
    let mut raw = vec![(Vec3::ZERO, f32::INFINITY); gbuf.len()];
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
    (width, height): (u32, u32),
    (eye, forward): (Vec3, Vec3),
    raw: Vec<(Vec3, f32)>,
) -> BounceScreen {
    let (delta, reach): (Vec<Vec3>, Vec<f32>) = raw.into_iter().unzip();
    let view = AoView::new(&setup.camera, width, height);
    let delta = STEPS.iter().fold(delta, |d, &step| {
        edge_aware_blur(gbuf, &view, &d, (&TENT, step), Some(&reach), Vec3::ZERO)
    });
    BounceScreen {
        width: width as usize,
        height: height as usize,
        delta,
        depth: gbuf.iter().map(|g| g.depth).collect(),
        geo_normal: gbuf.iter().map(|g| g.geo_normal).collect(),
        position: Vec::new(),
        clip_from_world: setup.clip_from_world,
        eye,
        forward,
    }
}
