//! glTF materials end to end: KHR_materials_unlit, ior, specular,
//! clearcoat, transmission, volume, sheen and iridescence against their
//! models' values on a cube face, anisotropy's stretched highlight, and
//! KHR_materials_variants picking each primitive's material by the
//! model's `variant`.

use crate::common;

use common::render_frame;
use common::{cube, gltf_text};
use glam::Vec3;
use softraster::scene::Scene;

/// A unit cube with `material` (JSON) seen face-on from +Z, lit by the
/// neutral environment (radiance 1) and `lights` (TOML): the linear colour
/// at the center of its front face.
fn cube_face_color(name: &str, material: &str, used: &str, lights: &str) -> Vec3 {
    cube_face_color_over(name, material, used, lights, "")
}

/// `cube_face_color` with more `[output]` keys (e.g. the background).
fn cube_face_color_over(
    name: &str,
    material: &str,
    used: &str,
    lights: &str,
    output: &str,
) -> Vec3 {
    let dir = common::scratch(name);
    let (text, _) = gltf_text(
        &cube(),
        r#", "material": 0"#,
        &format!(
            r#""nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0,
            "extensionsUsed": [{used}], "materials": [{material}]"#
        ),
        None,
    );
    std::fs::write(dir.join("c.gltf"), text).unwrap();
    let scene = format!(
        "[output]\nwidth = 32\nheight = 32\n{output}[render]\nshading = \"pbr\"\n\
         [environment]\npreset = \"neutral\"\n{lights}[[model]]\npath = \"c.gltf\"\n\
         [[camera]]\neye = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 2.0\n"
    );
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    render_frame(&s, 0, 0).color[16 * 32 + 16].truncate()
}

