//! An FBX file's skins and animation stacks as the rig and clips glTF
//! animation plays (`assets::rig`, `assets::clip`): the node tree with
//! each node's local transform, each skin deformer's bones with their
//! geometry-to-bone (inverse bind) matrices, per mesh instance its
//! vertices as the file gives them (geometry space for skinned meshes,
//! node space for the others), and each animation stack baked by ufbx
//! into linear keys of translation, rotation and scale per node.
//!
//! Blend shapes are morph targets: each blend channel's full-weight shape
//! (in-between shapes are not read), its weight the node's default, and
//! its `DeformPercent` keys a weights channel of the stack's clip.

use glam::{Mat4, Quat, Vec3};

use super::{matrix, vec3};
use crate::assets::gltf::pose::{Influences, Target};
use crate::assets::keyframes::{Channel, ChannelPath, Clip, Interpolation};
use crate::assets::rig::{Rig, RigNode, RigSkin, Segment, SegmentNormals};

/// The loaded mesh's vertices of one mesh instance: where they start and,
/// per vertex, the ufbx vertex and face corner it came from.
pub(super) struct Instance {
    pub node: usize,
    pub first: u32,
    pub vertices: Vec<u32>,
    pub corners: Vec<u32>,
}

/// The rig of `scene`, whose mesh instances became `instances`.
pub(super) fn rig(scene: &ufbx::Scene, instances: &[Instance]) -> Result<Rig, String> {
    let nodes: Vec<RigNode> = scene
        .nodes
        .iter()
        .map(|n| {
            let t = &n.local_transform;
            RigNode {
                parent: n.parent.as_ref().map(|p| p.element.typed_id as usize),
                matrix: matrix(&n.node_to_parent),
                trs: (vec3(&t.translation), quat(&t.rotation), vec3(&t.scale)),
                weights: Vec::new(),
            }
        })
        .collect();
    let mut nodes = nodes;
    for inst in instances {
        if let Some(mesh) = &scene.nodes[inst.node].mesh {
            nodes[inst.node].weights = blend_channels(mesh)
                .iter()
                .map(|c| finite(c.weight))
                .collect();
        }
    }
    let order = parents_first(&nodes)?;
    let skins: Vec<RigSkin> = scene
        .skin_deformers
        .iter()
        .map(|s| RigSkin {
            joints: s
                .clusters
                .iter()
                .map(|c| {
                    c.bone_node
                        .as_ref()
                        .map_or(0, |b| b.element.typed_id as usize)
                })
                .collect(),
            inverse_bind: s
                .clusters
                .iter()
                .map(|c| matrix(&c.geometry_to_bone))
                .collect(),
        })
        .collect();
    let segments = instances
        .iter()
        .map(|i| segment(scene, i))
        .collect::<Result<Vec<_>, String>>()?;
    let clips = scene
        .anim_stacks
        .iter()
        .map(|s| (s.element.name.to_string(), clip(scene, s, instances)))
        .collect();
    Ok(Rig {
        nodes,
        order,
        skins,
        segments,
        light_nodes: Vec::new(),
        clips,
    })
}

fn quat(q: &ufbx::Quat) -> Quat {
    let q = Quat::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32);
    if q.is_finite() && q.length_squared() > 0.0 {
        q.normalize()
    } else {
        Quat::IDENTITY
    }
}

/// Node indices, parents before children.
fn parents_first(nodes: &[RigNode]) -> Result<Vec<usize>, String> {
    let n = nodes.len();
    let mut children = vec![Vec::new(); n];
    let mut order = Vec::with_capacity(n);
    for (i, node) in nodes.iter().enumerate() {
        match node.parent {
            Some(p) if p < n => children[p].push(i),
            _ => order.push(i),
        }
    }
    let mut k = 0;
    while k < order.len() {
        order.extend(children[order[k]].iter().copied());
        k += 1;
    }
    if order.len() != n {
        return Err("the FBX node hierarchy has a cycle".into());
    }
    Ok(order)
}

