//! USD models through the `openusd` crate (MIT, pure Rust): `.usda` text,
//! `.usdc` binary and `.usdz` packages, composed as a stage (sublayers,
//! references, payloads, variants at their selections).
//!
//! What is read:
//! - every `Mesh` prim that is visible and of the default or render
//!   purpose, placed by its ancestors' transform stacks (at the earliest
//!   time sample, else the default value), in Y-up metres: the stage's
//!   `upAxis` and `metersPerUnit` (USD's fallback: Y, centimetres) are
//!   converted as glTF's are;
//! - points, faces (polygons triangulated, holes skipped, `leftHanded`
//!   orientation reversed), normals, the `st` texture coordinates and
//!   `displayColor`, at any interpolation, indexed or not;
//! - materials: each mesh's bound `UsdPreviewSurface` (`material:binding`
//!   on it or an ancestor, and per-face `GeomSubset`s), as
//!   metallic-roughness (`material`);
//! - textures beside the file, or inside the `.usdz` package.
//!
//! Not read: skeletons and animation (drawn at rest), cameras and lights,
//! subdivision (meshes are drawn as their control cage), other shading
//! dialects (MDL, MaterialX: such meshes get the default material).

mod material;
mod trial;

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3, Vec4};
use openusd::schemas::geom::{Imageable, Xformable};
use openusd::sdf::{self, Value};
use openusd::usd::{Prim, SchemaBase, SchemaKind, Stage, TimeCode};

use super::gltf::GltfMaterial;
use super::input::Input;
use super::mesh::{Group, Mesh, smooth_normals};
use crate::error::Error;

/// A model read from a USD file.
#[derive(Debug)]
pub struct UsdModel {
    pub mesh: Mesh,
    /// Indexed by `Group::material`.
    pub materials: Vec<GltfMaterial>,
    pub warnings: Vec<String>,
}

/// The most prims walked, and the most face corners read from one file:
/// past them the file is refused rather than exhausting memory or time.
const MAX_PRIMS: usize = 1 << 20;

/// Reads the USD file at `path` through `input` (the sandbox and the
/// read cap apply to the file itself; the layers it composes are read by
/// the crate, and in the sandbox each must lie in the file's folder).
pub fn load(path: &Path, input: &Input) -> Result<UsdModel, Error> {
    let bytes = input.read(path, None, None)?;
    trial::survives(input.budget(), bytes.len(), || {
        let _ = read(path, input, &bytes);
    })
    .map_err(|m| Error::asset(path, None, m))?;
    read(path, input, &bytes)
}

/// `load` of the file at `path`, whose bytes are `bytes`.
fn read(path: &Path, input: &Input, bytes: &[u8]) -> Result<UsdModel, Error> {
    let fail = |m: String| Error::asset(path, None, m);
    let name = path
        .to_str()
        .ok_or_else(|| fail("the USD file's path is not UTF-8".into()))?;
    let stage = guarded(|| Stage::open(name))
        .map_err(|e| fail(format!("cannot read the USD file: {e}")))?;
    if input.is_sandboxed() {
        confine_layers(&stage, path)?;
    }
    let package = material::Package::of(path, bytes);
    let mut reader = Reader {
        stage: &stage,
        dir: path.parent().unwrap_or(Path::new("")),
        package: &package,
        model: UsdModel {
            mesh: Mesh::default(),
            materials: Vec::new(),
            warnings: Vec::new(),
        },
        bound: Vec::new(),
        prims: 0,
        budget: input.budget() / 64,
    };
    let root = axes(&stage);
    guarded(|| reader.walk(root)).map_err(|e| fail(format!("cannot read the USD file: {e}")))?;
    let mut model = reader.model;
    if model.mesh.triangles.is_empty() {
        return Err(fail("the USD file has no mesh with faces".into()));
    }
    if model.mesh.normals.len() == model.mesh.positions.len() {
        let missing: Vec<bool> = model
            .mesh
            .normals
            .iter()
            .map(|n| *n == Vec3::ZERO)
            .collect();
        if missing.iter().any(|&m| m) {
            let m = &mut model.mesh;
            smooth_normals(&m.positions, &m.triangles, &mut m.normals, &missing);
        }
    }
    Ok(model)
}

