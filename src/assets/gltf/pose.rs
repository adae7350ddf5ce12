//! The default pose of skinned and morphed glTF meshes: morph targets
//! blended with the node's (or the mesh's) default weights, and skinned
//! vertices placed by their joints at the joints' default transforms
//! (glTF: a skinned mesh ignores its own node's transform; each vertex is
//! sum of weight_i * jointWorld_i * inverseBind_i applied to it), and the
//! pieces `rig` poses them with at other times: morph targets, skin
//! influences, and the file's animation clips.

use glam::{Mat4, Vec3};
use gltf::accessor::{DataType, Dimensions};

use crate::assets::accessor::{Attributes, read_floats};
use crate::assets::keyframes::{Channel, ChannelPath, Clip, Interpolation};

/// World matrix of every node at its default transform, following its
/// parents (a node without a parent is a root). A cycle is an error.
pub fn node_worlds(doc: &gltf::Document) -> Result<Vec<Mat4>, String> {
    let n = doc.nodes().count();
    let mut parent = vec![None; n];
    for node in doc.nodes() {
        for c in node.children() {
            parent[c.index()] = Some(node.index());
        }
    }
    let local: Vec<Mat4> = doc
        .nodes()
        .map(|node| Mat4::from_cols_array_2d(&node.transform().matrix()))
        .collect();
    let mut world = vec![None; n];
    for i in 0..n {
        // Up to the root (or a node already known), then down again.
        let mut chain = vec![i];
        while let Some(p) = parent[*chain.last().unwrap_or(&i)] {
            if world[p].is_some() {
                break;
            }
            if chain.len() > n {
                return Err(format!("node {i}: its parents form a cycle"));
            }
            chain.push(p);
        }
        let top = *chain.last().unwrap_or(&i);
        let mut m = parent[top].and_then(|p| world[p]).unwrap_or(Mat4::IDENTITY);
        for &k in chain.iter().rev() {
            if let Some(w) = world[k] {
                m = w;
                continue;
            }
            m *= local[k];
            world[k] = Some(m);
        }
    }
    Ok(world
        .into_iter()
        .map(|w| w.unwrap_or(Mat4::IDENTITY))
        .collect())
}

/// A morph target's displacements (each absent where the file gives none).
#[derive(Debug, Clone, Default)]
pub struct Target {
    pub positions: Option<Vec<Vec3>>,
    pub normals: Option<Vec<Vec3>>,
    pub tangents: Option<Vec<Vec3>>,
}

/// The primitive's morph targets, `n` vertices each. Only float targets
/// are read; a target of another type or length is an error.
pub fn read_targets(
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    n: usize,
) -> Result<Vec<Target>, String> {
    let targets: Vec<_> = prim.morph_targets().collect();
    for (k, t) in targets.iter().enumerate() {
        for (acc, name) in [
            (t.positions(), "POSITION"),
            (t.normals(), "NORMAL"),
            (t.tangents(), "TANGENT"),
        ] {
            if let Some(acc) = acc
                && (acc.data_type() != DataType::F32
                    || acc.dimensions() != Dimensions::Vec3
                    || acc.count() != n)
            {
                return Err(format!(
                    "morph target {k}: its {name} accessor is {} {:?} {:?}, not {n} float VEC3",
                    acc.count(),
                    acc.data_type(),
                    acc.dimensions()
                ));
            }
        }
    }
    if targets.is_empty() {
        return Ok(Vec::new());
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let vecs = |it: Option<gltf::accessor::Iter<'_, [f32; 3]>>| {
        it.map(|i| i.map(Vec3::from).collect::<Vec<_>>())
    };
    Ok(reader
        .read_morph_targets()
        .map(|(dp, dn, dt)| Target {
            positions: vecs(dp),
            normals: vecs(dn),
            tangents: vecs(dt),
        })
        .collect())
}

/// Morph target `k`'s weight in `weights` (0 where missing or not finite).
fn weight(weights: &[f32], k: usize) -> f32 {
    weights
        .get(k)
        .copied()
        .filter(|w| w.is_finite())
        .unwrap_or(0.0)
}

