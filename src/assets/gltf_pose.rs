//! The default pose of skinned and morphed glTF meshes: morph targets
//! blended with the node's (or the mesh's) default weights, and skinned
//! vertices placed by their joints at the joints' default transforms
//! (glTF: a skinned mesh ignores its own node's transform; each vertex is
//! sum of weight_i * jointWorld_i * inverseBind_i applied to it). Playback
//! of animation clips is not here yet: every frame shows this pose.

use glam::{Mat4, Vec3};
use gltf::accessor::{DataType, Dimensions};

use super::accessor::Attributes;

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

/// Blends the primitive's morph targets into `a` with `weights` (the
/// node's, else the mesh's; missing weights are 0). Only float targets are
/// read; a target of another type or length is an error.
pub fn apply_morph(
    prim: &gltf::Primitive,
    weights: &[f32],
    buffers: &[Vec<u8>],
    a: &mut Attributes,
) -> Result<(), String> {
    let targets: Vec<_> = prim.morph_targets().collect();
    if targets.is_empty() || weights.iter().all(|w| *w == 0.0) {
        return Ok(());
    }
    let n = a.positions.len();
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
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    for (k, (dp, dn, dt)) in reader.read_morph_targets().enumerate() {
        let w = weights.get(k).copied().unwrap_or(0.0);
        if w == 0.0 || !w.is_finite() {
            continue;
        }
        if let Some(dp) = dp {
            for (p, d) in a.positions.iter_mut().zip(dp) {
                *p += Vec3::from(d) * w;
            }
        }
        if let (Some(dn), Some(normals)) = (dn, a.normals.as_mut()) {
            for (v, d) in normals.iter_mut().zip(dn) {
                *v += Vec3::from(d) * w;
            }
        }
        if let (Some(dt), Some(tangents)) = (dt, a.tangents.as_mut()) {
            for (v, d) in tangents.iter_mut().zip(dt) {
                *v += Vec3::from(d).extend(0.0) * w;
            }
        }
    }
    if a.positions.iter().any(|p| !p.is_finite()) {
        return Err("its morph targets make positions non-finite".into());
    }
    Ok(())
}

/// Per vertex of a skinned primitive: the matrix placing it in the world,
/// sum of weight * jointWorld * inverseBind over its influences (JOINTS_0
/// and WEIGHTS_0, plus JOINTS_1 and WEIGHTS_1 for eight). Weights are
/// normalized to sum 1; a vertex without any weight stays at the skin's
/// first joint.
pub fn skin_matrices(
    prim: &gltf::Primitive,
    skin: &gltf::Skin,
    worlds: &[Mat4],
    buffers: &[Vec<u8>],
    n: usize,
) -> Result<Vec<Mat4>, String> {
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
    let joint_m: Vec<Mat4> = joints
        .iter()
        .zip(&ibm)
        .map(|(&j, b)| worlds[j] * *b)
        .collect();
    if let Some(j) = joint_m.iter().position(|m| !m.is_finite()) {
        return Err(format!(
            "skin {}: joint {j}'s matrix is not finite",
            skin.index()
        ));
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let mut acc = vec![(Mat4::ZERO, 0.0f32); n];
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
                let m = joint_m.get(j[k] as usize).ok_or_else(|| {
                    format!(
                        "vertex {v}: joint {} is out of range (the skin has {})",
                        j[k],
                        joint_m.len()
                    )
                })?;
                if !(w.is_finite() && w > 0.0) {
                    continue;
                }
                acc[v].0 += *m * w;
                acc[v].1 += w;
                any = true;
            }
        }
    }
    if !any {
        return Err("a skinned primitive without JOINTS_0 and WEIGHTS_0".into());
    }
    let out: Vec<Mat4> = acc
        .into_iter()
        .map(|(m, w)| if w > 0.0 { m * (1.0 / w) } else { joint_m[0] })
        .collect();
    if out.iter().any(|m| !m.is_finite()) {
        return Err("its skinning weights give non-finite matrices".into());
    }
    Ok(out)
}
