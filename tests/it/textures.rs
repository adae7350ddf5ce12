//! Texturing and materials: filter accuracy against a supersampled
//! reference, normal maps against analytic shading, degenerate UVs,
//! tangent- against object-space maps, cutout and blended opacity.

use crate::common;
use softraster::render::Shot;

use common::render_frame;
use glam::{Vec3, Vec4};
use softraster::output::png;
use softraster::output::{Image8, resolve};
use softraster::render::{Frame, Renderer};

use common::{scene_in, scratch, shared_assets};

/// A unit quad in the xy plane facing +z, u along +x, v (OBJ, up) along +y.
const QUAD: &str = "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl m\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";

fn solid_png(path: &std::path::Path, rgba: [u8; 4]) {
    let img = Image8 {
        width: 8,
        height: 8,
        channels: 4,
        data: rgba.repeat(64),
    };
    png::write(path, &img).unwrap();
}

const TOP_DOWN: &str = "[output]\nwidth = 32\nheight = 32\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n\
[[camera]]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nprojection = \"orthographic\"\nheight = 2.5\n";

#[test]
fn tangent_space_normal_map_on_a_flat_quad_gives_the_analytic_shading() {
    let dir = scratch("flat_normal_map");
    // A normal tilted towards +u and +v (tangent space, OpenGL convention).
    let bytes = [166u8, 153, 242, 255];
    solid_png(&dir.join("nm.png"), bytes);
    let l = Vec3::new(0.6, 0.5, 0.6).normalize();
    let scene = format!(
        "{TOP_DOWN}[render]\ntexture_filter = \"bilinear\"\n\
         [[model]]\npath = \"quad.obj\"\n[[light]]\nkind = \"directional\"\n\
         direction = [{}, {}, {}]\nirradiance = 2.0\n",
        -l.x, -l.y, -l.z
    );
    let s = scene_in(
        &dir,
        &scene,
        &[
            ("quad.obj", QUAD),
            (
                "quad.mtl",
                "newmtl m\nKd 0.5 0.5 0.5\nillum 1\nnorm nm.png\n",
            ),
        ],
    );
    let f = render_frame(&s, 0, 0);
    let d = |b: u8| b as f32 / 255.0 * 2.0 - 1.0;
    // T = +x, B = +y, N = +z for this quad.
    let n = Vec3::new(d(bytes[0]), d(bytes[1]), d(bytes[2])).normalize();
    let expected = 0.5 * 2.0 * n.dot(l).max(0.0);
    for (px, py) in [(16, 16), (8, 20), (24, 10)] {
        let c = f.color[py * 32 + px];
        assert!(
            (c.x - expected).abs() < 1e-3,
            "pixel ({px},{py}): {} expected {expected}",
            c.x
        );
    }
    // And the map really tilts: unperturbed it would be 0.5 * 2 * l.z.
    assert!((expected - l.z).abs() > 0.05);
}

#[test]
fn zero_area_uvs_give_finite_pixels_with_normal_and_bump_maps() {
    let dir = scratch("zero_uv");
    let quad = QUAD.replace("vt 1 0\nvt 1 1\nvt 0 1\n", "vt 0 0\nvt 0 0\nvt 0 0\n");
    solid_png(&dir.join("nm.png"), [128, 128, 255, 255]);
    solid_png(&dir.join("h.png"), [90, 90, 90, 255]);
    let render = |mtl: &str| {
        // One light along the view (the tolerance is for a 0.0039 tilt of
        // the normal under it).
        let light = "[[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, -1.0]\n";
        let scene = format!("{TOP_DOWN}{light}[[model]]\npath = \"quad.obj\"\n");
        let s = scene_in(
            &dir,
            &scene,
            &[
                ("quad.obj", &quad),
                ("quad.mtl", &format!("newmtl m\nKd 0.5 0.5 0.5\n{mtl}\n")),
            ],
        );
        render_frame(&s, 0, 0)
    };
    let plain = render("");
    for map in ["norm nm.png", "map_Bump -bm 4 h.png"] {
        let f = render(map);
        assert!(f.color.iter().all(|c| c.is_finite()), "{map}");
        // A flat map on a flat quad (tangent from the fallback) leaves the
        // shading as it is without the map; 128 encodes 0.0039, not 0.
        let worst = f
            .color
            .iter()
            .zip(&plain.color)
            .map(|(a, b)| (*a - *b).abs().max_element())
            .fold(0.0f32, f32::max);
        assert!(worst < 2e-3, "{map}: differs by {worst}");
        assert!(f.color[16 * 32 + 16].x > 0.4, "{map}: the quad is lit");
    }
}

