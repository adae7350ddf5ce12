//! The shadow pass of one frame: for each light with `shadows = true`, a
//! depth map rendered from the light over this frame's geometry (the
//! models as turned for this frame), or, for `render.shadows = "raytraced"`,
//! the scene's BVH. No pass at all when no light casts shadows.
//!
//! Fitting: a directional light's orthographic map covers the bounds of all
//! vertices in light space; a spot light's perspective map covers its outer
//! cone; a point light gets six 90-degree faces. Every map is padded by two
//! texels so the PCF footprint at its border reads real depths. Shadow maps
//! draw both faces of every triangle, with opaque depth (alpha-tested and
//! blended materials cast full shadows).
//!
//! A flat model (every vertex on one plane) with the light on one side of
//! it and every other model on that side too (a floor under the models)
//! can darken only points beyond its plane, where there are none: it is
//! left out of that light's map (the map's fit still covers it). That
//! saves rasterizing the floor over the whole map each frame, and the
//! floor's depths no longer reach, through the PCF footprint, into the
//! shadow tests of points that touch it.

use crate::bigbuf::BigBuf;
use std::sync::{Arc, Mutex};

use glam::{Mat4, Vec3, Vec4};
use rayon::prelude::*;

use super::draw_list::DrawList;
use super::vertex::ModelVertices;
use crate::raster::bin::{TileGrid, bin};
use crate::raster::clip::{ClipVertex, Clipped, clip_triangle};
use crate::raster::coverage::raster_depth_max;
use crate::raster::setup::{Tri, Viewport, setup};
use crate::raytrace::Tracer;
use crate::scene::light::{Light, LightKind};
use crate::scene::settings::{CullMode, ShadowMethod};
use crate::shade::shadow::{
    DRAWN_TILE, Drawn, Filter, LightShadow, MapProjection, OrthoBox, ShadowMap, Shadows,
};

const CHUNK: usize = 4096;

// A map's band of rows is one row of its `Drawn` tiles.
const _: () = assert!(crate::raster::bin::BAND_ROWS as usize == DRAWN_TILE);

/// The depth buffer of an earlier frame's map, drawn into again: 0 but
/// in the tiles `drawn` marks.
pub(super) struct Spare {
    depth: BigBuf<f32>,
    drawn: Drawn,
}

impl Spare {
    /// `m`'s buffer and marks (`m` keeps empty ones).
    fn take(m: &mut ShadowMap) -> Spare {
        Spare {
            depth: std::mem::take(&mut m.depth),
            drawn: std::mem::take(&mut m.drawn),
        }
    }
}

/// One model's world-space vertices and triangles this frame, and
/// whether it goes into the light's map (`casts_nothing`).
#[derive(Clone, Copy)]
struct Geo<'g> {
    world: &'g [Vec3],
    triangles: &'g [[u32; 3]],
    casts: bool,
}

/// The shadow maps of the last frame rendered, with what they depend on:
/// a frame whose lights and model placements are the same (a turntable
/// that turns the camera, or a still scene) reuses them instead of
/// rendering them again.
#[derive(Default)]
pub(super) struct MapCache {
    last: Mutex<Option<(MapKey, Arc<[LightShadow]>)>>,
}

#[derive(PartialEq)]
struct MapKey {
    lights: Vec<Light>,
    world_from_object: Vec<Mat4>,
    /// The clip time of each posed model.
    poses: Vec<Option<f32>>,
    method: ShadowMethod,
    size: u32,
}

