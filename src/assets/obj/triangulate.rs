//! Polygons to triangles: a fan for convex faces (what every exporter
//! expects of them), ear clipping for concave and non-planar ones, in the
//! polygon's best-fit plane (Newell's normal). Triangles keep the face's
//! winding.

use glam::{Vec2, Vec3};

/// Above this many corners a face is fanned: ear clipping is quadratic or
/// worse, and faces this large are convex caps in practice.
const EAR_CLIP_LIMIT: usize = 512;

/// Triangles of the polygon `points` as corner indices.
pub fn triangulate(points: &[Vec3]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    let fan = || (1..n - 1).map(|i| [0, i, i + 1]).collect();
    if n == 3 || n > EAR_CLIP_LIMIT {
        return fan();
    }
    // Newell's normal, relative to the first point for precision.
    let o = points[0];
    let mut normal = Vec3::ZERO;
    for i in 0..n {
        let (a, b) = (points[i] - o, points[(i + 1) % n] - o);
        normal += Vec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let Some(normal) = normal.try_normalize() else {
        return fan();
    };
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let p: Vec<Vec2> = points
        .iter()
        .map(|q| Vec2::new((*q - o).dot(u), (*q - o).dot(v)))
        .collect();
    // In this basis the polygon runs counter-clockwise.
    let turn = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - b);
    let convex = (0..n).all(|i| turn(p[i], p[(i + 1) % n], p[(i + 2) % n]) >= 0.0);
    if convex {
        return fan();
    }
    ear_clip(&p)
}

fn ear_clip(p: &[Vec2]) -> Vec<[usize; 3]> {
    let mut ring: Vec<usize> = (0..p.len()).collect();
    let mut out = Vec::with_capacity(p.len() - 2);
    let cross = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
    let mut i = 0;
    let mut misses = 0;
    while ring.len() > 3 {
        let m = ring.len();
        let (ia, ib, ic) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
        let (a, b, c) = (p[ia], p[ib], p[ic]);
        let is_ear = cross(a, b, c) > 0.0
            && ring.iter().all(|&j| {
                if j == ia || j == ib || j == ic {
                    return true;
                }
                let q = p[j];
                if q == a || q == b || q == c {
                    return true;
                }
                // Not an ear if q lies inside or on the triangle.
                !(cross(a, b, q) >= 0.0 && cross(b, c, q) >= 0.0 && cross(c, a, q) >= 0.0)
            });
        // After a full lap without an ear (a self-intersecting or
        // degenerate polygon) clip anyway, so the loop ends.
        if is_ear || misses >= m {
            out.push([ia, ib, ic]);
            ring.remove(i);
            misses = 0;
            // Next, the corner before the clipped one.
            i = if i == 0 { m - 2 } else { i - 1 };
        } else {
            misses += 1;
            i = (i + 1) % m;
        }
    }
    out.push([ring[0], ring[1], ring[2]]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(points: &[Vec3], tris: &[[usize; 3]]) -> f32 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| points[i]);
                (b - a).cross(c - a).z * 0.5
            })
            .sum()
    }

    #[test]
    fn a_u_shape_keeps_its_notch() {
        // A U: 3 wide, 2 high, a 1x1 notch from the top middle; area 5.
        let u: Vec<Vec3> = [
            (0., 0.),
            (3., 0.),
            (3., 2.),
            (2., 2.),
            (2., 1.),
            (1., 1.),
            (1., 2.),
            (0., 2.),
        ]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, 0.0))
        .collect();
        let t = triangulate(&u);
        assert_eq!(t.len(), 6);
        // Every triangle counter-clockwise, and they add up to the area
        // (a fan would cover the notch and overlap: wrong signs).
        for tri in &t {
            assert!(area(&u, &[*tri]) > 0.0, "{tri:?}");
        }
        assert!((area(&u, &t) - 5.0).abs() < 1e-5);
        // The notch's center is in no triangle.
        let q = Vec2::new(1.5, 1.5);
        for tri in &t {
            let [a, b, c] = tri.map(|i| u[i].truncate());
            let s = |a: Vec2, b: Vec2| (b - a).perp_dot(q - a) > 0.0;
            assert!(!(s(a, b) && s(b, c) && s(c, a)), "{tri:?}");
        }
    }

    #[test]
    fn convex_faces_fan_and_degenerate_ones_end() {
        let sq: Vec<Vec3> = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)]
            .iter()
            .map(|&(x, y)| Vec3::new(x, y, 0.0))
            .collect();
        assert_eq!(triangulate(&sq), vec![[0, 1, 2], [0, 2, 3]]);
        // A clockwise face seen from the other side is still convex.
        let rev: Vec<Vec3> = sq.iter().rev().copied().collect();
        assert_eq!(triangulate(&rev).len(), 2);
        // All on one point, a bow tie, a line: n-2 triangles, no hang.
        assert_eq!(triangulate(&[Vec3::ZERO; 6]).len(), 4);
        let bow: Vec<Vec3> = [(0., 0.), (1., 1.), (1., 0.), (0., 1.), (0.5, 2.0)]
            .iter()
            .map(|&(x, y)| Vec3::new(x, y, 0.0))
            .collect();
        assert_eq!(triangulate(&bow).len(), 3);
        let line: Vec<Vec3> = (0..7).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        assert_eq!(triangulate(&line).len(), 5);
    }
}
