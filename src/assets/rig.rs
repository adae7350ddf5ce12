//! What it takes to pose a glTF model at any time of its clips: the node
//! hierarchy with every node's own transform and default morph weights,
//! the skins, and per primitive instance ("segment") its source vertices
//! as the file gives them (before morphing and skinning) with the range of
//! the loaded mesh's vertices they became. The loaded mesh keeps its
//! topology, UVs and materials; a pose replaces positions, normals and
//! tangents only.
//!
//! Posing follows glTF: each animated node's local transform is T * R * S
//! from its channels (unanimated parts keep the node's), worlds compose
//! parent first; a skinned vertex is placed by the sum of weight *
//! jointWorld * inverseBind (its own node's transform ignored), other
//! vertices by their node's world. Morph targets displace positions and
//! normals first, with the node's weights.

use glam::{Mat3, Mat4, Quat, Vec3, Vec4};
use rayon::prelude::*;

use super::gltf::pose::{Influences, Target, joint_matrices, morph_vertex};
use super::keyframes::{ChannelPath, Clip};
use super::mesh::Mesh;

/// A node of a glTF file.
#[derive(Debug, Clone)]
pub struct RigNode {
    /// Its parent's index (None: a root).
    pub parent: Option<usize>,
    /// The node's own transform as the file gives it.
    pub matrix: Mat4,
    /// The same as translation, rotation, scale (what channels replace).
    pub trs: (Vec3, Quat, Vec3),
    /// Default morph weights of the node's mesh (the node's, else the
    /// mesh's).
    pub weights: Vec<f32>,
}

/// A glTF skin.
#[derive(Debug, Clone)]
pub struct RigSkin {
    /// Node index of each joint.
    pub joints: Vec<usize>,
    /// Per joint: mesh space to the joint's space at bind time.
    pub inverse_bind: Vec<Mat4>,
}

/// How a segment's normals are made.
#[derive(Debug, Clone)]
pub enum SegmentNormals {
    /// The file's, per source vertex.
    Vertex(Vec<Vec3>),
    /// None in the file: the face normal per corner (three mesh vertices
    /// per triangle, from `first_triangle` on).
    /// Face normals, from a triangle on.
    Faces {
        /// The first of the segment's triangles in the mesh.
        first_triangle: u32,
    },
    /// Points and lines: +Y, unused.
    Fixed,
}

/// One primitive at one node.
#[derive(Debug, Clone)]
pub struct Segment {
    /// The first of its vertices in the loaded mesh.
    pub first: u32,
    /// Per mesh vertex of the segment: its source vertex (None: the same
    /// index).
    pub order: Option<Vec<u32>>,
    /// The node the primitive hangs on.
    pub node: usize,
    /// The skin that bends it (index in `Rig::skins`).
    pub skin: Option<usize>,
    /// Per source vertex: its position.
    pub positions: Vec<Vec3>,
    /// Its normals.
    pub normals: SegmentNormals,
    /// Its morph targets.
    pub targets: Vec<Target>,
    /// Skinned segments: per source vertex.
    pub influences: Vec<Influences>,
}

impl Segment {
    /// Its vertices in the loaded mesh.
    pub fn len(&self) -> usize {
        self.order.as_ref().map_or(self.positions.len(), Vec::len)
    }

    /// Whether it has no vertex.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn source(&self, k: usize) -> usize {
        self.order.as_ref().map_or(k, |o| o[k] as usize)
    }

    /// The matrix placing source vertex `s`: blended from the skin's
    /// `joints` matrices when skinned, else the node's `world`.
    fn matrix(&self, s: usize, joints: Option<&Vec<Mat4>>, world: Mat4) -> Mat4 {
        match (joints, self.influences.get(s)) {
            (Some(j), Some(i)) => i.blend(j),
            _ => world,
        }
    }
}