/// Mesh instance `inst`'s segment: its vertices in geometry space with
/// their bone weights (skinned), or in its node's space.
fn segment(scene: &ufbx::Scene, inst: &Instance) -> Result<Segment, String> {
    let node = &scene.nodes[inst.node];
    let mesh = node.mesh.as_ref().ok_or("a mesh instance without a mesh")?;
    let skin = mesh.skin_deformers.first();
    // Skinned vertices are placed by their bones alone; the others by
    // their node, after the geometric transform.
    let to_node = if skin.is_some() {
        Mat4::IDENTITY
    } else {
        matrix(&node.geometry_to_node)
    };
    let normal_m = glam::Mat3::from_mat4(to_node).inverse().transpose();
    let positions = inst
        .vertices
        .iter()
        .map(|&v| to_node.transform_point3(vec3(&mesh.vertices[v as usize])))
        .collect();
    let normals = inst
        .corners
        .iter()
        .map(|&c| {
            if mesh.vertex_normal.exists {
                (normal_m * vec3(&mesh.vertex_normal[c as usize])).normalize_or(Vec3::Y)
            } else {
                Vec3::Y
            }
        })
        .collect();
    let (skin_index, influences) = match skin {
        Some(s) => (
            Some(s.element.typed_id as usize),
            inst.vertices.iter().map(|&v| influences(s, v)).collect(),
        ),
        None => (None, Vec::new()),
    };
    let linear = glam::Mat3::from_mat4(to_node);
    let targets = blend_channels(mesh)
        .iter()
        .map(|c| target(mesh, c, inst, linear))
        .collect();
    Ok(Segment {
        first: inst.first,
        order: None,
        node: inst.node,
        skin: skin_index,
        positions,
        normals: SegmentNormals::Vertex(normals),
        targets,
        influences,
    })
}

/// The blend channels of `mesh`'s blend deformers, in order.
fn blend_channels(mesh: &ufbx::Mesh) -> Vec<&ufbx::BlendChannel> {
    mesh.blend_deformers
        .iter()
        .flat_map(|d| d.channels.iter().map(|c| &**c))
        .collect()
}

/// `v` as f32, 0 where not finite.
fn finite(v: f64) -> f32 {
    if v.is_finite() { v as f32 } else { 0.0 }
}

/// Channel `c`'s full-weight shape as a morph target of `inst`'s
/// vertices (offsets turned by `linear`, the segment's placement).
fn target(
    mesh: &ufbx::Mesh,
    c: &ufbx::BlendChannel,
    inst: &Instance,
    linear: glam::Mat3,
) -> Target {
    let shape = c
        .target_shape
        .as_ref()
        .or_else(|| c.keyframes.iter().last().map(|k| &k.shape));
    let mut offsets = vec![Vec3::ZERO; mesh.num_vertices];
    if let Some(shape) = shape {
        for (v, d) in shape
            .offset_vertices
            .iter()
            .zip(shape.position_offsets.iter())
        {
            if let Some(o) = offsets.get_mut(*v as usize) {
                let d = vec3(d);
                *o = if d.is_finite() {
                    linear * d
                } else {
                    Vec3::ZERO
                };
            }
        }
    }
    Target {
        positions: Some(inst.vertices.iter().map(|&v| offsets[v as usize]).collect()),
        normals: None,
        tangents: None,
    }
}

/// Vertex `v`'s eight heaviest bone weights in skin `s`.
fn influences(s: &ufbx::SkinDeformer, v: u32) -> Influences {
    let mut out = Influences {
        joints: [0; 8],
        weights: [0.0; 8],
        inv_total: 0.0,
    };
    let Some(sv) = s.vertices.get(v as usize) else {
        return out;
    };
    let begin = sv.weight_begin as usize;
    let end = begin
        .saturating_add(sv.num_weights as usize)
        .min(s.weights.len());
    let mut list: Vec<(u16, f32)> = (begin.min(end)..end)
        .map(|k| &s.weights[k])
        .filter(|w| w.weight.is_finite() && w.weight > 0.0)
        .filter_map(|w| Some((u16::try_from(w.cluster_index).ok()?, w.weight as f32)))
        .collect();
    // ufbx sorts a vertex's weights heaviest first; keep eight.
    list.truncate(8);
    let total: f32 = list.iter().map(|w| w.1).sum();
    for (k, (j, w)) in list.into_iter().enumerate() {
        out.joints[k] = j;
        out.weights[k] = w;
    }
    if total > 0.0 {
        out.inv_total = 1.0 / total;
    }
    out
}