/// In the sandbox: every layer the stage composed lies in the folder of
/// `path` (the root file, which the sandbox has checked). The crate names
/// layers by their resolved paths; anonymous layers have no file.
fn confine_layers(stage: &Stage, path: &Path) -> Result<(), Error> {
    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let folder = folder.canonicalize().map_err(|e| {
        Error::asset(
            path,
            None,
            format!("cannot resolve the model's folder: {e}"),
        )
    })?;
    for layer in stage.layer_identifiers() {
        if layer.starts_with("anon:") {
            continue;
        }
        // "pkg.usdz[inner.usdc]": the package is the file.
        let file = match layer.find('[') {
            Some(k) => &layer[..k],
            None => layer.as_str(),
        };
        let inside = Path::new(file)
            .canonicalize()
            .is_ok_and(|real| real.starts_with(&folder));
        if !inside {
            return Err(Error::Sandbox {
                path: PathBuf::from(file),
                message: format!(
                    " (a layer of {}): outside the model's folder",
                    path.display()
                ),
            });
        }
    }
    Ok(())
}

/// Runs `f`, turning a panic inside the crate into an error (a file that
/// trips it is bad input, never a crash).
fn guarded<T>(f: impl FnOnce() -> anyhow::Result<T>) -> Result<T, String> {
    match super::guard::catch(f) {
        Some(Ok(v)) => Ok(v),
        Some(Err(e)) => Err(format!("{e:#}")),
        None => Err("the USD reader failed on this file".into()),
    }
}

/// The stage's axes and unit to Y-up metres.
fn axes(stage: &Stage) -> Mat4 {
    let meta = |k: &str| stage.stage_metadata(k).ok().flatten();
    let metres = match meta("metersPerUnit") {
        Some(Value::Double(m)) if m.is_finite() && m > 0.0 => m as f32,
        Some(Value::Float(m)) if m.is_finite() && m > 0.0 => m,
        _ => 0.01,
    };
    let z_up = matches!(meta("upAxis"), Some(Value::Token(t)) if t.as_str() == "Z");
    let up = if z_up {
        Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2)
    } else {
        Mat4::IDENTITY
    };
    up * Mat4::from_scale(Vec3::splat(metres))
}

/// Any prim seen as transformable (its `xformOpOrder`, if it has one).
struct AnyXform(Prim);

impl SchemaBase for AnyXform {
    const KIND: SchemaKind = SchemaKind::ConcreteTyped;

    fn prim(&self) -> &Prim {
        &self.0
    }
}

impl Imageable for AnyXform {}
impl Xformable for AnyXform {}

/// The stage walk's state.
struct Reader<'s> {
    stage: &'s Stage,
    dir: &'s Path,
    package: &'s material::Package,
    model: UsdModel,
    /// Materials converted so far, by prim path (None: the default).
    bound: Vec<(Option<sdf::Path>, usize)>,
    prims: usize,
    /// Face corners left to read.
    budget: u64,
}

