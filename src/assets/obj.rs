//! Wavefront OBJ and MTL through tobj, plus what tobj leaves to us: texture
//! options inside map names (`-bm 1.0`, `-s`, `-o`, `-clamp on`), MTL keys it
//! does not know (`map_Ke`, `norm`, `disp`, `Tr`), paths relative to the MTL
//! file, smooth normals per position, OBJ's upward v, and the line of a
//! malformed face (tobj reports errors without one; `locate_error` finds it).

use std::cell::RefCell;
use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::mesh::{Group, Mesh, smooth_normals};
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
    /// Made up by the loader for faces without a material (no MTL, or no
    /// `usemtl`): the renderer's defaults apply rather than MTL's.
    pub synthetic: bool,
}

#[derive(Debug)]
pub struct ObjModel {
    pub mesh: Mesh,
    /// Indexed by `Group::material`. A model without MTL (or faces without
    /// `usemtl`) gets one material named "default" with every key unset.
    pub materials: Vec<MtlMaterial>,
}

pub fn load(path: &Path) -> Result<ObjModel, Error> {
    let text = std::fs::read(path)
        .map_err(|e| Error::asset(path, None, format!("cannot read model: {e}")))?;
    let text = String::from_utf8_lossy(&text);
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let (models, tobj_mats, libs) = parse(path, &text, &dir)?;
    let mut mats = materials(&tobj_mats, libs, &dir)?;
    let (mut mesh, missing_normal) = mesh(&models, &mut mats);
    if mesh.triangles.is_empty() {
        return Err(Error::asset(path, None, "the model has no faces"));
    }
    if missing_normal.iter().any(|m| *m) {
        smooth_normals(
            &mesh.positions,
            &mesh.triangles,
            &mut mesh.normals,
            &missing_normal,
        );
    }
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        return Err(Error::asset(path, None, "a vertex position is not finite"));
    }
    Ok(ObjModel {
        mesh,
        materials: mats,
    })
}

/// Each material library read, with how many materials it gave.
type Libraries = Vec<(PathBuf, usize)>;

