//! The points-and-lines pass: OBJ `p`/`l` and glTF point and line
//! primitives, drawn after the triangles as screen-space discs
//! (`render.point_size` output pixels across) and anti-aliased lines
//! (`render.line_width` wide), depth-tested against the triangles' depth
//! at each pixel center and composited over the frame. They are unlit:
//! their colour is the material's diffuse (Kd, or glTF's base colour)
//! times the vertex colour. Coverage is the box-filtered distance to the
//! segment (clamp(w/2 + 0.5 - d, 0, 1)), as for the wireframe view.
//! Primitives are drawn in file order, so frames are deterministic.

use glam::{Mat4, Vec2, Vec3, Vec4};

use super::draw_list::DrawList;
use super::frame::Frame;
use super::vertex::ModelVertices;

/// A projected end of a segment (or a point): screen position, 1/w and
/// view depth / w (their ratio, interpolated linearly on screen, is the
/// view depth at any pixel, perspective or orthographic).
#[derive(Clone, Copy)]
struct End {
    s: Vec2,
    inv_w: f32,
    depth_w: f32,
    color: Vec3,
}

/// Lines drawn on a surface pass the depth test within this relative
/// distance (a polygon offset for lines and points).
const DEPTH_SLACK: f32 = 2e-3;

/// Whether some model of the scene has lines or points to draw.
pub(super) fn any(setup: &DrawList) -> bool {
    setup
        .scene
        .models
        .iter()
        .any(|m| !m.mesh.lines.is_empty() || !m.mesh.points.is_empty())
}

pub(super) fn draw(setup: &DrawList, verts: &[ModelVertices], pixel_scale: f32, out: &mut Frame) {
    let s = &setup.scene.settings;
    let view = setup.camera.view_from_world();
    let near = setup.camera.near;
    let half_line = 0.5 * s.line_width * pixel_scale;
    let radius = 0.5 * s.point_size * pixel_scale;
    for (m, mv) in setup.scene.models.iter().zip(verts) {
        let mesh = &m.mesh;
        if mesh.lines.is_empty() && mesh.points.is_empty() {
            continue;
        }
        let color = |v: u32, material: usize| {
            let c = mesh.colors.get(v as usize).copied().unwrap_or(Vec4::ONE);
            m.materials[material].diffuse_color() * c.truncate()
        };
        for l in &mesh.lines {
            let [a, b] = l.vertices.map(|v| v as usize);
            let (pa, pb) = (mv.world[a], mv.world[b]);
            let (ca, cb) = (
                color(l.vertices[0], l.material),
                color(l.vertices[1], l.material),
            );
            let (da, db) = (-view.transform_point3(pa).z, -view.transform_point3(pb).z);
            if !(da.is_finite() && db.is_finite()) || (da < near && db < near) {
                continue;
            }
            // Clip to the near plane in world space.
            let cut = |p: Vec3, d: f32, q: Vec3, e: f32| {
                if d >= near {
                    (p, d)
                } else {
                    let t = (near - d) / (e - d);
                    (p + (q - p) * t, near)
                }
            };
            let ((pa, da), (pb, db)) = (cut(pa, da, pb, db), cut(pb, db, pa, da));
            let (Some(ea), Some(eb)) = (
                project(setup.clip_from_world, pa, da, ca, out),
                project(setup.clip_from_world, pb, db, cb, out),
            ) else {
                continue;
            };
            segment(ea, eb, half_line, out);
        }
        for p in &mesh.points {
            let v = p.vertices[0];
            let w = mv.world[v as usize];
            let d = -view.transform_point3(w).z;
            if d.is_nan() || d < near {
                continue;
            }
            if let Some(e) = project(setup.clip_from_world, w, d, color(v, p.material), out) {
                disc(e, radius, out);
            }
        }
    }
}

fn project(clip_from_world: Mat4, p: Vec3, depth: f32, color: Vec3, out: &Frame) -> Option<End> {
    let c = clip_from_world * p.extend(1.0);
    let inv_w = 1.0 / c.w;
    let s = Vec2::new(
        (c.x * inv_w * 0.5 + 0.5) * out.width as f32,
        (0.5 - c.y * inv_w * 0.5) * out.height as f32,
    );
    (inv_w.is_finite() && s.is_finite() && depth.is_finite()).then_some(End {
        s,
        inv_w,
        depth_w: depth * inv_w,
        color,
    })
}