/// Vertex `s` blended with `targets` at `weights`: position and normal.
pub fn morph_vertex(
    targets: &[Target],
    weights: &[f32],
    s: usize,
    mut p: Vec3,
    mut n: Vec3,
) -> (Vec3, Vec3) {
    for (k, t) in targets.iter().enumerate() {
        let w = weight(weights, k);
        if w == 0.0 {
            continue;
        }
        if let Some(d) = &t.positions {
            p += d[s] * w;
        }
        if let Some(d) = &t.normals {
            n += d[s] * w;
        }
    }
    (p, n)
}

/// Blends the primitive's morph targets into `a` with `weights` (the
/// node's, else the mesh's; missing weights are 0).
pub fn apply_morph(
    prim: &gltf::Primitive,
    weights: &[f32],
    buffers: &[Vec<u8>],
    a: &mut Attributes,
) -> Result<(), String> {
    if prim.morph_targets().next().is_none() || weights.iter().all(|w| *w == 0.0) {
        return Ok(());
    }
    let targets = read_targets(prim, buffers, a.positions.len())?;
    for (s, p) in a.positions.iter_mut().enumerate() {
        let n = a.normals.as_ref().map_or(Vec3::ZERO, |v| v[s]);
        let (q, m) = morph_vertex(&targets, weights, s, *p, n);
        *p = q;
        if let Some(normals) = a.normals.as_mut() {
            normals[s] = m;
        }
    }
    if let Some(tangents) = a.tangents.as_mut() {
        for (k, t) in targets.iter().enumerate() {
            let w = weight(weights, k);
            if let (Some(d), true) = (&t.tangents, w != 0.0) {
                for (v, d) in tangents.iter_mut().zip(d) {
                    *v += d.extend(0.0) * w;
                }
            }
        }
    }
    if a.positions.iter().any(|p| !p.is_finite()) {
        return Err("its morph targets make positions non-finite".into());
    }
    Ok(())
}

/// A vertex's joints and weights (up to eight; unused slots weigh 0) and
/// the inverse of their sum (0: the vertex has no weight and follows the
/// skin's first joint).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Influences {
    pub joints: [u16; 8],
    pub weights: [f32; 8],
    pub inv_total: f32,
}

impl Influences {
    /// The matrix placing the vertex: sum of weight * joint matrix over its
    /// influences, over their total.
    pub fn blend(&self, joint_m: &[Mat4]) -> Mat4 {
        if self.inv_total == 0.0 {
            return joint_m[0];
        }
        let mut m = Mat4::ZERO;
        for (j, w) in self.joints.iter().zip(&self.weights) {
            if *w > 0.0 {
                m += joint_m[*j as usize] * *w;
            }
        }
        m * self.inv_total
    }
}

