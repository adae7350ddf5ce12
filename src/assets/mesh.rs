//! Indexed triangle meshes, as every loader produces them, and the smooth
//! normals computed for meshes that have none.

use std::collections::HashMap;
use std::ops::Range;

use glam::{Vec2, Vec3};

/// A run of triangles drawn with one material.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// The triangles, as a range of `Mesh::triangles`.
    pub triangles: Range<u32>,
    /// Index into the model's material list.
    pub material: usize,
    /// The named part the triangles belong to (`Mesh::parts`; 0 for a
    /// mesh without parts): a glTF node, for the object-id pass.
    pub part: u32,
}

/// A point or line: its vertices and its material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Primitive<const N: usize> {
    /// Its vertex indices.
    pub vertices: [u32; N],
    /// Index into the model's material list.
    pub material: usize,
}

/// A loaded mesh: per-vertex attributes, triangles grouped by material,
/// lines and points.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// Vertex positions in object space.
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
    /// Runs of triangles by material.
    pub groups: Vec<Group>,
    /// Line segments (OBJ `l`, glTF lines, strips and loops): two vertices
    /// and a material, drawn as anti-aliased lines `render.line_width`
    /// pixels wide.
    pub lines: Vec<Primitive<2>>,
    /// Points (OBJ `p`, glTF points), drawn as discs `render.point_size`
    /// pixels across.
    pub points: Vec<Primitive<1>>,
    /// Per triangle corner (3 per triangle): unit tangent (xyz) and
    /// bitangent sign (w), MikkTSpace; empty unless a normal or bump map
    /// needs them (`compute_tangents`).
    pub tangents: Vec<glam::Vec4>,
    /// Names of the mesh's parts (glTF nodes with a mesh, by the node's
    /// name, else its mesh's); empty: the mesh is one part.
    pub parts: Vec<String>,
}

impl Mesh {
    /// The axis-aligned bounds of the positions (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }

    /// Whether the mesh has texture coordinates.
    pub fn has_uvs(&self) -> bool {
        !self.uvs.is_empty()
    }

    /// Whether the surface is closed and consistently wound: every edge
    /// (between positions, so UV seams and split normals do not open it)
    /// is used once in each direction. Degenerate triangles are ignored.
    pub fn is_closed(&self) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        // Weld by sorting positions (bitwise equal ones share an id).
        let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        let mut order: Vec<u32> = (0..self.positions.len() as u32).collect();
        order.sort_unstable_by_key(|&i| key(self.positions[i as usize]));
        let mut ids = vec![0u32; self.positions.len()];
        let mut id = 0;
        for (k, w) in order.windows(2).enumerate() {
            if key(self.positions[w[0] as usize]) != key(self.positions[w[1] as usize]) {
                id += 1;
            }
            ids[order[k + 1] as usize] = id;
        }
        // Directed edges as sorted u64 keys: each used once, its reverse
        // present.
        let mut edges: Vec<u64> = Vec::with_capacity(self.triangles.len() * 3);
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| ids[i as usize] as u64);
            if a == b || b == c || a == c {
                continue;
            }
            edges.extend([(a << 32) | b, (b << 32) | c, (c << 32) | a]);
        }
        edges.sort_unstable();
        !edges.is_empty()
            && edges.windows(2).all(|w| w[0] != w[1])
            && edges
                .iter()
                .all(|&e| edges.binary_search(&e.rotate_right(32)).is_ok())
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
        let faces = if uvs.len() == self.positions.len() {
            self.mikk_safe_faces(uvs)
        } else {
            Vec::new()
        };
        if !faces.is_empty() {
            let mut g = MikkGeometry {
                mesh: self,
                uvs,
                faces: &faces,
                out: vec![glam::Vec4::ZERO; faces.len() * 3],
            };
            mikktspace::generate_tangents(&mut g);
            let out = g.out;
            for (k, &f) in faces.iter().enumerate() {
                self.tangents[f as usize * 3..f as usize * 3 + 3]
                    .copy_from_slice(&out[k * 3..k * 3 + 3]);
            }
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

impl Mesh {
    /// The triangles MikkTSpace may see: three distinct, finite positions
    /// spanning a non-zero area, finite normals and UVs, in a set whose
    /// extent is finite. mikktspace 0.3 is unsafe code that reads out of
    /// bounds when every triangle is degenerate, panics on an infinite or
    /// zero extent and loops forever on NaN; the rest get fallback tangents.
    fn mikk_safe_faces(&self, uvs: &[Vec2]) -> Vec<u32> {
        let ok = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let finite = t.iter().all(|&i| {
                self.positions[i as usize].is_finite()
                    && self.normals[i as usize].is_finite()
                    && uvs[i as usize].is_finite()
            });
            finite && a != b && b != c && a != c && {
                let n = (b - a).cross(c - a);
                n.is_finite() && n != Vec3::ZERO
            }
        };
        let faces: Vec<u32> = (0..self.triangles.len() as u32)
            .filter(|&f| ok(&self.triangles[f as usize]))
            .collect();
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for &f in &faces {
            for &i in &self.triangles[f as usize] {
                lo = lo.min(self.positions[i as usize]);
                hi = hi.max(self.positions[i as usize]);
            }
        }
        if faces.is_empty() || !(hi - lo).is_finite() {
            return Vec::new();
        }
        faces
    }
}

