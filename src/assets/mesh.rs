//! Indexed triangle meshes, as every loader produces them, and the smooth
//! normals computed for meshes that have none.

use std::collections::HashMap;
use std::ops::Range;

use glam::{Vec2, Vec3};

/// A run of triangles drawn with one material.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    pub triangles: Range<u32>,
    /// Index into the model's material list.
    pub material: usize,
}

#[derive(Debug, Clone, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// One unit normal per vertex (always present after loading).
    pub normals: Vec<Vec3>,
    /// Texture coordinates, image convention (v down); empty when the file
    /// has none.
    pub uvs: Vec<Vec2>,
    /// Counter-clockwise triangles (front faces).
    pub triangles: Vec<[u32; 3]>,
    pub groups: Vec<Group>,
}

impl Mesh {
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }

    pub fn has_uvs(&self) -> bool {
        !self.uvs.is_empty()
    }
}

/// Area-weighted smooth normals for the vertices in `missing`, accumulated
/// per *position* (vertices with bitwise-equal coordinates share one normal),
/// so UV seams and material boundaries do not split the shading. Vertices
/// whose faces all have zero area get +Y rather than NaN.
pub fn smooth_normals(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    normals: &mut [Vec3],
    missing: &[bool],
) {
    let mut weld: HashMap<[u32; 3], u32> = HashMap::new();
    let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let welded: Vec<u32> = positions
        .iter()
        .map(|p| {
            let n = weld.len() as u32;
            *weld.entry(key(*p)).or_insert(n)
        })
        .collect();
    let mut acc = vec![Vec3::ZERO; weld.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        // Length of the cross product = twice the area: area weighting.
        let n = (b - a).cross(c - a);
        if n.is_finite() {
            for &i in t {
                acc[welded[i as usize] as usize] += n;
            }
        }
    }
    for (i, n) in normals.iter_mut().enumerate() {
        if missing[i] {
            *n = acc[welded[i] as usize].try_normalize().unwrap_or(Vec3::Y);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seams_do_not_split_normals() {
        // Two triangles of a tent whose shared edge vertices are duplicated
        // (as across a UV seam): the ridge gets one averaged normal.
        let p = vec![
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, -1.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, -1.0),
        ];
        let tris = vec![[0, 1, 2], [3, 4, 5]];
        let mut n = vec![Vec3::ZERO; 6];
        smooth_normals(&p, &tris, &mut n, &[true; 6]);
        assert!((n[1] - Vec3::Y).length() < 1e-6, "{:?}", n[1]);
        assert_eq!(n[1], n[3]);
        assert!((n[0] - Vec3::new(-1.0, 1.0, 0.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn degenerate_faces_give_finite_normals() {
        let p = vec![Vec3::ZERO; 3];
        let mut n = vec![Vec3::ZERO; 3];
        smooth_normals(&p, &[[0, 1, 2]], &mut n, &[true; 3]);
        assert!(
            n.iter()
                .all(|v| v.is_finite() && (v.length() - 1.0).abs() < 1e-6)
        );
    }
}
