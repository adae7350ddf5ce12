//! glTF 2.0 through the gltf crate: `.gltf` with external or data-URI
//! buffers and images, and `.glb`. Every node of the default scene is
//! flattened into one mesh in the scene's space (its composed TRS or matrix
//! applied to positions, normals and tangents; mirroring nodes flip the
//! winding), one group per primitive. Triangles, strips and fans, indexed
//! or not. glTF's texture coordinates already have the image's top-left
//! origin, so they are stored as they are (OBJ's are flipped on load).
//!
//! What the crate leaves to us, and is checked here so that bad files give
//! an error instead of a panic or garbage: buffers (GLB chunk, data URIs,
//! files next to the model) and their lengths, accessor ranges, indices
//! within the primitive's vertices, and the required extensions.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use base64::Engine;
use glam::{Affine2, Mat2, Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::accessor::{Attributes, read_floats};
use super::input::Input;
use super::mesh::{Group, Mesh, Primitive};
use super::rig::{Rig, RigNode, RigSkin, Segment, SegmentNormals};
use super::texture::Wrap;
use super::texture::{AddressMode, TextureFilter};
use crate::error::Error;

mod accessors;
mod buffers;
mod lights;
mod materials;
pub mod pose;

use accessors::*;
use buffers::*;
pub use lights::*;
pub use materials::*;

/// Extensions that change how softraster draws a file; a file that
/// requires any other one is refused.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "EXT_meshopt_compression",
    "KHR_draco_mesh_compression",
    "KHR_lights_punctual",
    "KHR_materials_anisotropy",
    "KHR_materials_clearcoat",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_dispersion",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_iridescence",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_volume",
    "KHR_mesh_quantization",
    "KHR_texture_basisu",
    "KHR_texture_transform",
];

/// Where an image's bytes are.
#[derive(Debug, Clone)]
pub enum ImageSource {
    File(PathBuf),
    /// In a buffer or a data URI; `name` (`model.glb#image3`) stands for it.
    Memory {
        name: PathBuf,
        bytes: Arc<[u8]>,
    },
}

impl ImageSource {
    /// The path that names (and caches) the image.
    pub fn key(&self) -> &Path {
        match self {
            ImageSource::File(p) => p,
            ImageSource::Memory { name, .. } => name,
        }
    }
}

#[derive(Debug)]
pub struct GltfModel {
    pub mesh: Mesh,
    /// Indexed by `Group::material`; a default material is appended when a
    /// primitive has none.
    pub materials: Vec<GltfMaterial>,
    pub lights: Vec<GltfLight>,
    pub cameras: Vec<GltfCamera>,
    /// Things ignored on the way (optional extensions, point and line
    /// primitives), for the user to see.
    pub warnings: Vec<String>,
    /// Files with animations: what posing the mesh at other times takes,
    /// or why it cannot be done.
    pub rig: Option<Result<Arc<Rig>, String>>,
    /// KHR_materials_variants: the variants' names, in the file's order.
    pub variants: Vec<String>,
    /// The material slots the variants change (`VariantSlot`).
    pub variant_slots: Vec<VariantSlot>,
}

/// The top-level collections of a glTF file: arrays in 2.0, objects keyed
/// by id in 1.0.
const COLLECTIONS: [&str; 14] = [
    "accessors",
    "animations",
    "bufferViews",
    "buffers",
    "cameras",
    "images",
    "materials",
    "meshes",
    "nodes",
    "samplers",
    "scenes",
    "skins",
    "textures",
    "techniques",
];

/// The version of a glTF 1.x file (`asset.version` "1.0", or a binary
/// glTF with container version 1), None for anything else.
fn version_1(bytes: &[u8]) -> Option<String> {
    if bytes.starts_with(b"glTF") {
        let v = u32::from_le_bytes(bytes.get(4..8)?.try_into().ok()?);
        return (v == 1).then(|| "1.0 (binary)".to_string());
    }
    let json: serde_json::Value = serde_json::from_slice(bytes).ok()?;
    let v = json.get("asset").and_then(|a| a.get("version"));
    match v {
        Some(serde_json::Value::String(s)) if s.starts_with("1.") => Some(s.clone()),
        // 1.0 files may lack asset.version; their top-level collections
        // (meshes, accessors, nodes, ...) are objects keyed by id, not
        // arrays.
        None if COLLECTIONS
            .iter()
            .any(|k| json.get(k).is_some_and(|m| m.is_object())) =>
        {
            Some("1.0".into())
        }
        _ => None,
    }
}

