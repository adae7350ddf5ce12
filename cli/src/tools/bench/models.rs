//! The benchmark's model files, generated from the shared assets into a
//! cache directory (`$TMPDIR/softraster-bench-cache`, never the
//! repository): subdivided meshes, the harness's floor, nefertiti with
//! spherical texture coordinates, diablo3 with 4096² maps.

use std::path::{Path, PathBuf};

use glam::Vec3;

use softraster::error::Error;

/// `model` (an OBJ of triangles) with every triangle split into four at
/// its edge midpoints, `levels` times (5,022 triangles of diablo3 become
/// 20k, 80k, 321k, 1.29M): positions, texture coordinates and normals
/// are interpolated, so the surface, its texturing and the pixels it
/// covers stay the same while the triangle count grows. Written once into
/// the benchmark cache.
pub(super) fn subdivided(model: &Path, levels: usize) -> Result<PathBuf, Error> {
    if levels == 0 {
        return Ok(model.to_path_buf());
    }
    let dir = std::env::temp_dir().join("softraster-bench-cache");
    let out = dir.join(format!("diablo3_sub{levels}.obj"));
    if out.is_file() {
        return Ok(out);
    }
    let text = std::fs::read_to_string(model).map_err(|e| Error::io(model, e))?;
    // Attribute lists (positions, uvs, normals) and triangles of
    // (position, uv, normal) indices, 0-based.
    let mut attr: [Vec<Vec3>; 3] = Default::default();
    let mut tris: Vec<[[usize; 3]; 3]> = Vec::new();
    for line in text.lines() {
        let mut t = line.split_whitespace();
        let kind = match t.next() {
            Some("v") => 0,
            Some("vt") => 1,
            Some("vn") => 2,
            Some("f") => {
                let corners: Vec<[usize; 3]> = t
                    .map(|c| {
                        let mut it = c.split('/').map(|x| x.parse::<usize>().unwrap_or(1) - 1);
                        [0, 1, 2].map(|_| it.next().unwrap_or(0))
                    })
                    .collect();
                for k in 1..corners.len().saturating_sub(1) {
                    tris.push([corners[0], corners[k], corners[k + 1]]);
                }
                continue;
            }
            _ => continue,
        };
        let v: Vec<f32> = t.filter_map(|x| x.parse().ok()).collect();
        attr[kind].push(Vec3::new(
            v.first().copied().unwrap_or(0.0),
            v.get(1).copied().unwrap_or(0.0),
            v.get(2).copied().unwrap_or(0.0),
        ));
    }
    if tris
        .iter()
        .flatten()
        .any(|c| (0..3).any(|k| c[k] >= attr[k].len()))
    {
        return Err(Error::asset(
            model,
            None,
            "benchmark model: index out of range",
        ));
    }
    for _ in 0..levels {
        // One midpoint per edge and attribute, shared by both triangles.
        let mut mid: [std::collections::HashMap<(usize, usize), usize>; 3] = Default::default();
        let mut next = Vec::with_capacity(tris.len() * 4);
        for t in &tris {
            let mut m = [[0usize; 3]; 3];
            for (e, (a, b)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
                for k in 0..3 {
                    let (i, j) = (t[a][k], t[b][k]);
                    let key = (i.min(j), i.max(j));
                    m[e][k] = *mid[k].entry(key).or_insert_with(|| {
                        attr[k].push((attr[k][i] + attr[k][j]) * 0.5);
                        attr[k].len() - 1
                    });
                }
            }
            next.push([t[0], m[0], m[2]]);
            next.push([m[0], t[1], m[1]]);
            next.push([m[2], m[1], t[2]]);
            next.push([m[0], m[1], m[2]]);
        }
        tris = next;
    }
    use std::fmt::Write;
    let mut s = String::new();
    for (k, tag) in ["v", "vt", "vn"].iter().enumerate() {
        for a in &attr[k] {
            let _ = writeln!(s, "{tag} {} {} {}", a.x, a.y, a.z);
        }
    }
    for t in &tris {
        let c = |c: [usize; 3]| format!("{}/{}/{}", c[0] + 1, c[1] + 1, c[2] + 1);
        let _ = writeln!(s, "f {} {} {}", c(t[0]), c(t[1]), c(t[2]));
    }
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let tmp = dir.join(format!(".sub.{}.obj", std::process::id()));
    std::fs::write(&tmp, s).map_err(|e| Error::io(&tmp, e))?;
    std::fs::rename(&tmp, &out).map_err(|e| Error::io(&out, e))?;
    Ok(out)
}

/// The bounding box of an OBJ's `v` lines.
pub(super) fn obj_bounds(path: &Path) -> Result<(Vec3, Vec3), Error> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("v ") {
            let v: Vec<f32> = rest
                .split_whitespace()
                .filter_map(|t| t.parse().ok())
                .collect();
            if v.len() >= 3 {
                let q = Vec3::new(v[0], v[1], v[2]);
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
    }
    if !lo.is_finite() {
        return Err(Error::asset(path, None, "benchmark model has no vertices"));
    }
    Ok((lo, hi))
}

