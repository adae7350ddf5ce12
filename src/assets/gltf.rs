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
use super::mesh::{Group, Mesh, Primitive};
use super::rig::{Rig, RigNode, RigSkin, Segment, SegmentNormals};
use super::texture::Wrap;
use super::texture::{AddressMode, TextureFilter};
use crate::error::Error;

/// Extensions that change how softraster draws a file; a file that
/// requires any other one is refused.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "EXT_meshopt_compression",
    "KHR_draco_mesh_compression",
    "KHR_lights_punctual",
    "KHR_materials_clearcoat",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_iridescence",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
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

/// A texture reference of a material: image, sampler, coordinates.
#[derive(Debug, Clone)]
pub struct TexInfo {
    pub image: ImageSource,
    pub texcoord: u8,
    /// KHR_texture_transform (identity without it).
    pub transform: Affine2,
    pub wrap: Wrap,
    pub min_limit: Option<TextureFilter>,
    pub mag_nearest: bool,
}

/// A material's `alphaMode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GltfAlphaMode {
    Opaque,
    /// Cut out below `alphaCutoff`.
    Mask,
    Blend,
}

/// A glTF metallic-roughness material as the file states it.
#[derive(Debug, Clone)]
pub struct GltfMaterial {
    pub name: String,
    pub base_color: Vec4,
    pub base_color_tex: Option<TexInfo>,
    pub metallic: f32,
    pub roughness: f32,
    pub metallic_roughness_tex: Option<TexInfo>,
    pub normal_tex: Option<TexInfo>,
    pub normal_scale: f32,
    pub occlusion_tex: Option<TexInfo>,
    pub occlusion_strength: f32,
    /// emissiveFactor times KHR_materials_emissive_strength.
    pub emissive: Vec3,
    pub emissive_tex: Option<TexInfo>,
    pub alpha_mode: GltfAlphaMode,
    pub alpha_cutoff: f32,
    pub double_sided: bool,
    /// KHR_materials_unlit: the base colour, without light.
    pub unlit: bool,
    /// KHR_materials_ior (1.5 without it).
    pub ior: f32,
    /// KHR_materials_specular: factor (the dielectric's F90 and weight on
    /// F0), colour factor (on F0), and their textures (alpha; sRGB RGB).
    pub specular: Option<GltfSpecular>,
    /// KHR_materials_clearcoat (None without it, or with a factor of 0).
    pub clearcoat: Option<GltfClearcoat>,
    /// KHR_materials_transmission (None without it, or with a factor of 0).
    pub transmission: Option<GltfTransmission>,
    /// KHR_materials_sheen (None without it, or with a black colour).
    pub sheen: Option<GltfSheen>,
    /// KHR_materials_iridescence (None without it, or with a factor of 0).
    pub iridescence: Option<GltfIridescence>,
}

/// KHR_materials_iridescence.
#[derive(Debug, Clone)]
pub struct GltfIridescence {
    pub factor: f32,
    /// Red multiplies `factor`.
    pub texture: Option<TexInfo>,
    pub ior: f32,
    /// Nanometres.
    pub thickness_min: f32,
    pub thickness_max: f32,
    /// Green: from `thickness_min` to `thickness_max`.
    pub thickness_texture: Option<TexInfo>,
}

/// KHR_materials_sheen.
#[derive(Debug, Clone)]
pub struct GltfSheen {
    pub color: Vec3,
    /// sRGB; RGB multiplies `color`.
    pub color_texture: Option<TexInfo>,
    pub roughness: f32,
    /// Alpha multiplies `roughness`.
    pub roughness_texture: Option<TexInfo>,
}

/// KHR_materials_clearcoat: a second, colourless GGX layer over the
/// material (F0 0.04), with its own roughness and normal map.
#[derive(Debug, Clone)]
pub struct GltfClearcoat {
    pub factor: f32,
    /// Red channel multiplies `factor`.
    pub texture: Option<TexInfo>,
    pub roughness: f32,
    /// Green channel multiplies `roughness`.
    pub roughness_texture: Option<TexInfo>,
    pub normal_texture: Option<TexInfo>,
    pub normal_scale: f32,
}