#[test]
fn khr_materials_unlit_ior_and_specular() {
    // Unlit: the base colour, whatever lights the scene.
    let base = r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.5}"#;
    let unlit = cube_face_color(
        "gltf_unlit",
        &format!(r#"{base}, "extensions": {{"KHR_materials_unlit": {{}}}}}}"#),
        r#""KHR_materials_unlit""#,
        "[[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, -1.0]\nirradiance = 5.0\n",
    );
    assert!(
        (unlit - Vec3::new(0.2, 0.4, 0.6)).abs().max_element() < 1e-5,
        "{unlit}"
    );
    // specularFactor 0: no specular lobe at all, so a uniform environment
    // of radiance 1 shows the base colour exactly (Lambertian).
    let matte = cube_face_color(
        "gltf_specular0",
        &format!(
            r#"{base}, "extensions": {{"KHR_materials_specular": {{"specularFactor": 0.0}}}}}}"#
        ),
        r#""KHR_materials_specular""#,
        "",
    );
    assert!(
        (matte - Vec3::new(0.2, 0.4, 0.6)).abs().max_element() < 2e-3,
        "{matte}"
    );
    // The default dielectric (ior 1.5) reflects more than that, and a
    // higher ior more still.
    let plain = cube_face_color("gltf_ior15", &format!("{base}}}"), "", "");
    let ior2 = cube_face_color(
        "gltf_ior2",
        &format!(r#"{base}, "extensions": {{"KHR_materials_ior": {{"ior": 2.0}}}}}}"#),
        r#""KHR_materials_ior""#,
        "",
    );
    assert!(
        plain.x > matte.x + 0.01 && ior2.x > plain.x + 0.02,
        "{matte} {plain} {ior2}"
    );
}

/// tex.png and plain.gltf (the textured cube) in `dir`; the cube.

#[test]
fn khr_materials_clearcoat_transmission_and_volume() {
    // A matte base (specularFactor 0) shows its base colour exactly in the
    // uniform environment; a smooth clearcoat seen head-on reflects
    // F0 = 0.04 of the light and takes that share from the base.
    let matte = r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.5}, "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}"#;
    let used = r#""KHR_materials_specular", "KHR_materials_clearcoat""#;
    let coated = cube_face_color(
        "gltf_clearcoat",
        &format!(
            r#"{matte}, "KHR_materials_clearcoat": {{"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.0}}}}}}"#
        ),
        used,
        "",
    );
    let expect = Vec3::new(0.2, 0.4, 0.6) * 0.96 + Vec3::splat(0.04);
    assert!(
        (coated - expect).abs().max_element() < 4e-3,
        "{coated} vs {expect}"
    );
    // The sampled reference (Monte Carlo over the environment, with the
    // coat as a lobe of its own) agrees.
    let sampled = cube_face_color(
        "gltf_clearcoat_sampled",
        &format!(
            r#"{matte}, "KHR_materials_clearcoat": {{"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.0}}}}}}"#
        ),
        used,
        "method = \"sampled\"\nsamples = 64\n",
    );
    assert!(
        (sampled - expect).abs().max_element() < 0.01,
        "sampled {sampled} vs {expect}"
    );
    // A factor of 0 is no coat at all.
    let uncoated = cube_face_color(
        "gltf_clearcoat0",
        &format!(r#"{matte}, "KHR_materials_clearcoat": {{"clearcoatFactor": 0.0}}}}}}"#),
        used,
        "",
    );
    assert!(
        (uncoated - Vec3::new(0.2, 0.4, 0.6)).abs().max_element() < 2e-3,
        "{uncoated}"
    );
    // Under a light straight on, the coat adds its highlight.
    let light =
        "[[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, -1.0]\nirradiance = 1.0\n";
    let lit_coat = cube_face_color(
        "gltf_clearcoat_lit",
        &format!(
            r#"{matte}, "KHR_materials_clearcoat": {{"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.3}}}}}}"#
        ),
        used,
        light,
    );
    let lit_plain = cube_face_color("gltf_clearcoat_lit0", &format!("{matte}}}}}"), used, light);
    assert!(lit_coat.x > lit_plain.x + 0.1, "{lit_coat} vs {lit_plain}");

    // Transmission: a white, fully transmissive dielectric in a uniform
    // environment in front of that environment is invisible (what it
    // reflects plus what it lets through is all the light).
    let clear = |name: &str, base: &str, volume: &str| {
        cube_face_color_over(
            name,
            &format!(
                r#"{{"pbrMetallicRoughness": {{"baseColorFactor": {base}, "metallicFactor": 0.0, "roughnessFactor": 0.3}}, "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 1.0}}{volume}}}}}"#
            ),
            r#""KHR_materials_transmission", "KHR_materials_volume""#,
            "",
            "background = \"environment\"\n",
        )
    };
    let glass = clear("gltf_transmission", "[1.0, 1.0, 1.0, 1.0]", "");
    assert!(
        (glass - Vec3::ONE).abs().max_element() < 0.01,
        "white glass: {glass}"
    );
    // A tinted one lets its base colour through (and reflects ~0.04).
    let tinted = clear("gltf_transmission_tint", "[0.2, 0.4, 0.6, 1.0]", "");
    let expect = Vec3::new(0.2, 0.4, 0.6) * 0.96 + Vec3::splat(0.04);
    assert!(
        (tinted - expect).abs().max_element() < 0.01,
        "{tinted} vs {expect}"
    );
    // A volume attenuates by attenuationColor^(thickness / distance).
    let volume = clear(
        "gltf_volume",
        "[1.0, 1.0, 1.0, 1.0]",
        r#", "KHR_materials_volume": {"thicknessFactor": 2.0, "attenuationColor": [0.5, 0.8, 1.0], "attenuationDistance": 1.0}"#,
    );
    let expect = Vec3::new(0.25, 0.64, 1.0) * 0.96 + Vec3::splat(0.04);
    assert!(
        (volume - expect).abs().max_element() < 0.01,
        "{volume} vs {expect}"
    );
}

#[test]
fn khr_materials_sheen_prefiltered_agrees_with_sampled() {
    // A black, matte base (no specular) shows the sheen alone: under the
    // uniform environment, head-on, its albedo E(1, r) times the colour;
    // the sampled reference integrates the lobe itself and agrees.
    let sheen = |name: &str, env: &str, color: &str| {
        cube_face_color(
            name,
            &format!(
                r#"{{"pbrMetallicRoughness": {{"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0}}, "extensions": {{"KHR_materials_specular": {{"specularFactor": 0.0}}, "KHR_materials_sheen": {{"sheenColorFactor": {color}, "sheenRoughnessFactor": 0.5}}}}}}"#
            ),
            r#""KHR_materials_specular", "KHR_materials_sheen""#,
            env,
        )
    };
    let pre = sheen("gltf_sheen", "", "[1.0, 0.5, 0.25]");
    // The sheen's directional albedo at cos 1, roughness 0.5 (Zeltner et
    // al.'s fit; the shading module's unit test pins the value).
    let expect = Vec3::new(1.0, 0.5, 0.25) * 0.024_9;
    assert!(
        (pre - expect).abs().max_element() < 2e-3,
        "{pre} vs {expect}"
    );
    assert!(pre.x > 0.02, "{pre}");
    let sampled = sheen(
        "gltf_sheen_sampled",
        "method = \"sampled\"\nsamples = 64\n",
        "[1.0, 0.5, 0.25]",
    );
    assert!(
        (sampled - pre).abs().max_element() < 0.01,
        "sampled {sampled} vs prefiltered {pre}"
    );
    // A black sheen is none.
    let none = sheen("gltf_sheen_black", "", "[0.0, 0.0, 0.0]");
    assert!(none.max_element() < 1e-4, "{none}");
}

#[test]
fn khr_materials_iridescence_colours_the_reflection_as_the_film_model_says() {
    // A black, smooth dielectric in the uniform environment, seen head on,
    // reflects F0 = 0.04 of the light; under a 400 nm film of index 1.3
    // (the extension's defaults without a thickness texture) it reflects
    // the film's Fresnel over that F0 instead.
    let black = r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.0}"#;
    let used = r#""KHR_materials_iridescence""#;
    let plain = cube_face_color("gltf_iridescence_plain", &format!("{black}}}"), used, "");
    let film = |name: &str, ext: &str, env: &str| {
        cube_face_color(
            name,
            &format!(r#"{black}, "extensions": {{"KHR_materials_iridescence": {ext}}}}}"#),
            used,
            env,
        )
    };
    let coloured = film(
        "gltf_iridescence",
        r#"{"iridescenceFactor": 1.0, "iridescenceIor": 1.3}"#,
        "",
    );
    // The film's Fresnel at normal incidence over F0 = 0.04 (the shading
    // module's model; its unit test pins these values).
    let model = Vec3::new(0.007_456_456, 0.038_351_72, 0.016_038_207);
    let expect = plain / 0.04 * model;
    assert!(
        (coloured - expect).abs().max_element() < 0.01 * expect.max_element(),
        "{coloured} vs {expect} (plain {plain})"
    );
    // Coloured, not grey.
    assert!(coloured.max_element() - coloured.min_element() > 0.2 * coloured.max_element());
    // The thickness range: without a texture, the maximum is used.
    let thin = film(
        "gltf_iridescence_thin",
        r#"{"iridescenceFactor": 1.0, "iridescenceThicknessMaximum": 250.0}"#,
        "",
    );
    let model_thin = Vec3::new(0.047_993_07, 0.026_858_89, 0.004_917_93);
    let expect_thin = plain / 0.04 * model_thin;
    assert!(
        (thin - expect_thin).abs().max_element() < 0.01 * expect_thin.max_element(),
        "{thin} vs {expect_thin}"
    );
    // A factor of 0 is no film.
    let off = film("gltf_iridescence_off", r#"{"iridescenceFactor": 0.0}"#, "");
    assert!((off - plain).abs().max_element() < 1e-6, "{off} vs {plain}");
    // The sampled reference (the film in the BRDF at v.h) agrees with the
    // split sum (the film at n.v) on a rough film.
    let rough = r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.3}"#;
    let rough_film = |name: &str, env: &str| {
        cube_face_color(
            name,
            &format!(
                r#"{rough}, "extensions": {{"KHR_materials_iridescence": {{"iridescenceFactor": 1.0}}}}}}"#
            ),
            used,
            env,
        )
    };
    let prefiltered = rough_film("gltf_iridescence_rough", "");
    let sampled = rough_film(
        "gltf_iridescence_rough_sampled",
        "method = \"sampled\"\nsamples = 256\n",
    );
    assert!(
        (prefiltered - sampled).abs().max_element() < 0.15 * sampled.max_element(),
        "prefiltered {prefiltered} vs sampled {sampled}"
    );
}

/// Unlit materials of four colours, and a cube whose primitive draws the
/// grey one by default and KHR_materials_variants maps: "summer" to red,
/// "winter" and "night" to blue ("plain" maps nothing).
fn variant_cube(dir: &std::path::Path) {
    let unlit = |rgb: &str| {
        format!(
            r#"{{"pbrMetallicRoughness": {{"baseColorFactor": [{rgb}, 1.0]}}, "extensions": {{"KHR_materials_unlit": {{}}}}}}"#
        )
    };
    let mappings = r#", "material": 0, "extensions": {"KHR_materials_variants": {"mappings": [{"material": 1, "variants": [0]}, {"material": 2, "variants": [1, 2]}]}}"#;
    let (text, _) = gltf_text(
        &cube(),
        mappings,
        &format!(
            r#""nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0,
            "extensionsUsed": ["KHR_materials_unlit", "KHR_materials_variants"],
            "extensions": {{"KHR_materials_variants": {{"variants": [{{"name": "summer"}}, {{"name": "winter"}}, {{"name": "night"}}, {{"name": "plain"}}]}}}},
            "materials": [{}, {}, {}, {}]"#,
            unlit("0.5, 0.5, 0.5"),
            unlit("0.8, 0.1, 0.1"),
            unlit("0.1, 0.1, 0.8"),
            unlit("0.1, 0.8, 0.1"),
        ),
        None,
    );
    std::fs::write(dir.join("c.gltf"), text).unwrap();
}

/// The scene of `variant_cube` seen face-on, with `variant` (a TOML line,
/// or nothing) in its `[[model]]`.
fn variant_scene(variant: &str) -> String {
    format!(
        "[output]\nwidth = 32\nheight = 32\n[render]\nshading = \"pbr\"\n\
         [[model]]\npath = \"c.gltf\"\n{variant}\
         [[camera]]\neye = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 2.0\n"
    )
}

#[test]
fn khr_materials_variants_pick_each_primitives_material_by_name() {
    let dir = common::scratch("gltf_variants");
    variant_cube(&dir);
    let face = |variant: &str| {
        std::fs::write(dir.join("s.toml"), variant_scene(variant)).unwrap();
        let s =
            Scene::load(&dir.join("s.toml"), &Default::default()).unwrap_or_else(|e| panic!("{e}"));
        render_frame(&s, 0, 0).color[16 * 32 + 16].truncate()
    };
    for (variant, want) in [
        ("", Vec3::splat(0.5)),
        ("variant = \"summer\"\n", Vec3::new(0.8, 0.1, 0.1)),
        ("variant = \"winter\"\n", Vec3::new(0.1, 0.1, 0.8)),
        ("variant = \"night\"\n", Vec3::new(0.1, 0.1, 0.8)),
        ("variant = \"plain\"\n", Vec3::splat(0.5)),
    ] {
        let got = face(variant);
        assert!(
            (got - want).abs().max_element() < 1e-5,
            "{variant:?}: {got} vs {want}"
        );
    }
    // A name the file lacks: an error at the key, listing the variants.
    std::fs::write(dir.join("s.toml"), variant_scene("variant = \"autumn\"\n")).unwrap();
    let e = Scene::load(&dir.join("s.toml"), &Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("s.toml:8:")
            && e.contains("model.variant = \"autumn\"")
            && e.contains("\"summer\", \"winter\", \"night\", \"plain\""),
        "{e}"
    );
    // A mapping to a material the file lacks.
    let text = std::fs::read_to_string(dir.join("c.gltf"))
        .unwrap()
        .replace(
            r#"{"material": 2, "variants""#,
            r#"{"material": 9, "variants""#,
        );
    std::fs::write(dir.join("c.gltf"), text).unwrap();
    std::fs::write(dir.join("s.toml"), variant_scene("")).unwrap();
    let e = Scene::load(&dir.join("s.toml"), &Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("c.gltf")
            && e.contains("KHR_materials_variants maps material 9; the file has 4"),
        "{e}"
    );
}

#[test]
fn out_of_range_volume_values_warn_naming_the_file_and_the_material() {
    let dir = common::scratch("gltf_volume_bounds");
    let (text, _) = gltf_text(
        &cube(),
        r#", "material": 0"#,
        r#""nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0,
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume"],
        "materials": [{"name": "glass", "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
            "KHR_materials_volume": {"thicknessFactor": -0.5, "attenuationDistance": -2.0}}}]"#,
        None,
    );
    std::fs::write(dir.join("c.gltf"), text).unwrap();
    let s = Scene::load(&dir.join("c.gltf"), &Default::default()).unwrap();
    let all = s.warnings.join("\n");
    for want in [
        "c.gltf: material 0 (\"glass\"): KHR_materials_volume thicknessFactor -0.5 is negative; 0 (thin-walled) is used",
        "c.gltf: material 0 (\"glass\"): KHR_materials_volume attenuationDistance -2 is not positive; the volume does not attenuate",
    ] {
        assert!(all.contains(want), "{all}");
    }
    // Errors under --strict.
    let strict = softraster::scene::LoadOptions {
        strict: true,
        ..Default::default()
    };
    let e = Scene::load(&dir.join("c.gltf"), &strict)
        .unwrap_err()
        .to_string();
    assert!(e.contains("thicknessFactor -0.5 is negative"), "{e}");
}