/// The nodes, skins and clips of a model file: what poses its mesh over
/// time.
#[derive(Debug, Clone, Default)]
pub struct Rig {
    /// The file's nodes.
    pub nodes: Vec<RigNode>,
    /// Node indices, parents before children.
    pub order: Vec<usize>,
    /// The file's skins.
    pub skins: Vec<RigSkin>,
    /// In mesh vertex order, covering every vertex.
    pub segments: Vec<Segment>,
    /// Per light of the file (in the order the loader lists them): its
    /// node.
    pub light_nodes: Vec<usize>,
    /// The file's animations; one that cannot be played holds why.
    pub clips: Vec<(String, Result<Clip, String>)>,
}

/// Every node's world transform and morph weights at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct NodePose {
    /// Per node: object to world.
    pub worlds: Vec<Mat4>,
    /// Per node: its morph weights.
    pub weights: Vec<Vec<f32>>,
}

/// A mesh's vertices as one pose places them (the mesh's object space).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Posed {
    /// Per vertex: its position.
    pub positions: Vec<Vec3>,
    /// Per vertex: its unit normal.
    pub normals: Vec<Vec3>,
    /// Per triangle corner, as `Mesh::tangents` (empty when it is).
    pub tangents: Vec<Vec4>,
}

/// What a pose computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parts {
    /// Positions only (bounds).
    Positions,
    /// Positions, normals and tangents.
    All,
}