/// KHR_materials_transmission, with KHR_materials_volume's thickness and
/// attenuation when the material has that extension too.
#[derive(Debug, Clone)]
pub struct GltfTransmission {
    pub factor: f32,
    /// Red channel multiplies `factor`.
    pub texture: Option<TexInfo>,
    /// KHR_materials_volume thicknessFactor (0: thin-walled).
    pub thickness: f32,
    /// Green channel multiplies `thickness`.
    pub thickness_texture: Option<TexInfo>,
    pub attenuation_color: Vec3,
    /// +inf: no attenuation.
    pub attenuation_distance: f32,
}

#[derive(Debug, Clone)]
pub struct GltfSpecular {
    pub factor: f32,
    pub texture: Option<TexInfo>,
    pub color: Vec3,
    pub color_texture: Option<TexInfo>,
}

impl GltfMaterial {
    /// The material of primitives without one (glTF's default).
    fn default_material() -> GltfMaterial {
        GltfMaterial {
            name: "default".into(),
            base_color: Vec4::ONE,
            base_color_tex: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_tex: None,
            normal_tex: None,
            normal_scale: 1.0,
            occlusion_tex: None,
            occlusion_strength: 1.0,
            emissive: Vec3::ZERO,
            emissive_tex: None,
            alpha_mode: GltfAlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
            unlit: false,
            ior: 1.5,
            specular: None,
            clearcoat: None,
            transmission: None,
            sheen: None,
            iridescence: None,
        }
    }

    /// Every texture with whether it holds sRGB color.
    pub fn textures(&self) -> impl Iterator<Item = (&TexInfo, bool)> {
        [
            (self.base_color_tex.as_ref(), true),
            (self.metallic_roughness_tex.as_ref(), false),
            (self.normal_tex.as_ref(), false),
            (self.occlusion_tex.as_ref(), false),
            (self.emissive_tex.as_ref(), true),
            (
                self.specular.as_ref().and_then(|s| s.texture.as_ref()),
                false,
            ),
            (
                self.specular
                    .as_ref()
                    .and_then(|s| s.color_texture.as_ref()),
                true,
            ),
            (
                self.clearcoat.as_ref().and_then(|c| c.texture.as_ref()),
                false,
            ),
            (
                self.clearcoat
                    .as_ref()
                    .and_then(|c| c.roughness_texture.as_ref()),
                false,
            ),
            (
                self.clearcoat
                    .as_ref()
                    .and_then(|c| c.normal_texture.as_ref()),
                false,
            ),
            (
                self.transmission.as_ref().and_then(|t| t.texture.as_ref()),
                false,
            ),
            (
                self.transmission
                    .as_ref()
                    .and_then(|t| t.thickness_texture.as_ref()),
                false,
            ),
            (
                self.sheen.as_ref().and_then(|t| t.color_texture.as_ref()),
                true,
            ),
            (
                self.sheen
                    .as_ref()
                    .and_then(|t| t.roughness_texture.as_ref()),
                false,
            ),
            (
                self.iridescence.as_ref().and_then(|t| t.texture.as_ref()),
                false,
            ),
            (
                self.iridescence
                    .as_ref()
                    .and_then(|t| t.thickness_texture.as_ref()),
                false,
            ),
        ]
        .into_iter()
        .filter_map(|(t, srgb)| t.map(|t| (t, srgb)))
    }
}

