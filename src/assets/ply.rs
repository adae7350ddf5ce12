//! PLY models (Stanford polygon files), ASCII and binary, read by the
//! `ply-rs-bw` crate: `vertex` elements with x y z and optionally normals
//! (nx ny nz), colours (red green blue, 0-255 or 0-1) and texture
//! coordinates (s t, u v or texture_u texture_v); `face` elements with a
//! `vertex_indices` (or `vertex_index`) list, polygons triangulated like
//! OBJ faces. Meshes without normals get smooth ones. A file with
//! vertices and no faces (a scanner's point cloud) is drawn as points.

use std::path::Path;

use glam::{Vec2, Vec3, Vec4};
use ply_rs_bw::ply::{DefaultElement, Property};

use super::mesh::{Group, Mesh, Primitive, smooth_normals};
use super::obj::triangulate;
use crate::color::srgb_to_linear;
use crate::error::Error;

pub fn load(path: &Path, input: &super::input::Input) -> Result<Mesh, Error> {
    let err = |msg: String| Error::asset(path, None, msg);
    let bytes = input.read(path, None, None)?;
    let parser = ply_rs_bw::parser::Parser::<DefaultElement>::new();
    let ply = parser
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| err(format!("malformed PLY: {e}")))?;
    let empty = Vec::new();
    let vertices = ply.payload.get("vertex").unwrap_or(&empty);
    let faces = ply.payload.get("face").unwrap_or(&empty);
    let mut mesh = Mesh::default();
    let (mut any_n, mut any_uv, mut any_c) = (false, false, false);
    for v in vertices {
        let p = [scalar(v, "x"), scalar(v, "y"), scalar(v, "z")];
        let [Some(x), Some(y), Some(z)] = p else {
            return Err(err("malformed PLY: a vertex lacks x, y or z".into()));
        };
        let p = Vec3::new(x, y, z);
        if !p.is_finite() {
            return Err(err("a vertex position is not finite".into()));
        }
        mesh.positions.push(p);
        let n = match [scalar(v, "nx"), scalar(v, "ny"), scalar(v, "nz")] {
            [Some(x), Some(y), Some(z)] => Vec3::new(x, y, z).try_normalize(),
            _ => None,
        };
        any_n |= n.is_some();
        mesh.normals.push(n.unwrap_or(Vec3::ZERO));
        let uv = ["s", "u", "texture_u"]
            .iter()
            .zip(["t", "v", "texture_v"])
            .find_map(|(u, w)| Some(Vec2::new(scalar(v, u)?, scalar(v, w)?)));
        any_uv |= uv.is_some();
        // PLY's t runs up, like OBJ's.
        mesh.uvs
            .push(uv.map(|t| Vec2::new(t.x, 1.0 - t.y)).unwrap_or(Vec2::ZERO));
        let c = color(v);
        any_c |= c.is_some();
        mesh.colors.push(c.unwrap_or(Vec4::ONE));
    }
    for (i, face) in faces.iter().enumerate() {
        let Some(idx) = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(list)
        else {
            return Err(err(format!(
                "malformed PLY: face {i} has no vertex_indices list"
            )));
        };
        if idx.len() < 3 {
            continue;
        }
        if let Some(bad) = idx.iter().find(|&&k| k >= mesh.positions.len() as u64) {
            return Err(err(format!(
                "malformed PLY: face {i} names vertex {bad}, the file has {}",
                mesh.positions.len()
            )));
        }
        let pts: Vec<Vec3> = idx.iter().map(|&k| mesh.positions[k as usize]).collect();
        for t in triangulate::triangulate(&pts) {
            mesh.triangles.push(t.map(|k| idx[k] as u32));
        }
    }
    if mesh.triangles.is_empty() && mesh.positions.is_empty() {
        return Err(err("the model has no vertices".into()));
    }
    // A scan's point cloud (vertices, no faces): drawn as its points.
    if mesh.triangles.is_empty() {
        mesh.points = (0..mesh.positions.len() as u32)
            .map(|v| Primitive {
                vertices: [v],
                material: 0,
            })
            .collect();
    }
    if !any_uv {
        mesh.uvs.clear();
    }
    if !any_c {
        mesh.colors.clear();
    }
    let missing: Vec<bool> = mesh.normals.iter().map(|n| *n == Vec3::ZERO).collect();
    if !any_n || missing.iter().any(|m| *m) {
        smooth_normals(
            &mesh.positions,
            &mesh.triangles,
            &mut mesh.normals,
            &missing,
        );
    }
    mesh.groups.push(Group {
        triangles: 0..mesh.triangles.len() as u32,
        material: 0,
        part: 0,
    });
    Ok(mesh)
}

fn scalar(e: &DefaultElement, key: &str) -> Option<f32> {
    Some(match e.get(key)? {
        Property::Char(v) => *v as f32,
        Property::UChar(v) => *v as f32,
        Property::Short(v) => *v as f32,
        Property::UShort(v) => *v as f32,
        Property::Int(v) => *v as f32,
        Property::UInt(v) => *v as f32,
        Property::Float(v) => *v,
        Property::Double(v) => *v as f32,
        _ => return None,
    })
}

/// A vertex colour as linear RGBA: integer channels are 0-255, float
/// channels 0-1, both sRGB-encoded like the displays they were made for.
fn color(e: &DefaultElement) -> Option<Vec4> {
    let int = matches!(
        e.get("red")?,
        Property::UChar(_) | Property::UShort(_) | Property::Int(_) | Property::UInt(_)
    );
    let scale = if int { 1.0 / 255.0 } else { 1.0 };
    let ch = |k: &str| scalar(e, k).map(|v| srgb_to_linear((v * scale).clamp(0.0, 1.0)));
    Some(Vec4::new(ch("red")?, ch("green")?, ch("blue")?, 1.0))
}

fn list(p: &Property) -> Option<Vec<u64>> {
    let conv = |v: i64| u64::try_from(v).unwrap_or(u64::MAX);
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| conv(x as i64)).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as u64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| conv(x as i64)).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as u64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| conv(x as i64)).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as u64).collect(),
        _ => return None,
    })
}
