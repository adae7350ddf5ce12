//! softraster against Blender Cycles on the scenes of the reference set
//! cheap enough for a test (`tests/cycles`: 160x120, the glTF scenes of
//! `benches/cycles/scenes.py` whose files are small, under two HDRIs of
//! `../shared/assets/hdri`). Each golden is Cycles' frame (128 samples,
//! denoised, the "Standard" view); the test renders the scene with the
//! default method and holds mean FLIP within 0.01 of what was measured
//! when the golden was made (`docs/cycles.md` has the whole set at
//! 320x240). SKIPPED without the shared HDRIs; a failure under CI.

use crate::binary::run;
use crate::common::{root, scratch, shared_assets};

/// Renders `tests/cycles/{name}.toml` and measures its mean FLIP against
/// `{name}-cycles.png`.
fn flip_against_cycles(name: &str) -> f64 {
    let dir = root().join("tests/cycles");
    let out = scratch(&format!("cycles_{name}"));
    let scene = dir.join(format!("{name}.toml"));
    let (scene, out_dir) = (scene.to_str().unwrap(), out.to_str().unwrap());
    let mut render = vec!["render", scene, "--out", out_dir];
    render.extend(["--quiet", "--set", "output.name=frame"]);
    let (code, _, err) = run(&render);
    assert_eq!(code, 0, "{name}: {err}");
    let golden = dir.join(format!("{name}-cycles.png"));
    let frame = out.join("frame.png");
    let (golden, frame) = (golden.to_str().unwrap(), frame.to_str().unwrap());
    let mut compare = vec!["compare", golden, frame];
    compare.extend(["--metric", "flip", "--json", "--threshold", "1000"]);
    let (code, json, err) = run(&compare);
    assert_eq!(code, 0, "{name}: {err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    v["files"][0]["value"].as_f64().unwrap()
}

#[test]
fn the_default_method_stays_as_close_to_cycles_as_measured() {
    if shared_assets().is_none() {
        return;
    }
    // Measured when the goldens were made: texture transform 0.045 and
    // 0.035 (e234314); anisotropy discs 0.137 and 0.090, after the Cycles
    // driver gave the discs the extension's alphas and direction (their
    // lower discs see the upper ones: `docs/cycles.md`); with the traced
    // reflections, which show the upper discs' backs in part, 0.127 and
    // 0.090.
    for (name, measured) in [
        ("texture-transform-courtyard", 0.0454),
        ("texture-transform-studio", 0.0353),
        ("anisotropy-discs-courtyard", 0.1265),
        ("anisotropy-discs-studio", 0.0895),
    ] {
        let flip = flip_against_cycles(name);
        assert!(
            flip <= measured + 0.01,
            "{name}: FLIP {flip:.4} against Cycles, measured {measured}"
        );
    }
}
