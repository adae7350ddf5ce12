//! Anti-aliasing against analytic truth and a supersampled reference:
//! exact MSAA coverage of a rectangle from the standard sample positions,
//! shading inside the triangle (centroid) when the pixel center is not,
//! alpha-cutout edges resolved per sample, SSAA as an exact box filter,
//! edge error falling with the sample count, and the wireframe's lines.

use crate::common;

use std::path::Path;

use common::render_frame;
use softraster::render::Frame;
use softraster::render::msaa_sample_positions;
use softraster::scene::Scene;
use softraster_cli::tools::accuracy;

/// A white unlit rectangle seen by an orthographic camera at 64x48 pixels
/// of 0.1 world units: x from pixel 21.7 to 45.1, y from 14.45 to 32.7
/// (screen, y down). No edge lies on a 1/16-pixel sample position.
const RECT: [f32; 4] = [21.7, 45.1, 14.45, 32.7];

fn rect_scene(dir: &Path, render: &str) -> Scene {
    let [x0, x1, y0, y1] = RECT;
    let wx = |x: f32| x * 0.1 - 3.2;
    let wy = |y: f32| 2.4 - y * 0.1;
    let obj = format!(
        "v {} {} 0\nv {} {} 0\nv {} {} 0\nv {} {} 0\nf 1 2 3\nf 1 3 4\n",
        wx(x0),
        wy(y1),
        wx(x1),
        wy(y1),
        wx(x1),
        wy(y0),
        wx(x0),
        wy(y0)
    );
    common::scene_in(
        dir,
        &format!(
            "[output]\nwidth = 64\nheight = 48\nbackground = \"transparent\"\n[render]\nshading = \"unlit\"\n{render}\n\
             [[model]]\npath = \"rect.obj\"\n[model.material]\nkd = [1.0, 1.0, 1.0]\n\
             [[camera]]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n\
             projection = \"orthographic\"\nheight = 4.8\n"
        ),
        &[("rect.obj", &obj)],
    )
}

#[test]
fn msaa_coverage_is_the_fraction_of_standard_samples_inside() {
    let dir = common::scratch("aa_rect");
    let [x0, x1, y0, y1] = RECT;
    for n in [1u32, 2, 4, 8, 16] {
        let scene = rect_scene(&dir, &format!("msaa = {n}"));
        let f = render_frame(&scene, 0, 0);
        let pattern = msaa_sample_positions(n).unwrap();
        let mut partial = 0;
        let (mut sum, mut worst) = (0.0f64, 0.0f32);
        for py in 0..48 {
            for px in 0..64 {
                let inside = pattern
                    .iter()
                    .filter(|(ox, oy)| {
                        let x = px as f32 + 0.5 + *ox as f32 / 16.0;
                        let y = py as f32 + 0.5 + *oy as f32 / 16.0;
                        x0 <= x && x < x1 && y0 <= y && y < y1
                    })
                    .count();
                let want = inside as f32 / n as f32;
                let got = f.color[py * 64 + px];
                worst = worst.max((got.x - want).abs()).max((got.w - want).abs());
                if 0 < inside && inside < n as usize {
                    partial += 1;
                }
                sum += got.x as f64;
            }
        }
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        eprintln!(
            "msaa {n:2}: worst |coverage - samples inside/n| = {worst:.2e}, {partial} partly covered pixels, total {sum:.3} vs area {area:.3}"
        );
        assert!(worst < 1e-6, "msaa {n}: coverage off by {worst}");
        if n > 1 {
            assert!(partial > 40, "msaa {n}: the edges must be partly covered");
        }
        // The perimeter pixels' errors partly cancel: with 4 samples or more
        // the total is within a few pixels of the exact area.
        if n >= 4 {
            assert!((sum - area).abs() < 4.0, "msaa {n}: {sum} vs {area}");
        }
    }
}

