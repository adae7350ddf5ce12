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
    /// Second texture-coordinate set (glTF TEXCOORD_1), same convention;
    /// empty when absent.
    pub uvs1: Vec<Vec2>,
    /// Linear RGBA vertex colors (glTF COLOR_0), multiplying the base
    /// color; empty when absent.
    pub colors: Vec<glam::Vec4>,
    /// Tangents given by the file, per vertex (glTF TANGENT): xyz and the
    /// bitangent sign; w = 0 where none was given. Empty when none at all.
    pub authored_tangents: Vec<glam::Vec4>,
    /// Counter-clockwise triangles (front faces).
    pub triangles: Vec<[u32; 3]>,
    pub groups: Vec<Group>,
    /// Per triangle corner (3 per triangle): unit tangent (xyz) and
    /// bitangent sign (w), MikkTSpace; empty unless a normal or bump map
    /// needs them (`compute_tangents`).
    pub tangents: Vec<glam::Vec4>,
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

impl Mesh {
    /// MikkTSpace tangents per triangle corner from texture-coordinate set
    /// `set` (0 or 1), with the bitangent pointing up the image (OBJ's v
    /// up; glTF's "+Y up" normal maps), the way OpenGL-style tangent-space
    /// normal maps store green. Tangents the file gives (glTF TANGENT) win
    /// over computed ones. Corners whose triangle has no usable UV area get
    /// a tangent perpendicular to the normal instead, never NaN.
    pub fn compute_tangents(&mut self, set: usize) {
        let n = self.triangles.len() * 3;
        self.tangents = vec![glam::Vec4::ZERO; n];
        let uvs = if set == 1 { &self.uvs1 } else { &self.uvs };
        if !uvs.is_empty() {
            let mut g = MikkGeometry {
                mesh: self,
                uvs,
                out: vec![glam::Vec4::ZERO; n],
            };
            mikktspace::generate_tangents(&mut g);
            let out = g.out;
            self.tangents = out;
        }
        for (c, t) in self.tangents.iter_mut().enumerate() {
            let vi = self.triangles[c / 3][c % 3] as usize;
            if let Some(a) = self.authored_tangents.get(vi)
                && a.w != 0.0
            {
                *t = *a;
            }
            let nrm = self.normals[vi];
            let xyz = t.truncate();
            let ok = xyz.is_finite() && xyz.length_squared() > 1e-12 && t.w != 0.0;
            let xyz = if ok {
                (xyz - nrm * nrm.dot(xyz)).try_normalize()
            } else {
                None
            };
            *t = match xyz {
                Some(v) => v.extend(if t.w < 0.0 { -1.0 } else { 1.0 }),
                None => nrm.any_orthonormal_vector().extend(1.0),
            };
        }
    }
}

struct MikkGeometry<'a> {
    mesh: &'a Mesh,
    uvs: &'a [Vec2],
    out: Vec<glam::Vec4>,
}

impl mikktspace::Geometry for MikkGeometry<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.triangles.len()
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.triangles[face][vert] as usize].to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.mesh.triangles[face][vert] as usize].to_array()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.uvs[self.mesh.triangles[face][vert] as usize];
        [uv.x, 1.0 - uv.y]
    }
    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        self.out[face * 3 + vert] = glam::Vec4::from_array(tangent);
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
    fn tangents_follow_u_and_survive_zero_uv_area() {
        // A quad in the xy plane, u along +x, v (OBJ, up) along +y; a third
        // triangle whose UVs are all equal.
        let mut m = Mesh {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(3.0, 0.0, 0.0),
                Vec3::new(2.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 7],
            // image convention: v down
            uvs: vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
                Vec2::splat(0.5),
                Vec2::splat(0.5),
                Vec2::splat(0.5),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]],
            ..Default::default()
        };
        m.compute_tangents(0);
        for c in 0..6 {
            let t = m.tangents[c];
            assert!((t.truncate() - Vec3::X).length() < 1e-4, "{t}");
            // bitangent = w * n x t = +y (up the image)
            assert!((Vec3::Z.cross(t.truncate()) * t.w - Vec3::Y).length() < 1e-4);
        }
        for c in 6..9 {
            let t = m.tangents[c];
            assert!(t.is_finite() && (t.truncate().length() - 1.0).abs() < 1e-4);
            assert!(t.truncate().dot(Vec3::Z).abs() < 1e-4);
        }
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
