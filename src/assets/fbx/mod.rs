//! FBX models through ufbx (the `ufbx` crate, MIT OR Unlicense, around
//! the ufbx C library): binary and ASCII FBX 6 and 7.
//!
//! What is read:
//! - every mesh instance of the node tree, placed by its node's
//!   geometry-to-world transform, in Y-up metres (ufbx converts the file's
//!   axes and unit, as glTF's are);
//! - per corner: position, normal (made by ufbx where the file has none),
//!   the first UV set and the first colour set;
//! - faces triangulated (ear clipping, by ufbx), grouped by material;
//! - materials as metallic-roughness: ufbx's PBR view of each material,
//!   which is the file's own for 3ds Max, Maya and Blender PBR materials
//!   and a conversion of Lambert and Phong (diffuse colour and map, the
//!   specular exponent as roughness, emission, opacity, normal map);
//! - textures embedded in the file, or external (relative to the FBX file,
//!   then by name beside it); a missing one is a warning, as for glTF.
//!
//! - skins, blend shapes and animation stacks (`rig`), played as glTF
//!   animation is: `model.animation` names a stack or gives its index.
//!
//! - lights and cameras (`lights`), for `model.lights` and
//!   `model.cameras`.

mod lights;
mod rig;

use std::path::Path;
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};

use super::rig::Rig;

use super::gltf::{GltfAlphaMode, GltfCamera, GltfLight, GltfMaterial, ImageSource, TexInfo};
use super::input::Input;
use super::mesh::{Group, Mesh};
use super::texture::{AddressMode, Wrap};
use crate::error::Error;

/// A model read from an FBX file.
#[derive(Debug)]
pub struct FbxModel {
    pub mesh: Mesh,
    /// Indexed by `Group::material`.
    pub materials: Vec<GltfMaterial>,
    pub warnings: Vec<String>,
    /// Files with skins or animation stacks: what posing the mesh at
    /// other times takes, or why it cannot be done.
    pub rig: Option<Result<Arc<Rig>, String>>,
    /// Placed in the file's (converted) space.
    pub lights: Vec<GltfLight>,
    pub cameras: Vec<GltfCamera>,
}

/// Reads the FBX file at `path` through `input` (bounded reads, the
/// sandbox, the memory budget).
pub fn load(path: &Path, input: &Input) -> Result<FbxModel, Error> {
    let bytes = input.read(path, None, None)?;
    // ufbx sizes arrays as the file declares them; a compressed array
    // inflates at most about 1,032 times, so more than that per byte of
    // file (or more than the budget) is a lie, refused as ufbx's
    // "memory limit" before it is allocated.
    let limit = (bytes.len() as u64)
        .saturating_mul(1100)
        .saturating_add(64 << 20)
        .min(input.budget());
    let alloc = |limit: u64| ufbx::AllocatorOpts {
        memory_limit: usize::try_from(limit).unwrap_or(usize::MAX),
        ..Default::default()
    };
    let opts = ufbx::LoadOpts {
        temp_allocator: alloc(limit),
        result_allocator: alloc(limit),
        load_external_files: false,
        ignore_missing_external_files: true,
        generate_missing_normals: true,
        target_axes: ufbx::CoordinateAxes::right_handed_y_up(),
        target_unit_meters: 1.0,
        space_conversion: ufbx::SpaceConversion::ModifyGeometry,
        ..Default::default()
    };
    let scene = ufbx::load_memory(&bytes, opts).map_err(|e| {
        Error::asset(
            path,
            None,
            format!("cannot read the FBX file: {}", e.description),
        )
    })?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut model = FbxModel {
        mesh: Mesh::default(),
        materials: Vec::new(),
        warnings: Vec::new(),
        rig: None,
        lights: Vec::new(),
        cameras: Vec::new(),
    };
    let mut materials: Vec<(u32, usize)> = Vec::new();
    let mut instances = Vec::new();
    for node in scene.nodes.iter() {
        let Some(mesh) = &node.mesh else { continue };
        let world = matrix(&node.geometry_to_world);
        let list = &mut model.materials;
        let first = model.mesh.positions.len() as u32;
        let mut instance = rig::Instance {
            node: node.element.typed_id as usize,
            first,
            vertices: Vec::new(),
            corners: Vec::new(),
        };
        add_mesh(
            &mut model.mesh,
            (mesh, node, world),
            &mut instance,
            &mut |m: Option<&ufbx::Material>| {
                // Materials by element id, each converted once.
                let id = m.map_or(u32::MAX, |m| m.element.element_id);
                if let Some(&(_, k)) = materials.iter().find(|(i, _)| *i == id) {
                    return k;
                }
                let k = model_material(list, m, dir);
                materials.push((id, k));
                k
            },
        );
        instances.push(instance);
    }
    if model.mesh.triangles.is_empty() {
        return Err(Error::asset(
            path,
            None,
            "the FBX file has no mesh with faces",
        ));
    }
    let rigged = !scene.skin_deformers.is_empty() || !scene.blend_deformers.is_empty();
    if rigged || !scene.anim_stacks.is_empty() {
        model.rig = Some(rig::rig(&scene, &instances).map(Arc::new));
    }
    model.lights = lights::lights(&scene, &mut model.warnings);
    model.cameras = lights::cameras(&scene);
    for m in &model.materials {
        for (t, _) in m.textures() {
            if let ImageSource::File(p) = &t.image
                && !p.is_file()
            {
                model.warnings.push(format!(
                    "{}: texture {} not found; the material renders without it",
                    path.display(),
                    p.display()
                ));
            }
        }
    }
    Ok(model)
}

