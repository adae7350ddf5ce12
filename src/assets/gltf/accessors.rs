//! A primitive's accessors checked against their buffers and read into
//! vertex attributes (positions, normals, tangents, two texture sets,
//! colours, indices; quantized ones through `accessor`).

use super::*;

/// Every accessor lies within its buffer view and buffer, has at least one
/// element, and a stride no smaller than its element (the crate assumes
/// all three); its elements, read out (a sparse or view-less accessor is
/// filled from zeros), fit in the memory budget, and a sparse accessor's
/// indices and values lie within their views.
pub(super) fn check_accessors(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    input: &crate::assets::input::Input,
) -> Result<(), String> {
    for v in doc.views() {
        let len = buffers[v.buffer().index()].len();
        if v.offset()
            .checked_add(v.length())
            .is_none_or(|end| end > len)
        {
            return Err(format!(
                "buffer view {} (bytes {}..{}) lies outside buffer {} ({len} bytes)",
                v.index(),
                v.offset(),
                v.offset().saturating_add(v.length()),
                v.buffer().index()
            ));
        }
    }
    for a in doc.accessors() {
        let i = a.index();
        if a.count() == 0 {
            return Err(format!("accessor {i} has no elements"));
        }
        // Read out as f32 (or u32) components: at most 16 of 4 bytes.
        let read = (a.count() as u64).saturating_mul(a.dimensions().multiplicity() as u64 * 4);
        input
            .check(&format!("accessor {i} ({} elements)", a.count()), read)
            .map_err(|m| m.to_string())?;
        if let Some(sparse) = a.sparse() {
            check_sparse(i, a.count(), a.size(), &sparse)?;
            continue;
        }
        let Some(view) = a.view() else { continue };
        let size = a.size();
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(format!(
                "accessor {i}: its buffer view's stride {stride} is smaller than an element ({size} bytes)"
            ));
        }
        let end = (a.count() - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(a.offset()))
            .and_then(|x| x.checked_add(size));
        if end.is_none_or(|end| end > view.length()) {
            return Err(format!(
                "accessor {i} ({} elements from byte {}) runs past the end of buffer view {} ({} bytes)",
                a.count(),
                a.offset(),
                view.index(),
                view.length()
            ));
        }
    }
    Ok(())
}

/// A sparse accessor: no more substitutions than elements, and its
/// indices and values within their views.
fn check_sparse(
    i: usize,
    count: usize,
    size: usize,
    sparse: &gltf::accessor::sparse::Sparse,
) -> Result<(), String> {
    let n = sparse.count();
    if n > count {
        return Err(format!(
            "accessor {i}: {n} sparse substitutions for {count} elements"
        ));
    }
    let index_size = sparse.indices().index_type().size();
    for (what, view, offset, each) in [
        (
            "indices",
            sparse.indices().view(),
            sparse.indices().offset(),
            index_size,
        ),
        (
            "values",
            sparse.values().view(),
            sparse.values().offset(),
            size,
        ),
    ] {
        let end = n.checked_mul(each).and_then(|x| x.checked_add(offset));
        if end.is_none_or(|end| end > view.length()) {
            return Err(format!(
                "accessor {i}: its {n} sparse {what} from byte {offset} run past the end of buffer view {} ({} bytes)",
                view.index(),
                view.length()
            ));
        }
    }
    Ok(())
}

/// The types of a primitive's accessors, as its readers assume them: an
/// error names the first that is not.
pub(super) fn check_accessor_types(prim: &gltf::Primitive) -> Result<(), String> {
    // KHR_mesh_quantization: integer positions, normals, tangents and
    // texture coordinates, which the gltf crate reads as f32 only.
    // Each attribute's accessor must have its type (the gltf crate's
    // readers assume it); integer ones are read here.
    for (sem, dims, name) in [
        (gltf::Semantic::Positions, Dimensions::Vec3, "POSITION"),
        (gltf::Semantic::Normals, Dimensions::Vec3, "NORMAL"),
        (gltf::Semantic::Tangents, Dimensions::Vec4, "TANGENT"),
        (gltf::Semantic::TexCoords(0), Dimensions::Vec2, "TEXCOORD_0"),
        (gltf::Semantic::TexCoords(1), Dimensions::Vec2, "TEXCOORD_1"),
    ] {
        if let Some(a) = prim.get(&sem)
            && a.dimensions() != dims
        {
            return Err(format!(
                "its {name} accessor is {:?}, not {dims:?}",
                a.dimensions()
            ));
        }
    }
    // The gltf crate's readers reach `unreachable!` on other types.
    if let Some(a) = prim.indices()
        && (a.dimensions() != Dimensions::Scalar
            || !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32))
    {
        return Err(format!(
            "its indices accessor is {:?} {:?}, not unsigned integer scalars",
            a.data_type(),
            a.dimensions()
        ));
    }
    if let Some(a) = prim.get(&gltf::Semantic::Colors(0))
        && (!matches!(a.dimensions(), Dimensions::Vec3 | Dimensions::Vec4)
            || !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::F32))
    {
        return Err(format!(
            "its COLOR_0 accessor is {:?} {:?}, not RGB or RGBA of unsigned bytes, shorts or floats",
            a.data_type(),
            a.dimensions()
        ));
    }
    Ok(())
}

