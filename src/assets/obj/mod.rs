//! Wavefront OBJ and MTL, read by our own parser (`parse`, `mtl`) so that
//! every error names its line and nothing in a file can panic: texture
//! options inside map names (`-bm 1.0`, `-s`, `-o`, `-clamp on`), paths
//! relative to the MTL file, smooth normals per position, OBJ's upward v,
//! concave faces (`triangulate`), any text encoding (`assets::text`).
//! Lenient: a missing library, an unknown key or a value that cannot be
//! read is a warning, and the model renders with defaults.

mod mtl;
mod parse;
pub(crate) mod triangulate;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::input::Input;
use super::mesh::{Group, Mesh, Primitive, smooth_normals};
use crate::color::srgb_to_linear;
use crate::error::Error;

/// A texture reference in an MTL file, options split off.
#[derive(Debug, Clone, PartialEq)]
pub struct MapSpec {
    /// Resolved against the MTL file's directory (or the scene file's for
    /// scene overrides).
    pub path: PathBuf,
    /// `-bm`: bump multiplier.
    pub bump_scale: Option<f32>,
    /// `-s u v w`.
    pub scale: [f32; 3],
    /// `-o u v w`.
    pub offset: [f32; 3],
    /// `-clamp on`.
    pub clamp: bool,
    /// `-mm base gain` (displacement and bump heights: base + gain * h).
    pub mm: Option<(f32, f32)>,
}

/// A material as the MTL file states it; unset keys stay `None`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MtlMaterial {
    pub name: String,
    pub ka: Option<[f32; 3]>,
    pub kd: Option<[f32; 3]>,
    pub ks: Option<[f32; 3]>,
    pub ke: Option<[f32; 3]>,
    pub ns: Option<f32>,
    pub ni: Option<f32>,
    pub d: Option<f32>,
    pub illum: Option<u8>,
    pub map_ka: Option<MapSpec>,
    pub map_kd: Option<MapSpec>,
    pub map_ks: Option<MapSpec>,
    pub map_ke: Option<MapSpec>,
    pub map_ns: Option<MapSpec>,
    pub map_d: Option<MapSpec>,
    /// `map_Bump` / `bump`: a normal map or a height map, told apart by
    /// content (a grey image is heights).
    pub map_bump: Option<MapSpec>,
    /// `norm`: always a normal map.
    pub norm: Option<MapSpec>,
    pub disp: Option<MapSpec>,
    /// The PBR extension of MTL (Exocortex; Blender and tinyobjloader
    /// write it): roughness, metallic, clearcoat thickness and roughness.
    pub pr: Option<f32>,
    pub pm: Option<f32>,
    pub pc: Option<f32>,
    pub pcr: Option<f32>,
    pub map_pr: Option<MapSpec>,
    pub map_pm: Option<MapSpec>,
    /// `newmtl` gave no name (`name` is then `material<position>`).
    pub unnamed: bool,
    /// Made up by the loader for faces without a material (no MTL, or no
    /// `usemtl`): the renderer's defaults apply rather than MTL's.
    pub synthetic: bool,
}

#[derive(Debug)]
pub struct ObjModel {
    pub mesh: Mesh,
    /// Indexed by `Group::material`. A model without MTL (or faces without
    /// `usemtl`, or naming a material no library has) gets one material
    /// named "default" with every key unset.
    pub materials: Vec<MtlMaterial>,
    /// What was skipped or could not be read, each naming file and line.
    pub warnings: Vec<String>,
}