/// The skin's joints (node indices) and inverse bind matrices (identity
/// where the file gives none).
pub fn read_skin(
    skin: &gltf::Skin,
    buffers: &[Vec<u8>],
) -> Result<(Vec<usize>, Vec<Mat4>), String> {
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    if joints.is_empty() {
        return Err(format!("skin {} has no joints", skin.index()));
    }
    let ibm: Vec<Mat4> = match skin.inverse_bind_matrices() {
        Some(acc) => {
            if acc.data_type() != DataType::F32
                || acc.dimensions() != Dimensions::Mat4
                || acc.count() < joints.len()
            {
                return Err(format!(
                    "skin {}: its inverseBindMatrices accessor is {} {:?} {:?}, not {} float MAT4",
                    skin.index(),
                    acc.count(),
                    acc.data_type(),
                    acc.dimensions(),
                    joints.len()
                ));
            }
            let r = skin.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            r.read_inverse_bind_matrices()
                .ok_or("the skin's inverse bind matrices cannot be read")?
                .map(|m| Mat4::from_cols_array_2d(&m))
                .collect()
        }
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    Ok((joints, ibm))
}

/// The joint matrices of a skin with every node's world transform:
/// jointWorld * inverseBind per joint; a non-finite one is an error.
pub fn joint_matrices(
    joints: &[usize],
    ibm: &[Mat4],
    worlds: &[Mat4],
) -> Result<Vec<Mat4>, String> {
    let m: Vec<Mat4> = joints
        .iter()
        .zip(ibm)
        .map(|(&j, b)| worlds.get(j).copied().unwrap_or(Mat4::IDENTITY) * *b)
        .collect();
    match m.iter().position(|m| !m.is_finite()) {
        Some(j) => Err(format!("joint {j}'s matrix is not finite")),
        None => Ok(m),
    }
}

/// Per vertex of a skinned primitive: its influences from JOINTS_0 and
/// WEIGHTS_0, plus JOINTS_1 and WEIGHTS_1 for eight. A joint out of the
/// skin's `count` joints with a weight is an error; weights that are not
/// positive and finite are dropped.
pub fn read_influences(
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    n: usize,
    count: usize,
) -> Result<Vec<Influences>, String> {
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let empty = Influences {
        joints: [0; 8],
        weights: [0.0; 8],
        inv_total: 0.0,
    };
    let mut out = vec![empty; n];
    let mut any = false;
    for set in 0..2u32 {
        let (Some(ja), Some(wa)) = (
            prim.get(&gltf::Semantic::Joints(set)),
            prim.get(&gltf::Semantic::Weights(set)),
        ) else {
            continue;
        };
        let ok_j = ja.dimensions() == Dimensions::Vec4
            && matches!(ja.data_type(), DataType::U8 | DataType::U16);
        let ok_w = wa.dimensions() == Dimensions::Vec4
            && matches!(wa.data_type(), DataType::U8 | DataType::U16 | DataType::F32);
        if !ok_j || !ok_w || ja.count() != n || wa.count() != n {
            return Err(format!(
                "its JOINTS_{set}/WEIGHTS_{set} accessors are not {n} VEC4 of unsigned integers / weights"
            ));
        }
        let (Some(js), Some(ws)) = (reader.read_joints(set), reader.read_weights(set)) else {
            return Err(format!("its JOINTS_{set}/WEIGHTS_{set} cannot be read"));
        };
        for (v, (j, w)) in js.into_u16().zip(ws.into_f32()).enumerate() {
            for k in 0..4 {
                let w = w[k];
                if w == 0.0 {
                    continue;
                }
                if j[k] as usize >= count {
                    return Err(format!(
                        "vertex {v}: joint {} is out of range (the skin has {count})",
                        j[k]
                    ));
                }
                if !(w.is_finite() && w > 0.0) {
                    continue;
                }
                let slot = set as usize * 4 + k;
                out[v].joints[slot] = j[k];
                out[v].weights[slot] = w;
                any = true;
            }
        }
    }
    if !any {
        return Err("a skinned primitive without JOINTS_0 and WEIGHTS_0".into());
    }
    for i in &mut out {
        let total: f32 = i.weights.iter().sum();
        i.inv_total = if total > 0.0 && total.is_finite() {
            1.0 / total
        } else {
            0.0
        };
    }
    Ok(out)
}

/// Per vertex of a skinned primitive: the matrix placing it in the world
/// at the joints' default transforms (`worlds`). Weights are normalized to
/// sum 1; a vertex without any weight stays at the skin's first joint.
pub fn skin_matrices(
    prim: &gltf::Primitive,
    skin: &gltf::Skin,
    worlds: &[Mat4],
    buffers: &[Vec<u8>],
    n: usize,
) -> Result<Vec<Mat4>, String> {
    let (joints, ibm) = read_skin(skin, buffers)?;
    let joint_m =
        joint_matrices(&joints, &ibm, worlds).map_err(|e| format!("skin {}: {e}", skin.index()))?;
    let inf = read_influences(prim, buffers, n, joint_m.len())?;
    let out: Vec<Mat4> = inf.iter().map(|i| i.blend(&joint_m)).collect();
    if out.iter().any(|m| !m.is_finite()) {
        return Err("its skinning weights give non-finite matrices".into());
    }
    Ok(out)
}

/// The file's animations as clips; one whose channels cannot be read or
/// make no sense holds the reason instead.
pub fn read_clips(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
) -> Vec<(String, Result<Clip, String>)> {
    doc.animations()
        .map(|a| {
            let name = a.name().unwrap_or("").to_string();
            (name, read_clip(doc, &a, buffers))
        })
        .collect()
}

fn read_clip(
    doc: &gltf::Document,
    a: &gltf::Animation,
    buffers: &[Vec<u8>],
) -> Result<Clip, String> {
    let mut channels = Vec::new();
    for i in 0..a.channels().count() {
        let c =
            read_channel(doc, a.index(), i, buffers).map_err(|e| format!("channel {i}: {e}"))?;
        channels.push(c);
    }
    let duration = channels
        .iter()
        .filter_map(|c: &Channel| c.times.last().copied())
        .fold(0.0f32, f32::max);
    Ok(Clip {
        name: a.name().unwrap_or("").to_string(),
        channels,
        duration,
    })
}

/// Channel `i` of `a`, read from the JSON (the gltf crate's accessors
/// unwrap values its validation lets through, such as an unknown path).
fn read_channel(
    document: &gltf::Document,
    a: usize,
    i: usize,
    buffers: &[Vec<u8>],
) -> Result<Channel, String> {
    use gltf::animation::{Interpolation as I, Property};
    use gltf::json::validation::Checked;
    let doc = document.as_json();
    let json = doc.animations.get(a).ok_or("the animation is missing")?;
    let ch = json.channels.get(i).ok_or("it is missing")?;
    let node = ch.target.node.value();
    if node >= doc.nodes.len() {
        return Err(format!("its target node {node} does not exist"));
    }
    let path = match &ch.target.path {
        Checked::Valid(Property::Translation) => ChannelPath::Translation,
        Checked::Valid(Property::Rotation) => ChannelPath::Rotation,
        Checked::Valid(Property::Scale) => ChannelPath::Scale,
        Checked::Valid(Property::MorphTargetWeights) => ChannelPath::Weights,
        Checked::Invalid => {
            return Err("its target path is not translation, rotation, scale or weights".into());
        }
    };
    let sampler = json
        .samplers
        .get(ch.sampler.value())
        .ok_or_else(|| format!("its sampler {} does not exist", ch.sampler.value()))?;
    let interpolation = match &sampler.interpolation {
        Checked::Valid(I::Step) => Interpolation::Step,
        Checked::Valid(I::Linear) => Interpolation::Linear,
        Checked::Valid(I::CubicSpline) => Interpolation::CubicSpline,
        Checked::Invalid => {
            return Err("its interpolation is not STEP, LINEAR or CUBICSPLINE".into());
        }
    };
    let accessor = |k: usize| {
        document
            .accessors()
            .nth(k)
            .ok_or_else(|| format!("its accessor {k} does not exist"))
    };
    let input = accessor(sampler.input.value())?;
    if input.dimensions() != Dimensions::Scalar || input.data_type() != DataType::F32 {
        return Err(format!(
            "its input accessor {} is {:?} {:?}, not float SCALAR times",
            input.index(),
            input.data_type(),
            input.dimensions()
        ));
    }
    let times: Vec<f32> = read_floats::<1>(&input, buffers)?
        .into_iter()
        .map(|[t]| t)
        .collect();
    let output = accessor(sampler.output.value())?;
    let (width, values): (usize, Vec<f32>) = match path {
        ChannelPath::Translation | ChannelPath::Scale => {
            need(&output, Dimensions::Vec3, "VEC3")?;
            (3, read_floats::<3>(&output, buffers)?.concat())
        }
        ChannelPath::Rotation => {
            need(&output, Dimensions::Vec4, "VEC4")?;
            (4, read_floats::<4>(&output, buffers)?.concat())
        }
        ChannelPath::Weights => {
            need(&output, Dimensions::Scalar, "SCALAR")?;
            let v: Vec<f32> = read_floats::<1>(&output, buffers)?.concat();
            let per = if interpolation == Interpolation::CubicSpline {
                3
            } else {
                1
            };
            let keys = times.len() * per;
            if keys == 0 || !v.len().is_multiple_of(keys) {
                return Err(format!(
                    "its {} weights do not divide into {} keys",
                    v.len(),
                    times.len()
                ));
            }
            (v.len() / keys, v)
        }
    };
    let c = Channel {
        node,
        path,
        interpolation,
        times,
        values,
        width,
    };
    c.check()?;
    Ok(c)
}

fn need(a: &gltf::Accessor, dims: Dimensions, name: &str) -> Result<(), String> {
    if a.dimensions() != dims {
        return Err(format!(
            "its output accessor {} is {:?}, not {name}",
            a.index(),
            a.dimensions()
        ));
    }
    Ok(())
}