/// The frame's shadows. `tracer`: the frame's ray tracer, which
/// `render.shadows = "raytraced"` tests against. `cache`: the maps of the
/// renderer's last frame.
pub(super) fn shadows<'a>(
    setup: &DrawList,
    mv: &[ModelVertices],
    tracer: Option<&'a Tracer<'a>>,
    cache: &MapCache,
) -> Shadows<'a> {
    let s = &setup.scene.settings;
    if s.shadows == ShadowMethod::Off || !setup.lights.iter().any(|l| l.shadows) {
        return Shadows::none();
    }
    let filter = if s.shadows == ShadowMethod::Hard {
        Filter::Hard
    } else {
        Filter::Pcf
    };
    let mut out = Shadows {
        lights: Arc::new([]),
        filter,
        bias: s.shadow_bias,
        tracer: None,
    };
    if s.shadows == ShadowMethod::Raytraced {
        out.tracer = tracer;
        out.lights = light_shadows(setup, mv, &mut Vec::new()).into();
        return out;
    }
    let key = MapKey {
        lights: setup.lights.clone(),
        world_from_object: setup.world_from_object.clone(),
        poses: setup
            .posed
            .iter()
            .map(|p| p.as_ref().map(|p| p.1))
            .collect(),
        method: s.shadows,
        size: s.shadow_map_size,
    };
    // A poisoned lock only means another frame panicked: the cache holds
    // whole values, so it is still consistent.
    let cached = {
        let last = cache.last.lock().unwrap_or_else(|e| e.into_inner());
        last.as_ref()
            .filter(|(k, _)| *k == key)
            .map(|(_, maps)| maps.clone())
    };
    out.lights = match cached {
        Some(maps) => maps,
        None => {
            // The last maps' depth buffers, where no other frame holds
            // them, are drawn into again (a fresh 16 MB buffer per 2048
            // map costs its page faults, which the threads take in turn).
            let mut spare = Vec::new();
            if let Some((_, mut old)) = cache.last.lock().unwrap_or_else(|e| e.into_inner()).take()
                && let Some(old) = Arc::get_mut(&mut old)
            {
                for ls in old.iter_mut() {
                    match ls {
                        LightShadow::Map(m) => spare.push(Spare::take(m)),
                        LightShadow::Cube { faces, .. } => {
                            spare.extend(faces.iter_mut().map(Spare::take))
                        }
                        LightShadow::None | LightShadow::Ray { .. } | LightShadow::Disc { .. } => {}
                    }
                }
            }
            let maps: Arc<[LightShadow]> = light_shadows(setup, mv, &mut spare).into();
            *cache.last.lock().unwrap_or_else(|e| e.into_inner()) = Some((key, maps.clone()));
            maps
        }
    };
    out
}

/// Each light's shadow: its map(s), rays, or none. Maps draw into the
/// buffers of `spare` where they fit.
fn light_shadows(
    setup: &DrawList,
    mv: &[ModelVertices],
    spare: &mut Vec<Spare>,
) -> Vec<LightShadow> {
    let s = &setup.scene.settings;
    let mut out = Vec::with_capacity(setup.lights.len());
    let size = s.shadow_map_size;
    let verts: Vec<Geo> = mv
        .iter()
        .zip(&setup.scene.models)
        .map(|(v, m)| Geo {
            world: &v.world,
            triangles: &m.mesh.triangles,
            casts: true,
        })
        .collect();
    let eps = 1e-5 * setup.scene.bounds_radius.max(f32::MIN_POSITIVE);
    let planes: Vec<Option<Plane>> = verts.iter().map(|g| plane_of(g, eps)).collect();
    for light in &setup.lights {
        let mut verts = verts.clone();
        for (k, plane) in planes.iter().enumerate() {
            if let Some(plane) = plane {
                verts[k].casts = !casts_nothing(&verts, k, *plane, &light.kind, eps);
            }
        }
        let verts = verts.as_slice();
        let ls = if !light.shadows {
            LightShadow::None
        } else if s.shadows == ShadowMethod::Raytraced {
            match light.kind {
                LightKind::Directional { angle, .. } => LightShadow::Ray {
                    position: None,
                    cone: angle,
                },
                LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
                    LightShadow::Ray {
                        position: Some(position),
                        cone: 0.0,
                    }
                }
                LightKind::Area {
                    position,
                    axis,
                    radius,
                    ..
                } => LightShadow::Disc {
                    center: position,
                    axis,
                    radius,
                },
            }
        } else {
            match light.kind {
                LightKind::Directional { direction, .. } => {
                    directional(verts, direction, size, spare)
                }
                LightKind::Spot {
                    position,
                    direction,
                    cos_outer,
                    ..
                } => spot(verts, position, direction, cos_outer, size, spare),
                LightKind::Point { position, .. } | LightKind::Area { position, .. } => {
                    point(verts, position, size, spare)
                }
            }
        };
        out.push(ls);
    }
    out
}

/// A plane: unit normal n and offset d, n.p = d on it.
#[derive(Clone, Copy)]
struct Plane {
    n: Vec3,
    d: f32,
}