/// Appends the triangles of `mesh` as `node` places it (`world`), with
/// `material` giving the model's material index of each of its materials;
/// records where each vertex came from in `instance`.
fn add_mesh(
    out: &mut Mesh,
    (mesh, node, world): (&ufbx::Mesh, &ufbx::Node, Mat4),
    instance: &mut rig::Instance,
    material: &mut dyn FnMut(Option<&ufbx::Material>) -> usize,
) {
    let normal_world = Mat4::from_mat3(glam::Mat3::from_mat4(world).inverse().transpose());
    let has_uv = mesh.vertex_uv.exists;
    let has_color = mesh.vertex_color.exists;
    let mut corners = vec![0u32; mesh.max_face_triangles * 3];
    // A node's own materials (per instance) win over its mesh's.
    let list = if node.materials.is_empty() {
        &mesh.materials
    } else {
        &node.materials
    };
    for part in mesh.material_parts.iter() {
        if part.num_triangles == 0 {
            continue;
        }
        let m = list.get(part.index as usize).map(|m| &**m);
        let k = material(m);
        let first = out.triangles.len() as u32;
        for &f in part.face_indices.iter() {
            let face = mesh.faces[f as usize];
            let n = mesh.triangulate_face(&mut corners, face) as usize;
            for tri in corners[..3 * n].chunks_exact(3) {
                let base = out.positions.len() as u32;
                for &ix in tri {
                    instance.corners.push(ix);
                    instance.vertices.push(mesh.vertex_indices[ix as usize]);
                    let ix = ix as usize;
                    let p = vec3(&mesh.vertex_position[ix]);
                    out.positions.push(world.transform_point3(p));
                    let nrm = if mesh.vertex_normal.exists {
                        normal_world.transform_vector3(vec3(&mesh.vertex_normal[ix]))
                    } else {
                        Vec3::ZERO
                    };
                    out.normals.push(nrm.normalize_or(Vec3::Y));
                    if has_uv {
                        let uv = &mesh.vertex_uv[ix];
                        // FBX's v runs up; the mesh's image convention down.
                        out.uvs.push(Vec2::new(uv.x as f32, 1.0 - uv.y as f32));
                    }
                    if has_color {
                        let c = &mesh.vertex_color[ix];
                        out.colors
                            .push(Vec4::new(c.x as f32, c.y as f32, c.z as f32, c.w as f32));
                    }
                }
                out.triangles.push([base, base + 1, base + 2]);
            }
        }
        out.groups.push(Group {
            triangles: first..out.triangles.len() as u32,
            material: k,
            part: 0,
        });
    }
    // A set only some meshes have: the others' corners get neutral values.
    let n = out.positions.len();
    if !out.uvs.is_empty() {
        out.uvs.resize(n, Vec2::ZERO);
    }
    if !out.colors.is_empty() {
        out.colors.resize(n, Vec4::ONE);
    }
}