/// Animation stack `stack` baked into linear keys per node, and the blend
/// channels' weights of `instances`.
fn clip(
    scene: &ufbx::Scene,
    stack: &ufbx::AnimStack,
    instances: &[Instance],
) -> Result<Clip, String> {
    let opts = ufbx::BakeOpts {
        trim_start_time: true,
        ..Default::default()
    };
    let baked = ufbx::bake_anim(scene, &stack.anim, opts)
        .map_err(|e| format!("ufbx cannot bake it: {}", e.description))?;
    let mut channels = Vec::new();
    for n in baked.nodes.iter() {
        let node = n.typed_id as usize;
        let mut push = |path, times: Vec<f32>, values: Vec<f32>, width| {
            if !times.is_empty() {
                channels.push(Channel {
                    node,
                    path,
                    interpolation: Interpolation::Linear,
                    times,
                    values,
                    width,
                });
            }
        };
        let vec3s = |keys: &[ufbx::BakedVec3]| {
            let times = keys.iter().map(|k| k.time as f32).collect();
            let values = keys
                .iter()
                .flat_map(|k| [k.value.x as f32, k.value.y as f32, k.value.z as f32])
                .collect();
            (times, values)
        };
        let (t, v) = vec3s(&n.translation_keys);
        push(ChannelPath::Translation, t, v, 3);
        let keys = &n.rotation_keys;
        let t = keys.iter().map(|k| k.time as f32).collect();
        let v = keys
            .iter()
            .flat_map(|k| quat(&k.value).to_array())
            .collect();
        push(ChannelPath::Rotation, t, v, 4);
        let (t, v) = vec3s(&n.scale_keys);
        push(ChannelPath::Scale, t, v, 3);
    }
    for inst in instances {
        if let Some(mesh) = &scene.nodes[inst.node].mesh
            && let Some(c) = weights(&baked, &blend_channels(mesh), inst.node)
        {
            channels.push(c);
        }
    }
    for (k, c) in channels.iter().enumerate() {
        c.check().map_err(|e| format!("channel {k}: {e}"))?;
    }
    let duration = channels
        .iter()
        .filter_map(|c| c.times.last().copied())
        .fold(0.0f32, f32::max);
    Ok(Clip {
        name: stack.element.name.to_string(),
        channels,
        duration,
    })
}

/// The weights channel of node `node` whose blend channels are `blend`,
/// from their baked `DeformPercent` keys (None when none is animated):
/// every channel sampled at every key time of any.
fn weights(baked: &ufbx::BakedAnim, blend: &[&ufbx::BlendChannel], node: usize) -> Option<Channel> {
    let keys: Vec<Option<&[ufbx::BakedVec3]>> = blend
        .iter()
        .map(|c| {
            let e = baked
                .elements
                .iter()
                .find(|e| e.element_id == c.element.element_id)?;
            let p = e.props.iter().find(|p| &*p.name == "DeformPercent")?;
            Some(p.keys.as_ref())
        })
        .collect();
    let mut times: Vec<f64> = keys
        .iter()
        .flatten()
        .flat_map(|k| k.iter().map(|k| k.time))
        .collect();
    if times.is_empty() {
        return None;
    }
    times.sort_by(f64::total_cmp);
    times.dedup();
    let mut values = Vec::with_capacity(times.len() * blend.len());
    for &t in &times {
        for (c, k) in blend.iter().zip(&keys) {
            values.push(match k {
                Some(k) => finite(sample(k, t) / 100.0),
                None => finite(c.weight),
            });
        }
    }
    Some(Channel {
        node,
        path: ChannelPath::Weights,
        interpolation: Interpolation::Linear,
        times: times.iter().map(|&t| t as f32).collect(),
        values,
        width: blend.len(),
    })
}

/// Keys `k` (x) at time `t`, linearly; the first before, the last after.
fn sample(k: &[ufbx::BakedVec3], t: f64) -> f64 {
    let Some(first) = k.first() else { return 0.0 };
    if t <= first.time {
        return first.value.x;
    }
    for w in k.windows(2) {
        if t <= w[1].time {
            let span = w[1].time - w[0].time;
            let f = if span > 0.0 {
                (t - w[0].time) / span
            } else {
                1.0
            };
            return w[0].value.x + (w[1].value.x - w[0].value.x) * f;
        }
    }
    k.last().map_or(0.0, |l| l.value.x)
}