/// The linear colours across the middle row of a 64x64 frame: a glass
/// ball (radius 0.5, ior 1.5, `volume`: its KHR_materials_volume JSON)
/// 2 in front of a backdrop that glows red left of x = 0 and blue right
/// of it, seen from 4 in front of the ball. No light and no environment
/// (`extra`: more of the scene's TOML): what the ball shows is what it
/// lets through.
fn ball_over_backdrop(name: &str, volume: &str, extra: &str) -> Vec<Vec3> {
    let dir = common::scratch(name);
    let b = softraster::procedural::sphere(0.5, 96, 48);
    let ball = common::Prim {
        positions: b.v.clone(),
        normals: b.vn.clone(),
        indices: b.f.iter().flatten().map(|&i| i as u32 - 1).collect(),
        ..Default::default()
    };
    let (text, _) = gltf_text(
        &ball,
        r#", "material": 0"#,
        &format!(
            r#""nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0,
            "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_dispersion"],
            "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0, "roughnessFactor": 0.0}},
                "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 1.0}}{volume}}}}}]"#
        ),
        None,
    );
    std::fs::write(dir.join("ball.gltf"), text).unwrap();
    let obj = "mtllib b.mtl\nv -3 -3 -2\nv 0 -3 -2\nv 0 3 -2\nv -3 3 -2\nv 3 -3 -2\nv 3 3 -2\n\
               usemtl red\nf 1 2 3\nf 1 3 4\nusemtl blue\nf 2 5 6\nf 2 6 3\n";
    let mtl =
        "newmtl red\nKd 0 0 0\nKs 0 0 0\nKe 1 0 0\nnewmtl blue\nKd 0 0 0\nKs 0 0 0\nKe 0 0 1\n";
    std::fs::write(dir.join("b.obj"), obj).unwrap();
    std::fs::write(dir.join("b.mtl"), mtl).unwrap();
    let scene = "[output]\nwidth = 64\nheight = 64\n[render]\nmsaa = 1\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n\
         [[model]]\npath = \"b.obj\"\n[[model]]\npath = \"ball.gltf\"\n\
         [[camera]]\neye = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 30.0\n";
    std::fs::write(dir.join("s.toml"), format!("{scene}{extra}")).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let f = render_frame(&s, 0, 0);
    (0..64).map(|x| f.color[32 * 64 + x].truncate()).collect()
}