/// Reads an OBJ file and its material libraries through `input` (bounded
/// reads, the sandbox).
pub fn load(path: &Path, input: &Input) -> Result<ObjModel, Error> {
    let text = input.read_text(path, None)?;
    let mut warnings = Vec::new();
    let mut file = parse::parse(path, &text, &mut warnings)?;
    points_of_bare_vertices(&mut file);
    let mut mats = libraries(&file, path, input, &mut warnings)?;
    let mut mesh = build_mesh(&file, &mut mats, path, &mut warnings);
    if mesh.triangles.is_empty() && mesh.lines.is_empty() && mesh.points.is_empty() {
        return Err(Error::asset(
            path,
            None,
            "the model has no faces, lines or points",
        ));
    }
    let (lo, hi) = mesh.bounds();
    if !(hi - lo).length().is_finite() {
        return Err(Error::asset(
            path,
            None,
            format!(
                "the model's extent ({:e}, {:e}, {:e} to {:e}, {:e}, {:e}) is too large to compute with in 32-bit floats; scale the model down",
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
            ),
        ));
    }
    let missing: Vec<bool> = mesh.normals.iter().map(|n| *n == Vec3::ZERO).collect();
    if missing.iter().any(|m| *m) {
        smooth_normals(
            &mesh.positions,
            &mesh.triangles,
            &mut mesh.normals,
            &missing,
        );
    }
    Ok(ObjModel {
        mesh,
        materials: mats,
        warnings,
    })
}

/// The materials of every `mtllib`, in order. A library that cannot be
/// read is a warning: its materials fall back to the default (one the
/// sandbox refuses is an error).
fn libraries(
    file: &parse::ObjFile,
    path: &Path,
    input: &Input,
    warnings: &mut Vec<String>,
) -> Result<Vec<MtlMaterial>, Error> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut mats = Vec::new();
    for (arg, line) in &file.mtllibs {
        // A name with spaces, else a list of names.
        let whole = dir.join(fix_separators(arg));
        let names: Vec<PathBuf> = if whole.is_file() {
            vec![whole]
        } else {
            arg.split_whitespace()
                .map(|n| dir.join(fix_separators(n)))
                .collect()
        };
        for lib in names {
            match input.read_text(&lib, Some(path)) {
                Ok(text) => mats.extend(mtl::parse(&lib, &text, warnings)),
                Err(e @ Error::Sandbox { .. }) => return Err(e),
                Err(e) => warnings.push(format!(
                    "{}:{line}: material library {} cannot be read ({}); its materials render with the default material",
                    path.display(),
                    lib.display(),
                    reason(&e)
                )),
            }
        }
    }
    Ok(mats)
}

/// Why a file could not be read, without the paths (the warning names
/// them).
fn reason(e: &Error) -> String {
    match e {
        Error::Asset { message, .. } => {
            let m = message.strip_prefix("cannot read: ").unwrap_or(message);
            m.split(" (named by ").next().unwrap_or(m).to_string()
        }
        other => other.to_string(),
    }
}