impl Reader<'_> {
    /// Walks the stage depth first, parent transforms composed onto
    /// `root`.
    fn walk(&mut self, root: Mat4) -> anyhow::Result<()> {
        let mut stack = vec![(self.stage.prim(sdf::Path::abs_root()), root)];
        while let Some((prim, world)) = stack.pop() {
            self.prims += 1;
            anyhow::ensure!(self.prims <= MAX_PRIMS, "more than {MAX_PRIMS} prims");
            for child in prim.children()?.into_iter().rev() {
                if !shown(&child)? {
                    continue;
                }
                let x = AnyXform(child);
                let local = x.local_to_parent_transform(TimeCode::EARLIEST)?;
                let local = Mat4::from_cols_array(&local.0.map(|v| v as f32));
                let world = if x.resets_xform_stack()? { root } else { world } * local;
                let child = x.0;
                if child.type_name()?.is_some_and(|t| t.as_str() == "Mesh") {
                    self.mesh(&child, world)?;
                }
                stack.push((child, world));
            }
        }
        Ok(())
    }

    /// Appends mesh prim `prim`, placed by `world`.
    fn mesh(&mut self, prim: &Prim, world: Mat4) -> anyhow::Result<()> {
        let counts: Vec<i32> = ints(prim, "faceVertexCounts")?;
        let indices: Vec<i32> = ints(prim, "faceVertexIndices")?;
        let points = vec3s(prim, "points")?;
        let corners = indices.len() as u64;
        anyhow::ensure!(
            corners <= self.budget,
            "{}: {corners} face corners, more than the memory budget allows",
            prim.path().as_str()
        );
        self.budget -= corners;
        let faces = Faces::new(&counts, &indices, points.len())
            .map_err(|m| anyhow::anyhow!("{}: {m}", prim.path().as_str()))?;
        let holes: Vec<i32> = ints(prim, "holeIndices").unwrap_or_default();
        let left = matches!(prim.attribute("orientation").get::<Value>()?,
            Some(Value::Token(t)) if t.as_str() == "leftHanded");
        let normals = Primvar::read(prim, "normals", "primvars:normals")?;
        let st = texture_coordinates(prim)?;
        let (face_material, bound) = self.face_materials(prim, counts.len())?;
        // displayColor stands in for a material, as USD viewers draw it.
        let colors = if bound {
            Primvar::none()
        } else {
            Primvar::read(prim, "primvars:displayColor", "primvars:displayColor")?
        };
        let normal_world = Mat4::from_mat3(glam::Mat3::from_mat4(world).inverse().transpose());
        let out = &mut self.model.mesh;
        // A set only some meshes have: the others' corners get neutral
        // values.
        if st.present() {
            out.uvs.resize(out.positions.len(), Vec2::ZERO);
        }
        if colors.present() {
            out.colors.resize(out.positions.len(), Vec4::ONE);
        }
        let mut by_material: Vec<(usize, Vec<[u32; 3]>)> = Vec::new();
        for (f, range) in faces.iter().enumerate() {
            if holes.contains(&(f as i32)) {
                continue;
            }
            let ring: Vec<usize> = range.clone().collect();
            let at = |k: usize| points[indices[ring[k]] as usize];
            let polygon: Vec<Vec3> = (0..ring.len()).map(at).collect();
            let tris = super::obj::triangulate::triangulate(&polygon);
            let m = face_material[f];
            let list = match by_material.iter_mut().find(|(k, _)| *k == m) {
                Some((_, l)) => l,
                None => {
                    by_material.push((m, Vec::new()));
                    &mut by_material.last_mut().expect("just pushed").1
                }
            };
            for t in tris {
                let t = if left { [t[0], t[2], t[1]] } else { t };
                let base = out.positions.len() as u32;
                for k in t {
                    let corner = ring[k];
                    let point = indices[corner] as usize;
                    out.positions.push(world.transform_point3(points[point]));
                    let n = normals.at(f, point, corner).map_or(Vec3::ZERO, |n| {
                        normal_world.transform_vector3(n).normalize_or_zero()
                    });
                    out.normals.push(n);
                    if st.present() {
                        // USD's t runs up; the mesh's image convention down.
                        let uv = st.at2(f, point, corner).unwrap_or(Vec2::ZERO);
                        out.uvs.push(Vec2::new(uv.x, 1.0 - uv.y));
                    }
                    if colors.present() {
                        let c = colors.at(f, point, corner).unwrap_or(Vec3::ONE);
                        out.colors.push(c.extend(1.0));
                    }
                }
                list.push([base, base + 1, base + 2]);
            }
        }
        let n = out.positions.len();
        if !out.uvs.is_empty() {
            out.uvs.resize(n, Vec2::ZERO);
        }
        if !out.colors.is_empty() {
            out.colors.resize(n, Vec4::ONE);
        }
        for (m, tris) in by_material {
            let first = out.triangles.len() as u32;
            out.triangles.extend(tris);
            out.groups.push(Group {
                triangles: first..out.triangles.len() as u32,
                material: m,
                part: 0,
            });
        }
        Ok(())
    }

    /// The model material of each of `prim`'s `faces` faces: its bound
    /// material, where a `GeomSubset` of the material family binds one of
    /// its own to some faces; and whether any material is bound.
    fn face_materials(&mut self, prim: &Prim, faces: usize) -> anyhow::Result<(Vec<usize>, bool)> {
        let whole = self.bound_material(prim)?;
        let mut bound = whole.is_some();
        let whole = self.material(whole)?;
        let mut out = vec![whole; faces];
        for child in prim.children()? {
            let subset = child
                .type_name()?
                .is_some_and(|t| t.as_str() == "GeomSubset");
            if !subset {
                continue;
            }
            let Some(m) = binding(&child)? else { continue };
            bound = true;
            let m = self.material(Some(m))?;
            for f in ints(&child, "indices").unwrap_or_default() {
                if let Some(slot) = usize::try_from(f).ok().and_then(|f| out.get_mut(f)) {
                    *slot = m;
                }
            }
        }
        Ok((out, bound))
    }

    /// The material bound to `prim` or its nearest ancestor with one.
    fn bound_material(&self, prim: &Prim) -> anyhow::Result<Option<sdf::Path>> {
        let mut path = prim.path().clone();
        loop {
            let p = self.stage.prim(path.clone());
            if let Some(m) = binding(&p)? {
                return Ok(Some(m));
            }
            match path.parent() {
                Some(parent) if parent != path && !parent.as_str().is_empty() => path = parent,
                _ => return Ok(None),
            }
        }
    }

    /// The model's index of material `m` (the default for None),
    /// converted once.
    fn material(&mut self, m: Option<sdf::Path>) -> anyhow::Result<usize> {
        if let Some(&(_, k)) = self.bound.iter().find(|(p, _)| *p == m) {
            return Ok(k);
        }
        let warnings = &mut self.model.warnings;
        let g = match &m {
            Some(path) => {
                let g =
                    material::preview_surface(self.stage, path, self.dir, self.package, warnings)?;
                if g.is_none() {
                    warnings.push(format!(
                        "material {} is not a UsdPreviewSurface; its meshes get the default material",
                        path.as_str()
                    ));
                }
                g
            }
            None => None,
        };
        let g = g.unwrap_or_else(|| {
            let mut d = GltfMaterial::default_material();
            d.metallic = 0.0;
            d.roughness = 0.5;
            d
        });
        let list = &mut self.model.materials;
        list.push(g);
        self.bound.push((m, list.len() - 1));
        Ok(list.len() - 1)
    }
}