#[test]
fn cutout_holes_show_what_is_behind_and_blending_composites_in_order() {
    let dir = scratch("opacity");
    // Left half of the texture transparent (a hole), right half opaque white.
    let mut data = Vec::new();
    for _y in 0..8 {
        for x in 0..8 {
            data.extend_from_slice(&if x < 4 { [255, 255, 255, 0] } else { [255; 4] });
        }
    }
    png::write(
        &dir.join("holes.png"),
        &Image8 {
            width: 8,
            height: 8,
            channels: 4,
            data,
        },
    )
    .unwrap();
    let back = QUAD
        .replace("mtllib quad.mtl", "mtllib back.mtl")
        .replace(" 0\nv", " -1\nv")
        .replace("v -1 1 0", "v -1 1 -1")
        .replace("usemtl m", "usemtl red");
    let back_mtl = "newmtl red\nKd 1 0 0\nKe 0 0 0\nillum 0\n";
    let unlit = "[render]\nshading = \"unlit\"\ntexture_filter = \"nearest\"\n";
    // Cutout: a binary alpha channel.
    let s = scene_in(
        &dir,
        &format!(
            "{TOP_DOWN}{unlit}[[model]]\npath = \"quad.obj\"\n[[model]]\npath = \"back.obj\"\n"
        ),
        &[
            ("quad.obj", QUAD),
            ("quad.mtl", "newmtl m\nKd 1 1 1\nmap_Kd holes.png\n"),
            ("back.obj", &back),
            ("back.mtl", back_mtl),
        ],
    );
    assert!(matches!(
        s.models[0].materials[0].alpha,
        softraster::scene::material::AlphaMode::Mask(_)
    ));
    let f = render_frame(&s, 0, 0);
    let left = f.color[16 * 32 + 8];
    let right = f.color[16 * 32 + 24];
    assert!(
        (left - Vec4::new(1.0, 0.0, 0.0, 1.0)).abs().max_element() < 1e-4,
        "{left}"
    );
    assert!((right - Vec4::ONE).abs().max_element() < 1e-4, "{right}");

    // Blend: d 0.25 white over red, and over a transparent background.
    for (bg, expected) in [
        ("[0.0, 0.0, 0.0]", Vec4::new(1.0, 0.25, 0.25, 1.0)),
        ("\"transparent\"", Vec4::new(0.25, 0.25, 0.25, 0.25)),
    ] {
        let models = if bg.contains("transparent") {
            "[[model]]\npath = \"quad.obj\"\n"
        } else {
            "[[model]]\npath = \"quad.obj\"\n[[model]]\npath = \"back.obj\"\n"
        };
        let scene = format!("{TOP_DOWN}{unlit}{models}").replace(
            "height = 32\n",
            &format!("height = 32\nbackground = {bg}\n"),
        );
        let s = scene_in(
            &dir,
            &scene,
            &[
                ("quad.obj", QUAD),
                ("quad.mtl", "newmtl m\nKd 1 1 1\nd 0.25\n"),
                ("back.obj", &back),
                ("back.mtl", back_mtl),
            ],
        );
        let f = render_frame(&s, 0, 0);
        let c = f.color[16 * 32 + 16];
        assert!((c - expected).abs().max_element() < 1e-4, "{bg}: {c}");
        if bg.contains("transparent") {
            let img = resolve(&f, &s.settings);
            assert_eq!(img.channels, 4);
        }
    }
}