/// A horizontal disc, facing up, at the bottom of the box `lo`..`hi`,
/// centred under it, of the area of the harness's floor quad (half side
/// 1.6 x the box's half diagonal), in the benchmark cache.
pub(super) fn floor_disc(lo: Vec3, hi: Vec3) -> Result<PathBuf, Error> {
    let c = (lo + hi) * 0.5;
    let r = (hi - lo).length() * 0.5;
    let radius = 1.6 * r * 2.0 / std::f32::consts::PI.sqrt();
    const N: usize = 64;
    let mut text = format!("v {} {} {}\n", c.x, lo.y, c.z);
    for k in 0..N {
        let a = k as f32 / N as f32 * std::f32::consts::TAU;
        text.push_str(&format!(
            "v {} {} {}\n",
            c.x + radius * a.cos(),
            lo.y,
            c.z - radius * a.sin()
        ));
    }
    text.push_str("vn 0 1 0\n");
    for k in 0..N {
        let (a, b) = (k + 2, (k + 1) % N + 2);
        text.push_str(&format!("f 1//1 {a}//1 {b}//1\n"));
    }
    let dir = std::env::temp_dir().join("softraster-bench-cache");
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    // Named by its content: concurrent runs never write each other's file.
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    text.hash(&mut h);
    let path = dir.join(format!("floor-{:016x}.obj", h.finish()));
    if !path.is_file() {
        let tmp = dir.join(format!(".floor.{}.obj", std::process::id()));
        std::fs::write(&tmp, text).map_err(|e| Error::io(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e))?;
    }
    Ok(path)
}

/// `model` turned from Z-up to Y-up (x, z, -y) with the harness's
/// spherical texture coordinates about its box center (u = 0.5 +
/// atan2(x, z) / 2pi, v = 0.5 + asin(y) / pi of the unit direction), one
/// per position, written once into the benchmark cache.
pub(super) fn spherical_uv_model(model: &Path) -> Result<PathBuf, Error> {
    let dir = std::env::temp_dir().join("softraster-bench-cache/nefertiti_uv");
    let out = dir.join("nefertiti_uv.obj");
    if out.is_file() {
        return Ok(out);
    }
    if !model.is_file() {
        return Err(Error::asset(
            model,
            None,
            "benchmark model not found (pass --assets)",
        ));
    }
    let text = std::fs::read_to_string(model).map_err(|e| Error::io(model, e))?;
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    for line in text.lines() {
        let mut t = line.split_whitespace();
        match t.next() {
            Some("v") => {
                let v: Vec<f32> = t.filter_map(|x| x.parse().ok()).collect();
                if v.len() >= 3 {
                    pos.push(Vec3::new(v[0], v[2], -v[1]));
                }
            }
            Some("f") => {
                let n = pos.len() as i64;
                let idx: Vec<i64> = t
                    .filter_map(|c| c.split('/').next()?.parse::<i64>().ok())
                    .map(|i| if i < 0 { n + i + 1 } else { i })
                    .collect();
                faces.push(idx);
            }
            _ => {}
        }
    }
    let (lo, hi) = pos.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &q| (lo.min(q), hi.max(q)),
    );
    let c = (lo + hi) * 0.5;
    let mut s = String::with_capacity(text.len() * 2);
    for q in &pos {
        s.push_str(&format!("v {} {} {}\n", q.x, q.y, q.z));
    }
    for q in &pos {
        let d = (*q - c).normalize_or(Vec3::Y);
        let u = 0.5 + d.x.atan2(d.z) / std::f32::consts::TAU;
        let v = 0.5 + d.y.clamp(-1.0, 1.0).asin() / std::f32::consts::PI;
        s.push_str(&format!("vt {u} {v}\n"));
    }
    for f in &faces {
        s.push('f');
        for i in f {
            s.push_str(&format!(" {i}/{i}"));
        }
        s.push('\n');
    }
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let tmp = dir.join(format!(".nefertiti_uv.{}.obj", std::process::id()));
    std::fs::write(&tmp, s).map_err(|e| Error::io(&tmp, e))?;
    std::fs::rename(&tmp, &out).map_err(|e| Error::io(&out, e))?;
    Ok(out)
}

/// diablo3_pose_mtl with every map resampled to 4096x4096, generated once
/// into a cache directory (never into the repository).
pub(super) fn resampled_diablo3(src: &Path) -> Result<PathBuf, Error> {
    let dir = std::env::temp_dir().join("softraster-bench-cache/diablo3_4k");
    let done = dir.join(".complete");
    if done.is_file() && dir.join("diablo3_pose.obj").is_file() {
        return Ok(dir);
    }
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    for f in [
        "diablo3_pose_mtl.obj",
        "diablo3_pose.mtl",
        "diablo3_pose.obj",
    ] {
        std::fs::copy(src.join(f), dir.join(f)).map_err(|e| Error::io(src.join(f), e))?;
    }
    use rayon::prelude::*;
    ["diffuse", "spec", "glow", "nm_tangent"]
        .par_iter()
        .try_for_each(|m| -> Result<(), Error> {
            let from = src.join(format!("diablo3_pose_{m}.tga"));
            let img = image::open(&from)
                .map_err(|e| Error::asset(&from, None, format!("cannot decode: {e}")))?;
            let big = img.resize_exact(4096, 4096, image::imageops::FilterType::Triangle);
            let to = dir.join(format!("diablo3_pose_{m}.tga"));
            big.to_rgb8()
                .save(&to)
                .map_err(|e| Error::asset(&to, None, format!("cannot write: {e}")))
        })?;
    std::fs::write(&done, "").map_err(|e| Error::io(&done, e))?;
    Ok(dir)
}