/// `prim`'s texture coordinates: `primvars:st`, else its first other
/// 2-vector primvar (exporters name them `UVMap`, `map1`, `st0`, ...).
fn texture_coordinates(prim: &Prim) -> anyhow::Result<Primvar> {
    let st = Primvar::read(prim, "primvars:st", "primvars:st")?;
    if st.present() {
        return Ok(st);
    }
    for name in prim.property_names()? {
        let name = name.as_str();
        if name.starts_with("primvars:") && !name.ends_with(":indices") {
            let p = Primvar::read(prim, name, name)?;
            if matches!(p.values, Values::V2(_)) {
                return Ok(p);
            }
        }
    }
    Ok(st)
}

/// Whether `prim` is drawn: not `invisible`, and of the default or render
/// purpose (guides and proxies are not).
fn shown(prim: &Prim) -> anyhow::Result<bool> {
    let token = |name: &str| -> anyhow::Result<Option<String>> {
        Ok(match prim.attribute(name).get::<Value>()? {
            Some(Value::Token(t)) => Some(t.as_str().to_string()),
            _ => None,
        })
    };
    let hidden = token("visibility")?.is_some_and(|v| v == "invisible");
    let purpose = token("purpose")?;
    let aside = purpose.is_some_and(|p| p == "guide" || p == "proxy");
    Ok(prim.is_active()? && !hidden && !aside)
}

/// The target of `prim`'s all-purpose material binding.
fn binding(prim: &Prim) -> anyhow::Result<Option<sdf::Path>> {
    Ok(prim
        .relationship("material:binding")
        .targets()?
        .into_iter()
        .next())
}

/// Attribute `name` of `prim` as integers (empty where unauthored).
fn ints(prim: &Prim, name: &str) -> anyhow::Result<Vec<i32>> {
    Ok(match prim.attribute(name).get::<Value>()? {
        Some(Value::IntVec(v)) => v,
        Some(Value::Int(v)) => vec![v],
        Some(other) => anyhow::bail!(
            "{}.{name}: expected int[], found {}",
            prim.path().as_str(),
            kind(&other)
        ),
        None => Vec::new(),
    })
}

/// Attribute `name` of `prim` as 3-vectors (empty where unauthored).
fn vec3s(prim: &Prim, name: &str) -> anyhow::Result<Vec<Vec3>> {
    let v = prim.attribute(name).get::<Value>()?;
    Ok(v.and_then(|v| as_vec3s(&v)).unwrap_or_default())
}

fn as_vec3s(v: &Value) -> Option<Vec<Vec3>> {
    Some(match v {
        Value::Vec3fVec(v) => v.iter().map(|p| Vec3::new(p.x, p.y, p.z)).collect(),
        Value::Vec3dVec(v) => v
            .iter()
            .map(|p| Vec3::new(p.x as f32, p.y as f32, p.z as f32))
            .collect(),
        Value::Vec3f(p) => vec![Vec3::new(p.x, p.y, p.z)],
        _ => return None,
    })
}

fn as_vec2s(v: &Value) -> Option<Vec<Vec2>> {
    Some(match v {
        Value::Vec2fVec(v) => v.iter().map(|p| Vec2::new(p.x, p.y)).collect(),
        Value::Vec2dVec(v) => v
            .iter()
            .map(|p| Vec2::new(p.x as f32, p.y as f32))
            .collect(),
        _ => return None,
    })
}