/// Reads a .gltf or .glb file, its buffers and the names of its images,
/// through `input` (bounded reads, the sandbox, the memory budget).
pub fn load(path: &Path, input: &Input) -> Result<GltfModel, Error> {
    let bytes = input.read(path, None, None)?;
    let err = |msg: String| Error::asset(path, None, msg);
    // A 1.0 file is named as one before its container is checked (a 1.0
    // binary's header differs after the version).
    if let Some(v) = version_1(&bytes) {
        return Err(err(format!(
            "glTF {v} is not supported; convert it to glTF 2.0 (e.g. with the Khronos glTF-Sample-Viewer's converter, `npx gltf-pipeline` from Cesium, or Blender's importer and exporter)"
        )));
    }
    if bytes.starts_with(b"glTF") && bytes.len() < 12 {
        return Err(err(format!(
            "truncated .glb: {} bytes, less than its 12-byte header",
            bytes.len()
        )));
    }
    if bytes.starts_with(b"glTF") && bytes.len() >= 12 {
        let declared = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
        // (The gltf crate subtracts the header from this length unchecked.)
        if declared < 12 {
            return Err(err(format!(
                "malformed .glb: its header declares {declared} bytes, less than the header itself"
            )));
        }
        if declared > bytes.len() {
            return Err(err(format!(
                "truncated .glb: its header declares {declared} bytes, the file has {}",
                bytes.len()
            )));
        }
    }
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| err(format!("malformed glTF: {e}")))?;
    let doc = &gltf.document;
    let mut warnings = extensions(doc, path).map_err(err)?;
    validate(doc).map_err(err)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut buffers = load_buffers(doc, gltf.blob.as_deref(), path, input)?;
    super::meshopt::decode_views(doc, &mut buffers).map_err(err)?;
    check_accessors(doc, &buffers, input).map_err(err)?;
    let images = image_sources(doc, &buffers, dir, path).map_err(err)?;

    let mut materials: Vec<GltfMaterial> = doc
        .materials()
        .map(|m| material(&m, doc, &images, &mut warnings, path))
        .collect();
    let mut b = Builder {
        mesh: Mesh::default(),
        any_uv: [false; 2],
        any_color: false,
        any_tangent: false,
        default_material: None,
        views: doc
            .views()
            .map(|v| (v.buffer().index(), v.offset(), v.length()))
            .collect(),
        // Only files with animations keep their source vertices.
        segments: doc.animations().next().is_some().then(Vec::new),
        rig_error: None,
        budget: input.budget(),
        part: 0,
    };
    let mut placed = Placed::default();
    walk_nodes(doc, &buffers, &mut materials, &mut b, &mut placed).map_err(err)?;
    let segments = b.segments.take();
    let rig_error = b.rig_error.take();
    let mut mesh = b.finish();
    mesh.groups.retain(|g| !g.triangles.is_empty());
    let rig = segments.map(|segments| match rig_error {
        Some(e) => Err(e),
        None => rig(doc, &buffers, segments, placed.light_nodes.clone()).map(Arc::new),
    });
    Ok(GltfModel {
        mesh,
        materials,
        lights: placed.lights,
        cameras: placed.cameras,
        warnings,
        rig,
        variants: variant_names(doc),
        variant_slots: placed.variant_slots,
    })
}