#[test]
fn tangent_and_object_space_maps_of_diablo3_agree() {
    let Some(assets) = shared_assets() else {
        return;
    };
    use softraster::assets::texture::Texture;
    use softraster::scene::settings::AddressMode;
    let d3 = assets.join("tinyrenderer/diablo3_pose");
    let scene =
        softraster::scene::Scene::load(&d3.join("diablo3_pose.obj"), &Default::default()).unwrap();
    let mut mesh = (*scene.models[0].mesh).clone();
    mesh.compute_tangents(0);
    let tangent_map = Texture::load(
        &d3.join("diablo3_pose_nm_tangent.tga"),
        false,
        &softraster::assets::input::Input::default(),
    )
    .unwrap();
    let object_map = Texture::load(
        &d3.join("diablo3_pose_nm.tga"),
        false,
        &softraster::assets::input::Input::default(),
    )
    .unwrap();
    let decode = |t: &Texture, uv: glam::Vec2| {
        (t.sample_bilinear(uv, AddressMode::Repeat).truncate() * 2.0 - Vec3::ONE).normalize()
    };
    // At each triangle's centroid: the tangent-space map taken to object
    // space through the MikkTSpace frame, against the object-space map.
    // Triangles are grouped by bitangent sign: the model's mirrored halves
    // (arms, tail) share texels, and an object-space map, one normal per
    // texel, can only hold the normals of the half it was baked for.
    let mut by_sign: [Vec<f32>; 2] = [Vec::new(), Vec::new()];
    for (i, tri) in mesh.triangles.iter().enumerate() {
        let k = tri.map(|v| v as usize);
        let uv = (mesh.uvs[k[0]] + mesh.uvs[k[1]] + mesh.uvs[k[2]]) / 3.0;
        let n = (mesh.normals[k[0]] + mesh.normals[k[1]] + mesh.normals[k[2]]).normalize();
        let t4 = mesh.tangents[i * 3];
        let t =
            (mesh.tangents[i * 3] + mesh.tangents[i * 3 + 1] + mesh.tangents[i * 3 + 2]).truncate();
        let t = (t - n * n.dot(t)).normalize();
        let b = n.cross(t) * t4.w;
        let c = decode(&tangent_map, uv);
        let from_tangent = (t * c.x + b * c.y + n * c.z).normalize();
        let from_object = decode(&object_map, uv);
        let angle = from_tangent
            .dot(from_object)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        by_sign[(t4.w > 0.0) as usize].push(angle);
    }
    let median = |v: &mut Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    let (neg, pos) = (by_sign[0].len(), by_sign[1].len());
    let (m_neg, m_pos) = (median(&mut by_sign[0]), median(&mut by_sign[1]));
    println!(
        "bitangent sign -1: {neg} triangles, median {m_neg:.1} deg; +1: {pos} triangles, median {m_pos:.1} deg"
    );
    let (baked, other) = if m_neg < m_pos {
        (m_neg, m_pos)
    } else {
        (m_pos, m_neg)
    };
    assert!(
        baked < 4.0,
        "the maps disagree on the half the object map was baked for: {baked}"
    );
    assert!(
        other > 2.0 * baked,
        "the mirrored half should disagree: {other} vs {baked}"
    );
}

#[test]
fn mip_chains_are_built_only_for_minified_textures() {
    let dir = scratch("mips_on_demand");
    for (size, minified) in [(8u32, false), (256, true)] {
        let img = Image8 {
            width: size,
            height: size,
            channels: 4,
            data: [200u8, 100, 50, 255].repeat((size * size) as usize),
        };
        png::write(&dir.join("t.png"), &img).unwrap();
        let s = scene_in(
            &dir,
            &format!("{TOP_DOWN}[[model]]\npath = \"quad.obj\"\n"),
            &[
                ("quad.obj", QUAD),
                ("quad.mtl", "newmtl m\nKd 1 1 1\nmap_Kd t.png\n"),
            ],
        );
        let renderer = Renderer::new(&s);
        assert!(!s.textures[0].has_mip_chain());
        renderer
            .render(Shot::new(0, 0), &mut Frame::new(0, 0))
            .unwrap();
        assert_eq!(
            s.textures[0].has_mip_chain(),
            minified,
            "{size}x{size} on 32x32"
        );
    }
}

/// The renderer keeps BVHs, shadow maps and the environment across
/// frames, and the textures keep their mip chains: a frame must not
/// depend on which frames were rendered before.
#[test]
fn render_state_carried_across_frames_changes_no_pixel() {
    use softraster::render::Shot;
    use softraster::scene::{LoadOptions, Scene};
    let root = common::root();
    let sets = [
        "output.width=96",
        "output.height=72",
        "render.msaa=1",
        "light.0.shadows=true",
        "render.ao={method=\"raytraced\",samples=4}",
        "render.texture_filter=\"anisotropic\"",
    ];
    let opts = LoadOptions {
        sets: sets.iter().map(|s| s.parse().unwrap()).collect(),
        ..Default::default()
    };
    let load = || Scene::load(&root.join("scenes/showcase.toml"), &opts).unwrap();
    let frame = |r: &Renderer, f: u32| {
        let mut out = Frame::new(0, 0);
        r.render(Shot::new(0, f), &mut out).unwrap();
        out
    };
    let scene = load();
    let warm = Renderer::new(&scene);
    for f in 0..3 {
        frame(&warm, f);
    }
    // The frames minified some texture: a chain is carried over.
    assert!(scene.textures.iter().any(|t| t.has_mip_chain()));
    let after = frame(&warm, 5);
    // A new renderer of the same scene (its textures keep their chains),
    // and one of the scene loaded again (nothing built yet).
    let again = frame(&Renderer::new(&scene), 5);
    let other = load();
    assert!(!other.textures.iter().any(|t| t.has_mip_chain()));
    let fresh = frame(&Renderer::new(&other), 5);
    for f in [&again, &fresh] {
        assert_eq!(after.color, f.color);
        assert_eq!(after.depth, f.depth);
        assert_eq!(after.ao, f.ao);
    }
}