/// A KHR_lights_punctual light placed by its node (in the file's space).
#[derive(Debug, Clone)]
pub struct GltfLight {
    pub name: String,
    pub kind: GltfLightKind,
    /// Linear RGB.
    pub color: Vec3,
    /// Candela (point, spot) or lux (directional).
    pub intensity: f32,
    /// Point and spot: the distance where the light ends (None: unlimited).
    pub range: Option<f32>,
    pub position: Vec3,
    /// Unit direction the light travels along (the node's -Z).
    pub direction: Vec3,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GltfLightKind {
    Directional,
    Point,
    /// Cone angles in radians from the axis.
    Spot {
        inner_cone_angle: f32,
        outer_cone_angle: f32,
    },
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GltfProjection {
    /// Vertical field of view in degrees.
    Perspective { fov_y: f32 },
    /// Full height of the view volume.
    Orthographic { height: f32 },
}

/// A camera placed by its node: it looks down the node's -Z, up +Y.
#[derive(Debug, Clone)]
pub struct GltfCamera {
    pub name: String,
    pub eye: Vec3,
    pub forward: Vec3,
    pub up: Vec3,
    pub projection: GltfProjection,
    pub near: f32,
    /// None: infinite (perspective without zfar).
    pub far: Option<f32>,
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
}

impl GltfLight {
    /// The light at a node whose world transform is `world`: at its
    /// origin, shining down its -Z.
    pub fn placed(&self, world: Mat4) -> GltfLight {
        GltfLight {
            position: world.transform_point3(Vec3::ZERO),
            direction: world
                .transform_vector3(Vec3::NEG_Z)
                .try_normalize()
                .unwrap_or(Vec3::NEG_Z),
            ..self.clone()
        }
    }
}

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
        // 1.0 files may lack asset.version; their meshes, accessors and
        // materials are objects keyed by id, not arrays.
        None if json.get("meshes").is_some_and(|m| m.is_object()) => Some("1.0".into()),
        _ => None,
    }
}

pub fn load(path: &Path) -> Result<GltfModel, Error> {
    let bytes = std::fs::read(path)
        .map_err(|e| Error::asset(path, None, format!("cannot read model: {e}")))?;
    let err = |msg: String| Error::asset(path, None, msg);
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
    if let Some(v) = version_1(&bytes) {
        return Err(err(format!(
            "glTF {v} is not supported; convert it to glTF 2.0 (e.g. with the Khronos glTF-Sample-Viewer's converter, `npx gltf-pipeline` from Cesium, or Blender's importer and exporter)"
        )));
    }
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| err(format!("malformed glTF: {e}")))?;
    let doc = &gltf.document;
    let mut warnings = extensions(doc, path).map_err(err)?;
    validate(doc).map_err(err)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut buffers = load_buffers(doc, gltf.blob.as_deref(), dir, path)?;
    super::meshopt::decode_views(doc, &mut buffers).map_err(err)?;
    check_accessors(doc, &buffers).map_err(err)?;
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
            let (joints, inverse_bind) = super::gltf_pose::read_skin(&s, buffers)?;
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
        clips: super::gltf_pose::read_clips(doc, buffers),
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
        super::gltf_pose::node_worlds(doc)?
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
            lights.push(light(&l, &node, world));
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