/// One mesh: a vertex per distinct (position, uv, normal) corner, each
/// face triangulated, a group per run of one material. Faces without a
/// material, or naming one no library defines, get a `default` material
/// appended to `mats`.
fn build_mesh(
    f: &parse::ObjFile,
    mats: &mut Vec<MtlMaterial>,
    path: &Path,
    warnings: &mut Vec<String>,
) -> Mesh {
    // usemtl index -> material index (None: the default).
    let resolved: Vec<Option<usize>> = f
        .usemtl
        .iter()
        .map(|(name, line)| {
            // `usemtl` without a name picks the library's unnamed
            // material (`newmtl` without a name, named by position).
            let i = mats.iter().position(|m| m.name == *name).or_else(|| {
                name.is_empty()
                    .then(|| mats.iter().position(|m| m.unnamed))
                    .flatten()
            });
            if i.is_none() && (!mats.is_empty() || !f.mtllibs.is_empty()) {
                warnings.push(format!(
                    "{}:{line}: usemtl {name}: no material library defines it; the default material is used",
                    path.display()
                ));
            }
            i
        })
        .collect();
    let mut default_material = None;
    let mut material_of = |face: &parse::Face, mats: &mut Vec<MtlMaterial>| match face
        .material
        .and_then(|m| resolved[m as usize])
    {
        Some(i) => i,
        None => *default_material.get_or_insert_with(|| {
            mats.push(MtlMaterial {
                name: "default".into(),
                synthetic: true,
                ..Default::default()
            });
            mats.len() - 1
        }),
    };
    let mut b = VertexBuilder {
        f,
        any_uv: f.corners.iter().any(|c| c.t.is_some()),
        any_color: f.colors.iter().any(Option::is_some),
        remap: HashMap::new(),
        mesh: Mesh::default(),
    };
    let mut points = Vec::new();
    for face in &f.faces {
        let material = material_of(face, mats);
        let corners = &f.corners[face.start as usize..(face.start + face.len) as usize];
        points.clear();
        points.extend(corners.iter().map(|c| f.positions[c.v as usize]));
        let first_tri = b.mesh.triangles.len() as u32;
        for tri in triangulate::triangulate(&points) {
            let t = tri.map(|k| b.vertex(corners[k]));
            b.mesh.triangles.push(t);
        }
        let range = first_tri..b.mesh.triangles.len() as u32;
        match b.mesh.groups.last_mut() {
            Some(g) if g.material == material && g.triangles.end == range.start => {
                g.triangles.end = range.end
            }
            _ if range.is_empty() => {}
            _ => b.mesh.groups.push(Group {
                triangles: range,
                material,
                part: 0,
            }),
        }
    }
    for (list, is_line) in [(&f.points, false), (&f.lines, true)] {
        for e in list {
            let material = material_of(e, mats);
            let corners = &f.corners[e.start as usize..(e.start + e.len) as usize];
            let v: Vec<u32> = corners.iter().map(|c| b.vertex(*c)).collect();
            if is_line {
                b.mesh.lines.extend(v.windows(2).map(|w| Primitive {
                    vertices: [w[0], w[1]],
                    material,
                }));
            } else {
                b.mesh.points.extend(v.iter().map(|&i| Primitive {
                    vertices: [i],
                    material,
                }));
            }
        }
    }
    b.mesh
}

/// A file of vertices alone (a scan's point cloud, `v x y z [r g b]`
/// lines with no face, line or point) is drawn as its points: one `p`
/// element naming every vertex.
fn points_of_bare_vertices(f: &mut parse::ObjFile) {
    if !(f.faces.is_empty() && f.lines.is_empty() && f.points.is_empty()) {
        return;
    }
    let n = f.positions.len() as u32;
    if n == 0 {
        return;
    }
    let start = f.corners.len() as u32;
    f.corners.extend((0..n).map(|v| parse::Corner {
        v,
        t: None,
        n: None,
    }));
    f.points.push(parse::Face {
        start,
        len: n,
        material: None,
    });
}

/// Vertices of the mesh, one per distinct (position, uv, normal) corner.
struct VertexBuilder<'a> {
    f: &'a parse::ObjFile,
    any_uv: bool,
    any_color: bool,
    remap: HashMap<parse::Corner, u32>,
    mesh: Mesh,
}

impl VertexBuilder<'_> {
    fn vertex(&mut self, c: parse::Corner) -> u32 {
        let (f, mesh) = (self.f, &mut self.mesh);
        let (any_uv, any_color) = (self.any_uv, self.any_color);
        *self.remap.entry(c).or_insert_with(|| {
            mesh.positions.push(f.positions[c.v as usize]);
            if any_uv {
                // OBJ's v runs up; textures are addressed top-down.
                let uv = c.t.map(|t| f.texcoords[t as usize]).unwrap_or(Vec2::ZERO);
                mesh.uvs.push(Vec2::new(uv.x, 1.0 - uv.y));
            }
            if any_color {
                let rgb = f.colors[c.v as usize].unwrap_or(Vec3::ONE);
                let lin = rgb
                    .clamp(Vec3::ZERO, Vec3::ONE)
                    .to_array()
                    .map(srgb_to_linear);
                mesh.colors
                    .push(glam::Vec4::new(lin[0], lin[1], lin[2], 1.0));
            }
            let n =
                c.n.and_then(|n| f.normals[n as usize].try_normalize())
                    .unwrap_or(Vec3::ZERO);
            mesh.normals.push(n);
            (mesh.positions.len() - 1) as u32
        })
    }
}

