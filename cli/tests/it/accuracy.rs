//! The renderer measured by the tools' own accuracy scenes: texture filters
//! ranked against a supersampled reference (`bench --case filters`), and
//! SSAO against ray-traced AO on the scenes of `bench --case ao`.

use std::path::Path;

use crate::common::{self, render_frame, scene_in, scratch};

/// AO buffer of `scene` (TOML text holding `{ao}`) under `ao` (an inline table).
fn ao_of(dir: &Path, scene: &str, ao: &str) -> Vec<f32> {
    let f = render_frame(&scene_in(dir, &scene.replace("{ao}", ao), &[]), 0, 0);
    assert!(!f.ao.is_empty());
    f.ao
}

#[test]
fn filters_rank_by_error_against_a_supersampled_reference() {
    let dir = scratch("filters");
    let r = softraster_cli::tools::bench::filter_accuracy(&dir, 160, 120).unwrap();
    println!("filter,mean_abs_error_linear,ms");
    for f in &r {
        println!("{},{:.5},{:.2}", f.filter, f.mean_error, f.ms);
    }
    let e: Vec<f64> = r.iter().map(|f| f.mean_error).collect();
    assert!(
        e[0] > e[1] && e[1] > e[2] && e[2] > e[3],
        "expected nearest > bilinear > trilinear > anisotropic, got {e:?}"
    );
    // Anisotropic filtering is close to the reference, not just better.
    assert!(e[3] < 0.01, "{e:?}");
}

/// RMSE of SSAO against ray-traced AO over covered pixels, and the count.
fn ssao_rmse(dir: &Path, scene: &str, radius: f32) -> (f64, usize) {
    let truth = ao_of(
        dir,
        scene,
        &format!("{{ method = \"raytraced\", samples = 512, radius = {radius} }}"),
    );
    let ssao = ao_of(
        dir,
        scene,
        &format!("{{ method = \"ssao\", radius = {radius} }}"),
    );
    let off = scene.replace("{ao}", "{ method = \"off\" }");
    let depth = render_frame(&scene_in(dir, &off, &[]), 0, 0).depth;
    if std::env::var_os("DUMP_AO").is_some() {
        let side = (truth.len() as f64).sqrt() as u32;
        for (name, v) in [("truth", &truth), ("ssao", &ssao)] {
            let img = softraster::output::Image8 {
                width: side,
                height: side,
                channels: 3,
                data: v.iter().flat_map(|a| [(a * 255.0) as u8; 3]).collect(),
            };
            softraster::output::png::write(&dir.join(format!("{name}.png")), &img).unwrap();
        }
    }
    let mut n = 0;
    let mut sum = 0.0f64;
    for i in 0..truth.len() {
        if depth[i].is_finite() {
            sum += ((ssao[i] - truth[i]) as f64).powi(2);
            n += 1;
        }
    }
    ((sum / n as f64).sqrt(), n)
}

#[test]
fn ssao_matches_raytraced_ao_on_bunny_and_diablo3() {
    let Some(assets) = common::shared_assets() else {
        return;
    };
    let dir = common::scratch("ssao_vs_raytraced");
    let size = 160u32;
    // The scenes of `bench --case ao`.
    for (name, model, eye) in softraster_cli::tools::accuracy::AO_SCENES {
        let (scene, radius) =
            softraster_cli::tools::accuracy::ao_scene(&dir, &assets.join(model), eye, size)
                .unwrap();
        let (rmse, n) = ssao_rmse(&dir, &scene, radius);
        println!(
            "{name}: SSAO (16 samples, radius {radius:.3}) vs ray-traced AO (512 rays): RMSE {rmse:.4} over {n} pixels"
        );
        assert!(n > 5000, "{n}");
        assert!(rmse < 0.05, "{name}: RMSE {rmse}");
    }
}