/// `method = "sampled"` in the dark: the ball's refraction is traced
/// through it (`shade::refraction::traced`), what it shows is the
/// backdrop's glow.
const SAMPLED_DARK: &str =
    "[environment]\npreset = \"neutral\"\nintensity = 0.0\nmethod = \"sampled\"\nsamples = 4\n";

#[test]
fn a_glass_ball_refracts_the_backdrop_upside_down_and_a_thin_wall_does_not() {
    // In screen space (the default) and traced (`sampled`).
    for (mode, extra) in [("", ""), ("_sampled", SAMPLED_DARK)] {
        upside_down_through_the_ball(mode, extra);
    }
}

fn upside_down_through_the_ball(mode: &str, extra: &str) {
    // The ball covers x = 32 +- 15 pixels. Left of its centre, a solid
    // ball (thickness = its diameter) is a lens that shows the backdrop's
    // right half, and right of its centre the left half; the backdrop
    // beside it keeps its own colour.
    let solid = ball_over_backdrop(
        &format!("gltf_refraction_ball{mode}"),
        r#", "KHR_materials_volume": {"thicknessFactor": 1.0}"#,
        extra,
    );
    let red = |c: Vec3| c.x > 0.5 && c.z < 0.1;
    let blue = |c: Vec3| c.z > 0.5 && c.x < 0.1;
    assert!(
        red(solid[5]) && blue(solid[58]),
        "{} {}",
        solid[5],
        solid[58]
    );
    for x in [24, 27] {
        assert!(blue(solid[x]), "{mode} solid ball at x = {x}: {}", solid[x]);
    }
    for x in [36, 39] {
        assert!(red(solid[x]), "{mode} solid ball at x = {x}: {}", solid[x]);
    }
    // A thin wall (no volume) lets the backdrop straight through.
    let thin = ball_over_backdrop(&format!("gltf_refraction_thin{mode}"), "", extra);
    for x in [24, 27] {
        assert!(red(thin[x]), "{mode} thin wall at x = {x}: {}", thin[x]);
    }
    for x in [36, 39] {
        assert!(blue(thin[x]), "{mode} thin wall at x = {x}: {}", thin[x]);
    }
}

