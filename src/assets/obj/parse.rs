//! OBJ statements to arrays, with the line of everything that can go wrong.
//! Reads what other tools read: `v` with vertex colours (`v x y z r g b`)
//! on some vertices, negative (relative) indices, `\` line continuations,
//! `usemtl` and `mtllib` names with spaces, faces of any size. Points
//! (`p`) and lines (`l`) are kept like faces; free-form geometry is
//! skipped with a warning.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::error::Error;

/// One face corner, indices resolved to 0-based.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Corner {
    pub v: u32,
    pub t: Option<u32>,
    pub n: Option<u32>,
}

#[derive(Debug, Clone)]
pub struct Face {
    /// Range into `ObjFile::corners`.
    pub start: u32,
    pub len: u32,
    /// Index into `ObjFile::usemtl`, None before any `usemtl`.
    pub material: Option<u32>,
}

#[derive(Debug, Default)]
pub struct ObjFile {
    pub positions: Vec<Vec3>,
    /// Per position: the vertex colour given after it, if any (0..1, as
    /// written).
    pub colors: Vec<Option<Vec3>>,
    pub texcoords: Vec<Vec2>,
    pub normals: Vec<Vec3>,
    pub corners: Vec<Corner>,
    pub faces: Vec<Face>,
    /// `p` elements (each corner a point) and `l` elements (polylines), in
    /// `corners` like faces.
    pub points: Vec<Face>,
    pub lines: Vec<Face>,
    /// `mtllib` arguments with their lines.
    pub mtllibs: Vec<(String, usize)>,
    /// Distinct `usemtl` names, in order of first use, with the line.
    pub usemtl: Vec<(String, usize)>,
}

/// Statements that describe free-form geometry or rendering hints
/// softraster does not use; they are skipped, with one warning for the
/// free-form ones.
const FREE_FORM: &[&str] = &[
    "vp", "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole", "scrv",
    "sp", "end", "con",
];
const IGNORED: &[&str] = &[
    "o",
    "g",
    "s",
    "mg",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "maplib",
    "usemap",
];

pub fn parse(path: &Path, text: &str, warnings: &mut Vec<String>) -> Result<ObjFile, Error> {
    let mut f = ObjFile::default();
    let mut material: Option<u32> = None;
    let mut skipped: Vec<(String, usize)> = Vec::new();
    for (line_no, line) in logical_lines(text) {
        let line = line.split('#').next().unwrap_or("");
        let line = line.trim();
        let Some((tag, rest)) = split_tag(line) else {
            continue;
        };
        let err = |msg: String| Error::asset(path, Some(line_no), format!("{msg}: `{line}`"));
        match tag {
            "v" => {
                let (p, c) = vertex(rest).map_err(err)?;
                f.positions.push(p);
                f.colors.push(c.filter(|c| c.is_finite()));
            }
            "vt" => {
                let n = numbers(rest).map_err(|w| err(format!("`{w}` is not a number")))?;
                if n.is_empty() {
                    return Err(err("expected numbers after vt".into()));
                }
                let uv = Vec2::new(n[0], n.get(1).copied().unwrap_or(0.0));
                f.texcoords
                    .push(if uv.is_finite() { uv } else { Vec2::ZERO });
            }
            "vn" => {
                let n = numbers(rest).map_err(|w| err(format!("`{w}` is not a number")))?;
                if n.len() != 3 {
                    return Err(err("expected three numbers after vn".into()));
                }
                f.normals.push(Vec3::new(n[0], n[1], n[2]));
            }
            "f" | "fo" => {
                let (start, len) = corners(rest, &mut f).map_err(err)?;
                if len < 3 {
                    f.corners.truncate(start as usize);
                    warnings.push(format!(
                        "{}:{line_no}: a face needs at least three corners; skipped: `{line}`",
                        path.display()
                    ));
                    continue;
                }
                f.faces.push(Face {
                    start,
                    len,
                    material,
                });
            }
            "p" | "l" => {
                let (start, len) = corners(rest, &mut f).map_err(err)?;
                let (list, min) = if tag == "p" {
                    (&mut f.points, 1)
                } else {
                    (&mut f.lines, 2)
                };
                if len >= min {
                    list.push(Face {
                        start,
                        len,
                        material,
                    });
                }
            }
            "usemtl" => {
                let name = rest.trim();
                let i = match f.usemtl.iter().position(|(n, _)| n == name) {
                    Some(i) => i,
                    None => {
                        f.usemtl.push((name.to_string(), line_no));
                        f.usemtl.len() - 1
                    }
                };
                material = Some(i as u32);
            }
            "mtllib" => {
                if !rest.trim().is_empty() {
                    f.mtllibs.push((rest.trim().to_string(), line_no));
                }
            }
            t if IGNORED.contains(&t) => {}
            t if FREE_FORM.contains(&t) => {
                if !skipped.iter().any(|(s, _)| s == "free-form") {
                    skipped.push(("free-form".into(), line_no));
                }
            }
            t => {
                if !skipped.iter().any(|(s, _)| s == t) {
                    skipped.push((t.to_string(), line_no));
                }
            }
        }
    }
    for (what, line) in skipped {
        let what = if what == "free-form" {
            "free-form geometry (curves and surfaces) is not drawn".to_string()
        } else {
            format!("unknown statement `{what}` skipped")
        };
        warnings.push(format!("{}:{line}: {what}", path.display()));
    }
    Ok(f)
}

