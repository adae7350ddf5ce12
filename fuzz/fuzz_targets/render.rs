//! The render path: a tiny scene built from fuzzed geometry (raw f32 bits,
//! so extreme and tiny magnitudes), a fuzzed light (with a range or a
//! second ranged light: per-tile culling), camera, shadow, AO,
//! cull and anti-aliasing settings, and half the time fuzzed texture
//! coordinates on a textured, normal-mapped material with a fuzzed filter
//! and address mode, rendered at 32x32. This is the target
//! that finds arithmetic overflow (debug assertions are on).

#![no_main]
#[path = "common.rs"]
mod common;

use common::toml_f32;
use libfuzzer_sys::fuzz_target;

struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        let (b, rest) = self
            .0
            .split_first()
            .map(|(b, r)| (*b, r))
            .unwrap_or((0, &[]));
        self.0 = rest;
        b
    }
    /// A quarter of the time raw f32 bits (extreme, tiny, non-finite
    /// values), otherwise a modest number (-128..128 in steps of 1/256),
    /// so most scenes load and render.
    fn f32(&mut self) -> f32 {
        if self.u8() % 4 == 0 {
            f32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
        } else {
            i16::from_le_bytes([self.u8(), self.u8()]) as f32 / 256.0
        }
    }
    fn pick<'s>(&mut self, options: &[&'s str]) -> &'s str {
        options[self.u8() as usize % options.len()]
    }
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let n_verts = 3 + b.u8() as usize % 30;
    let n_tris = 1 + b.u8() as usize % 40;
    let verts: Vec<(f32, f32, f32)> = (0..n_verts).map(|_| (b.f32(), b.f32(), b.f32())).collect();
    let tris: Vec<(usize, usize, usize)> = (0..n_tris)
        .map(|_| {
            (
                1 + b.u8() as usize % n_verts,
                1 + b.u8() as usize % n_verts,
                1 + b.u8() as usize % n_verts,
            )
        })
        .collect();
    // Some points and lines, drawn by their own pass.
    let lines: Vec<(usize, usize)> = (0..b.u8() % 4)
        .map(|_| (1 + b.u8() as usize % n_verts, 1 + b.u8() as usize % n_verts))
        .collect();
    let light = b.pick(&["point", "directional", "spot"]);
    let (lx, ly, lz) = (b.f32(), b.f32(), b.f32());
    // Point and spot lights with a range: per-tile light culling (a
    // second, unshadowed ranged light beside the first).
    let range = match (light, b.u8() % 3) {
        ("directional", _) | (_, 0) => String::new(),
        (_, 1) => format!("range = {}\n", toml_f32(b.f32().abs().max(1e-6))),
        _ => format!(
            "range = {}\n[[light]]\nkind = \"{light}\"\nposition = [{}, {}, {}]\nrange = {}\n",
            toml_f32(b.f32().abs().max(1e-6)),
            toml_f32(b.f32()),
            toml_f32(b.f32()),
            toml_f32(b.f32()),
            toml_f32(b.f32().abs().max(1e-6)),
        ),
    };
    let shadows = b.pick(&["\"hard\"", "\"pcf\"", "\"raytraced\""]);
    let ao = b.pick(&[
        "",
        "ao = { method = \"ssao\" }\n",
        "ao = { method = \"raytraced\", samples = 2 }\n",
    ]);
    let cull = b.pick(&["auto", "back", "front", "none"]);
    let msaa = b.pick(&["1", "4"]);
    let ssaa = b.pick(&["1", "2"]);
    let ground = b.pick(&["false", "true"]);
    let camera = match b.u8() % 3 {
        0 => String::new(),
        1 => format!(
            "[[camera]]\neye = [{}, {}, {}]\ntarget = [0.0, 0.0, 0.0]\nfov = {}\n",
            toml_f32(b.f32()),
            toml_f32(b.f32()),
            toml_f32(b.f32()),
            toml_f32(b.f32())
        ),
        _ => format!(
            "[[camera]]\nelevation = {}\nazimuth = {}\n",
            toml_f32(b.f32()),
            toml_f32(b.f32())
        ),
    };
    let scale = toml_f32(b.f32());
    let point_size = 0.5 + (b.u8() % 64) as f32;
    let line_width = 0.25 + (b.u8() % 64) as f32 * 0.5;
    // Small maps: a 2048^2 map per input held the target at about 15
    // inputs a second; the arithmetic is the same at any size.
    let map_size = b.pick(&["16", "64", "256"]);
    // Textured (the common library's material: a colour map and a normal
    // map) with fuzzed texture coordinates, filter and address mode: the
    // four-lane texture lookups.
    let textured = b.u8() % 2 == 1;
    let filter = b.pick(&["nearest", "bilinear", "trilinear", "anisotropic"]);
    let address = b.pick(&["repeat", "mirror", "clamp", "border"]);
    let mut obj = String::new();
    if textured {
        obj += "mtllib lib.mtl\nusemtl m\n";
    }
    for (x, y, z) in &verts {
        obj += &format!("v {x:?} {y:?} {z:?}\n");
    }
    if textured {
        for _ in 0..n_verts {
            obj += &format!("vt {:?} {:?}\n", b.f32(), b.f32());
        }
    }
    for (i, j, k) in &tris {
        obj += &if textured {
            format!("f {i}/{i} {j}/{j} {k}/{k}\n")
        } else {
            format!("f {i} {j} {k}\n")
        };
    }
    for (i, j) in &lines {
        obj += &format!("l {i} {j}\np {i}\n");
    }
    let dir = common::dir();
    if std::fs::write(dir.join("render.obj"), obj).is_err() {
        return;
    }
    let scene = format!(
        "[output]\nwidth = 32\nheight = 32\n\
         [render]\nshadows = {shadows}\ncull = \"{cull}\"\nmsaa = {msaa}\nssaa = {ssaa}\n\
         point_size = {point_size:?}\nline_width = {line_width:?}\n\
         shadow_map_size = {map_size}\ntexture_filter = \"{filter}\"\naddress = \"{address}\"\n{ao}\
         [ground]\nshadow = {ground}\n\
         [[model]]\npath = \"render.obj\"\nscale = {scale}\n\
         [[light]]\nkind = \"{light}\"\nposition = [{}, {}, {}]\ndirection = [{}, {}, {}]\nshadows = true\n{range}{camera}",
        toml_f32(lx),
        toml_f32(ly),
        toml_f32(lz),
        toml_f32(-lx),
        toml_f32(-ly),
        toml_f32(-lz),
    );
    common::load_and_render("render.toml", &scene, true);
});