/// An opaque core inside a solid glass ball (a bulb's filament): a cube
/// glowing green, 0.24 wide, at the ball's centre. Through the ball's
/// middle it shows, in screen space (the default: the opaque frame holds
/// it, and the refracted ray lands on it) and traced (`sampled`: the
/// path meets it inside the volume); around it the ball still turns the
/// backdrop upside down.
#[test]
fn an_opaque_core_inside_a_glass_ball_shows_through_it() {
    for (mode, extra) in [("", ""), ("_sampled", SAMPLED_DARK)] {
        let dir = common::scratch(&format!("gltf_refraction_core_obj{mode}"));
        let obj = softraster::procedural::cube([0.0; 3], 0.12).to_obj("core", "core.mtl", "green");
        std::fs::write(dir.join("core.obj"), obj.text).unwrap();
        std::fs::write(
            dir.join("core.mtl"),
            "newmtl green\nKd 0 0 0\nKs 0 0 0\nKe 0 1 0\n",
        )
        .unwrap();
        let core = format!("{extra}[[model]]\npath = {:?}\n", dir.join("core.obj"));
        let row = ball_over_backdrop(
            &format!("gltf_refraction_core{mode}"),
            r#", "KHR_materials_volume": {"thicknessFactor": 1.0}"#,
            &core,
        );
        let green = |c: Vec3| c.y > 0.5 && c.x < 0.1 && c.z < 0.1;
        for x in [31, 32] {
            assert!(green(row[x]), "{mode} core at x = {x}: {}", row[x]);
        }
        // Beyond the core, the lens as before: the backdrop's right half
        // on the left, its left half on the right.
        assert!(
            row[24].z > 0.5 && row[24].x < 0.1,
            "{mode} x = 24: {}",
            row[24]
        );
        assert!(
            row[39].x > 0.5 && row[39].z < 0.1,
            "{mode} x = 39: {}",
            row[39]
        );
    }
}