/// The mesh's safe faces, as MikkTSpace's geometry.
struct MikkGeometry<'a> {
    mesh: &'a Mesh,
    uvs: &'a [Vec2],
    faces: &'a [u32],
    out: Vec<glam::Vec4>,
}

impl MikkGeometry<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.mesh.triangles[self.faces[face] as usize][vert] as usize
    }
}

impl mikktspace::Geometry for MikkGeometry<'_> {
    fn num_faces(&self) -> usize {
        self.faces.len()
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.vertex(face, vert)].to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.vertex(face, vert)].to_array()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.uvs[self.vertex(face, vert)];
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
    fn closed_meshes_are_told_from_open_ones() {
        // A tetrahedron, counter-clockwise from outside.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let mut m = Mesh {
            positions: p,
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            ..Default::default()
        };
        assert!(m.is_closed());
        // A seam: vertex 3 duplicated at the same position stays closed.
        m.positions.push(Vec3::Z);
        m.triangles[3] = [1, 2, 4];
        assert!(m.is_closed());
        // One face flipped: inconsistent winding.
        m.triangles[3] = [2, 1, 4];
        assert!(!m.is_closed());
        // One face missing: open.
        m.triangles.truncate(3);
        assert!(!m.is_closed());
        assert!(!Mesh::default().is_closed());
    }

    #[test]
    fn tangents_of_hostile_meshes() {
        // Found by fuzzing mikktspace 0.3: all faces degenerate (out-of-
        // bounds reads), zero and infinite extents (panic), NaN (hang).
        let mk = |positions: Vec<Vec3>, triangles: Vec<[u32; 3]>| Mesh {
            normals: vec![Vec3::Z; positions.len()],
            uvs: (0..positions.len())
                .map(|i| Vec2::splat(i as f32))
                .collect(),
            positions,
            triangles,
            ..Default::default()
        };
        let cases = [
            mk(vec![Vec3::ZERO, Vec3::X], vec![[0, 1, 1], [1, 1, 0]]),
            mk(vec![Vec3::ONE; 3], vec![[0, 1, 2]]),
            mk(
                vec![
                    Vec3::new(-3e38, 0.0, 0.0),
                    Vec3::new(3e38, 0.0, 0.0),
                    Vec3::Y,
                ],
                vec![[0, 1, 2]],
            ),
            mk(
                vec![Vec3::NAN, Vec3::X, Vec3::Y],
                vec![[0, 1, 2], [2, 1, 0]],
            ),
        ];
        for mut m in cases {
            m.compute_tangents(0);
            assert_eq!(m.tangents.len(), m.triangles.len() * 3);
            assert!(m.tangents.iter().all(|t| t.is_finite()), "{:?}", m.tangents);
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
