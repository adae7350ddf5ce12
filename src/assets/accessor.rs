//! A glTF primitive's attributes as the loaders hand them on, and glTF
//! accessors of any component type as floats: what
//! KHR_mesh_quantization allows for positions, normals, tangents and
//! texture coordinates (8- and 16-bit integers, normalized or not, signed
//! or not), which the gltf crate's readers take as f32 only. Ranges were
//! checked against the buffers (`check_accessors`) before this runs.

use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};

/// The elements of `a` as `N` floats each; normalized integers map to
/// [0, 1] (unsigned) or [-1, 1] (signed, max(v / max, -1)), others keep
/// their value.
pub fn read_floats<const N: usize>(
    a: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<[f32; N]>, String> {
    let dims = match a.dimensions() {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        other => {
            return Err(format!(
                "accessor {}: {other:?} where vectors were expected",
                a.index()
            ));
        }
    };
    if dims < N {
        return Err(format!(
            "accessor {}: {dims} components, {N} expected",
            a.index()
        ));
    }
    if a.sparse().is_some() {
        return Err(format!(
            "accessor {}: sparse accessors of quantized (integer) data are not supported",
            a.index()
        ));
    }
    let Some(view) = a.view() else {
        // No view: all zeros, as the specification says.
        return Ok(vec![[0.0; N]; a.count()]);
    };
    let comp = a.data_type().size();
    let stride = view.stride().unwrap_or(a.size());
    let data = buffers
        .get(view.buffer().index())
        .and_then(|b| b.get(view.offset()..view.offset().checked_add(view.length())?))
        .ok_or_else(|| format!("accessor {}: its view lies outside its buffer", a.index()))?;
    let norm = a.normalized();
    let value = |b: &[u8]| -> f32 {
        match a.data_type() {
            DataType::I8 => {
                let v = b[0] as i8 as f32;
                if norm { (v / 127.0).max(-1.0) } else { v }
            }
            DataType::U8 => {
                let v = b[0] as f32;
                if norm { v / 255.0 } else { v }
            }
            DataType::I16 => {
                let v = i16::from_le_bytes([b[0], b[1]]) as f32;
                if norm { (v / 32767.0).max(-1.0) } else { v }
            }
            DataType::U16 => {
                let v = u16::from_le_bytes([b[0], b[1]]) as f32;
                if norm { v / 65535.0 } else { v }
            }
            DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        }
    };
    (0..a.count())
        .map(|i| {
            let start = a.offset() + i * stride;
            let mut out = [0.0; N];
            for (k, o) in out.iter_mut().enumerate() {
                let at = start + k * comp;
                let bytes = data.get(at..at + comp).ok_or_else(|| {
                    format!("accessor {}: element {i} lies outside its view", a.index())
                })?;
                *o = value(bytes);
            }
            Ok(out)
        })
        .collect()
}

/// A primitive's vertex attributes and indices, read and checked: every
/// attribute as long as POSITION, every index in range.
pub struct Attributes {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub tangents: Option<Vec<Vec4>>,
    pub uv: [Option<Vec<Vec2>>; 2],
    pub colors: Option<Vec<Vec4>>,
    /// Without an index accessor: 0..n.
    pub indices: Vec<u32>,
}
