//! KHR_draco_mesh_compression: a primitive whose attributes and indices
//! are one Draco bitstream in a buffer view, decoded by the pure-Rust
//! `draco-core` crate (Apache-2.0; decoding bounded by its `DecodeLimits`, set from the memory
//! budget).
//! The extension maps each glTF attribute to a Draco attribute id; the
//! accessors still give count, type and normalization.

use glam::{Vec2, Vec3, Vec4};
use serde_json::Value;

use super::accessor::Attributes;

/// The primitive's attributes from its Draco stream.
pub(super) fn read(
    prim: &gltf::Primitive,
    ext: &Value,
    buffers: &[Vec<u8>],
    views: &[(usize, usize, usize)],
    budget: u64,
) -> Result<Attributes, String> {
    let err = |m: String| format!("KHR_draco_mesh_compression: {m}");
    if prim.mode() != gltf::mesh::Mode::Triangles {
        return Err(err(format!(
            "mode {:?}: only triangles are compressed",
            prim.mode()
        )));
    }
    let view_index = ext
        .get("bufferView")
        .and_then(Value::as_u64)
        .ok_or_else(|| err("no bufferView".into()))?;
    let &(buffer, offset, length) = views
        .get(view_index as usize)
        .ok_or_else(|| err(format!("buffer view {view_index} does not exist")))?;
    let bytes = buffers
        .get(buffer)
        .and_then(|b| b.get(offset..offset.checked_add(length)?))
        .ok_or_else(|| err(format!("buffer view {view_index} lies outside its buffer")))?;
    // The decoded attributes are copied once more into the mesh: half
    // the budget each; a face is 12 bytes of indices, twice.
    let limits = draco_core::DecodeLimits::default()
        .with_max_decoded_bytes(budget / 2)
        .with_max_faces(budget / 24);
    let mut buffer = draco_core::DecoderBuffer::new(bytes).with_limits(limits);
    let mut mesh = draco_core::Mesh::new();
    draco_core::MeshDecoder::new()
        .decode(&mut buffer, &mut mesh)
        .map_err(|e| err(format!("the Draco stream cannot be decoded: {e}")))?;
    let n = mesh.num_points();
    let ids = ext.get("attributes").and_then(Value::as_object);
    let attribute = |name: &str, comps: usize| -> Result<Option<Vec<f32>>, String> {
        let Some(id) = ids.and_then(|m| m.get(name)).and_then(Value::as_u64) else {
            return Ok(None);
        };
        let att = mesh
            .attribute_by_unique_id(id as u32)
            .ok_or_else(|| err(format!("{name}: the stream has no attribute {id}")))?;
        let mut v = att.read_f32s(n, comps);
        // Integer attributes (colours, some texture coordinates) come out
        // as their stored values; the accessor says whether they are
        // normalized.
        let accessor = prim
            .attributes()
            .find(|(s, _)| s.to_string() == name)
            .map(|(_, a)| a);
        if accessor.is_some_and(|a| a.normalized()) {
            let max = match att.data_type() {
                draco_core::DataType::Uint8 => 255.0,
                draco_core::DataType::Int8 => 127.0,
                draco_core::DataType::Uint16 => 65535.0,
                draco_core::DataType::Int16 => 32767.0,
                _ => 1.0,
            };
            v.iter_mut().for_each(|x| *x = (*x / max).max(-1.0));
        }
        Ok(Some(v))
    };
    let positions: Vec<Vec3> = attribute("POSITION", 3)?
        .ok_or_else(|| err("the stream has no POSITION".into()))?
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect();
    let normals =
        attribute("NORMAL", 3)?.map(|v| v.chunks_exact(3).map(Vec3::from_slice).collect());
    let tangents =
        attribute("TANGENT", 4)?.map(|v| v.chunks_exact(4).map(Vec4::from_slice).collect());
    let uv = [
        attribute("TEXCOORD_0", 2)?.map(|v| v.chunks_exact(2).map(Vec2::from_slice).collect()),
        attribute("TEXCOORD_1", 2)?.map(|v| v.chunks_exact(2).map(Vec2::from_slice).collect()),
    ];
    let colors = match attribute("COLOR_0", 4)? {
        Some(v) => {
            // RGB colours: alpha 1.
            let rgb = prim
                .get(&gltf::Semantic::Colors(0))
                .is_some_and(|a| a.dimensions() == gltf::accessor::Dimensions::Vec3);
            Some(
                v.chunks_exact(4)
                    .map(|c| Vec4::new(c[0], c[1], c[2], if rgb { 1.0 } else { c[3] }))
                    .collect(),
            )
        }
        None => None,
    };
    let mut indices = Vec::with_capacity(mesh.num_faces() * 3);
    for f in mesh.faces() {
        for p in f {
            if p.0 as usize >= n {
                return Err(err(format!(
                    "a face names point {}, the stream has {n}",
                    p.0
                )));
            }
            indices.push(p.0);
        }
    }
    Ok(Attributes {
        positions,
        normals,
        tangents,
        uv,
        colors,
        indices,
    })
}