/// The rig of a file with animations: its nodes (parents first), skins,
/// the segments the loader recorded and its clips.
fn rig(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    segments: Vec<Segment>,
    light_nodes: Vec<usize>,
) -> Result<Rig, String> {
    let n = doc.nodes().count();
    let mut parent = vec![None; n];
    for node in doc.nodes() {
        for c in node.children() {
            parent[c.index()] = Some(node.index());
        }
    }
    // Parents before children: roots, then each level's children.
    let mut order: Vec<usize> = (0..n).filter(|&i| parent[i].is_none()).collect();
    let mut k = 0;
    while k < order.len() {
        let i = order[k];
        if let Some(node) = doc.nodes().nth(i) {
            order.extend(node.children().map(|c| c.index()));
        }
        k += 1;
        if order.len() > n {
            return Err("the node hierarchy has a cycle or a node with two parents".into());
        }
    }
    if order.len() != n {
        return Err("the node hierarchy has a cycle".into());
    }
    let nodes = doc
        .nodes()
        .map(|node| {
            let (t, r, s) = node.transform().decomposed();
            RigNode {
                parent: parent[node.index()],
                matrix: Mat4::from_cols_array_2d(&node.transform().matrix()),
                trs: (Vec3::from(t), glam::Quat::from_array(r), Vec3::from(s)),
                weights: node
                    .weights()
                    .or(node.mesh().and_then(|m| m.weights()))
                    .unwrap_or(&[])
                    .to_vec(),
            }
        })
        .collect();
    let skins = doc
        .skins()
        .map(|s| {
            let (joints, inverse_bind) = pose::read_skin(&s, buffers)?;
            Ok(RigSkin {
                joints,
                inverse_bind,
            })
        })
        .collect::<Result<_, String>>()?;
    Ok(Rig {
        nodes,
        order,
        skins,
        segments,
        light_nodes,
        clips: pose::read_clips(doc, buffers),
    })
}

/// An error for a required extension softraster lacks; warnings for the
/// optional ones it ignores.
fn extensions(doc: &gltf::Document, path: &Path) -> Result<Vec<String>, String> {
    for ext in doc.extensions_required() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            return Err(format!(
                "the file requires the glTF extension `{ext}`, which softraster does not support (it supports {})",
                SUPPORTED_EXTENSIONS.join(", ")
            ));
        }
    }
    Ok(doc
        .extensions_used()
        .filter(|ext| {
            !SUPPORTED_EXTENSIONS.contains(ext) && !doc.extensions_required().any(|r| r == *ext)
        })
        .map(|ext| {
            format!(
                "{}: uses the optional glTF extension `{ext}`, which softraster ignores",
                path.display()
            )
        })
        .collect())
}

/// Where a mesh's primitives go: the node's world transform, its morph
/// weights, and its skin with every node's world transform (for joints).
struct Pose<'a> {
    node: usize,
    world: Mat4,
    weights: &'a [f32],
    skin: Option<(&'a gltf::Skin<'a>, &'a [Mat4])>,
}

/// The lights and cameras the node hierarchy places.
#[derive(Default)]
struct Placed {
    lights: Vec<GltfLight>,
    /// Per light: its node.
    light_nodes: Vec<usize>,
    cameras: Vec<GltfCamera>,
    /// The primitives KHR_materials_variants maps.
    variant_slots: Vec<VariantSlot>,
}

/// Walks the default scene's nodes (or the first scene's; without scenes,
/// every root), depth first in document order, adding each mesh's
/// primitives to `b` with the node's world transform; a node reached twice
/// or with a non-finite transform is an error.
fn walk_nodes(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    materials: &mut Vec<GltfMaterial>,
    b: &mut Builder,
    placed: &mut Placed,
) -> Result<(), String> {
    let (lights, cameras) = (&mut placed.lights, &mut placed.cameras);
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => {
            let children: BTreeSet<usize> = doc
                .nodes()
                .flat_map(|n| n.children().map(|c| c.index()).collect::<Vec<_>>())
                .collect();
            doc.nodes()
                .filter(|n| !children.contains(&n.index()))
                .collect()
        }
    };
    let mut seen = vec![false; doc.nodes().count()];
    // Every node's default world transform, for skins' joints.
    let worlds = if doc.skins().next().is_some() {
        pose::node_worlds(doc)?
    } else {
        Vec::new()
    };
    let mut stack: Vec<(gltf::Node, Mat4)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(format!(
                "node {} is reached twice in the scene's hierarchy (a cycle, or a node with two parents)",
                node.index()
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(format!(
                "node {}: its transform is not finite",
                node.index()
            ));
        }
        if let Some(mesh) = node.mesh() {
            // A part per node with a mesh, for the object-id pass.
            b.part = b.mesh.parts.len() as u32;
            b.mesh.parts.push(
                node.name()
                    .or(mesh.name())
                    .map_or_else(|| format!("node{}", node.index()), str::to_string),
            );
            let weights = node.weights().or(mesh.weights()).unwrap_or(&[]);
            let skin = node.skin();
            for prim in mesh.primitives() {
                let mat = match prim.material().index() {
                    Some(i) => i,
                    None => *b.default_material.get_or_insert_with(|| {
                        materials.push(GltfMaterial::default_material());
                        materials.len() - 1
                    }),
                };
                let at = (mesh.index(), prim.index());
                let mat = variant_slot(doc, at, mat, materials, &mut placed.variant_slots)
                    .map_err(|m| format!("mesh {} primitive {}: {m}", at.0, at.1))?;
                let pose = Pose {
                    node: node.index(),
                    world,
                    weights,
                    skin: skin.as_ref().map(|s| (s, worlds.as_slice())),
                };
                b.add_primitive(&prim, buffers, &pose, mat).map_err(|m| {
                    format!("mesh {} primitive {}: {m}", mesh.index(), prim.index())
                })?;
            }
        }
        if let Some(l) = node.light() {
            lights.push(light(&l, world));
            placed.light_nodes.push(node.index());
        }
        if let Some(c) = node.camera() {
            cameras.push(camera(&c, &node, world, cameras.len()));
        }
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, world));
        }
    }
    Ok(())
}

