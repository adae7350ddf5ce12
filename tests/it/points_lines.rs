//! Points and lines (OBJ `p`/`l`, glTF modes 0-3) against analytic
//! coverage, and their depth test against triangles; concave faces and
//! two-sided drawing of open meshes.

use crate::common;

use common::{scene_in, scratch};

const MTL: &str = "newmtl black\nKd 0 0 0\nKs 0 0 0\nnewmtl white\nKd 1 1 1\nKs 0 0 0\n";

/// A black quad at z = 0 filling the view, seen straight on by an
/// orthographic camera 4 units tall at 64x64 (16 pixels a unit), with one
/// dim light and no ambient: lines and points are unlit and white.
fn scene(extra_obj: &str, sets: &str) -> softraster::scene::Scene {
    let dir = scratch(&format!("points-lines-{}", extra_obj.len() + sets.len()));
    let obj = format!(
        "mtllib m.mtl\nv -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nusemtl black\nf 1 2 3 4\nusemtl white\n{extra_obj}"
    );
    let toml = format!(
        "[output]\nwidth = 64\nheight = 64\nbackground = [0.0, 0.0, 0.0]\n\
         [render]\ntonemap = \"clamp\"\n{sets}\n\
         [[model]]\npath = \"m.obj\"\n\
         [[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, -1.0]\nirradiance = 0.1\n\
         [[camera]]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 4.0\n"
    );
    scene_in(&dir, &toml, &[("m.obj", &obj), ("m.mtl", MTL)])
}

/// Sum of the red channel over column `x` (the line's coverage there).
fn column(frame: &softraster::render::Frame, x: usize) -> f32 {
    (0..frame.height as usize)
        .map(|y| frame.color[y * frame.width as usize + x].x)
        .sum()
}

#[test]
fn a_line_covers_its_width_in_every_column() {
    // A horizontal line in front of the quad, 3 pixels wide: the box-
    // filtered coverage of each column sums to the width exactly.
    let s = scene("v -3 0.1 0.5\nv 3 0.1 0.5\nl 5 6\n", "line_width = 3.0");
    let f = common::render_frame(&s, 0, 0);
    for x in [3, 20, 31, 50, 60] {
        let c = column(&f, x);
        assert!((c - 3.0).abs() < 1e-3, "column {x}: {c}");
    }
    // Half a pixel wide: still the width.
    let s = scene("v -3 0.13 0.5\nv 3 0.13 0.5\nl 5 6\n", "line_width = 0.5");
    let f = common::render_frame(&s, 0, 0);
    let c = column(&f, 40);
    assert!((c - 0.5).abs() < 1e-3, "{c}");
}

#[test]
fn lines_and_points_behind_a_face_are_hidden() {
    let s = scene(
        "v -3 0.1 -0.5\nv 3 0.1 -0.5\nv 0.5 0.5 -0.5\nl 5 6\np 7\n",
        "line_width = 3.0",
    );
    let f = common::render_frame(&s, 0, 0);
    let lit: f32 = f.color.iter().map(|c| c.x).sum();
    assert!(lit < 0.05, "{lit}");
    // Lying on the face (z = 0): drawn, as a wire over its surface.
    let s = scene("v -3 0.1 0\nv 3 0.1 0\nl 5 6\n", "line_width = 2.0");
    let f = common::render_frame(&s, 0, 0);
    assert!((column(&f, 30) - 2.0).abs() < 1e-3, "{}", column(&f, 30));
}

#[test]
fn a_point_is_a_disc_of_its_size() {
    let s = scene("v 0.03 -0.02 0.5\np 5\n", "point_size = 8.0");
    let f = common::render_frame(&s, 0, 0);
    let area: f32 = f.color.iter().map(|c| c.x).sum();
    let disc = std::f32::consts::PI * 16.0;
    assert!((area - disc).abs() < 0.02 * disc, "{area} vs {disc}");
}

#[test]
fn gltf_lines_strips_loops_and_points_are_drawn() {
    // Four corners of a square, as each mode: lines (2 segments), a strip
    // (3), a loop (4) and points (4).
    let dir = scratch("gltf-lines");
    for (mode, name) in [(1, "lines"), (3, "strip"), (2, "loop"), (0, "points")] {
        let p = common::Prim {
            positions: vec![
                [-1.0, -1.0, 0.0],
                [1.0, -1.0, 0.0],
                [1.0, 1.0, 0.0],
                [-1.0, 1.0, 0.0],
            ],
            normals: vec![],
            uv0: vec![],
            uv1: vec![],
            colors: vec![],
            indices: vec![0, 1, 2, 3],
        };
        let nodes = r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]"#;
        let (text, _) = common::gltf_text(&p, &format!(", \"mode\": {mode}"), nodes, None);
        std::fs::write(dir.join(format!("{name}.gltf")), text).unwrap();
        let toml = format!(
            "[output]\nwidth = 64\nheight = 64\nbackground = \"transparent\"\n\
             [render]\nline_width = 2.0\npoint_size = 4.0\n\
             [[model]]\npath = \"{name}.gltf\"\n\
             [[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, -1.0]\n\
             [[camera]]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 4.0\n"
        );
        std::fs::write(dir.join(format!("{name}.toml")), toml).unwrap();
        let s = softraster::scene::Scene::load(
            &dir.join(format!("{name}.toml")),
            &softraster::scene::LoadOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let f = common::render_frame(&s, 0, 0);
        let covered: f32 = f.color.iter().map(|c| c.w).sum();
        // Each side is 2 units = 32 pixels long and 2 wide (plus caps).
        let expect = match name {
            "lines" => 2.0 * 32.0 * 2.0,
            "strip" => 3.0 * 32.0 * 2.0,
            "loop" => 4.0 * 32.0 * 2.0,
            _ => 4.0 * std::f32::consts::PI * 4.0,
        };
        assert!(
            (covered - expect).abs() < 0.12 * expect,
            "{name}: {covered} vs {expect}"
        );
    }
}

