//! 3MF models (3D Manufacturing Format: a zip package of XML parts), read
//! with `zip` and `roxmltree`.
//!
//! What is read: the root model part that `_rels/.rels` names (else
//! `3D/3dmodel.model`); its build items, placed by their transforms and
//! their components' (nested objects, to a depth of 32); each mesh's
//! vertices and triangles; colours from base materials (`displaycolor`)
//! and the materials extension's colour groups, per triangle or per
//! corner, as vertex colours (sRGB in the file, linear in the mesh). The
//! model's unit (millimetres by default) becomes metres, and its Z up
//! becomes Y up. Triangles are drawn faceted, as CAD and slicer viewers
//! draw them. Not read: textures, composite and multi-property groups,
//! objects in other model parts (the production extension), slices and
//! beam lattices.

use std::collections::HashMap;
use std::io::{Cursor, Read};
use std::path::Path;

use glam::{Mat4, Vec3, Vec4};

use super::gltf::GltfMaterial;
use super::input::Input;
use super::mesh::{Group, Mesh};
use crate::error::Error;

/// A model read from a 3MF file.
#[derive(Debug)]
pub struct ThreeMfModel {
    pub mesh: Mesh,
    /// One material; colours are the mesh's vertex colours.
    pub materials: Vec<GltfMaterial>,
    pub warnings: Vec<String>,
}

/// How deep components may nest (a cycle is refused when it gets there).
const MAX_DEPTH: usize = 32;