fn validate(doc: &gltf::Document) -> Result<(), String> {
    use gltf::json::validation::Validate;
    let root = doc.as_json();
    // gltf-json 1.4.1's own validation indexes the POSITION accessor
    // without a bounds check: check it first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let pos = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(i) = prim.attributes.get(&pos)
                && i.value() >= root.accessors.len()
            {
                return Err(format!(
                    "mesh {m} primitive {p}: POSITION names accessor {}, the file has {}",
                    i.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    let draco = doc
        .extensions_used()
        .any(|e| e == "KHR_draco_mesh_compression");
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, e| {
        let path = path().to_string();
        // Required extensions are `extensions()`'s to judge: the gltf
        // crate does not know EXT_meshopt_compression and
        // KHR_mesh_quantization, which softraster decodes itself.
        // Draco primitives' accessors have no views: the stream holds
        // their data.
        let draco_accessor = draco
            && path.starts_with("accessors[")
            && path.ends_with(".bufferView")
            && matches!(e, gltf::json::validation::Error::Missing);
        if !path.starts_with("extensionsRequired") && !draco_accessor {
            errors.push(format!("{path}: {e}"))
        }
    });
    match errors.len() {
        0 => Ok(()),
        1 => Err(format!("invalid glTF: {}", errors[0])),
        n => Err(format!("invalid glTF: {} (and {} more)", errors[0], n - 1)),
    }
}

fn image_sources(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    dir: &Path,
    path: &Path,
) -> Result<Vec<ImageSource>, String> {
    let name = |i: usize| PathBuf::from(format!("{}#image{i}", path.display()));
    doc.images()
        .map(|img| {
            let i = img.index();
            // The gltf crate's `source()` unwraps these (its validation
            // lets both through): an image is a uri, or a bufferView with
            // a mimeType (found by fuzzing).
            let json = &doc.as_json().images[i];
            match (&json.buffer_view, &json.uri, &json.mime_type) {
                (Some(_), _, None) => {
                    return Err(format!("image {i}: a bufferView image needs a mimeType"));
                }
                (None, None, _) => {
                    return Err(format!("image {i}: has neither a uri nor a bufferView"));
                }
                _ => {}
            }
            Ok(match img.source() {
                gltf::image::Source::View { view, .. } => {
                    let b = &buffers[view.buffer().index()];
                    let bytes = b
                        .get(view.offset()..view.offset().saturating_add(view.length()))
                        .ok_or_else(|| {
                            format!("image {i}: its bufferView reaches past its buffer")
                        })?;
                    ImageSource::Memory {
                        name: name(i),
                        bytes: bytes.into(),
                    }
                }
                gltf::image::Source::Uri { uri, .. } => match data_uri(uri) {
                    Some(d) => ImageSource::Memory {
                        name: name(i),
                        bytes: d.map_err(|m| format!("image {i}: {m}"))?.into(),
                    },
                    None => ImageSource::File(dir.join(percent_decode(uri))),
                },
            })
        })
        .collect()
}

/// The source vertex of each mesh vertex a primitive adds, and the face
/// normals: with normals, every vertex once; without, glTF asks for flat
/// shading: every corner its own vertex with its face's normal (and any
/// tangents ignored), `tris` renumbered to match.
fn vertex_order(
    has_normals: bool,
    tris: &mut Vec<[u32; 3]>,
    positions: &[Vec3],
) -> (Vec<u32>, Option<Vec<Vec3>>) {
    if has_normals {
        return ((0..positions.len() as u32).collect(), None);
    }
    let order: Vec<u32> = tris.iter().flatten().copied().collect();
    let face_normals: Vec<Vec3> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::Y)
        })
        .collect();
    *tris = (0..tris.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    (order, Some(face_normals))
}