impl End {
    fn lerp(self, o: End, t: f32) -> End {
        End {
            s: self.s + (o.s - self.s) * t,
            inv_w: self.inv_w + (o.inv_w - self.inv_w) * t,
            depth_w: self.depth_w + (o.depth_w - self.depth_w) * t,
            color: self.color + (o.color - self.color) * t,
        }
    }
}

/// The part of segment a-b inside the frame grown by `pad` pixels
/// (Liang-Barsky), None when it misses it. Everything interpolated is
/// linear on screen, so the cut ends are exact.
fn clip_to_frame(a: End, b: End, pad: f32, out: &Frame) -> Option<(End, End)> {
    let d = b.s - a.s;
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    let (w, h) = (out.width as f32, out.height as f32);
    for (p, q) in [
        (-d.x, a.s.x + pad),
        (d.x, w + pad - a.s.x),
        (-d.y, a.s.y + pad),
        (d.y, h + pad - a.s.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1 && t0.is_finite() && t1.is_finite()).then(|| (a.lerp(b, t0), a.lerp(b, t1)))
}

/// Blends `color` with coverage `cov` over pixel (x, y) when `depth` is
/// not behind what is there.
fn blend(out: &mut Frame, x: i64, y: i64, cov: f32, depth: f32, color: Vec3) {
    if cov <= 0.0 || x < 0 || y < 0 || x >= out.width as i64 || y >= out.height as i64 {
        return;
    }
    let i = y as usize * out.width as usize + x as usize;
    let there = out.depth[i];
    // (NaN depths fail too.)
    if depth.is_nan() || depth > there * (1.0 + DEPTH_SLACK) {
        return;
    }
    let c = &mut out.color[i];
    *c = color.extend(1.0) * cov + *c * (1.0 - cov);
    if depth < there {
        out.depth[i] = depth;
    }
}

fn segment(a: End, b: End, half: f32, out: &mut Frame) {
    let Some((a, b)) = clip_to_frame(a, b, half + 2.0, out) else {
        return;
    };
    let d = b.s - a.s;
    let len2 = d.length_squared();
    let reach = half + 1.0;
    // Step along the major axis; cover the minor axis around the line.
    let major_x = d.x.abs() >= d.y.abs();
    let (lo, hi) = if major_x {
        (a.s.x.min(b.s.x), a.s.x.max(b.s.x))
    } else {
        (a.s.y.min(b.s.y), a.s.y.max(b.s.y))
    };
    let slope = if major_x {
        if d.x != 0.0 { d.y / d.x } else { 0.0 }
    } else if d.y != 0.0 {
        d.x / d.y
    } else {
        0.0
    };
    let spread = reach * (1.0 + slope * slope).sqrt() + 1.0;
    let (first, last) = ((lo - reach).floor() as i64, (hi + reach).ceil() as i64);
    let size = if major_x { out.width } else { out.height } as i64;
    for m in first.max(0)..=last.min(size - 1) {
        let center = m as f32 + 0.5;
        let (start, minor0) = if major_x {
            (a.s.x, a.s.y)
        } else {
            (a.s.y, a.s.x)
        };
        let minor = minor0 + (center - start) * slope;
        for n in (minor - spread).floor() as i64..=(minor + spread).ceil() as i64 {
            let (x, y) = if major_x { (m, n) } else { (n, m) };
            let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let t = if len2 > 0.0 {
                ((q - a.s).dot(d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let dist = (q - (a.s + d * t)).length();
            let cov = (half + 0.5 - dist).clamp(0.0, 1.0);
            if cov > 0.0 {
                let inv_w = a.inv_w + (b.inv_w - a.inv_w) * t;
                let depth = (a.depth_w + (b.depth_w - a.depth_w) * t) / inv_w;
                let color = a.color + (b.color - a.color) * t;
                blend(out, x, y, cov, depth, color);
            }
        }
    }
}

fn disc(e: End, radius: f32, out: &mut Frame) {
    let (w, h) = (out.width as f32, out.height as f32);
    if e.s.x < -radius - 2.0
        || e.s.y < -radius - 2.0
        || e.s.x > w + radius + 2.0
        || e.s.y > h + radius + 2.0
    {
        return;
    }
    let depth = e.depth_w / e.inv_w;
    let r = radius + 1.0;
    for y in (e.s.y - r).floor() as i64..=(e.s.y + r).ceil() as i64 {
        for x in (e.s.x - r).floor() as i64..=(e.s.x + r).ceil() as i64 {
            let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let cov = (radius + 0.5 - (q - e.s).length()).clamp(0.0, 1.0);
            blend(out, x, y, cov, depth, e.color);
        }
    }
}