fn load_buffers(
    doc: &gltf::Document,
    blob: Option<&[u8]>,
    dir: &Path,
    path: &Path,
) -> Result<Vec<Vec<u8>>, Error> {
    let mut out = Vec::new();
    // Room for meshopt-decoded views, bounded by what the real buffers
    // could decode to.
    let real: usize = doc
        .buffers()
        .filter(|b| !super::meshopt::is_fallback(b))
        .map(|b| b.length())
        .sum();
    for b in doc.buffers() {
        let i = b.index();
        let no_data = matches!(b.source(), gltf::buffer::Source::Bin) && blob.is_none();
        if super::meshopt::is_fallback(&b) && no_data {
            if b.length() > real.saturating_mul(256) + (1 << 20) {
                return Err(Error::asset(
                    path,
                    None,
                    format!(
                        "buffer {i}: a meshopt fallback of {} bytes is out of proportion",
                        b.length()
                    ),
                ));
            }
            out.push(vec![0; b.length()]);
            continue;
        }
        let data = match b.source() {
            gltf::buffer::Source::Bin => blob.map(<[u8]>::to_vec).ok_or_else(|| {
                Error::asset(
                    path,
                    None,
                    format!(
                        "buffer {i} refers to the GLB binary chunk, which the file does not have"
                    ),
                )
            })?,
            gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(d) => d.map_err(|m| Error::asset(path, None, format!("buffer {i}: {m}")))?,
                None => {
                    let file = dir.join(percent_decode(uri));
                    std::fs::read(&file).map_err(|e| {
                        Error::asset(
                            &file,
                            None,
                            format!("cannot read buffer {i} of {}: {e}", path.display()),
                        )
                    })?
                }
            },
        };
        if data.len() < b.length() {
            return Err(Error::asset(
                path,
                None,
                format!(
                    "buffer {i} holds {} bytes but declares {} (truncated file?)",
                    data.len(),
                    b.length()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// `data:[mime];base64,...`: Some(decoded) for a data URI, None otherwise.
fn data_uri(uri: &str) -> Option<Result<Vec<u8>, String>> {
    let rest = uri.strip_prefix("data:")?;
    let Some((_, payload)) = rest.split_once(";base64,") else {
        return Some(Err("data URIs must be base64-encoded".into()));
    };
    Some(
        base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("bad base64 data URI: {e}")),
    )
}

fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            let v = (h * 16 + l) as u8;
            out.push(v);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Every accessor lies within its buffer view and buffer, has at least one
/// element, and a stride no smaller than its element (the crate assumes
/// all three).
fn check_accessors(doc: &gltf::Document, buffers: &[Vec<u8>]) -> Result<(), String> {
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
        if a.sparse().is_some() {
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

/// KHR_texture_transform as an affine map of texture coordinates:
/// translate * rotate * scale, the rotation as implementations and the
/// sample models have it (u' = cos u + sin v, v' = -sin u + cos v: the
/// image turns clockwise on screen for a positive angle). Also returns its
/// texCoord override.
fn texture_transform(t: Option<Transform>) -> (Affine2, Option<u32>) {
    let Some(t) = t else {
        return (Affine2::IDENTITY, None);
    };
    let (s, c) = t.rotation.sin_cos();
    let rot = Mat2::from_cols(Vec2::new(c, -s), Vec2::new(s, c));
    let m = Affine2::from_mat2_translation(rot * Mat2::from_diagonal(t.scale), t.offset);
    (m, t.tex_coord)
}

/// KHR_texture_transform's values.
#[derive(Debug, Clone, Copy)]
struct Transform {
    offset: Vec2,
    rotation: f32,
    scale: Vec2,
    tex_coord: Option<u32>,
}

impl Transform {
    /// From a textureInfo (the crate parses the extension there).
    fn of_info(i: &gltf::texture::Info) -> Option<Transform> {
        i.texture_transform().map(|t| Transform {
            offset: Vec2::from(t.offset()),
            rotation: t.rotation(),
            scale: Vec2::from(t.scale()),
            tex_coord: t.tex_coord(),
        })
    }

    /// From the raw extension object (normal and occlusion textures, where
    /// the crate leaves it as JSON).
    fn of_json(v: Option<&gltf::json::Value>) -> Option<Transform> {
        let v = v?;
        let pair = |k: &str, d: Vec2| -> Vec2 {
            v.get(k)
                .and_then(|a| a.as_array())
                .filter(|a| a.len() == 2)
                .and_then(|a| Some(Vec2::new(a[0].as_f64()? as f32, a[1].as_f64()? as f32)))
                .unwrap_or(d)
        };
        Some(Transform {
            offset: pair("offset", Vec2::ZERO),
            rotation: v.get("rotation").and_then(|r| r.as_f64()).unwrap_or(0.0) as f32,
            scale: pair("scale", Vec2::ONE),
            tex_coord: v.get("texCoord").and_then(|t| t.as_u64()).map(|t| t as u32),
        })
    }
}

fn tex_info(
    texture: gltf::Texture,
    tex_coord: u32,
    transform: Option<Transform>,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<TexInfo> {
    // The texture's own image (a PNG or JPEG fallback, when
    // KHR_texture_basisu gives one), else its KTX2 image.
    let basisu = texture
        .extension_value("KHR_texture_basisu")
        .and_then(|v| v.get("source"))
        .and_then(|i| i.as_u64())
        .and_then(|i| usize::try_from(i).ok());
    let Some(index) = texture.source().map(|i| i.index()).or(basisu) else {
        warnings.push(format!(
            "{}: texture {} has no image; materials use it without that map",
            path.display(),
            texture.index()
        ));
        return None;
    };
    let Some(image) = images.get(index).cloned() else {
        warnings.push(format!(
            "{}: texture {} names image {index}, which the file does not have",
            path.display(),
            texture.index()
        ));
        return None;
    };
    let (transform, tc) = texture_transform(transform);
    let set = tc.unwrap_or(tex_coord);
    let texcoord = if set > 1 {
        warnings.push(format!(
            "{}: texture {} reads TEXCOORD_{set}; softraster reads sets 0 and 1 and uses 0",
            path.display(),
            texture.index()
        ));
        0
    } else {
        set as u8
    };
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let sampler = texture.sampler();
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => AddressMode::Clamp,
        WrappingMode::MirroredRepeat => AddressMode::Mirror,
        WrappingMode::Repeat => AddressMode::Repeat,
    };
    let min_limit = match sampler.min_filter() {
        Some(MinFilter::Nearest) => Some(TextureFilter::Nearest),
        Some(MinFilter::Linear) => Some(TextureFilter::Bilinear),
        _ => None,
    };
    Some(TexInfo {
        image,
        texcoord,
        transform,
        wrap: Wrap(wrap(sampler.wrap_s()), wrap(sampler.wrap_t())),
        min_limit,
        mag_nearest: sampler.mag_filter() == Some(MagFilter::Nearest),
    })
}

/// The types of a primitive's accessors, as its readers assume them: an
/// error names the first that is not.
fn check_accessor_types(prim: &gltf::Primitive) -> Result<(), String> {
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

fn read_attributes(
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    views: &[(usize, usize, usize)],
) -> Result<Attributes, String> {
    if let Some(ext) = prim
        .extensions()
        .and_then(|e| e.get("KHR_draco_mesh_compression"))
    {
        return super::draco::read(prim, ext, buffers, views);
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

fn material(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> GltfMaterial {
    const TT: &str = "KHR_texture_transform";
    let pbr = m.pbr_metallic_roughness();
    let info = |i: Option<gltf::texture::Info>, w: &mut Vec<String>| {
        i.and_then(|i| {
            tex_info(
                i.texture(),
                i.tex_coord(),
                Transform::of_info(&i),
                images,
                w,
                path,
            )
        })
    };
    let base_color_tex = info(pbr.base_color_texture(), warnings);
    let metallic_roughness_tex = info(pbr.metallic_roughness_texture(), warnings);
    let emissive_tex = info(m.emissive_texture(), warnings);
    let normal = m.normal_texture();
    let normal_tex = normal.as_ref().and_then(|n| {
        tex_info(
            n.texture(),
            n.tex_coord(),
            Transform::of_json(n.extension_value(TT)),
            images,
            warnings,
            path,
        )
    });
    let occlusion = m.occlusion_texture();
    let occlusion_tex = occlusion.as_ref().and_then(|o| {
        tex_info(
            o.texture(),
            o.tex_coord(),
            Transform::of_json(o.extension_value(TT)),
            images,
            warnings,
            path,
        )
    });
    GltfMaterial {
        name: m
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("material{}", m.index().unwrap_or(0))),
        base_color: Vec4::from(pbr.base_color_factor()),
        base_color_tex,
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        metallic_roughness_tex,
        normal_tex,
        normal_scale: normal.as_ref().map(|n| n.scale()).unwrap_or(1.0),
        occlusion_tex,
        occlusion_strength: occlusion.as_ref().map(|o| o.strength()).unwrap_or(1.0),
        emissive: Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
        emissive_tex,
        alpha_mode: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => GltfAlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => GltfAlphaMode::Mask,
            gltf::material::AlphaMode::Blend => GltfAlphaMode::Blend,
        },
        alpha_cutoff: m.alpha_cutoff().unwrap_or(0.5),
        double_sided: m.double_sided(),
        unlit: m.unlit(),
        ior: m
            .ior()
            .filter(|i| i.is_finite() && *i >= 1.0)
            .unwrap_or(1.5),
        specular: m.specular().map(|s| GltfSpecular {
            factor: s.specular_factor().clamp(0.0, 1.0),
            texture: info(s.specular_texture(), warnings),
            color: Vec3::from(s.specular_color_factor()).max(Vec3::ZERO),
            color_texture: info(s.specular_color_texture(), warnings),
        }),
        clearcoat: clearcoat(m, doc, images, warnings, path),
        transmission: transmission(m, doc, images, warnings, path),
        sheen: sheen(m, doc, images, warnings, path),
        iridescence: iridescence(m, doc, images, warnings, path),
    }
}

fn iridescence(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfIridescence> {
    let v = m.extension_value("KHR_materials_iridescence")?;
    let factor = json_number(v, "iridescenceFactor")
        .unwrap_or(0.0)
        .clamp(0.0, 1.0);
    if factor <= 0.0 {
        return None;
    }
    // An index of refraction below 1 or absurdly high is clamped to what
    // films are made of; thicknesses are kept to 0..10 um.
    let thickness =
        |key: &str, default: f32| json_number(v, key).unwrap_or(default).clamp(0.0, 10_000.0);
    Some(GltfIridescence {
        factor,
        texture: json_tex(v, "iridescenceTexture", doc, images, warnings, path),
        ior: json_number(v, "iridescenceIor")
            .unwrap_or(1.3)
            .clamp(1.0, 4.0),
        thickness_min: thickness("iridescenceThicknessMinimum", 100.0),
        thickness_max: thickness("iridescenceThicknessMaximum", 400.0),
        thickness_texture: json_tex(
            v,
            "iridescenceThicknessTexture",
            doc,
            images,
            warnings,
            path,
        ),
    })
}

fn sheen(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfSheen> {
    let v = m.extension_value("KHR_materials_sheen")?;
    let color = v
        .get("sheenColorFactor")
        .and_then(|c| c.as_array())
        .filter(|c| c.len() == 3)
        .and_then(|c| {
            let ch = |i: usize| c[i].as_f64().map(|x| x as f32).filter(|x| x.is_finite());
            Some(Vec3::new(ch(0)?, ch(1)?, ch(2)?))
        })
        .unwrap_or(Vec3::ZERO)
        .clamp(Vec3::ZERO, Vec3::ONE);
    if color == Vec3::ZERO {
        return None;
    }
    Some(GltfSheen {
        color,
        color_texture: json_tex(v, "sheenColorTexture", doc, images, warnings, path),
        roughness: json_number(v, "sheenRoughnessFactor")
            .unwrap_or(0.0)
            .clamp(0.0, 1.0),
        roughness_texture: json_tex(v, "sheenRoughnessTexture", doc, images, warnings, path),
    })
}

/// A number of an extension object, when it is a finite number.
fn json_number(v: &gltf::json::Value, key: &str) -> Option<f32> {
    v.get(key)
        .and_then(|x| x.as_f64())
        .map(|x| x as f32)
        .filter(|x| x.is_finite())
}

/// A textureInfo given as raw JSON inside a material extension (the
/// gltf crate does not parse these extensions): its texture, set and
/// KHR_texture_transform. An index that names no texture is a warning.
fn json_tex(
    v: &gltf::json::Value,
    key: &str,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<TexInfo> {
    let t = v.get(key)?;
    let texture = t
        .get("index")
        .and_then(|i| i.as_u64())
        .and_then(|i| doc.textures().nth(usize::try_from(i).ok()?));
    let Some(texture) = texture else {
        warnings.push(format!(
            "{}: `{key}` names no texture of the file; it is ignored",
            path.display()
        ));
        return None;
    };
    let set = t.get("texCoord").and_then(|c| c.as_u64()).unwrap_or(0);
    let transform = Transform::of_json(
        t.get("extensions")
            .and_then(|e| e.get("KHR_texture_transform")),
    );
    tex_info(
        texture,
        u32::try_from(set).unwrap_or(u32::MAX),
        transform,
        images,
        warnings,
        path,
    )
}

fn clearcoat(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfClearcoat> {
    let v = m.extension_value("KHR_materials_clearcoat")?;
    let factor = json_number(v, "clearcoatFactor")
        .unwrap_or(0.0)
        .clamp(0.0, 1.0);
    if factor <= 0.0 {
        return None;
    }
    let normal_scale = v
        .get("clearcoatNormalTexture")
        .map_or(1.0, |t| json_number(t, "scale").unwrap_or(1.0));
    Some(GltfClearcoat {
        factor,
        texture: json_tex(v, "clearcoatTexture", doc, images, warnings, path),
        roughness: json_number(v, "clearcoatRoughnessFactor")
            .unwrap_or(0.0)
            .clamp(0.0, 1.0),
        roughness_texture: json_tex(v, "clearcoatRoughnessTexture", doc, images, warnings, path),
        normal_texture: json_tex(v, "clearcoatNormalTexture", doc, images, warnings, path),
        normal_scale,
    })
}

fn transmission(
    m: &gltf::Material,
    doc: &gltf::Document,
    images: &[ImageSource],
    warnings: &mut Vec<String>,
    path: &Path,
) -> Option<GltfTransmission> {
    let v = m.extension_value("KHR_materials_transmission")?;
    let factor = json_number(v, "transmissionFactor")
        .unwrap_or(0.0)
        .clamp(0.0, 1.0);
    if factor <= 0.0 {
        return None;
    }
    let volume = m.extension_value("KHR_materials_volume");
    let vol_number = |k: &str| volume.and_then(|v| json_number(v, k));
    let attenuation_color = volume
        .and_then(|v| v.get("attenuationColor"))
        .and_then(|c| c.as_array())
        .filter(|c| c.len() == 3)
        .and_then(|c| {
            let ch = |i: usize| c[i].as_f64().map(|x| x as f32).filter(|x| x.is_finite());
            Some(Vec3::new(ch(0)?, ch(1)?, ch(2)?))
        })
        .unwrap_or(Vec3::ONE)
        .clamp(Vec3::ZERO, Vec3::ONE);
    Some(GltfTransmission {
        factor,
        texture: json_tex(v, "transmissionTexture", doc, images, warnings, path),
        thickness: vol_number("thicknessFactor").unwrap_or(0.0).max(0.0),
        thickness_texture: volume
            .and_then(|vv| json_tex(vv, "thicknessTexture", doc, images, warnings, path)),
        attenuation_color,
        attenuation_distance: vol_number("attenuationDistance")
            .filter(|d| *d > 0.0)
            .unwrap_or(f32::INFINITY),
    })
}

fn light(l: &gltf::khr_lights_punctual::Light, node: &gltf::Node, world: Mat4) -> GltfLight {
    use gltf::khr_lights_punctual::Kind;
    GltfLight {
        name: l
            .name()
            .or(node.name())
            .map(str::to_string)
            .unwrap_or_else(|| format!("light{}", l.index())),
        kind: match l.kind() {
            Kind::Directional => GltfLightKind::Directional,
            Kind::Point => GltfLightKind::Point,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => GltfLightKind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            },
        },
        color: Vec3::from(l.color()),
        intensity: l.intensity(),
        range: l.range(),
        position: Vec3::ZERO,
        direction: Vec3::NEG_Z,
    }
    .placed(world)
}

fn camera(c: &gltf::Camera, node: &gltf::Node, world: Mat4, n: usize) -> GltfCamera {
    let eye = world.transform_point3(Vec3::ZERO);
    let forward = world
        .transform_vector3(Vec3::NEG_Z)
        .try_normalize()
        .unwrap_or(Vec3::NEG_Z);
    let up = world
        .transform_vector3(Vec3::Y)
        .try_normalize()
        .unwrap_or(Vec3::Y);
    let (projection, near, far) = match c.projection() {
        gltf::camera::Projection::Perspective(p) => (
            GltfProjection::Perspective {
                fov_y: p.yfov().to_degrees(),
            },
            p.znear(),
            p.zfar(),
        ),
        gltf::camera::Projection::Orthographic(o) => (
            GltfProjection::Orthographic {
                height: 2.0 * o.ymag().abs(),
            },
            o.znear(),
            Some(o.zfar()),
        ),
    };
    GltfCamera {
        name: c
            .name()
            .or(node.name())
            .map(str::to_string)
            .unwrap_or_else(|| format!("gltf_camera{n}")),
        eye,
        forward,
        up,
        projection,
        near,
        far,
    }
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
        let a = read_attributes(prim, buffers, &self.views)?;
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
        let mut attributes = read_attributes(prim, buffers, &self.views)?;
        // Animated files: the source vertices, before morphing.
        let source = self
            .segments
            .is_some()
            .then(|| (attributes.positions.clone(), attributes.normals.clone()));
        super::gltf_pose::apply_morph(prim, pose.weights, buffers, &mut attributes)?;
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
            Some((skin, worlds)) => Some(super::gltf_pose::skin_matrices(
                prim, skin, worlds, buffers, n,
            )?),
            None => None,
        };
        let place = |s: usize| skinned.as_ref().map_or(world, |k| k[s]);
        let Some(mut tris) = triangulate(mode, &indices) else {
            return Ok(());
        };
        let m3 = Mat3::from_mat4(world);
        let mirrored = m3.determinant() < 0.0;
        let normal_m = m3.inverse().transpose();

        // Without normals glTF asks for flat shading: every corner its own
        // vertex with the face normal, and any tangents ignored.
        let (order, face_normals): (Vec<u32>, Option<Vec<Vec3>>) = if normals.is_some() {
            ((0..n as u32).collect(), None)
        } else {
            let order: Vec<u32> = tris.iter().flatten().copied().collect();
            let fn_: Vec<Vec3> = tris
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| positions[i as usize]);
                    (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::Y)
                })
                .collect();
            tris = (0..tris.len() as u32)
                .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect();
            (order, Some(fn_))
        };
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
        let end = m.triangles.len() as u32;
        m.groups.push(Group {
            triangles: first..end,
            material,
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
        let targets = super::gltf_pose::read_targets(prim, buffers, n).map_err(context)?;
        let (skin, influences) = match pose.skin {
            Some((skin, _)) => {
                let count = skin.joints().count();
                let inf =
                    super::gltf_pose::read_influences(prim, buffers, n, count).map_err(context)?;
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

    #[test]
    fn data_uris_and_percent_escapes() {
        assert_eq!(
            data_uri("data:application/octet-stream;base64,AAEC")
                .unwrap()
                .unwrap(),
            vec![0, 1, 2]
        );
        assert!(data_uri("data:text/plain,abc").unwrap().is_err());
        assert!(data_uri("model.bin").is_none());
        assert_eq!(percent_decode("a%20b.bin"), "a b.bin");
        assert_eq!(percent_decode("100%"), "100%");
    }
}