/// A camera the scene does not have is an error naming it, not a panic.
#[test]
fn a_camera_out_of_range_is_an_error() {
    use softraster::render::Shot;
    let dir = scratch("camera_out_of_range");
    let s = scene_in(
        &dir,
        &format!("{TOP_DOWN}[[model]]\npath = \"quad.obj\"\n"),
        &[("quad.obj", QUAD), ("quad.mtl", "newmtl m\nKd 1 1 1\n")],
    );
    let e = Renderer::new(&s)
        .render(Shot::new(3, 0), &mut Frame::new(0, 0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("camera 3") && e.contains("1 camera"), "{e}");
}

/// The centre of a square facing +Z with MTL `mtl`, seen head-on under the
/// neutral environment (radiance 1), shaded `shading`; `files` are written
/// beside it (maps).
fn mtl_square(name: &str, mtl: &str, shading: &str, files: &[(&str, Vec<u8>)]) -> glam::Vec3 {
    let dir = common::scratch(name);
    for (n, bytes) in files {
        std::fs::write(dir.join(n), bytes).unwrap();
    }
    let obj = "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl m\n\
               f 1/1/1 2/2/1 3/3/1 4/4/1\n";
    let scene = format!(
        "[output]\nwidth = 16\nheight = 16\n[render]\nshading = \"{shading}\"\n\
         [environment]\npreset = \"neutral\"\n[[model]]\npath = \"sq.obj\"\n\
         [[camera]]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n\
         projection = \"orthographic\"\nheight = 1.0\n"
    );
    let s = common::scene_in(&dir, &scene, &[("sq.obj", obj), ("m.mtl", mtl)]);
    common::render_frame(&s, 0, 0).color[8 * 16 + 8].truncate()
}

/// A 2x2 grey PNG of value `v`.
fn grey_png(v: u8) -> Vec<u8> {
    let img = image::GrayImage::from_pixel(2, 2, image::Luma([v]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

#[test]
fn mtl_pbr_extension_pr_pm_their_maps_and_clearcoat() {
    let kd = "newmtl m\nKd 0.2 0.4 0.6\nKs 0.5 0.5 0.5\nNs 200\n";
    // Pr/Pm make the material metallic-roughness: `auto` shades it as pbr.
    let pbr_mtl = format!("{kd}Pr 0.8\nPm 0\n");
    let auto = mtl_square("mtl_pbr_auto", &pbr_mtl, "auto", &[]);
    let pbr = mtl_square("mtl_pbr_pbr", &pbr_mtl, "pbr", &[]);
    let phong = mtl_square("mtl_pbr_phong", &pbr_mtl, "blinn-phong", &[]);
    assert_eq!(auto, pbr);
    assert!((auto - phong).abs().max_element() > 0.02, "{auto} {phong}");
    // Without them it stays Blinn-Phong.
    let plain_auto = mtl_square("mtl_plain_auto", kd, "auto", &[]);
    let plain_phong = mtl_square("mtl_plain_phong", kd, "blinn-phong", &[]);
    assert_eq!(plain_auto, plain_phong);
    // A rough dielectric in a uniform environment: the base colour plus a
    // little specular; a metal of the same colour has no diffuse part.
    let metal = mtl_square("mtl_pbr_metal", &format!("{kd}Pr 0.8\nPm 1\n"), "auto", &[]);
    assert!(
        (auto - glam::Vec3::new(0.2, 0.4, 0.6)).abs().max_element() < 0.06,
        "{auto}"
    );
    assert!((metal - auto).abs().max_element() > 0.05, "{metal} {auto}");
    // map_Pm and map_Pr multiply the factors (red channel, linear): a
    // black metallic map makes Pm 1 a dielectric, a white roughness map
    // leaves Pr as it is.
    let maps = [("black.png", grey_png(0)), ("white.png", grey_png(255))];
    let mapped = mtl_square(
        "mtl_pbr_maps",
        &format!("{kd}Pr 0.8\nPm 1\nmap_Pm black.png\nmap_Pr white.png\n"),
        "auto",
        &maps,
    );
    assert!(
        (mapped - auto).abs().max_element() < 1e-5,
        "{mapped} {auto}"
    );
    // Pc/Pcr: a smooth clearcoat seen head-on reflects 0.04 and takes that
    // share from the layer below.
    let coated = mtl_square(
        "mtl_pbr_coat",
        &format!("{kd}Pr 0.8\nPm 0\nPc 1\nPcr 0\n"),
        "auto",
        &[],
    );
    let expect = auto * 0.96 + glam::Vec3::splat(0.04);
    assert!(
        (coated - expect).abs().max_element() < 4e-3,
        "{coated} vs {expect}"
    );
}
