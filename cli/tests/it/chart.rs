//! `softraster chart` on a small scene with a reduced sweep: the CSV's
//! shape, every reference's error against itself (rendered again) is zero,
//! the Pareto flags, the chart files, and the same errors twice.

use crate::common;

use std::path::Path;

fn chart(out: &Path) -> Vec<Vec<String>> {
    let scene = common::root().join("scenes/showcase.toml");
    let (code, _, err) = crate::binary::run(&[
        "chart",
        scene.to_str().unwrap(),
        "--frame",
        "3",
        "--quick",
        "--runs",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "output.width=96",
        "--set",
        "output.height=72",
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(out.join("chart.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "knob,setting,default,reference,ms_median,ms_min,ms_max,runs,error,metric,pareto,against"
    );
    lines
        .map(|l| {
            let cols = split_csv(l);
            assert_eq!(cols.len(), 12, "{l}");
            cols
        })
        .collect()
}

/// One CSV line (RFC 4180 quoting) into fields.
fn split_csv(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                out.last_mut().unwrap().push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(String::new()),
            c => out.last_mut().unwrap().push(c),
        }
    }
    out
}

#[test]
fn reduced_sweep_has_its_shape_and_references_score_zero() {
    let dir = common::scratch("chart");
    let rows = chart(&dir.join("a"));
    let count = |k: &str| rows.iter().filter(|r| r[0] == k).count();
    // Quick sweep: aa 3 + reference, texture 2 + reference, shadows 4 +
    // reference (the showcase's lights are made to cast), ao 2 ssao + 1
    // raytraced + reference, depth 2.
    assert_eq!(
        [
            count("aa"),
            count("texture"),
            count("shadows"),
            count("ao"),
            count("depth")
        ],
        [4, 3, 5, 4, 2]
    );
    for k in ["aa", "texture", "shadows", "ao", "depth"] {
        let defaults = rows.iter().filter(|r| r[0] == k && r[2] == "true").count();
        assert_eq!(defaults, 1, "{k}: one default");
    }
    for r in &rows {
        let (ms, lo, hi): (f64, f64, f64) = (
            r[4].parse().unwrap(),
            r[5].parse().unwrap(),
            r[6].parse().unwrap(),
        );
        assert!(lo <= ms && ms <= hi && lo > 0.0, "{r:?}");
        let e: f64 = r[8].parse().unwrap();
        assert!(e.is_finite() && e >= 0.0, "{r:?}");
        if r[3] == "true" {
            assert_eq!(e, 0.0, "a reference against itself: {r:?}");
        } else if r[0] != "depth" {
            assert!(e > 0.0, "only the reference is exact here: {r:?}");
        }
    }
    // Standard depth fails on the far quads, reverse-Z does not.
    let depth = |s: &str| -> f64 {
        rows.iter().find(|r| r[0] == "depth" && r[1] == s).unwrap()[8]
            .parse()
            .unwrap()
    };
    assert!(depth("standard") > 0.2 && depth("reverse-z") == 0.0);
    // Pareto flags: a row is on the front exactly when no row of its knob
    // and reference is at least as fast and as accurate, and better in one.
    for r in &rows {
        let (t, e): (f64, f64) = (r[4].parse().unwrap(), r[8].parse().unwrap());
        let dominated = rows.iter().any(|o| {
            let (ot, oe): (f64, f64) = (o[4].parse().unwrap(), o[8].parse().unwrap());
            o[0] == r[0]
                && o[11] == r[11]
                && o[1] != r[1]
                && ot <= t
                && oe <= e
                && (ot < t || oe < e)
        });
        assert_eq!(r[10] == "true", !dominated, "{r:?}");
    }
    let png = image::open(dir.join("a/chart.png")).unwrap();
    assert_eq!((png.width(), png.height()), (1100, 700));
    let svg = std::fs::read_to_string(dir.join("a/chart.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("anti-aliasing"));

    // The same command gives the same errors (times vary).
    let again = chart(&dir.join("b"));
    let errors = |rows: &[Vec<String>]| -> Vec<(String, String)> {
        rows.iter().map(|r| (r[1].clone(), r[8].clone())).collect()
    };
    assert_eq!(errors(&rows), errors(&again));
}