pub(super) fn read_attributes(
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    views: &[(usize, usize, usize)],
    budget: u64,
) -> Result<Attributes, String> {
    if let Some(ext) = prim
        .extensions()
        .and_then(|e| e.get("KHR_draco_mesh_compression"))
    {
        return crate::assets::draco::read(prim, ext, buffers, views, budget);
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let unreadable = |what: &str| format!("its {what} cannot be read from the buffers");
    check_accessor_types(prim)?;
    let quantized = |s: gltf::Semantic| prim.get(&s).filter(|a| a.data_type() != DataType::F32);
    let positions: Vec<Vec3> = match quantized(gltf::Semantic::Positions) {
        Some(a) => read_floats::<3>(&a, buffers)?
            .into_iter()
            .map(Vec3::from)
            .collect(),
        None => reader
            .read_positions()
            .ok_or_else(|| {
                if prim.get(&gltf::Semantic::Positions).is_none() {
                    "it has no POSITION attribute".to_string()
                } else {
                    unreadable("POSITION")
                }
            })?
            .map(Vec3::from)
            .collect(),
    };
    let n = positions.len();
    let same_len = |what: &str, len: usize| {
        if len == n {
            Ok(())
        } else {
            Err(format!("{what} has {len} elements but POSITION has {n}"))
        }
    };
    let normals: Option<Vec<Vec3>> = match quantized(gltf::Semantic::Normals) {
        Some(a) => Some(
            read_floats::<3>(&a, buffers)?
                .into_iter()
                .map(Vec3::from)
                .collect(),
        ),
        None => match reader.read_normals() {
            Some(r) => Some(r.map(Vec3::from).collect()),
            None if prim.get(&gltf::Semantic::Normals).is_some() => {
                return Err(unreadable("NORMAL"));
            }
            None => None,
        },
    };
    let tangents: Option<Vec<Vec4>> = match quantized(gltf::Semantic::Tangents) {
        Some(a) => Some(
            read_floats::<4>(&a, buffers)?
                .into_iter()
                .map(Vec4::from)
                .collect(),
        ),
        None => reader.read_tangents().map(|r| r.map(Vec4::from).collect()),
    };
    let mut uv: [Option<Vec<Vec2>>; 2] = [None, None];
    for (s, slot) in uv.iter_mut().enumerate() {
        *slot = match quantized(gltf::Semantic::TexCoords(s as u32)) {
            Some(a) => Some(
                read_floats::<2>(&a, buffers)?
                    .into_iter()
                    .map(Vec2::from)
                    .collect(),
            ),
            None => reader
                .read_tex_coords(s as u32)
                .map(|r| r.into_f32().map(Vec2::from).collect()),
        };
    }
    let colors: Option<Vec<Vec4>> = reader
        .read_colors(0)
        .map(|r| r.into_rgba_f32().map(Vec4::from).collect());
    if let Some(v) = &normals {
        same_len("NORMAL", v.len())?;
    }
    if let Some(v) = &tangents {
        same_len("TANGENT", v.len())?;
    }
    for (s, v) in uv.iter().enumerate() {
        if let Some(v) = v {
            same_len(&format!("TEXCOORD_{s}"), v.len())?;
        }
    }
    if let Some(v) = &colors {
        same_len("COLOR_0", v.len())?;
    }
    let indices: Vec<u32> = match reader.read_indices() {
        Some(r) => r.into_u32().collect(),
        None if prim.indices().is_some() => return Err(unreadable("indices")),
        None => (0..n as u32).collect(),
    };
    if let Some((k, &bad)) = indices.iter().enumerate().find(|(_, i)| **i as usize >= n) {
        return Err(format!(
            "index {k} is {bad}, out of range: the primitive has {n} vertices"
        ));
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