impl Rig {
    /// The clip by name, or by index when `name` is a number.
    pub fn clip_names(&self) -> String {
        self.clips
            .iter()
            .enumerate()
            .map(|(i, (n, _))| {
                if n.is_empty() {
                    format!("{i} (unnamed)")
                } else {
                    format!("{i} \"{n}\"")
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Node worlds and weights at time `t` of `clip` (None: the file's
    /// default pose).
    pub fn node_pose(&self, clip: Option<(&Clip, f32)>) -> NodePose {
        let n = self.nodes.len();
        let mut trs: Vec<Option<(Vec3, Quat, Vec3)>> = vec![None; n];
        let mut weights: Vec<Vec<f32>> = self.nodes.iter().map(|x| x.weights.clone()).collect();
        if let Some((clip, t)) = clip {
            let mut buf = Vec::new();
            for c in &clip.channels {
                let Some(node) = self.nodes.get(c.node) else {
                    continue;
                };
                buf.resize(c.width.max(4), 0.0);
                c.sample(t, &mut buf);
                let v = trs[c.node].get_or_insert(node.trs);
                match c.path {
                    ChannelPath::Translation => v.0 = Vec3::from_slice(&buf),
                    ChannelPath::Rotation => {
                        let q = Quat::from_slice(&buf);
                        v.1 = if q.length_squared() > 0.0 {
                            q.normalize()
                        } else {
                            Quat::IDENTITY
                        };
                    }
                    ChannelPath::Scale => v.2 = Vec3::from_slice(&buf),
                    ChannelPath::Weights => weights[c.node] = buf[..c.width].to_vec(),
                }
            }
        }
        let mut worlds = vec![Mat4::IDENTITY; n];
        for &i in &self.order {
            let local = match trs[i] {
                Some((t, r, s)) => Mat4::from_scale_rotation_translation(s, r, t),
                None => self.nodes[i].matrix,
            };
            worlds[i] = match self.nodes[i].parent {
                Some(p) => worlds[p] * local,
                None => local,
            };
        }
        NodePose { worlds, weights }
    }

    /// The mesh's vertices as `pose` places them. `tangents`: the mesh's
    /// per-corner tangents in source space (`source_tangents`), turned
    /// with their vertex; empty for none.
    pub fn place(&self, pose: &NodePose, mesh: &Mesh, tangents: &[Vec4], parts: Parts) -> Posed {
        let nv = mesh.positions.len();
        let mut positions = vec![Vec3::ZERO; nv];
        let all = parts == Parts::All;
        let mut normals = if all { vec![Vec3::Y; nv] } else { Vec::new() };
        // Per vertex: the linear part of its placement (for tangents).
        let mut linear = if all && !tangents.is_empty() {
            vec![Mat3::IDENTITY; nv]
        } else {
            Vec::new()
        };
        let joint_m = self.joint_matrices(&pose.worlds);
        for seg in &self.segments {
            let first = seg.first as usize;
            if first + seg.len() > nv {
                continue;
            }
            let world = pose.worlds.get(seg.node).copied().unwrap_or(Mat4::IDENTITY);
            let joints = seg.skin.and_then(|s| joint_m.get(s));
            let weights = pose.weights.get(seg.node).map_or(&[][..], Vec::as_slice);
            // Per vertex: position, normal, the linear part of its placement.
            let placed: Vec<(Vec3, Vec3, Mat3)> = (0..seg.len())
                .into_par_iter()
                .with_min_len(1024)
                .map(|k| {
                    let s = seg.source(k);
                    let rest_n = match &seg.normals {
                        SegmentNormals::Vertex(v) => v[s],
                        _ => Vec3::Y,
                    };
                    let (q, m) = morph_vertex(&seg.targets, weights, s, seg.positions[s], rest_n);
                    let xf = seg.matrix(s, joints, world);
                    let m3 = Mat3::from_mat4(xf);
                    let n = match (&seg.normals, all) {
                        (SegmentNormals::Vertex(_), true) => (m3.inverse().transpose() * m)
                            .try_normalize()
                            .unwrap_or(Vec3::Y),
                        _ => Vec3::Y,
                    };
                    (xf.transform_point3(q), n, m3)
                })
                .collect();
            for (k, (p, n, m3)) in placed.into_iter().enumerate() {
                positions[first + k] = p;
                if all {
                    normals[first + k] = n;
                }
                if !linear.is_empty() {
                    linear[first + k] = m3;
                }
            }
            if !all {
                continue;
            }
            // Flat primitives: each corner the posed face's normal.
            if let SegmentNormals::Faces { first_triangle } = seg.normals {
                let tris = seg.len() / 3;
                for t in 0..tris {
                    let Some(tri) = mesh.triangles.get(first_triangle as usize + t) else {
                        break;
                    };
                    let [a, b, c] = tri.map(|i| positions[i as usize]);
                    let f = (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::Y);
                    for i in tri {
                        normals[*i as usize] = f;
                    }
                }
            }
        }
        let tangents = if linear.is_empty() {
            Vec::new()
        } else {
            tangents
                .par_iter()
                .enumerate()
                .map(|(c, t)| {
                    let v = mesh.triangles[c / 3][c % 3] as usize;
                    (linear[v] * t.truncate())
                        .try_normalize()
                        .map_or(*t, |d| d.extend(t.w))
                })
                .collect()
        };
        Posed {
            positions,
            normals,
            tangents,
        }
    }

    /// Per skin: its joint matrices with the nodes at `worlds` (identity
    /// for a skin whose matrices are not finite).
    fn joint_matrices(&self, worlds: &[Mat4]) -> Vec<Vec<Mat4>> {
        self.skins
            .iter()
            .map(|s| {
                joint_matrices(&s.joints, &s.inverse_bind, worlds)
                    .unwrap_or_else(|_| vec![Mat4::IDENTITY; s.joints.len()])
            })
            .collect()
    }

    /// The mesh's per-corner tangents (placed in the default pose) taken
    /// back to source space, for `place` to turn with each pose.
    pub fn source_tangents(&self, mesh: &Mesh) -> Vec<Vec4> {
        if mesh.tangents.is_empty() {
            return Vec::new();
        }
        let rest = self.node_pose(None);
        let nv = mesh.positions.len();
        let mut inverse = vec![Mat3::IDENTITY; nv];
        let joint_m = self.joint_matrices(&rest.worlds);
        for seg in &self.segments {
            let world = rest.worlds.get(seg.node).copied().unwrap_or(Mat4::IDENTITY);
            for k in 0..seg.len() {
                let v = seg.first as usize + k;
                if v >= nv {
                    break;
                }
                let s = seg.source(k);
                let xf = seg.matrix(s, seg.skin.and_then(|i| joint_m.get(i)), world);
                let m3 = Mat3::from_mat4(xf);
                if m3.determinant().abs() > 1e-20 {
                    inverse[v] = m3.inverse();
                }
            }
        }
        mesh.tangents
            .iter()
            .enumerate()
            .map(|(c, t)| {
                let v = mesh.triangles[c / 3][c % 3] as usize;
                (inverse[v] * t.truncate()).extend(t.w)
            })
            .collect()
    }
}