#[test]
fn fragments_are_shaded_inside_their_triangle() {
    // A sliver 0.3 px wide whose depth runs from 1 to 30: interpolated at a
    // pixel center outside it, its depth would leave that range. With MSAA
    // every fragment is shaded at the center only when the center is
    // inside, else at the centroid of its covered samples (inside, as the
    // triangle is convex).
    let dir = common::scratch("aa_centroid");
    let obj = "v -0.45 -0.45 -1\nv -0.4465 -0.45 -1\nv 12 10.5 -30\nf 1 2 3\n";
    for n in [1u32, 4, 16] {
        let scene = common::scene_in(
            &dir,
            &format!(
                "[output]\nwidth = 96\nheight = 96\nbackground = \"transparent\"\n[render]\nshading = \"unlit\"\ncull = \"none\"\nmsaa = {n}\n\
                 [[model]]\npath = \"s.obj\"\n\
                 [[camera]]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\nfov = 60.0\nnear = 0.5\nfar = 100.0\n"
            ),
            &[("s.obj", obj)],
        );
        let f = render_frame(&scene, 0, 0);
        let covered: Vec<f32> = f.depth.iter().copied().filter(|d| d.is_finite()).collect();
        let (lo, hi) = covered
            .iter()
            .fold((f32::INFINITY, 0f32), |(l, h), &d| (l.min(d), h.max(d)));
        let partial = f.color.iter().filter(|c| c.w > 0.0 && c.w < 1.0).count();
        eprintln!(
            "msaa {n:2}: {} pixels with a fragment, depth {lo:.3}..{hi:.3}, {partial} partly covered",
            covered.len()
        );
        assert!(!covered.is_empty(), "msaa {n}: the sliver must show");
        assert!(
            lo >= 1.0 - 1e-4 && hi <= 30.0 * (1.0 + 1e-4),
            "msaa {n}: a fragment was shaded outside its triangle ({lo}..{hi})"
        );
        if n > 1 {
            // Most of them have their center outside the sliver.
            assert!(
                partial > 30 && covered.len() > 30,
                "msaa {n}: the sliver covers parts of pixels"
            );
        }
    }
}

#[test]
fn ssaa_is_the_box_filtered_larger_frame() {
    let dir = common::scratch("aa_ssaa");
    let text = accuracy::edge_scene(&dir).unwrap();
    let load = |w: u32, h: u32, render: &str| {
        let t = text
            .replace("{width}", &w.to_string())
            .replace("{height}", &h.to_string())
            .replace("{render}", render);
        let p = dir.join("scene.toml");
        std::fs::write(&p, t).unwrap();
        Scene::load(&p, &Default::default()).unwrap()
    };
    let small = render_frame(&load(80, 60, "ssaa = 3"), 0, 0);
    let big = render_frame(&load(240, 180, ""), 0, 0);
    let mut worst = 0.0f32;
    for y in 0..60 {
        for x in 0..80 {
            let mut c = glam::Vec4::ZERO;
            for sy in 0..3 {
                for sx in 0..3 {
                    c += big.color[(y * 3 + sy) * 240 + x * 3 + sx];
                }
            }
            worst = worst.max((c / 9.0 - small.color[y * 80 + x]).abs().max_element());
        }
    }
    assert!(
        worst < 1e-5,
        "ssaa 3 differs from the 3x3 box filter by {worst}"
    );
}

#[test]
fn edge_error_falls_with_the_sample_count() {
    let dir = common::scratch("aa_edges");
    let rows = accuracy::edges(&dir, 160, 120, 1, None).unwrap();
    eprintln!("method, mae, rmse, flip (against 16x16 supersampling)");
    for r in &rows {
        eprintln!("{}, {:.5}, {:.5}, {:.5}", r.method, r.mae, r.rmse, r.flip);
    }
    let msaa: Vec<_> = rows
        .iter()
        .filter(|r| r.method.starts_with("msaa"))
        .collect();
    assert_eq!(msaa.len(), 5);
    for w in msaa.windows(2) {
        assert!(
            w[1].mae < w[0].mae && w[1].rmse < w[0].rmse,
            "{} ({:.5}) is not better than {} ({:.5})",
            w[1].method,
            w[1].mae,
            w[0].method,
            w[0].mae
        );
    }
    // 16 samples take most of the aliasing away.
    assert!(msaa[4].mae < 0.2 * msaa[0].mae);
    let ssaa4 = rows.iter().find(|r| r.method == "ssaa 4x4").unwrap();
    assert!(ssaa4.mae < msaa[0].mae * 0.2);
}