#[test]
fn concave_faces_keep_their_notch_and_open_meshes_are_two_sided() {
    // Only the extra geometry is white; the black quad is pushed behind
    // the camera's view by a U-shaped face in front of it at z = 1: 3
    // units wide, 2 high, a 1x1 notch from the top.
    let u = "v -1.5 -1 1\nv 1.5 -1 1\nv 1.5 1 1\nv 0.5 1 1\nv 0.5 0 1\nv -0.5 0 1\nv -0.5 1 1\nv -1.5 1 1\n";
    let s = scene(&format!("{u}f 5 6 7 8 9 10 11 12\n"), "");
    let f = common::render_frame(&s, 0, 0);
    let at = |x: f32, y: f32| {
        let (px, py) = ((x + 2.0) * 16.0, (2.0 - y) * 16.0);
        f.color[py as usize * 64 + px as usize].x
    };
    assert!(at(0.0, 0.5) < 0.01, "the notch is filled: {}", at(0.0, 0.5));
    assert!(
        at(-1.0, 0.5) > 0.05 && at(0.0, -0.5) > 0.05,
        "{} {}",
        at(-1.0, 0.5),
        at(0.0, -0.5)
    );
    // The same face wound the other way (its back toward the camera): an
    // open mesh is drawn two-sided and lit as if seen from the front.
    let s = scene(&format!("{u}f 12 11 10 9 8 7 6 5\n"), "");
    let g = common::render_frame(&s, 0, 0);
    assert_eq!(f.color, g.color);
    // Culling it on request hides it.
    let s = scene(&format!("{u}f 12 11 10 9 8 7 6 5\n"), "cull = \"back\"");
    let h = common::render_frame(&s, 0, 0);
    let lit: f32 = h.color.iter().map(|c| c.x).sum();
    assert!(lit < 0.01, "{lit}");
}

#[test]
fn a_scan_of_bare_vertices_reads_as_a_surface() {
    // 3,000 vertices on a unit sphere (a Fibonacci lattice), `v` lines
    // and nothing else, as a scanner writes them; and the same as a PLY
    // without faces. Drawn as points sized from their number: the
    // sphere's disc in a 200x200 frame reads as a surface (over 88% of
    // the pixels within 95% of its radius more than half covered; the rest
    // are the seams where three discs' anti-aliased edges meet), where
    // 1-pixel points leave most of it open.
    let dir = scratch("points-scan");
    let n = 3_000;
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let mut obj = String::new();
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
    );
    for i in 0..n {
        let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let r = (1.0 - y * y).sqrt();
        let (x, z) = (r * (golden * i as f32).cos(), r * (golden * i as f32).sin());
        obj.push_str(&format!("v {x} {y} {z}\n"));
        ply.push_str(&format!("{x} {y} {z}\n"));
    }
    let toml = |model: &str, sets: &str| {
        format!(
            "[output]\nwidth = 200\nheight = 200\nbackground = \"transparent\"\n\
             [render]\n{sets}\n[ground]\nshadow = false\n[[model]]\npath = \"{model}\"\n"
        )
    };
    let fill = |scene: &softraster::scene::Scene| {
        let f = common::render_frame(scene, 0, 0);
        let (w, h) = (f.width as usize, f.height as usize);
        let covered: Vec<(f32, f32)> = (0..w * h)
            .filter(|&i| f.color[i].w > 0.5)
            .map(|i| ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5))
            .collect();
        let (lo, hi) = covered.iter().fold(
            (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN)),
            |(lo, hi), &(x, y)| (lo.min(glam::Vec2::new(x, y)), hi.max(glam::Vec2::new(x, y))),
        );
        let (c, r) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.5);
        let inside = |x: f32, y: f32| (glam::Vec2::new(x, y) - c).length() < 0.95 * r;
        let disc = (0..w * h)
            .filter(|&i| inside((i % w) as f32 + 0.5, (i / w) as f32 + 0.5))
            .count();
        let hit = covered.iter().filter(|&&(x, y)| inside(x, y)).count();
        hit as f32 / disc as f32
    };
    std::fs::write(dir.join("scan.ply"), &ply).unwrap();
    for model in ["scan.obj", "scan.ply"] {
        let scene = scene_in(&dir, &toml(model, ""), &[("scan.obj", &obj)]);
        assert!(scene.models[0].mesh.triangles.is_empty());
        assert_eq!(scene.models[0].mesh.points.len(), n);
        let closed = fill(&scene);
        assert!(closed > 0.88, "{model}: {closed}");
    }
    let thin = scene_in(&dir, &toml("scan.obj", "point_size = 1.0"), &[]);
    let open = fill(&thin);
    assert!(open < 0.5, "1-pixel points: {open}");
}