/// Writes `dir/file`: a 2x2 plate (z = 0, facing +z; u along +x, v down
/// y) of one material, `material` (JSON members), with extension
/// `ext.0` whose JSON is `ext.1` (none where it is empty).
fn write_plate(dir: &std::path::Path, file: &str, material: &str, ext: (&str, &str)) {
    let plate = common::plate();
    let (name, json) = ext;
    let extension = if json.is_empty() {
        String::new()
    } else {
        format!(r#", "extensions": {{"{name}": {json}}}"#)
    };
    let (text, _) = gltf_text(
        &plate,
        r#", "material": 0"#,
        &format!(
            r#""nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0,
            "extensionsUsed": ["{name}"], "materials": [{{{material}{extension}}}]"#
        ),
        None,
    );
    std::fs::write(dir.join(file), text).unwrap();
}

/// A 2x2 metal plate (z = 0, facing the camera; u along +x, so its
/// tangents run along +x) with `aniso` (JSON of KHR_materials_anisotropy,
/// or empty), seen straight on, lit by a point light 1.5 in front of its
/// centre and nothing else: the spread of its highlight (the second
/// moments of the luminance about the centre, in pixels) along x and y.
fn plate_highlight(name: &str, aniso: &str) -> (f32, f32) {
    let dir = common::scratch(name);
    let material = r#""pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 1.0, "roughnessFactor": 0.3}"#;
    write_plate(
        &dir,
        "plate.gltf",
        material,
        ("KHR_materials_anisotropy", aniso),
    );
    let scene = "[output]\nwidth = 64\nheight = 64\n[render]\nmsaa = 1\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n\
         [[light]]\nkind = \"point\"\nposition = [0.0, 0.0, 1.5]\nintensity = 2.0\n\
         [[model]]\npath = \"plate.gltf\"\n\
         [[camera]]\neye = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 2.0\n";
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    let f = render_frame(&s, 0, 0);
    let (mut sum, mut xx, mut yy) = (0.0f32, 0.0f32, 0.0f32);
    for y in 0..64 {
        for x in 0..64 {
            let l = f.color[y * 64 + x].truncate().dot(Vec3::splat(1.0 / 3.0));
            let (dx, dy) = (x as f32 - 31.5, y as f32 - 31.5);
            sum += l;
            xx += l * dx * dx;
            yy += l * dy * dy;
        }
    }
    assert!(sum > 0.0, "{name}: the plate is black");
    ((xx / sum).sqrt(), (yy / sum).sqrt())
}

#[test]
fn khr_materials_anisotropy_stretches_the_highlight_along_its_direction() {
    // Without the extension (and at strength 0) the highlight is round.
    let (x, y) = plate_highlight("gltf_aniso_none", "");
    assert!((x / y - 1.0).abs() < 0.02, "isotropic: {x} x {y}");
    let zero = plate_highlight("gltf_aniso_zero", r#"{"anisotropyStrength": 0.0}"#);
    assert_eq!(zero, (x, y));
    // Rougher along the tangent (+x): wider along x than along y.
    let (ax, ay) = plate_highlight("gltf_aniso_x", r#"{"anisotropyStrength": 0.8}"#);
    assert!(ax > 1.5 * ay, "along the tangent: {ax} x {ay}");
    assert!((ay / y - 1.0).abs() < 0.25, "across: {ay} against {y}");
    // Turned a quarter turn counter-clockwise: along y instead.
    let (bx, by) = plate_highlight(
        "gltf_aniso_y",
        r#"{"anisotropyStrength": 0.8, "anisotropyRotation": 1.5707964}"#,
    );
    assert!((bx / ay - 1.0).abs() < 0.02, "turned: {bx} x {by}");
    assert!((by / ax - 1.0).abs() < 0.02, "turned: {bx} x {by}");
    // An eighth of a turn: as wide along x as along y, between the two.
    let (cx, cy) = plate_highlight(
        "gltf_aniso_diagonal",
        r#"{"anisotropyStrength": 0.8, "anisotropyRotation": 0.7853982}"#,
    );
    assert!((cx / cy - 1.0).abs() < 0.02, "diagonal: {cx} x {cy}");
    assert!(cx > ay && cx < ax, "diagonal: {cx} x {cy}");
}

/// The centre of a plate (z = 0, facing the camera at +z) with
/// KHR_materials_diffuse_transmission `dt` (JSON, or empty) over a base
/// colour (0.2, 0.5, 0.2), lit only by a directional light of irradiance 1
/// shining along `direction` (`shadows`: whether it casts them, onto a
/// shadow map the plate itself is drawn in).
fn leaf_centre(name: &str, dt: &str, direction: [f32; 3], shadows: bool) -> Vec3 {
    let light = format!(
        "[ambient]\ncolor = [0.0, 0.0, 0.0]\n[[light]]\nkind = \"directional\"\n\
         direction = {direction:?}\nirradiance = 1.0\nshadows = {shadows}\n"
    );
    leaf_lit_by(name, dt, &light)
}

/// `leaf_centre` lit by `light` (TOML: lights, ambient, environment).
fn leaf_lit_by(name: &str, dt: &str, light: &str) -> Vec3 {
    let dir = common::scratch(name);
    let material = r#""doubleSided": true, "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.5, 0.2, 1], "metallicFactor": 0.0, "roughnessFactor": 0.5}"#;
    write_plate(
        &dir,
        "leaf.gltf",
        material,
        ("KHR_materials_diffuse_transmission", dt),
    );
    let scene = format!(
        "[output]\nwidth = 32\nheight = 32\n[render]\nmsaa = 1\nshadows = \"pcf\"\n{light}\
         [[model]]\npath = \"leaf.gltf\"\n\
         [[camera]]\neye = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 2.0\n"
    );
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    let s = Scene::load(&dir.join("s.toml"), &Default::default()).unwrap();
    render_frame(&s, 0, 0).color[16 * 32 + 16].truncate()
}

#[test]
fn khr_materials_diffuse_transmission_lets_light_through_from_behind() {
    let behind = [0.0, 0.0, 1.0];
    // Without the extension a light behind the plate leaves its front dark.
    let opaque = leaf_centre("gltf_dt_none", "", behind, false);
    assert_eq!(opaque, Vec3::ZERO);
    // With it: the colour x the share / pi, times 1 - F (F0 = 0.04 at the
    // mirrored light's half vector, here the view itself).
    let dt =
        r#"{"diffuseTransmissionFactor": 0.6, "diffuseTransmissionColorFactor": [1.0, 0.8, 0.2]}"#;
    let lit = leaf_centre("gltf_dt_behind", dt, behind, false);
    let want = Vec3::new(1.0, 0.8, 0.2) * 0.6 * 0.96 / std::f32::consts::PI;
    assert!(
        (lit - want).abs().max_element() < 1e-4,
        "{lit} against {want}"
    );
    // The plate's own shadow does not hide the light it lets through.
    let shadowed = leaf_centre("gltf_dt_shadows", dt, behind, true);
    assert!(
        (shadowed - lit).abs().max_element() < 1e-4,
        "{shadowed} against {lit}"
    );
    // Lit from the front, the diffuse reflection keeps 1 - 0.6 of itself.
    let front = [0.0, 0.0, -1.0];
    let full = leaf_centre("gltf_dt_front_none", "", front, false);
    let kept = leaf_centre("gltf_dt_front", dt, front, false);
    let base = Vec3::new(0.2, 0.5, 0.2);
    // Both carry the same specular term: the difference is 0.6 of the
    // diffuse lobe, base x 0.96 / pi.
    let lost = full - kept;
    let want = base * 0.6 * 0.96 / std::f32::consts::PI;
    assert!(
        (lost - want).abs().max_element() < 1e-4,
        "{lost} against {want}"
    );
}

#[test]
fn diffuse_transmission_under_an_environment_sampled_agrees_with_prefiltered() {
    // Under uniform light (radiance 1 from every direction) the front
    // shows the base's diffuse reflection plus what the back lets through.
    let dt =
        r#"{"diffuseTransmissionFactor": 0.6, "diffuseTransmissionColorFactor": [1.0, 0.8, 0.2]}"#;
    let env = |method: &str| {
        format!(
            "[ambient]\ncolor = [0.0, 0.0, 0.0]\n[environment]\npreset = \"neutral\"\n\
             method = \"{method}\"\nsamples = 512\n"
        )
    };
    let none = leaf_lit_by("gltf_dt_env_none", "", &env("prefiltered"));
    let pre = leaf_lit_by("gltf_dt_env_prefiltered", dt, &env("prefiltered"));
    let sampled = leaf_lit_by("gltf_dt_env_sampled", dt, &env("sampled"));
    // The transmitted colour's red outweighs the base's lost red.
    assert!(pre.x > none.x + 0.2, "{pre} against {none}");
    assert!(
        (sampled - pre).abs().max_element() < 0.02,
        "sampled {sampled} against prefiltered {pre}"
    );
}

#[test]
fn khr_materials_dispersion_bends_red_and_blue_by_their_own_indices() {
    // Where the ball images the backdrop's red-blue edge, red (a lower
    // index) and blue (a higher one) move each their own way; green keeps
    // the material's index and lands where it did without dispersion.
    let solid = r#", "KHR_materials_volume": {"thicknessFactor": 1.0}"#;
    // (Traced, under `sampled`, the edge on the axis stays on the axis at
    // every index: `shade::refraction` tests the indices both methods
    // take.)
    let plain = ball_over_backdrop("gltf_dispersion_none", solid, "");
    let spread = ball_over_backdrop(
        "gltf_dispersion",
        &format!(r#"{solid}, "KHR_materials_dispersion": {{"dispersion": 6.0}}"#),
        "",
    );
    moved_apart(&plain, &spread, "screen space");
}

/// Red and blue moved between `plain` and `spread`, green did not.
fn moved_apart(plain: &[Vec3], spread: &[Vec3], mode: &str) {
    let most = |channel: fn(&Vec3) -> f32| {
        plain
            .iter()
            .zip(spread)
            .map(|(a, b)| (channel(a) - channel(b)).abs())
            .fold(0.0f32, f32::max)
    };
    assert!(
        most(|c| c.y) < 1e-6,
        "{mode}: green moved by {}",
        most(|c| c.y)
    );
    assert!(
        most(|c| c.x) > 0.05,
        "{mode}: red moved by {}",
        most(|c| c.x)
    );
    assert!(
        most(|c| c.z) > 0.05,
        "{mode}: blue moved by {}",
        most(|c| c.z)
    );
}