/// A value's type for messages.
fn kind(v: &Value) -> String {
    let d = format!("{v:?}");
    d.split(['(', ' ', '{']).next().unwrap_or("?").to_string()
}

/// The faces of a mesh: the corners of each, checked against the points.
struct Faces {
    starts: Vec<usize>,
}

impl Faces {
    fn new(counts: &[i32], indices: &[i32], points: usize) -> Result<Faces, String> {
        let mut starts = Vec::with_capacity(counts.len() + 1);
        let mut at = 0usize;
        starts.push(0);
        for &c in counts {
            let c = usize::try_from(c).map_err(|_| format!("a face of {c} corners"))?;
            at = at.saturating_add(c);
            starts.push(at);
        }
        if at != indices.len() {
            return Err(format!(
                "faceVertexCounts add up to {at} corners, faceVertexIndices has {}",
                indices.len()
            ));
        }
        if let Some(i) = indices.iter().find(|&&i| i < 0 || i as usize >= points) {
            return Err(format!(
                "faceVertexIndices names point {i}, the mesh has {points}"
            ));
        }
        Ok(Faces { starts })
    }

    /// Each face's corner range.
    fn iter(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.starts.windows(2).map(|w| w[0]..w[1])
    }
}

/// A primvar (or `normals`) with its interpolation and indices.
struct Primvar {
    values: Values,
    interpolation: Interp,
    indices: Option<Vec<i32>>,
}

enum Values {
    None,
    V3(Vec<Vec3>),
    V2(Vec<Vec2>),
}

#[derive(Clone, Copy, PartialEq)]
enum Interp {
    Constant,
    Uniform,
    Vertex,
    FaceVarying,
}

impl Primvar {
    /// Attribute `name` (else `fallback`) of `prim`.
    fn read(prim: &Prim, name: &str, fallback: &str) -> anyhow::Result<Primvar> {
        let (mut attr, mut used) = (prim.attribute(name), name);
        let mut value = attr.get::<Value>()?;
        if value.is_none() && fallback != name {
            (attr, used) = (prim.attribute(fallback), fallback);
            value = attr.get::<Value>()?;
        }
        let values = match &value {
            Some(v) => match (as_vec3s(v), as_vec2s(v)) {
                (Some(v), _) => Values::V3(v),
                (_, Some(v)) => Values::V2(v),
                _ => Values::None,
            },
            None => Values::None,
        };
        let interpolation = match attr.get_metadata::<Value>("interpolation")? {
            Some(Value::Token(t)) => match t.as_str() {
                "constant" => Interp::Constant,
                "uniform" => Interp::Uniform,
                "faceVarying" => Interp::FaceVarying,
                _ => Interp::Vertex,
            },
            // USD's fallback for primvars and normals alike.
            _ => Interp::Vertex,
        };
        let indices = match prim
            .attribute(format!("{used}:indices").as_str())
            .get::<Value>()?
        {
            Some(Value::IntVec(v)) => Some(v),
            _ => None,
        };
        Ok(Primvar {
            values,
            interpolation,
            indices,
        })
    }

    /// An unauthored primvar.
    fn none() -> Primvar {
        Primvar {
            values: Values::None,
            interpolation: Interp::Constant,
            indices: None,
        }
    }

    fn present(&self) -> bool {
        !matches!(self.values, Values::None)
    }

    /// Which element face `face`, point `point`, corner `corner` reads.
    fn element(&self, face: usize, point: usize, corner: usize) -> usize {
        let k = match self.interpolation {
            Interp::Constant => 0,
            Interp::Uniform => face,
            Interp::Vertex => point,
            Interp::FaceVarying => corner,
        };
        match &self.indices {
            Some(ix) => ix.get(k).map_or(usize::MAX, |&i| i as usize),
            None => k,
        }
    }

    fn at(&self, face: usize, point: usize, corner: usize) -> Option<Vec3> {
        match &self.values {
            Values::V3(v) => v.get(self.element(face, point, corner)).copied(),
            _ => None,
        }
        .filter(|v| v.is_finite())
    }

    fn at2(&self, face: usize, point: usize, corner: usize) -> Option<Vec2> {
        match &self.values {
            Values::V2(v) => v.get(self.element(face, point, corner)).copied(),
            _ => None,
        }
        .filter(|v| v.is_finite())
    }
}