/// The plane of a model whose vertices all lie within `eps` of one
/// (normal from the largest of its first 16 triangles); None for any
/// other model, or one without a triangle of non-zero area.
fn plane_of(g: &Geo, eps: f32) -> Option<Plane> {
    let corner = |i: u32| g.world.get(i as usize).copied();
    let mut best: Option<(Vec3, f32, Vec3)> = None;
    for t in g.triangles.iter().take(16) {
        let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) else {
            continue;
        };
        let n = (b - a).cross(c - a);
        let len = n.length();
        if len.is_finite() && len > 0.0 && best.is_none_or(|(_, l, _)| len > l) {
            best = Some((n / len, len, a));
        }
    }
    let (n, _, a) = best?;
    let d = n.dot(a);
    // A NaN distance is off the plane too.
    let off = |p: &Vec3| {
        let e = (n.dot(*p) - d).abs();
        e.is_nan() || e > eps
    };
    if g.world.iter().any(off) {
        return None;
    }
    Some(Plane { n, d })
}

/// Whether the flat model `k` (on `plane`) can shadow nothing under
/// `light`: the light lies off the plane on one side, and every vertex of
/// every other model on that side (or within `eps` of the plane). A
/// shadow ray leaves the light, passes the plane once and darkens only
/// what lies beyond it.
fn casts_nothing(verts: &[Geo], k: usize, plane: Plane, light: &LightKind, eps: f32) -> bool {
    let side = match *light {
        LightKind::Directional { direction, .. } => {
            // Toward the light is -direction; it must not graze the plane.
            let s = -plane.n.dot(direction);
            if s.is_nan() || s.abs() <= 1e-6 {
                return false;
            }
            s
        }
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
            let s = plane.n.dot(position) - plane.d;
            if s.is_nan() || s.abs() <= eps {
                return false;
            }
            s
        }
        // A disc: the plane must clear all of it.
        LightKind::Area {
            position, radius, ..
        } => {
            let s = plane.n.dot(position) - plane.d;
            if s.is_nan() || s.abs() <= eps.max(radius) {
                return false;
            }
            s
        }
    };
    let (n, d) = if side > 0.0 {
        (plane.n, plane.d)
    } else {
        (-plane.n, -plane.d)
    };
    verts
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != k)
        .all(|(_, g)| g.world.iter().all(|p| n.dot(*p) - d >= -eps))
}

/// A view matrix at `eye` looking along `dir` (unit).
fn look(eye: Vec3, dir: Vec3) -> Mat4 {
    let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let s = dir.cross(up).normalize();
    let u = s.cross(dir);
    Mat4::from_cols(
        Vec4::new(s.x, u.x, -dir.x, 0.0),
        Vec4::new(s.y, u.y, -dir.y, 0.0),
        Vec4::new(s.z, u.z, -dir.z, 0.0),
        Vec4::new(-s.dot(eye), -u.dot(eye), dir.dot(eye), 1.0),
    )
}