/// Triangle corner indices of a primitive's index list, per its mode.
pub fn triangulate(mode: Mode, idx: &[u32]) -> Option<Vec<[u32; 3]>> {
    let n = idx.len();
    Some(match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        // p_i = (v_i, v_{i+1+i%2}, v_{i+2-i%2}): every other one reversed,
        // so all keep the first one's winding.
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| {
                if i % 2 == 0 {
                    [idx[i], idx[i + 1], idx[i + 2]]
                } else {
                    [idx[i], idx[i + 2], idx[i + 1]]
                }
            })
            .collect(),
        // p_i = (v_{i+1}, v_{i+2}, v_0)
        Mode::TriangleFan => (0..n.saturating_sub(2))
            .map(|i| [idx[i + 1], idx[i + 2], idx[0]])
            .collect(),
        _ => return None,
    })
}

struct Builder {
    mesh: Mesh,
    any_uv: [bool; 2],
    any_color: bool,
    any_tangent: bool,
    default_material: Option<usize>,
    /// Every buffer view: (buffer, offset, length), for Draco streams.
    views: Vec<(usize, usize, usize)>,
    /// Files with animations: each primitive instance's source vertices,
    /// for posing at other times.
    segments: Option<Vec<Segment>>,
    /// Why the segments cannot pose the mesh (then the file still loads
    /// in its default pose).
    rig_error: Option<String>,
    /// The memory budget (a Draco stream's decode is bounded by it).
    budget: u64,
    /// The part (`Mesh::parts`) the primitives being added belong to.
    part: u32,
}

/// Vertex `s`'s texture coordinates (both sets) and colour, defaults where
/// the primitive has none.
fn push_uv_color(m: &mut Mesh, uv: &[Option<Vec<Vec2>>; 2], colors: &Option<Vec<Vec4>>, s: usize) {
    for (list, set) in [&mut m.uvs, &mut m.uvs1].into_iter().zip(uv) {
        list.push(set.as_ref().map(|v| v[s]).unwrap_or(Vec2::ZERO));
    }
    m.colors
        .push(colors.as_ref().map(|c| c[s]).unwrap_or(Vec4::ONE));
}

impl Builder {
    /// Which optional sets some primitive had (the others are dropped at
    /// the end).
    fn note_sets(&mut self, uv: &[Option<Vec<Vec2>>; 2], colors: &Option<Vec<Vec4>>) {
        self.any_uv[0] |= uv[0].is_some();
        self.any_uv[1] |= uv[1].is_some();
        self.any_color |= colors.is_some();
    }