/// tobj's models and materials of the OBJ text, and the libraries the
/// materials came from; an unreadable library is an error naming it.
fn parse(
    path: &Path,
    text: &str,
    dir: &Path,
) -> Result<(Vec<tobj::Model>, Vec<tobj::Material>, Libraries), Error> {
    // Which MTL file each material came from (for relative texture paths).
    let libs: RefCell<Libraries> = RefCell::new(Vec::new());
    let lib_error: RefCell<Option<Error>> = RefCell::new(None);
    let opts = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let result = tobj::load_obj_buf(&mut BufReader::new(text.as_bytes()), &opts, |p| {
        let mtl_path = dir.join(fix_separators(&p.to_string_lossy()));
        let r = std::fs::File::open(&mtl_path)
            .map_err(|e| {
                Error::asset(
                    &mtl_path,
                    None,
                    format!("cannot read material library: {e}"),
                )
            })
            .and_then(|f| {
                tobj::load_mtl_buf(&mut BufReader::new(f))
                    .map_err(|e| Error::asset(&mtl_path, None, format!("malformed MTL: {e}")))
            });
        match r {
            Ok((mats, map)) => {
                libs.borrow_mut().push((mtl_path, mats.len()));
                Ok((mats, map))
            }
            Err(e) => {
                lib_error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    });
    if let Some(e) = lib_error.into_inner() {
        return Err(e);
    }
    let (models, materials) = result.map_err(|e| match locate_error(text) {
        Some((line, msg)) => Error::asset(path, Some(line), msg),
        None => Error::asset(path, None, format!("malformed OBJ: {e}")),
    })?;
    Ok((models, materials.unwrap_or_default(), libs.into_inner()))
}

/// The materials, each with texture paths relative to its own library.
fn materials(
    tobj_mats: &[tobj::Material],
    libs: Libraries,
    dir: &Path,
) -> Result<Vec<MtlMaterial>, Error> {
    let mut mats = Vec::with_capacity(tobj_mats.len() + 1);
    let mut lib_iter = libs.into_iter();
    let mut current: Option<(PathBuf, usize)> = None;
    for m in tobj_mats {
        while current.as_ref().is_none_or(|c| c.1 == 0) {
            current = lib_iter.next();
            if current.is_none() {
                break;
            }
        }
        let base = current
            .as_ref()
            .and_then(|c| c.0.parent().map(Path::to_path_buf))
            .unwrap_or_else(|| dir.to_path_buf());
        if let Some(c) = current.as_mut() {
            c.1 -= 1;
        }
        let mtl_file = current.as_ref().map(|c| c.0.clone()).unwrap_or_default();
        mats.push(convert_material(m, &base, &mtl_file)?);
    }
    Ok(mats)
}

/// One mesh from tobj's models: a vertex per distinct (position, uv,
/// normal) corner, a group per run of one material (faces without one get
/// a `default` material appended to `mats`), and per vertex whether the
/// file gave it no usable normal.
fn mesh(models: &[tobj::Model], mats: &mut Vec<MtlMaterial>) -> (Mesh, Vec<bool>) {
    let mut mesh = Mesh::default();
    let mut missing_normal = Vec::new();
    let any_uv = models.iter().any(|m| {
        !m.mesh.texcoord_indices.is_empty() && m.mesh.texcoord_indices.len() == m.mesh.indices.len()
    });
    let mut default_material = None;
    for model in models {
        let m = &model.mesh;
        let has_uv = !m.texcoord_indices.is_empty() && m.texcoord_indices.len() == m.indices.len();
        let has_n = !m.normal_indices.is_empty() && m.normal_indices.len() == m.indices.len();
        let material = match m.material_id {
            Some(i) if i < mats.len() => i,
            _ => *default_material.get_or_insert_with(|| {
                mats.push(MtlMaterial {
                    name: "default".into(),
                    synthetic: true,
                    ..Default::default()
                });
                mats.len() - 1
            }),
        };
        let mut remap: HashMap<(u32, u32, u32), u32> = HashMap::new();
        let first_tri = mesh.triangles.len() as u32;
        for (c, corner) in m.indices.chunks_exact(3).enumerate() {
            let mut tri = [0u32; 3];
            for k in 0..3 {
                let j = c * 3 + k;
                let pi = corner[k];
                let ti = if has_uv {
                    m.texcoord_indices[j]
                } else {
                    u32::MAX
                };
                let ni = if has_n { m.normal_indices[j] } else { u32::MAX };
                tri[k] = *remap.entry((pi, ti, ni)).or_insert_with(|| {
                    let p = pi as usize * 3;
                    mesh.positions.push(Vec3::new(
                        m.positions[p],
                        m.positions[p + 1],
                        m.positions[p + 2],
                    ));
                    if any_uv {
                        mesh.uvs.push(if has_uv {
                            let t = ti as usize * 2;
                            // OBJ's v runs up; textures are addressed top-down.
                            Vec2::new(m.texcoords[t], 1.0 - m.texcoords[t + 1])
                        } else {
                            Vec2::ZERO
                        });
                    }
                    let n = if has_n {
                        let n = ni as usize * 3;
                        Vec3::new(m.normals[n], m.normals[n + 1], m.normals[n + 2]).try_normalize()
                    } else {
                        None
                    };
                    missing_normal.push(n.is_none());
                    mesh.normals.push(n.unwrap_or(Vec3::ZERO));
                    (mesh.positions.len() - 1) as u32
                });
            }
            mesh.triangles.push(tri);
        }
        let range = first_tri..mesh.triangles.len() as u32;
        match mesh.groups.last_mut() {
            Some(g) if g.material == material && g.triangles.end == range.start => {
                g.triangles.end = range.end
            }
            _ if range.is_empty() => {}
            _ => mesh.groups.push(Group {
                triangles: range,
                material,
            }),
        }
    }
    (mesh, missing_normal)
}

fn fix_separators(s: &str) -> String {
    s.replace('\\', "/")
}

fn convert_material(m: &tobj::Material, base: &Path, mtl: &Path) -> Result<MtlMaterial, Error> {
    let map = |raw: Option<&String>| -> Result<Option<MapSpec>, Error> {
        raw.map(|r| parse_map(r, base).map_err(|msg| Error::asset(mtl, None, msg)))
            .transpose()
    };
    let unknown = |key: &str| m.unknown_param.get(key);
    let d = match (m.dissolve, unknown("Tr")) {
        (Some(d), _) => Some(d),
        (None, Some(tr)) => Some(1.0 - parse_f32(tr, "Tr", mtl)?),
        (None, None) => None,
    };
    Ok(MtlMaterial {
        name: m.name.clone(),
        ka: m.ambient,
        kd: m.diffuse,
        ks: m.specular,
        ke: m.emissive,
        ns: m.shininess,
        ni: m.optical_density,
        d,
        illum: m.illumination_model,
        map_ka: map(m.ambient_texture.as_ref())?,
        map_kd: map(m.diffuse_texture.as_ref())?,
        map_ks: map(m.specular_texture.as_ref())?,
        map_ke: map(unknown("map_Ke"))?,
        map_ns: map(m.shininess_texture.as_ref())?,
        map_d: map(m.dissolve_texture.as_ref())?,
        map_bump: map(m.normal_texture.as_ref().or(unknown("bump")))?,
        norm: map(unknown("norm"))?,
        disp: map(unknown("disp"))?,
        synthetic: false,
    })
}

fn parse_f32(s: &str, key: &str, file: &Path) -> Result<f32, Error> {
    s.split_whitespace()
        .next()
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| Error::asset(file, None, format!("{key} {s}: expected a number")))
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

/// Finds the first line tobj would reject and says why, with its 1-based
/// line number. Used only after tobj failed, to name the line.
pub fn locate_error(text: &str) -> Option<(usize, String)> {
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    for (i, line) in text.lines().enumerate() {
        let mut w = line.split_whitespace();
        let Some(tag) = w.next() else { continue };
        let floats = |w: &mut std::str::SplitWhitespace, n: usize| {
            let v: Vec<_> = w.take(n).collect();
            v.len() == n && v.iter().all(|x| x.parse::<f32>().is_ok())
        };
        let bad = |what: &str| Some((i + 1, format!("{what}: `{}`", line.trim())));
        match tag {
            "v" if !floats(&mut w, 3) => return bad("expected three numbers after v"),
            "v" => nv += 1,
            "vt" if !floats(&mut w, 1) => return bad("expected numbers after vt"),
            "vt" => nt += 1,
            "vn" if !floats(&mut w, 3) => return bad("expected three numbers after vn"),
            "vn" => nn += 1,
            "f" | "l" => {
                for corner in w {
                    for (k, part) in corner.split('/').enumerate() {
                        if part.is_empty() && k > 0 {
                            continue;
                        }
                        let (count, what) = match k {
                            0 => (nv, "position"),
                            1 => (nt, "texture coordinate"),
                            2 => (nn, "normal"),
                            _ => return bad("a face corner has more than three indices"),
                        };
                        let Ok(idx) = part.parse::<i64>() else {
                            return bad(&format!("`{part}` is not an index"));
                        };
                        let resolved = if idx < 0 { count + idx + 1 } else { idx };
                        if idx == 0 || resolved < 1 || resolved > count {
                            return Some((
                                i + 1,
                                format!(
                                    "{what} index {idx} is out of range: {count} {what}s are defined before this line: `{}`",
                                    line.trim()
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
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

    #[test]
    fn bad_faces_are_located() {
        let t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n";
        let (line, msg) = locate_error(t).unwrap();
        assert_eq!(line, 5);
        assert!(msg.contains("position index 7"), "{msg}");
        assert_eq!(locate_error("v 0 0 0\nf -1 -1 -1\n"), None);
        assert_eq!(locate_error("v 0 0 0\nf -2 1 1\n").unwrap().0, 2);
        assert_eq!(locate_error("v 0 x 0\n").unwrap().0, 1);
    }
}
