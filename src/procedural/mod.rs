//! Procedural meshes and textures: spheres, tori, cubes, ground planes and
//! checker and band images, as OBJ text and 8-bit images. The command-line
//! package builds the showcase scene's assets from them, and tests build
//! their scenes from them.

use std::f32::consts::{PI, TAU};
use std::fmt::Write as _;

use crate::output::Image8;

/// A mesh as OBJ text: positions, uvs (OBJ convention, v up), normals, faces.
pub struct ObjText {
    /// The file's text.
    pub text: String,
}

/// A procedural mesh: one position, OBJ-convention uv (v up) and normal per
/// vertex; counter-clockwise triangles with 1-based indices (as OBJ writes
/// them).
pub struct Builder {
    /// Positions.
    pub v: Vec<[f32; 3]>,
    /// Texture coordinates (v up).
    pub vt: Vec<[f32; 2]>,
    /// Unit normals.
    pub vn: Vec<[f32; 3]>,
    /// Triangles: 1-based indices into all three lists.
    pub f: Vec<[usize; 3]>,
}

impl Builder {
    fn new() -> Builder {
        Builder {
            v: vec![],
            vt: vec![],
            vn: vec![],
            f: vec![],
        }
    }

    fn vertex(&mut self, p: [f32; 3], uv: [f32; 2], n: [f32; 3]) -> usize {
        self.v.push(p);
        self.vt.push(uv);
        self.vn.push(n);
        self.v.len()
    }

    /// A (rows+1) x (cols+1) vertex grid from `f(u, v)` -> (position, normal),
    /// triangulated counter-clockwise seen from the normal side.
    fn grid(
        &mut self,
        cols: usize,
        rows: usize,
        uv_scale: [f32; 2],
        f: impl Fn(f32, f32) -> ([f32; 3], [f32; 3]),
    ) {
        let base = self.v.len();
        for r in 0..=rows {
            for c in 0..=cols {
                let (u, v) = (c as f32 / cols as f32, r as f32 / rows as f32);
                let (p, n) = f(u, v);
                self.vertex(p, [u * uv_scale[0], v * uv_scale[1]], n);
            }
        }
        let idx = |r: usize, c: usize| base + r * (cols + 1) + c + 1;
        for r in 0..rows {
            for c in 0..cols {
                let (a, b, cc, d) = (idx(r, c), idx(r, c + 1), idx(r + 1, c + 1), idx(r + 1, c));
                self.f.push([a, b, cc]);
                self.f.push([a, cc, d]);
            }
        }
    }

    /// The mesh as OBJ text: object `name`, material library `mtllib`
    /// and material `material` (files the caller writes beside it).
    pub fn to_obj(self, name: &str, mtllib: &str, material: &str) -> ObjText {
        let mut t = String::new();
        let _ = writeln!(
            t,
            "# softraster procedural mesh `{name}` (generated, do not edit)"
        );
        let _ = writeln!(t, "mtllib {mtllib}\no {name}");
        for p in &self.v {
            let _ = writeln!(t, "v {:.5} {:.5} {:.5}", p[0], p[1], p[2]);
        }
        for uv in &self.vt {
            let _ = writeln!(t, "vt {:.5} {:.5}", uv[0], uv[1]);
        }
        for n in &self.vn {
            let _ = writeln!(t, "vn {:.5} {:.5} {:.5}", n[0], n[1], n[2]);
        }
        let _ = writeln!(t, "usemtl {material}");
        for f in &self.f {
            let _ = writeln!(t, "f {0}/{0}/{0} {1}/{1}/{1} {2}/{2}/{2}", f[0], f[1], f[2]);
        }
        ObjText { text: t }
    }
}

/// UV sphere of radius `r`: u around +Y, v from the south pole up.
pub fn sphere(r: f32, cols: usize, rows: usize) -> Builder {
    let mut b = Builder::new();
    b.grid(cols, rows, [2.0, 1.0], |u, v| {
        let phi = u * TAU;
        let theta = v * PI - PI / 2.0;
        let n = [
            theta.cos() * phi.sin(),
            theta.sin(),
            theta.cos() * phi.cos(),
        ];
        ([n[0] * r, n[1] * r, n[2] * r], n)
    });
    b
}

/// Torus around +Y with major radius `big` and tube radius `small`.
pub fn torus(big: f32, small: f32, cols: usize, rows: usize) -> Builder {
    let mut b = Builder::new();
    b.grid(cols, rows, [8.0, 2.0], |u, v| {
        let a = u * TAU;
        // Tube angle runs so that faces wind counter-clockwise outward.
        let t = v * TAU;
        let n = [t.cos() * a.sin(), t.sin(), t.cos() * a.cos()];
        let c = [big * a.sin(), 0.0, big * a.cos()];
        (
            [
                c[0] + small * n[0],
                c[1] + small * n[1],
                c[2] + small * n[2],
            ],
            n,
        )
    });
    b
}

/// Square in the XZ plane at height `y`, facing +Y, UVs repeating `tiles` times.
pub fn ground(half: f32, y: f32, tiles: f32) -> Builder {
    let mut b = Builder::new();
    b.grid(1, 1, [tiles, tiles], |u, v| {
        (
            [(u * 2.0 - 1.0) * half, y, (1.0 - v * 2.0) * half],
            [0.0, 1.0, 0.0],
        )
    });
    b
}

/// An axis-aligned cube of half-size `h` centered at `c`, faces facing out.
pub fn cube(c: [f32; 3], h: f32) -> Builder {
    let mut b = Builder::new();
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    ];
    for (n, s, t) in faces {
        b.grid(1, 1, [1.0, 1.0], |u, v| {
            let (a, bb) = (u * 2.0 - 1.0, v * 2.0 - 1.0);
            let p = [
                c[0] + h * (n[0] + a * s[0] + bb * t[0]),
                c[1] + h * (n[1] + a * s[1] + bb * t[1]),
                c[2] + h * (n[2] + a * s[2] + bb * t[2]),
            ];
            (p, n)
        });
    }
    b
}

/// Two-color checkerboard, `cells` cells across, sRGB bytes.
pub fn checker(size: u32, cells: u32, a: [u8; 3], b: [u8; 3]) -> Image8 {
    let mut data = Vec::with_capacity((size * size * 3) as usize);
    let cell = size / cells;
    for y in 0..size {
        for x in 0..size {
            let c = if ((x / cell) + (y / cell)).is_multiple_of(2) {
                a
            } else {
                b
            };
            data.extend_from_slice(&c);
        }
    }
    Image8 {
        width: size,
        height: size,
        channels: 3,
        data,
    }
}

/// Horizontal bands with soft edges (for the torus).
pub fn bands(size: u32, colors: &[[u8; 3]]) -> Image8 {
    let mut data = Vec::with_capacity((size * size * 3) as usize);
    let n = colors.len() as u32;
    for y in 0..size {
        for x in 0..size {
            let band = (x * n / size) as usize;
            let c = colors[band];
            // darker grooves between bands and along v, to show texture filtering
            let groove = (x * n % size) < size / 32 || y % (size / 4) < size / 64;
            let k = if groove { 0.35 } else { 1.0 };
            data.extend(c.iter().map(|v| (*v as f32 * k) as u8));
        }
    }
    Image8 {
        width: size,
        height: size,
        channels: 3,
        data,
    }
}