fn fix_separators(s: &str) -> String {
    s.replace('\\', "/")
}

/// Splits MTL texture options from the file name: `-bm 1.0 my map (2).png`
/// gives bump scale 1 and the file `my map (2).png`. The name is everything
/// after the options, spaces included; backslashes become slashes.
pub fn parse_map(raw: &str, base: &Path) -> Result<MapSpec, String> {
    let mut spec = MapSpec {
        path: PathBuf::new(),
        bump_scale: None,
        scale: [1.0; 3],
        offset: [0.0; 3],
        clamp: false,
        mm: None,
    };
    let mut rest = raw.trim();
    while let Some(opt) = rest.strip_prefix('-') {
        let (name, after) = split_word(opt);
        // How many arguments each option takes (at most, for -s -o -t).
        let (min, max) = match name {
            "bm" | "clamp" | "blendu" | "blendv" | "cc" | "texres" | "imfchan" | "type"
            | "boost" => (1, 1),
            "mm" => (2, 2),
            "s" | "o" | "t" => (1, 3),
            _ => return Err(format!("unknown texture option -{name} in `{raw}`")),
        };
        let mut args = Vec::new();
        let mut r = after;
        while args.len() < max {
            let (w, a) = split_word(r);
            let numeric = w.parse::<f32>().is_ok();
            let takes = match name {
                "clamp" | "blendu" | "blendv" | "cc" => w == "on" || w == "off",
                "imfchan" | "type" => !w.is_empty(),
                _ => numeric,
            };
            // The last word is always the file name.
            if !takes || (a.is_empty() && args.len() >= min) {
                break;
            }
            args.push(w);
            r = a;
        }
        if args.len() < min {
            return Err(format!(
                "texture option -{name} is missing its value in `{raw}`"
            ));
        }
        let num = |i: usize| args[i].parse::<f32>().unwrap_or(0.0);
        match name {
            "bm" => spec.bump_scale = Some(num(0)),
            "clamp" => spec.clamp = args[0] == "on",
            "mm" => spec.mm = Some((num(0), num(1))),
            "s" => {
                for (i, s) in spec.scale.iter_mut().enumerate().take(args.len()) {
                    *s = num(i);
                }
            }
            "o" => {
                for (i, o) in spec.offset.iter_mut().enumerate().take(args.len()) {
                    *o = num(i);
                }
            }
            _ => {}
        }
        rest = r.trim_start();
    }
    if rest.is_empty() {
        return Err(format!("texture statement `{raw}` has no file name"));
    }
    spec.path = base.join(fix_separators(rest));
    Ok(spec)
}

fn split_word(s: &str) -> (&str, &str) {
    let s = s.trim_start();
    match s.find(char::is_whitespace) {
        Some(i) => (&s[..i], s[i..].trim_start()),
        None => (s, ""),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_options_are_split_from_names() {
        let base = Path::new("/m");
        let s = parse_map("-bm 1.000000 diablo3_pose_nm_tangent.tga", base).unwrap();
        assert_eq!(s.bump_scale, Some(1.0));
        assert_eq!(s.path, Path::new("/m/diablo3_pose_nm_tangent.tga"));
        let s = parse_map("-s 2 2 -o 0.5 -clamp on my map (2).png", base).unwrap();
        assert_eq!(s.scale, [2.0, 2.0, 1.0]);
        assert_eq!(s.offset, [0.5, 0.0, 0.0]);
        assert!(s.clamp);
        assert_eq!(s.path, Path::new("/m/my map (2).png"));
        let s = parse_map("textures\\skin.png", base).unwrap();
        assert_eq!(s.path, Path::new("/m/textures/skin.png"));
        assert!(parse_map("-bm", base).is_err());
        assert!(parse_map("-zz 1 a.png", base).is_err());
    }
}