fn directional(verts: &[Geo], direction: Vec3, size: u32, spare: &mut Vec<Spare>) -> LightShadow {
    let view = look(Vec3::ZERO, direction);
    let (lo, hi) = verts
        .par_iter()
        .flat_map(|m| m.world.par_iter())
        .map(|p| {
            let q = view.transform_point3(*p);
            (q, q)
        })
        .reduce(
            || (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    if !(lo.is_finite() && hi.is_finite()) {
        return LightShadow::None;
    }
    let ext = (hi - lo).max(Vec3::splat(1e-6));
    let pad = ext.x.max(ext.y) * 2.0 / size as f32;
    // Square texels: the longer side sets the texel size.
    let side = ext.x.max(ext.y) + 2.0 * pad;
    let (cx, cy) = ((lo.x + hi.x) * 0.5, (lo.y + hi.y) * 0.5);
    let dz = ext.z * 0.01 + pad;
    let projection = MapProjection::Ortho(OrthoBox {
        x0: cx - side * 0.5,
        x1: cx + side * 0.5,
        y0: cy - side * 0.5,
        y1: cy + side * 0.5,
        // Distance is -z in view space.
        near: -hi.z - dz,
        far: -lo.z + dz,
    });
    LightShadow::Map(render_map(verts, view, projection, size, spare))
}

/// Nearest and farthest distance of any vertex from `position`.
fn distance_range(verts: &[Geo], position: Vec3) -> (f32, f32) {
    verts
        .par_iter()
        .flat_map(|m| m.world.par_iter())
        .map(|p| {
            let d = p.distance(position);
            (d, d)
        })
        .reduce(
            || (f32::INFINITY, 0.0f32),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        )
}

/// Near plane: closer than any vertex can be along a face's axis.
fn near_plane(verts: &[Geo], position: Vec3) -> Option<f32> {
    let (lo, hi) = distance_range(verts, position);
    (hi > 0.0 && hi.is_finite()).then(|| (lo * 0.25).max(hi * 1e-5))
}

fn spot(
    verts: &[Geo],
    position: Vec3,
    direction: Vec3,
    cos_outer: f32,
    size: u32,
    spare: &mut Vec<Spare>,
) -> LightShadow {
    let Some(near) = near_plane(verts, position) else {
        return LightShadow::None;
    };
    let half = cos_outer.clamp(-1.0, 1.0).acos().min(85f32.to_radians());
    let tan_half = half.tan() * (1.0 + 4.0 / size as f32);
    let projection = MapProjection::Perspective { tan_half, near };
    LightShadow::Map(render_map(
        verts,
        look(position, direction),
        projection,
        size,
        spare,
    ))
}

fn point(verts: &[Geo], position: Vec3, size: u32, spare: &mut Vec<Spare>) -> LightShadow {
    let Some(near) = near_plane(verts, position) else {
        return LightShadow::None;
    };
    // 90 degrees plus two texels on each side.
    let projection = MapProjection::Perspective {
        tan_half: 1.0 + 4.0 / size as f32,
        near,
    };
    let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]
        .map(|d| render_map(verts, look(position, d), projection, size, spare));
    LightShadow::Cube {
        position,
        faces: Box::new(faces),
    }
}

/// Rasterizes every triangle's depth (reverse-Z, nearest wins) into a
/// `size` x `size` map: clip, set up and bin in parallel chunks, then each
/// band of rows clears its rows and depth-tests its triangles in
/// submission order. The map's buffer is one of `spare` when one fits.
fn render_map(
    verts: &[Geo],
    view_from_world: Mat4,
    projection: MapProjection,
    size: u32,
    spare: &mut Vec<Spare>,
) -> ShadowMap {
    let clip_from_world = projection.clip_from_view() * view_from_world;
    let vp = Viewport {
        width: size,
        height: size,
        msaa: false,
    };
    let (gx, gy) = vp.guard_band();
    let grid = TileGrid::bands(size, size);
    let mut chunks = Vec::new();
    for (mi, m) in verts.iter().enumerate() {
        if !m.casts {
            continue;
        }
        let n = m.triangles.len();
        for start in (0..n).step_by(CHUNK) {
            chunks.push((mi, start, (start + CHUNK).min(n)));
        }
    }
    let clip: Vec<Vec<Vec4>> = verts
        .par_iter()
        .map(|m| {
            m.world
                .iter()
                .map(|p| clip_from_world * p.extend(1.0))
                .collect()
        })
        .collect();
    let per_chunk: Vec<(Vec<Tri>, Vec<Vec<u32>>)> = chunks
        .par_iter()
        .map(|&(mi, start, end)| {
            let c = &clip[mi];
            let mut tris = Vec::with_capacity(end - start);
            for idx in &verts[mi].triangles[start..end] {
                let v = idx.map(|i| c[i as usize]);
                let base = |k: usize| ClipVertex {
                    pos: v[k],
                    bary: Vec3::ZERO,
                };
                match clip_triangle(v, gx, gy) {
                    Clipped::Rejected => {}
                    Clipped::Inside => {
                        tris.extend(setup([base(0), base(1), base(2)], vp, CullMode::None, 0, 0))
                    }
                    Clipped::Polygon(p) => {
                        let p = p.as_slice();
                        for k in 1..p.len() - 1 {
                            tris.extend(setup([p[0], p[k], p[k + 1]], vp, CullMode::None, 0, 0));
                        }
                    }
                }
            }
            let bins = bin(&tris, &grid, false);
            (tris, bins)
        })
        .collect();
    let texels = size as usize * size as usize;
    // A spare buffer is 0 but for the tiles its map drew into (all of
    // them where its marks do not fit this size).
    let (mut depth, old) = match spare.iter().position(|d| d.depth.len() == texels) {
        Some(k) => {
            let s = spare.swap_remove(k);
            let drawn = if s.drawn.fits(size) {
                s.drawn
            } else {
                Drawn::all(size)
            };
            (s.depth, Some(drawn))
        }
        None => (BigBuf::zeroed(texels), None),
    };
    let band = (grid.tile_w * grid.tile_h) as usize;
    let mut drawn = Drawn::none(size);
    depth
        .par_chunks_mut(band)
        .zip(drawn.rows_mut().collect::<Vec<_>>())
        .enumerate()
        .for_each(|(ti, (d, marks))| {
            let rect = grid.rect(ti);
            let stride = rect.width();
            if let Some(old) = &old {
                for cols in old.columns(ti) {
                    let cols = cols.start.min(stride)..cols.end.min(stride);
                    for row in d.chunks_exact_mut(stride) {
                        row[cols.clone()].fill(0.0);
                    }
                }
            }
            for (tris, bins) in &per_chunk {
                for &i in &bins[ti] {
                    let t = &tris[i as usize];
                    let (x0, x1) = (t.min_x.max(rect.x0), t.max_x.min(rect.x1 - 1));
                    if x0 <= x1 {
                        Drawn::mark(marks, (x0 - rect.x0) as usize, (x1 - rect.x0) as usize);
                    }
                    raster_depth_max(t, rect, d, stride);
                }
            }
        });
    ShadowMap {
        size,
        view_from_world,
        projection,
        depth,
        drawn,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geo<'g>(world: &'g [Vec3], triangles: &'g [[u32; 3]]) -> Geo<'g> {
        Geo {
            world,
            triangles,
            casts: true,
        }
    }

    const QUAD: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];

    fn quad(y: f32, half: f32) -> [Vec3; 4] {
        [
            Vec3::new(-half, y, -half),
            Vec3::new(half, y, -half),
            Vec3::new(half, y, half),
            Vec3::new(-half, y, half),
        ]
    }

    fn sun(direction: Vec3) -> LightKind {
        LightKind::Directional {
            direction: direction.normalize(),
            irradiance: 1.0,
            angle: 0.0,
        }
    }

    fn lamp(position: Vec3) -> LightKind {
        LightKind::Point {
            position,
            intensity: 1.0,
        }
    }

    #[test]
    fn a_floor_under_everything_casts_nothing_and_only_then() {
        let eps = 1e-5;
        let floor = quad(0.0, 4.0);
        // A tetrahedron standing on the floor (one corner touching it).
        let tet = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.5),
            Vec3::new(0.0, 2.0, -1.0),
        ];
        let tet_tris = [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]];
        let verts = [geo(&floor, &QUAD), geo(&tet, &tet_tris)];
        let plane = plane_of(&verts[0], eps).expect("the floor is flat");
        assert!(plane_of(&verts[1], eps).is_none(), "a tetrahedron is not");
        let from_above = sun(Vec3::new(0.3, -1.0, 0.2));
        assert!(casts_nothing(&verts, 0, plane, &from_above, eps));
        // Lit from below, the floor shadows the model.
        let from_below = sun(Vec3::new(0.3, 1.0, 0.2));
        assert!(!casts_nothing(&verts, 0, plane, &from_below, eps));
        // A light grazing the plane, or a lamp in it: kept.
        assert!(!casts_nothing(&verts, 0, plane, &sun(Vec3::X), eps));
        assert!(!casts_nothing(
            &verts,
            0,
            plane,
            &lamp(Vec3::new(9.0, 0.0, 0.0)),
            eps
        ));
        assert!(casts_nothing(
            &verts,
            0,
            plane,
            &lamp(Vec3::new(0.0, 5.0, 0.0)),
            eps
        ));
        assert!(!casts_nothing(
            &verts,
            0,
            plane,
            &lamp(Vec3::new(0.0, -5.0, 0.0)),
            eps
        ));

        // A model reaching below the floor keeps it in the map.
        let sunk = tet.map(|p| p - Vec3::new(0.0, 0.5, 0.0));
        let verts = [geo(&floor, &QUAD), geo(&sunk, &tet_tris)];
        assert!(!casts_nothing(&verts, 0, plane, &from_above, eps));

        // A floor above another flat model shadows it; the lower one,
        // with everything on its lit side, casts nothing.
        let lower = quad(-1.0, 8.0);
        let verts = [geo(&floor, &QUAD), geo(&lower, &QUAD)];
        let lower_plane = plane_of(&verts[1], eps).expect("flat");
        assert!(!casts_nothing(&verts, 0, plane, &from_above, eps));
        assert!(casts_nothing(&verts, 1, lower_plane, &from_above, eps));

        // Coplanar tiles cannot shadow each other.
        let tile = quad(0.0, 1.0).map(|p| p + Vec3::new(10.0, 0.0, 0.0));
        let verts = [geo(&floor, &QUAD), geo(&tile, &QUAD)];
        assert!(casts_nothing(&verts, 0, plane, &from_above, eps));
    }

    #[test]
    fn flatness_is_checked_at_every_vertex() {
        let eps = 1e-5;
        let mut bent = quad(0.0, 1.0).to_vec();
        bent.push(Vec3::new(0.5, 1e-3, 0.5));
        let tris = [[0, 1, 2], [0, 2, 3], [2, 3, 4]];
        assert!(plane_of(&geo(&bent, &tris), eps).is_none());
        bent[4].y = 1e-7;
        assert!(plane_of(&geo(&bent, &tris), eps).is_some());
        bent[4].y = f32::NAN;
        assert!(plane_of(&geo(&bent, &tris), eps).is_none());
        // No triangle of any area.
        let line = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        assert!(plane_of(&geo(&line, &[[0, 1, 2]]), eps).is_none());
        assert!(plane_of(&geo(&line, &[[0, 1, 7]]), eps).is_none());
    }
}