/// A `v` statement's position and, where it has one, vertex colour.
fn vertex(rest: &str) -> Result<(Vec3, Option<Vec3>), String> {
    let n = numbers(rest).map_err(|w| format!("`{w}` is not a number"))?;
    let (p, c) = match n.len() {
        3 | 4 => (Vec3::new(n[0], n[1], n[2]), None),
        6 | 7 => (
            Vec3::new(n[0], n[1], n[2]),
            Some(Vec3::new(n[3], n[4], n[5])),
        ),
        _ => return Err("expected three numbers after v (or x y z r g b)".into()),
    };
    if !p.is_finite() {
        return Err("a vertex position is not finite".into());
    }
    Ok((p, c))
}

/// The corners of a face, point or line statement appended to
/// `f.corners`: where they start, and how many.
fn corners(rest: &str, f: &mut ObjFile) -> Result<(u32, u32), String> {
    let start = f.corners.len() as u32;
    for word in rest.split_whitespace() {
        let c = corner(word, f)?;
        f.corners.push(c);
    }
    Ok((start, f.corners.len() as u32 - start))
}

/// Lines with `\` continuations joined, each with its 1-based number (the
/// first physical line's).
fn logical_lines(text: &str) -> impl Iterator<Item = (usize, std::borrow::Cow<'_, str>)> {
    let mut lines = text.lines().enumerate().peekable();
    std::iter::from_fn(move || {
        let (i, first) = lines.next()?;
        let first = first.trim_end();
        if !first.ends_with('\\') {
            return Some((i + 1, std::borrow::Cow::Borrowed(first)));
        }
        let mut joined = first.trim_end_matches('\\').to_string();
        for (_, next) in lines.by_ref() {
            let next = next.trim_end();
            joined.push(' ');
            if let Some(cont) = next.strip_suffix('\\') {
                joined.push_str(cont);
            } else {
                joined.push_str(next);
                break;
            }
        }
        Some((i + 1, std::borrow::Cow::Owned(joined)))
    })
}

/// The statement's keyword and the rest of the line.
pub fn split_tag(line: &str) -> Option<(&str, &str)> {
    let line = line.trim_start();
    if line.is_empty() {
        return None;
    }
    Some(match line.find(char::is_whitespace) {
        Some(i) => (&line[..i], &line[i..]),
        None => (line, ""),
    })
}

/// Every word as a number, or the first word that is not one.
pub fn numbers(rest: &str) -> Result<Vec<f32>, String> {
    rest.split_whitespace()
        .map(|w| number(w).ok_or_else(|| w.to_string()))
        .collect()
}

/// A number as C's `strtod` reads it, and Fortran-style exponents
/// (`1.5D+02`) that some exporters write.
pub fn number(w: &str) -> Option<f32> {
    if let Ok(v) = w.parse::<f32>() {
        return Some(v);
    }
    let fixed = w.replace(['d', 'D'], "e");
    fixed.parse::<f32>().ok()
}

/// `v`, `v/t`, `v//n` or `v/t/n`, resolved against what is defined so far.
fn corner(word: &str, f: &ObjFile) -> Result<Corner, String> {
    let mut parts = word.split('/');
    let resolve = |part: Option<&str>, count: usize, what: &str| -> Result<Option<u32>, String> {
        let Some(part) = part.filter(|p| !p.is_empty()) else {
            return Ok(None);
        };
        let idx: i64 = part
            .parse()
            .map_err(|_| format!("`{part}` is not an index"))?;
        let count = count as i64;
        let resolved = if idx < 0 { count + idx } else { idx - 1 };
        if idx == 0 || resolved < 0 || resolved >= count {
            return Err(format!(
                "{what} index {idx} is out of range: {count} {what}s are defined before this line"
            ));
        }
        Ok(Some(resolved as u32))
    };
    let v = resolve(parts.next(), f.positions.len(), "position")?
        .ok_or_else(|| "a face corner has no position index".to_string())?;
    let t = resolve(parts.next(), f.texcoords.len(), "texture coordinate")?;
    let n = resolve(parts.next(), f.normals.len(), "normal")?;
    if parts.next().is_some() {
        return Err("a face corner has more than three indices".into());
    }
    Ok(Corner { v, t, n })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(s: &str) -> Result<(ObjFile, Vec<String>), Error> {
        let mut w = Vec::new();
        parse(Path::new("t.obj"), s, &mut w).map(|f| (f, w))
    }

    #[test]
    fn bad_indices_name_their_line() {
        let e = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n").unwrap_err();
        let msg = e.to_string();
        assert!(msg.starts_with("t.obj:5: position index 7"), "{msg}");
        assert!(parse_str("v 0 0 0\nf -1 -1 -1\n").is_ok());
        assert!(
            parse_str("v 0 0 0\nf -2 1 1\n")
                .unwrap_err()
                .to_string()
                .contains(":2:")
        );
        assert!(
            parse_str("v 0 x 0\n")
                .unwrap_err()
                .to_string()
                .contains(":1:")
        );
        assert!(parse_str("v 0 0 0\nf 1/1/1/1 1 1\n").is_err());
    }

    #[test]
    fn what_other_parsers_accept() {
        let (f, w) = parse_str(
            "v 1e0 .5 -2.E+1 1 0.5 0\nv +1 1.5D2 0\nv 0 0 1 \\\n   \n\
             vt 0.5\nusemtl my material\nf 1/1 2/1 3/1\nl 1 2\np 1\ncurv 0 1 1 2\n",
        )
        .unwrap();
        assert_eq!(f.positions[0], Vec3::new(1.0, 0.5, -20.0));
        assert_eq!(f.colors[0], Some(Vec3::new(1.0, 0.5, 0.0)));
        assert_eq!(f.colors[1], None);
        assert_eq!(f.positions[1].y, 150.0);
        assert_eq!(f.usemtl[0].0, "my material");
        assert_eq!((f.points.len(), f.lines.len(), f.faces.len()), (1, 1, 1));
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("free-form"), "{w:?}");
    }
}