    /// Points, lines, line strips and loops: vertices as placed (normals
    /// +Y, unused: they are drawn unlit), then the primitives.
    fn add_points_or_lines(
        &mut self,
        prim: &gltf::Primitive,
        buffers: &[Vec<u8>],
        pose: &Pose,
        material: usize,
    ) -> Result<(), String> {
        let world = pose.world;
        let a = read_attributes(prim, buffers, &self.views, self.budget)?;
        self.note_sets(&a.uv, &a.colors);
        let base = self.mesh.positions.len() as u32;
        if let Some(segments) = &mut self.segments {
            segments.push(Segment {
                first: base,
                order: None,
                node: pose.node,
                skin: None,
                positions: a.positions.clone(),
                normals: SegmentNormals::Fixed,
                targets: Vec::new(),
                influences: Vec::new(),
            });
        }
        let m = &mut self.mesh;
        for (s, p) in a.positions.iter().enumerate() {
            m.positions.push(world.transform_point3(*p));
            m.normals.push(Vec3::Y);
            push_uv_color(m, &a.uv, &a.colors, s);
            m.authored_tangents.push(Vec4::ZERO);
        }
        let idx = &a.indices;
        let seg = |i: u32, j: u32| Primitive {
            vertices: [base + i, base + j],
            material,
        };
        match prim.mode() {
            Mode::Points => m.points.extend(idx.iter().map(|&i| Primitive {
                vertices: [base + i],
                material,
            })),
            Mode::Lines => m.lines.extend(idx.chunks_exact(2).map(|p| seg(p[0], p[1]))),
            Mode::LineStrip => m.lines.extend(idx.windows(2).map(|p| seg(p[0], p[1]))),
            _ => {
                m.lines.extend(idx.windows(2).map(|p| seg(p[0], p[1])));
                if let (Some(&first), Some(&last)) = (idx.first(), idx.last())
                    && idx.len() > 2
                {
                    m.lines.push(seg(last, first));
                }
            }
        }
        Ok(())
    }

    fn add_primitive(
        &mut self,
        prim: &gltf::Primitive,
        buffers: &[Vec<u8>],
        pose: &Pose,
        material: usize,
    ) -> Result<(), String> {
        let world = pose.world;
        let mode = prim.mode();
        if matches!(
            mode,
            Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
        ) {
            return self.add_points_or_lines(prim, buffers, pose, material);
        }
        let mut attributes = read_attributes(prim, buffers, &self.views, self.budget)?;
        // Animated files: the source vertices, before morphing.
        let source = self
            .segments
            .is_some()
            .then(|| (attributes.positions.clone(), attributes.normals.clone()));
        pose::apply_morph(prim, pose.weights, buffers, &mut attributes)?;
        let Attributes {
            positions,
            normals,
            tangents,
            uv,
            colors,
            indices,
        } = attributes;
        let n = positions.len();
        // A skinned primitive: each vertex placed by its joints (the node's
        // own transform does not apply).
        let skinned = match pose.skin {
            Some((skin, worlds)) => Some(pose::skin_matrices(prim, skin, worlds, buffers, n)?),
            None => None,
        };
        let place = |s: usize| skinned.as_ref().map_or(world, |k| k[s]);
        let Some(mut tris) = triangulate(mode, &indices) else {
            return Ok(());
        };
        let m3 = Mat3::from_mat4(world);
        let mirrored = m3.determinant() < 0.0;
        let normal_m = m3.inverse().transpose();

        let (order, face_normals) = vertex_order(normals.is_some(), &mut tris, &positions);
        self.note_sets(&uv, &colors);
        let base = self.mesh.positions.len() as u32;
        if let Some((positions, normals)) = source {
            let segment = self.segment(prim, buffers, pose, base, (positions, normals), &order);
            match (segment, &mut self.segments) {
                (Ok(seg), Some(list)) => list.push(seg),
                (Err(e), _) => {
                    self.rig_error.get_or_insert(e);
                }
                _ => {}
            }
        }
        let m = &mut self.mesh;
        for (k, &src) in order.iter().enumerate() {
            let s = src as usize;
            let (xf, m3, normal_m) = match &skinned {
                None => (world, m3, normal_m),
                Some(_) => {
                    let xf = place(s);
                    let m3 = Mat3::from_mat4(xf);
                    (xf, m3, m3.inverse().transpose())
                }
            };
            let mirrored = m3.determinant() < 0.0;
            m.positions.push(xf.transform_point3(positions[s]));
            let nrm = match (&normals, &face_normals) {
                (Some(nv), _) => nv[s],
                (None, Some(f)) => f[k / 3],
                _ => Vec3::Y,
            };
            m.normals
                .push((normal_m * nrm).try_normalize().unwrap_or(Vec3::Y));
            push_uv_color(m, &uv, &colors, s);
            let t = match (&tangents, &face_normals) {
                (Some(t), None) => {
                    let t = t[s];
                    let xyz = (m3 * t.truncate()).try_normalize();
                    match xyz {
                        Some(v) if t.w != 0.0 => {
                            let w = if t.w < 0.0 { -1.0 } else { 1.0 };
                            v.extend(if mirrored { -w } else { w })
                        }
                        _ => Vec4::ZERO,
                    }
                }
                _ => Vec4::ZERO,
            };
            m.authored_tangents.push(t);
        }
        self.any_tangent |= tangents.is_some() && face_normals.is_none();
        let first = m.triangles.len() as u32;
        for t in tris {
            // Skinned: mirrored where the first corner's joints mirror.
            let mirrored = match &skinned {
                None => mirrored,
                Some(_) => {
                    Mat3::from_mat4(place(order[t[0] as usize] as usize)).determinant() < 0.0
                }
            };
            let [a, b, c] = t.map(|i| i + base);
            m.triangles
                .push(if mirrored { [a, c, b] } else { [a, b, c] });
        }
        let triangles = first..m.triangles.len() as u32;
        let part = self.part;
        m.groups.push(Group {
            triangles,
            material,
            part,
        });
        Ok(())
    }