#[cfg(test)]
mod drawn_tests {
    use super::*;

    /// A small square (a caster) at (cx, cz), 2 units above a floor that
    /// does not cast, under a sun from straight above.
    fn caster(cx: f32, cz: f32) -> Vec<Vec3> {
        let h = 0.3;
        let mut v = vec![
            Vec3::new(-4.0, 0.0, -4.0),
            Vec3::new(4.0, 0.0, -4.0),
            Vec3::new(4.0, 0.0, 4.0),
            Vec3::new(-4.0, 0.0, 4.0),
        ];
        v.extend([
            Vec3::new(cx - h, 2.0, cz - h),
            Vec3::new(cx + h, 2.0, cz - h),
            Vec3::new(cx + h, 2.0, cz + h),
            Vec3::new(cx - h, 2.0, cz + h),
        ]);
        v
    }

    fn map_of(world: &[Vec3], spare: &mut Vec<Spare>) -> ShadowMap {
        let tris = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        let floor = [[0u32, 1, 2], [0, 2, 3]];
        let verts = [
            Geo {
                world,
                triangles: &floor,
                casts: false,
            },
            Geo {
                world,
                triangles: &tris[2..],
                casts: true,
            },
        ];
        match directional(&verts, Vec3::new(0.0, -1.0, 0.0), 256, spare) {
            LightShadow::Map(m) => m,
            _ => panic!("a directional light over finite geometry has a map"),
        }
    }

