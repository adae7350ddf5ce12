//! STL models, ASCII and binary, read by the `stl_io` crate. STL is
//! faceted (CAD, 3D printing): each triangle is shaded flat with the normal
//! of its corners' winding (the file's own normals are often zero or stale).

use std::path::Path;

use glam::Vec3;

use super::mesh::{Group, Mesh};
use crate::error::Error;

pub fn load(path: &Path, input: &super::input::Input) -> Result<Mesh, Error> {
    let bytes = input.read(path, None, None)?;
    let mut cursor = std::io::Cursor::new(bytes);
    let stl = stl_io::read_stl(&mut cursor)
        .map_err(|e| Error::asset(path, None, format!("malformed STL: {e}")))?;
    let mut mesh = Mesh::default();
    for face in &stl.faces {
        let Some(p) = face
            .vertices
            .iter()
            .map(|&i| stl.vertices.get(i).map(|v| Vec3::from(v.0)))
            .collect::<Option<Vec<Vec3>>>()
        else {
            return Err(Error::asset(
                path,
                None,
                "malformed STL: a vertex index out of range",
            ));
        };
        if p.iter().any(|v| !v.is_finite()) {
            return Err(Error::asset(path, None, "a vertex position is not finite"));
        }
        let n = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize();
        let n = n
            .or_else(|| Vec3::from(face.normal.0).try_normalize())
            .unwrap_or(Vec3::Y);
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(&p);
        mesh.normals.extend([n; 3]);
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    if mesh.triangles.is_empty() {
        return Err(Error::asset(path, None, "the model has no faces"));
    }
    mesh.groups.push(Group {
        triangles: 0..mesh.triangles.len() as u32,
        material: 0,
        part: 0,
    });
    Ok(mesh)
}