/// Reads the 3MF file at `path` through `input`.
pub fn load(path: &Path, input: &Input) -> Result<ThreeMfModel, Error> {
    let bytes = input.read(path, None, None)?;
    let fail = |m: String| Error::asset(path, None, m);
    let mut zip = zip::ZipArchive::new(Cursor::new(&bytes[..]))
        .map_err(|e| fail(format!("cannot read the 3MF file (a zip package): {e}")))?;
    let part = root_part(&mut zip, input.read_cap()).unwrap_or_else(|| "3D/3dmodel.model".into());
    let text = entry(&mut zip, &part, input.read_cap())
        .ok_or_else(|| fail(format!("the 3MF package has no model part {part}")))?;
    let text = String::from_utf8(text)
        .map_err(|_| fail(format!("the 3MF model part {part} is not UTF-8 text")))?;
    let doc = roxmltree::Document::parse(&text)
        .map_err(|e| fail(format!("the 3MF model part {part} is not valid XML: {e}")))?;
    let model = Model::read(&doc).map_err(|m| fail(format!("{part}: {m}")))?;
    let mut mesh = Mesh::default();
    let mut warnings = Vec::new();
    let build = doc
        .descendants()
        .filter(|n| n.has_tag_name((CORE, "item")))
        .collect::<Vec<_>>();
    for item in build {
        let id = attr(&item, "objectid").unwrap_or("");
        let m = transform(item.attribute("transform")).map_err(|e| fail(format!("{part}: {e}")))?;
        model
            .place(id, model.root * m, 0, &mut mesh)
            .map_err(|e| fail(format!("{part}: {e}")))?;
    }
    if doc
        .descendants()
        .any(|n| n.attribute((PRODUCTION, "path")).is_some())
    {
        warnings.push(format!(
            "{}: objects in other model parts (the 3MF production extension) are not read",
            path.display()
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(fail("the 3MF file has no triangles to draw".into()));
    }
    mesh.groups.push(Group {
        triangles: 0..mesh.triangles.len() as u32,
        material: 0,
        part: 0,
    });
    let mut material = GltfMaterial::default_material();
    material.metallic = 0.0;
    material.roughness = 0.5;
    Ok(ThreeMfModel {
        mesh,
        materials: vec![material],
        warnings,
    })
}

const CORE: &str = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02";
const MATERIAL: &str = "http://schemas.microsoft.com/3dmanufacturing/material/2015/02";
const PRODUCTION: &str = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06";

/// Entry `name` of the package, at most `cap` bytes.
fn entry(zip: &mut zip::ZipArchive<Cursor<&[u8]>>, name: &str, cap: u64) -> Option<Vec<u8>> {
    let name = name.trim_start_matches('/');
    let file = zip.by_name(name).ok()?;
    if file.size() > cap {
        return None;
    }
    let mut out = Vec::new();
    file.take(cap).read_to_end(&mut out).ok()?;
    Some(out)
}

/// The model part the package's relationships name.
fn root_part(zip: &mut zip::ZipArchive<Cursor<&[u8]>>, cap: u64) -> Option<String> {
    let rels = String::from_utf8(entry(zip, "_rels/.rels", cap)?).ok()?;
    let doc = roxmltree::Document::parse(&rels).ok()?;
    doc.descendants()
        .filter(|n| n.tag_name().name() == "Relationship")
        .find(|n| n.attribute("Type").is_some_and(|t| t.ends_with("/3dmodel")))
        .and_then(|n| n.attribute("Target"))
        .map(str::to_string)
}

fn attr<'a>(n: &roxmltree::Node<'a, '_>, name: &str) -> Option<&'a str> {
    n.attribute(name)
}

/// A 3MF transform ("m00 m01 m02 m10 ... m32", row vectors) as a matrix;
/// the identity without one.
fn transform(t: Option<&str>) -> Result<Mat4, String> {
    let Some(t) = t else {
        return Ok(Mat4::IDENTITY);
    };
    let v: Vec<f32> = t
        .split_ascii_whitespace()
        .map(|s| s.parse::<f32>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("transform \"{t}\" is not 12 numbers"))?;
    if v.len() != 12 {
        return Err(format!("transform \"{t}\" is not 12 numbers"));
    }
    Ok(Mat4::from_cols(
        Vec4::new(v[0], v[1], v[2], 0.0),
        Vec4::new(v[3], v[4], v[5], 0.0),
        Vec4::new(v[6], v[7], v[8], 0.0),
        Vec4::new(v[9], v[10], v[11], 1.0),
    ))
}

/// "#RRGGBB" or "#RRGGBBAA" (sRGB) as linear RGBA.
fn colour(s: &str) -> Option<Vec4> {
    let h = s.strip_prefix('#')?;
    if !(h.len() == 6 || h.len() == 8) || !h.is_ascii() {
        return None;
    }
    let byte = |k: usize| u8::from_str_radix(&h[k..k + 2], 16).ok();
    let srgb = |b: u8| {
        let c = b as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let a = if h.len() == 8 { byte(6)? } else { 255 };
    Some(Vec4::new(
        srgb(byte(0)?),
        srgb(byte(2)?),
        srgb(byte(4)?),
        a as f32 / 255.0,
    ))
}

/// The model part's resources: objects by id, colour lists by id.
struct Model<'a, 'i> {
    objects: HashMap<&'a str, roxmltree::Node<'a, 'i>>,
    colours: HashMap<&'a str, Vec<Vec4>>,
    /// Unit and axes to Y-up metres.
    root: Mat4,
}

impl<'a, 'i> Model<'a, 'i> {
    fn read(doc: &'a roxmltree::Document<'i>) -> Result<Model<'a, 'i>, String> {
        let top = doc.root_element();
        if !top.has_tag_name((CORE, "model")) {
            return Err("the root element is not a 3MF <model>".into());
        }
        let metres = match top.attribute("unit").unwrap_or("millimeter") {
            "micron" => 1e-6,
            "millimeter" => 1e-3,
            "centimeter" => 1e-2,
            "inch" => 0.0254,
            "foot" => 0.3048,
            "meter" => 1.0,
            other => return Err(format!("unknown unit \"{other}\"")),
        };
        let root = Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2)
            * Mat4::from_scale(Vec3::splat(metres));
        let mut objects = HashMap::new();
        let mut colours = HashMap::new();
        for n in doc.descendants() {
            let id = n.attribute("id");
            if n.has_tag_name((CORE, "object")) {
                objects.insert(id.unwrap_or(""), n);
            } else if n.has_tag_name((CORE, "basematerials")) {
                let list = n
                    .children()
                    .filter(|c| c.has_tag_name((CORE, "base")))
                    .map(|c| {
                        c.attribute("displaycolor")
                            .and_then(colour)
                            .unwrap_or(Vec4::ONE)
                    });
                colours.insert(id.unwrap_or(""), list.collect());
            } else if n.has_tag_name((MATERIAL, "colorgroup")) {
                let list = n
                    .children()
                    .filter(|c| c.has_tag_name((MATERIAL, "color")))
                    .map(|c| c.attribute("color").and_then(colour).unwrap_or(Vec4::ONE));
                colours.insert(id.unwrap_or(""), list.collect());
            }
        }
        Ok(Model {
            objects,
            colours,
            root,
        })
    }

    /// Appends object `id` placed by `world` to `out`.
    fn place(&self, id: &str, world: Mat4, depth: usize, out: &mut Mesh) -> Result<(), String> {
        if depth > MAX_DEPTH {
            return Err(format!(
                "components nest deeper than {MAX_DEPTH} (a cycle?)"
            ));
        }
        let Some(object) = self.objects.get(id) else {
            return Err(format!(
                "a build item or component names object {id}, which is not there"
            ));
        };
        for c in object.descendants() {
            if c.has_tag_name((CORE, "component")) && c.attribute((PRODUCTION, "path")).is_none() {
                let m = transform(c.attribute("transform"))?;
                self.place(
                    c.attribute("objectid").unwrap_or(""),
                    world * m,
                    depth + 1,
                    out,
                )?;
            } else if c.has_tag_name((CORE, "mesh")) {
                self.mesh(object, c, world, out)?;
            }
        }
        Ok(())
    }

    /// Appends mesh `mesh` of `object`, placed by `world`.
    fn mesh(
        &self,
        object: &roxmltree::Node,
        mesh: roxmltree::Node,
        world: Mat4,
        out: &mut Mesh,
    ) -> Result<(), String> {
        let number = |n: &roxmltree::Node, k: &str| -> Result<f32, String> {
            n.attribute(k)
                .and_then(|v| v.parse::<f32>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("a <vertex> without a number {k}"))
        };
        let mut points = Vec::new();
        for v in mesh
            .descendants()
            .filter(|n| n.has_tag_name((CORE, "vertex")))
        {
            let p = Vec3::new(number(&v, "x")?, number(&v, "y")?, number(&v, "z")?);
            points.push(world.transform_point3(p));
        }
        let default_group = object.attribute("pid");
        let default_index = object
            .attribute("pindex")
            .and_then(|v| v.parse::<usize>().ok());
        let mut coloured = !out.colors.is_empty();
        for t in mesh
            .descendants()
            .filter(|n| n.has_tag_name((CORE, "triangle")))
        {
            let index = |k: &str| -> Result<usize, String> {
                let v = t.attribute(k).and_then(|v| v.parse::<usize>().ok());
                v.filter(|&v| v < points.len()).ok_or_else(|| {
                    format!(
                        "a <triangle> whose {k} is not a vertex of its mesh ({} vertices)",
                        points.len()
                    )
                })
            };
            let corners = [index("v1")?, index("v2")?, index("v3")?].map(|i| points[i]);
            let group = t
                .attribute("pid")
                .or(default_group)
                .and_then(|g| self.colours.get(g));
            let pick = |k: &str| t.attribute(k).and_then(|v| v.parse::<usize>().ok());
            let colours = group.map(|list| {
                let first = pick("p1").or(default_index);
                let at =
                    |i: Option<usize>| i.and_then(|i| list.get(i)).copied().unwrap_or(Vec4::ONE);
                [
                    at(first),
                    at(pick("p2").or(first)),
                    at(pick("p3").or(first)),
                ]
            });
            if colours.is_some() && !coloured {
                out.colors.resize(out.positions.len(), Vec4::ONE);
                coloured = true;
            }
            let [a, b, c] = corners;
            let n = (b - a).cross(c - a).normalize_or(Vec3::Y);
            let base = out.positions.len() as u32;
            for (k, p) in corners.into_iter().enumerate() {
                out.positions.push(p);
                out.normals.push(n);
                if coloured {
                    out.colors.push(colours.map_or(Vec4::ONE, |c| c[k]));
                }
            }
            out.triangles.push([base, base + 1, base + 2]);
        }
        Ok(())
    }
}