    /// The segment of a triangle primitive placed at `base` in the mesh,
    /// its vertices taken from the source in `order`.
    fn segment(
        &self,
        prim: &gltf::Primitive,
        buffers: &[Vec<u8>],
        pose: &Pose,
        base: u32,
        (positions, normals): (Vec<Vec3>, Option<Vec<Vec3>>),
        order: &[u32],
    ) -> Result<Segment, String> {
        let n = positions.len();
        let context = |e: String| {
            format!(
                "animating primitive {} of node {}: {e}",
                prim.index(),
                pose.node
            )
        };
        let targets = pose::read_targets(prim, buffers, n).map_err(context)?;
        let (skin, influences) = match pose.skin {
            Some((skin, _)) => {
                let count = skin.joints().count();
                let inf = pose::read_influences(prim, buffers, n, count).map_err(context)?;
                (Some(skin.index()), inf)
            }
            None => (None, Vec::new()),
        };
        let flat = normals.is_none();
        Ok(Segment {
            first: base,
            order: flat.then(|| order.to_vec()),
            node: pose.node,
            skin,
            positions,
            normals: match normals {
                Some(v) => SegmentNormals::Vertex(v),
                None => SegmentNormals::Faces {
                    first_triangle: self.mesh.triangles.len() as u32,
                },
            },
            targets,
            influences,
        })
    }

    fn finish(self) -> Mesh {
        let mut m = self.mesh;
        if !self.any_uv[0] {
            m.uvs.clear();
        }
        if !self.any_uv[1] {
            m.uvs1.clear();
        }
        if !self.any_color {
            m.colors.clear();
        }
        if !self.any_tangent {
            m.authored_tangents.clear();
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_keep_the_winding() {
        let idx = [0, 1, 2, 3, 4];
        assert_eq!(
            triangulate(Mode::TriangleStrip, &idx).unwrap(),
            vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]
        );
        assert_eq!(
            triangulate(Mode::TriangleFan, &idx).unwrap(),
            vec![[1, 2, 0], [2, 3, 0], [3, 4, 0]]
        );
        assert_eq!(
            triangulate(Mode::Triangles, &[0, 1, 2, 3]).unwrap(),
            vec![[0, 1, 2]]
        );
        assert!(triangulate(Mode::Lines, &idx).is_none());
        assert!(
            triangulate(Mode::TriangleStrip, &[0, 1])
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn texture_transform_matches_the_spec_example() {
        // KHR_texture_transform's example: the lower-left quadrant of the
        // image, rotated (offset [0, 1], rotation pi/2, scale 0.5).
        let v: gltf::json::Value = gltf::json::deserialize::from_str(
            r#"{"offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5], "texCoord": 1}"#,
        )
        .unwrap();
        let (m, tc) = texture_transform(Transform::of_json(Some(&v)));
        assert_eq!(tc, Some(1));
        let corners = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE].map(|p| m.transform_point2(p));
        for c in corners {
            assert!(c.x > -1e-6 && c.x < 0.5 + 1e-6, "{c}");
            assert!(c.y > 0.5 - 1e-6 && c.y < 1.0 + 1e-6, "{c}");
        }
        // u runs up the image: (1, 0) -> (0, 0.5).
        assert!((corners[1] - Vec2::new(0.0, 0.5)).length() < 1e-6);
    }
}