    /// Every texel of a tile the marks leave clear is 0, and something
    /// was drawn (so the test can fail).
    fn check_marks(m: &ShadowMap) {
        let n = m.size as usize;
        let mut drawn = 0;
        for y in 0..n {
            for x in 0..n {
                let d = m.depth[y * n + x];
                if d != 0.0 {
                    drawn += 1;
                    assert!(
                        m.drawn.tile(x / DRAWN_TILE, y / DRAWN_TILE),
                        "texel {x} {y} holds {d} in a tile marked clear"
                    );
                }
            }
        }
        assert!(drawn > 100, "the caster drew {drawn} texels");
    }

    #[test]
    fn marks_cover_every_drawn_texel_and_a_reused_buffer_equals_a_fresh_one() {
        let mut spare = Vec::new();
        let mut first = map_of(&caster(-2.0, -2.5), &mut spare);
        check_marks(&first);
        // The caster moves across the map: drawn into the first map's
        // buffer, whose old tiles are cleared, the map equals one drawn
        // into a new buffer (0 where the first caster stood).
        spare.push(Spare::take(&mut first));
        let moved = caster(2.5, 1.0);
        let reused = map_of(&moved, &mut spare);
        assert!(spare.is_empty(), "the spare buffer was used");
        let fresh = map_of(&moved, &mut Vec::new());
        check_marks(&reused);
        assert_eq!(&reused.depth[..], &fresh.depth[..]);
        // A spare whose marks say nothing is cleared whole.
        let mut stale = map_of(&caster(-2.0, -2.5), &mut Vec::new());
        stale.drawn = Drawn::default();
        let mut spare = vec![Spare::take(&mut stale)];
        let again = map_of(&moved, &mut spare);
        assert_eq!(&again.depth[..], &fresh.depth[..]);
    }
}