/// Appends the metallic-roughness form of `m` (the default material for
/// None) to `materials`; its index.
fn model_material(
    materials: &mut Vec<GltfMaterial>,
    m: Option<&ufbx::Material>,
    dir: &Path,
) -> usize {
    let mut g = GltfMaterial::default_material();
    if let Some(m) = m {
        let p = &m.pbr;
        let value = |map: &ufbx::MaterialMap, default: f32| {
            if map.has_value {
                map.value_vec4.x as f32
            } else {
                default
            }
        };
        let color = |map: &ufbx::MaterialMap| {
            let v = &map.value_vec4;
            Vec3::new(v.x as f32, v.y as f32, v.z as f32)
        };
        let texture = |map: &ufbx::MaterialMap| {
            map.texture
                .as_ref()
                .filter(|_| map.texture_enabled)
                .and_then(|t| tex_info(t, dir))
        };
        g.name = m.element.name.to_string();
        let base = color(&p.base_color) * value(&p.base_factor, 1.0);
        let opacity = value(&p.opacity, 1.0).clamp(0.0, 1.0);
        g.base_color = base.extend(opacity);
        g.base_color_tex = texture(&p.base_color);
        g.metallic = value(&p.metalness, 0.0).clamp(0.0, 1.0);
        g.roughness = value(&p.roughness, 0.5).clamp(0.0, 1.0);
        g.normal_tex = texture(&p.normal_map);
        g.emissive = color(&p.emission_color) * value(&p.emission_factor, 1.0);
        g.emissive_tex = texture(&p.emission_color);
        if opacity < 1.0 {
            g.alpha_mode = GltfAlphaMode::Blend;
        }
        if !g.base_color.is_finite() || !g.emissive.is_finite() {
            g.base_color = Vec4::ONE;
            g.emissive = Vec3::ZERO;
        }
    } else {
        g.metallic = 0.0;
        g.roughness = 0.5;
    }
    materials.push(g);
    materials.len() - 1
}

/// Where texture `t`'s image is: its embedded bytes, else its file
/// relative to the FBX file's folder, else by its name beside the file
/// (exporters write absolute paths of the machine they ran on).
fn tex_info(t: &ufbx::Texture, dir: &Path) -> Option<TexInfo> {
    let image = if !t.content.is_empty() {
        let name = if t.filename.is_empty() {
            format!("embedded{}", t.element.element_id)
        } else {
            t.filename.to_string()
        };
        ImageSource::Memory {
            name: dir.join(format!("{name}#fbx")),
            bytes: Arc::from(&t.content[..]),
        }
    } else {
        let named = [&t.relative_filename, &t.filename, &t.absolute_filename]
            .into_iter()
            .find(|s| !s.is_empty())?
            .replace('\\', "/");
        let relative = dir.join(&named);
        let beside = Path::new(&named).file_name().map(|f| dir.join(f));
        let path = match beside {
            Some(b) if !relative.is_file() && b.is_file() => b,
            _ => relative,
        };
        ImageSource::File(path)
    };
    let wrap = |w: ufbx::WrapMode| match w {
        ufbx::WrapMode::Clamp => AddressMode::Clamp,
        _ => AddressMode::Repeat,
    };
    Some(TexInfo {
        image,
        texcoord: 0,
        transform: glam::Affine2::IDENTITY,
        wrap: Wrap(wrap(t.wrap_u), wrap(t.wrap_v)),
        min_limit: None,
        mag_nearest: false,
    })
}

fn vec3(v: &ufbx::Vec3) -> Vec3 {
    Vec3::new(v.x as f32, v.y as f32, v.z as f32)
}

/// ufbx's affine 3x4 matrix (columns m?0, m?1, m?2, m?3) as a `Mat4`.
fn matrix(m: &ufbx::Matrix) -> Mat4 {
    let c = |x: f64, y: f64, z: f64, w: f32| glam::Vec4::new(x as f32, y as f32, z as f32, w);
    Mat4::from_cols(
        c(m.m00, m.m10, m.m20, 0.0),
        c(m.m01, m.m11, m.m21, 0.0),
        c(m.m02, m.m12, m.m22, 0.0),
        c(m.m03, m.m13, m.m23, 1.0),
    )
}