#[test]
fn wireframe_lines_are_filtered() {
    // The wireframe of a sphere: MSAA 4 must be closer to a 4x4
    // supersampled wireframe than one sample per pixel.
    let dir = common::scratch("aa_wire");
    let text = accuracy::edge_scene(&dir).unwrap();
    let frame = |render: &str| -> Frame {
        let t = text
            .replace("{width}", "160")
            .replace("{height}", "120")
            .replace("{render}", render)
            .replace("shading = \"unlit\"", "shading = \"wireframe\"");
        let p = dir.join("scene.toml");
        std::fs::write(&p, t).unwrap();
        render_frame(&Scene::load(&p, &Default::default()).unwrap(), 0, 0)
    };
    let reference = frame("ssaa = 4");
    let err = |f: &Frame| {
        f.color
            .iter()
            .zip(&reference.color)
            .map(|(a, b)| (a.x - b.x).abs() as f64)
            .sum::<f64>()
            / f.color.len() as f64
    };
    let (e1, e4) = (err(&frame("msaa = 1")), err(&frame("msaa = 4")));
    eprintln!("wireframe mean abs error vs ssaa 4x4: msaa 1 {e1:.5}, msaa 4 {e4:.5}");
    assert!(e4 < 0.7 * e1, "msaa 4 {e4} vs msaa 1 {e1}");
}

#[test]
fn msaa_resolves_alpha_cutout_edges_per_sample() {
    // A glTF quad (alphaMode MASK, cutoff 0.5) whose vertex alpha runs
    // from 0 at pixel x = 4 to 1 at x = 36.6: the cut is the line x = 20.3.
    // With MSAA the alpha test runs at each sample, so a pixel on the cut
    // is covered by exactly the samples right of it.
    let dir = common::scratch("aa_cutout");
    let wx = |x: f32| x * 0.1 - 3.2;
    let wy = |y: f32| 2.4 - y * 0.1;
    let (x0, x1, y0, y1) = (4.0, 36.6, 4.0, 44.0);
    let p = common::Prim {
        positions: vec![
            [wx(x0), wy(y1), 0.0],
            [wx(x1), wy(y1), 0.0],
            [wx(x1), wy(y0), 0.0],
            [wx(x0), wy(y0), 0.0],
        ],
        normals: vec![[0.0, 0.0, 1.0]; 4],
        colors: vec![
            [1.0, 1.0, 1.0, 0.0],
            [1.0, 1.0, 1.0, 1.0],
            [1.0, 1.0, 1.0, 1.0],
            [1.0, 1.0, 1.0, 0.0],
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    };
    let (text, _) = common::gltf_text(
        &p,
        r#", "material": 0"#,
        r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0,
        "materials": [{"alphaMode": "MASK", "alphaCutoff": 0.5, "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1]}}]"#,
        None,
    );
    std::fs::write(dir.join("cut.gltf"), text).unwrap();
    for n in [1u32, 4, 16] {
        let scene = common::scene_in(
            &dir,
            &format!(
                "[output]\nwidth = 64\nheight = 48\nbackground = \"transparent\"\n\
                 [render]\nshading = \"unlit\"\nmsaa = {n}\n\
                 [[model]]\npath = \"cut.gltf\"\n\
                 [[camera]]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n\
                 projection = \"orthographic\"\nheight = 4.8\n"
            ),
            &[],
        );
        let f = render_frame(&scene, 0, 0);
        let pattern = msaa_sample_positions(n).unwrap();
        let mut worst = 0.0f32;
        let mut partial = 0;
        for py in 10..38 {
            for px in 14..28 {
                let inside = pattern
                    .iter()
                    .filter(|(ox, _)| px as f32 + 0.5 + *ox as f32 / 16.0 >= 20.3)
                    .count();
                let want = inside as f32 / n as f32;
                let got = f.color[py * 64 + px].w;
                worst = worst.max((got - want).abs());
                if got > 0.0 && got < 1.0 {
                    partial += 1;
                }
            }
        }
        eprintln!(
            "msaa {n:2}: cut-edge coverage off by at most {worst:.2e}, {partial} partial pixels"
        );
        // The vertex alpha is interpolated in f32: a sample within 1e-4 px
        // of the cut could go either way; none is that close here.
        assert!(worst < 1e-6, "msaa {n}: {worst}");
        assert_eq!(partial > 0, n > 1, "msaa {n}: {partial} partial pixels");
    }
}
