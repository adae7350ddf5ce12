//! Homogeneous clipping (Sutherland-Hodgman in clip space).
//!
//! Always against the near (z >= 0 in reverse-Z, z <= w in standard: both are
//! kept, so 0 <= z <= w) and far planes, and against a guard band at `guard`
//! times the viewport in x and y: triangles crossing the screen edges are not
//! cut (the rasterizer's bounding box does that for free) unless they reach
//! far enough to overflow the fixed-point coordinates. Clipped vertices carry
//! their barycentric coordinates in the original triangle, so clipping never
//! has to know what attributes a vertex has.

use glam::{Vec3, Vec4};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipVertex {
    pub pos: Vec4,
    /// Barycentric coordinates of this vertex in the original triangle.
    pub bary: Vec3,
}

/// Up to 3 + 6 vertices after six planes.
pub const MAX_POLY: usize = 9;

/// A convex polygon in clip space.
#[derive(Debug, Clone)]
pub struct Polygon {
    pub verts: [ClipVertex; MAX_POLY],
    pub len: usize,
}

impl Polygon {
    pub fn as_slice(&self) -> &[ClipVertex] {
        &self.verts[..self.len]
    }
}

/// Signed distances to the six planes (inside where >= 0).
#[inline]
fn plane_distances(p: Vec4, guard_x: f32, guard_y: f32) -> [f32; 6] {
    [
        p.z,                 // z >= 0
        p.w - p.z,           // z <= w
        guard_x * p.w - p.x, // x <= gx w
        guard_x * p.w + p.x, // x >= -gx w
        guard_y * p.w - p.y,
        guard_y * p.w + p.y,
    ]
}

/// The outcode bits of the six planes (`outcode`).
pub const OUTSIDE_PLANES: u8 = 0x3f;
/// The outcode bit of a position with a NaN or infinite coordinate.
pub const NOT_FINITE: u8 = 0x40;

/// Which planes `p` lies outside of (bit k: distance k of
/// `plane_distances` below 0, as `clip_triangle` tests them), and
/// `NOT_FINITE`. Computed once per vertex, a triangle is classified from
/// its corners' codes as `clip_triangle` classifies it: all codes 0 is
/// `Inside`, a plane bit common to all three is `Rejected`.
#[inline]
pub fn outcode(p: Vec4, guard_x: f32, guard_y: f32) -> u8 {
    let d = plane_distances(p, guard_x, guard_y);
    let mut code = 0;
    for (k, dk) in d.iter().enumerate() {
        code |= u8::from(*dk < 0.0) << k;
    }
    if !p.is_finite() {
        code |= NOT_FINITE;
    }
    code
}

#[allow(clippy::large_enum_variant)] // returned by value per triangle; boxing would allocate
pub enum Clipped {
    /// Entirely outside one plane.
    Rejected,
    /// Entirely inside: use the original three vertices.
    Inside,
    /// Cut: the polygon to fan-triangulate.
    Polygon(Polygon),
}

/// Clips triangle `v` against the view volume with a guard band of
/// `guard_x`, `guard_y` (in units of the viewport half-size).
pub fn clip_triangle(v: [Vec4; 3], guard_x: f32, guard_y: f32) -> Clipped {
    let d = v.map(|p| plane_distances(p, guard_x, guard_y));
    let mut any_out = false;
    #[allow(clippy::needless_range_loop)] // k indexes the planes of all three vertices
    for k in 0..6 {
        let out = [d[0][k] < 0.0, d[1][k] < 0.0, d[2][k] < 0.0];
        if out[0] && out[1] && out[2] {
            return Clipped::Rejected;
        }
        any_out |= out[0] || out[1] || out[2];
    }
    // NaN positions (from a broken transform) fail every comparison above;
    // reject them here rather than let them reach the rasterizer.
    if v.iter().any(|p| !p.is_finite()) {
        return Clipped::Rejected;
    }
    if !any_out {
        return Clipped::Inside;
    }
    let mut poly = Polygon {
        verts: [ClipVertex {
            pos: Vec4::ZERO,
            bary: Vec3::ZERO,
        }; MAX_POLY],
        len: 3,
    };
    poly.verts[0] = ClipVertex {
        pos: v[0],
        bary: Vec3::X,
    };
    poly.verts[1] = ClipVertex {
        pos: v[1],
        bary: Vec3::Y,
    };
    poly.verts[2] = ClipVertex {
        pos: v[2],
        bary: Vec3::Z,
    };
    let mut scratch = poly.clone();
    for k in 0..6 {
        if d.iter().all(|dd| dd[k] >= 0.0) {
            continue;
        }
        scratch.len = 0;
        let n = poly.len;
        for i in 0..n {
            let a = poly.verts[i];
            let b = poly.verts[(i + 1) % n];
            let da = plane_distances(a.pos, guard_x, guard_y)[k];
            let db = plane_distances(b.pos, guard_x, guard_y)[k];
            if da >= 0.0 {
                push(&mut scratch, a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                let t = da / (da - db);
                push(
                    &mut scratch,
                    ClipVertex {
                        pos: a.pos.lerp(b.pos, t),
                        bary: a.bary.lerp(b.bary, t),
                    },
                );
            }
        }
        std::mem::swap(&mut poly, &mut scratch);
        if poly.len < 3 {
            return Clipped::Rejected;
        }
    }
    Clipped::Polygon(poly)
}

#[inline]
fn push(p: &mut Polygon, v: ClipVertex) {
    // A convex polygon cut by six planes has at most nine vertices; the
    // check only guards against NaN-driven misclassification.
    if p.len < MAX_POLY {
        p.verts[p.len] = v;
        p.len += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_and_outside_are_classified() {
        let t = [
            Vec4::new(-0.5, -0.5, 0.5, 1.0),
            Vec4::new(0.5, -0.5, 0.5, 1.0),
            Vec4::new(0.0, 0.5, 0.5, 1.0),
        ];
        assert!(matches!(clip_triangle(t, 2.0, 2.0), Clipped::Inside));
        let behind = t.map(|p| Vec4::new(p.x, p.y, -1.0, 1.0));
        assert!(matches!(clip_triangle(behind, 2.0, 2.0), Clipped::Rejected));
        let nan = [Vec4::NAN, t[1], t[2]];
        assert!(matches!(clip_triangle(nan, 2.0, 2.0), Clipped::Rejected));
    }

    #[test]
    fn near_plane_crossing_keeps_barycentrics_consistent() {
        // One vertex behind the eye (negative z and w, as perspective gives).
        let t = [
            Vec4::new(0.0, 0.0, 0.5, 1.0),
            Vec4::new(0.5, 0.0, 0.5, 1.0),
            Vec4::new(0.0, 0.5, -0.5, -0.5),
        ];
        let Clipped::Polygon(p) = clip_triangle(t, 2.0, 2.0) else {
            panic!("expected a cut polygon")
        };
        assert_eq!(p.len, 4);
        for v in p.as_slice() {
            assert!(v.pos.z >= -1e-6 && v.pos.w > 0.0);
            let rebuilt = t[0] * v.bary.x + t[1] * v.bary.y + t[2] * v.bary.z;
            assert!((rebuilt - v.pos).length() < 1e-5);
            assert!((v.bary.x + v.bary.y + v.bary.z - 1.0).abs() < 1e-5);
        }
    }
}
