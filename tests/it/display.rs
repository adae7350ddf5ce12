//! `Renderer::render_display` (display bytes made band by band, as each
//! band is shaded) gives the bytes of `resolve` of the rendered frame, and
//! the same frame as `render`, under every path that changes how or when
//! the bytes are made: AO's second pass, MSAA, supersampling's filter, a
//! transparent background (RGBA), tone maps and exposure, a data view, the
//! line overlay drawn after the bands, and an image reused across sizes.

use crate::common;
use softraster::render::Shot;

use common::{load_with, scene_in, scratch};
use softraster::output::{Image8, resolve};
use softraster::render::{Frame, Renderer};
use softraster::scene::Scene;

/// Frames `frames` of camera 0, both ways, into one image kept across
/// them (as the benchmark keeps it).
fn same_bytes(scene: &Scene, frames: &[u32], image: &mut Image8, what: &str) {
    let r = Renderer::new(scene);
    for &f in frames {
        let (mut a, mut b) = (Frame::new(0, 0), Frame::new(0, 0));
        r.render(Shot::new(0, f), &mut a).unwrap();
        r.render_display(Shot::new(0, f), &mut b, image).unwrap();
        let bits = |fr: &Frame| -> Vec<u32> {
            fr.color
                .iter()
                .flat_map(|c| c.to_array().map(f32::to_bits))
                .chain(fr.depth.iter().map(|d| d.to_bits()))
                .collect()
        };
        assert!(bits(&a) == bits(&b), "{what}, frame {f}: frames differ");
        let want = resolve(&a, &scene.settings);
        assert_eq!(
            (image.width, image.height, image.channels),
            (want.width, want.height, want.channels),
            "{what}, frame {f}"
        );
        if let Some(i) = (0..want.data.len()).find(|&i| image.data[i] != want.data[i]) {
            let px = i / want.channels as usize;
            panic!(
                "{what}, frame {f}: pixel {} {} channel {}: {} against resolve's {}",
                px % want.width as usize,
                px / want.width as usize,
                i % want.channels as usize,
                image.data[i],
                want.data[i]
            );
        }
        // Not a comparison of two blank images.
        let first = &want.data[..want.channels as usize];
        assert!(
            want.data.chunks(want.channels as usize).any(|p| p != first),
            "{what}: a uniform image"
        );
    }
}

#[test]
fn band_by_band_bytes_equal_the_resolve_of_the_frame() {
    let showcase = common::root().join("scenes/showcase.toml");
    let small = ["output.width=96", "output.height=72", "animation.frames=8"];
    let cases: &[(&str, &[&str])] = &[
        ("showcase (AO, MSAA 4, ACES)", &[]),
        (
            "no AO, no MSAA",
            &["render.ao.method=\"off\"", "render.msaa=1"],
        ),
        ("supersampled", &["render.ssaa=2", "render.msaa=1"]),
        (
            "clamp, exposure +1, flat grey",
            &[
                "render.tonemap=\"clamp\"",
                "render.exposure=1.0",
                "output.background=[0.2, 0.3, 0.4]",
                "render.ao.method=\"off\"",
            ],
        ),
        ("agx", &["render.tonemap=\"agx\"", "render.msaa=1"]),
        (
            "aces-hill",
            &["render.tonemap=\"aces-hill\"", "render.msaa=1"],
        ),
        ("normals view", &["render.shading=\"normals\""]),
        ("wide", &["output.width=131", "output.height=37"]),
    ];
    let mut image = Image8::empty();
    for (what, sets) in cases {
        let all: Vec<&str> = small.iter().chain(sets.iter()).copied().collect();
        let scene = load_with(&showcase, &all);
        same_bytes(&scene, &[0, 3], &mut image, what);
    }
}

#[test]
fn a_shots_exposure_scales_the_display_and_not_the_linear_frame() {
    let showcase = common::root().join("scenes/showcase.toml");
    let sets = [
        "output.width=64",
        "output.height=48",
        "render.tonemap=\"clamp\"",
        "render.exposure=0.5",
        "render.ao.method=\"off\"",
    ];
    let scene = load_with(&showcase, &sets);
    let r = Renderer::new(&scene);
    assert_eq!(r.exposure(), 0.5);
    let (mut scene_own, mut brighter) = (Frame::new(0, 0), Frame::new(0, 0));
    let (mut a, mut b) = (Image8::empty(), Image8::empty());
    r.render_display(Shot::new(0, 0), &mut scene_own, &mut a)
        .unwrap();
    let shot = Shot::new(0, 0).with_exposure(1.5);
    r.render_display(shot, &mut brighter, &mut b).unwrap();
    assert_eq!((scene_own.exposure, brighter.exposure), (0.5, 1.5));
    // The same linear frame; the bytes of each are its own exposure's.
    assert!(scene_own.color == brighter.color);
    assert!(a.data == resolve(&scene_own, &scene.settings).data);
    assert!(b.data == resolve(&brighter, &scene.settings).data);
    // One stop more doubles the radiance before the clamp: a pixel well
    // inside the range doubles its linear value.
    let lin = |v: u8| {
        let c = v as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let mid = (0..a.data.len())
        .find(|&i| (40..100).contains(&a.data[i]))
        .expect("a mid-grey channel");
    let ratio = lin(b.data[mid]) / lin(a.data[mid]);
    assert!((ratio - 2.0).abs() < 0.1, "{ratio}");
}

#[test]
fn a_transparent_background_gives_the_same_rgba() {
    let dir = scratch("display-transparent");
    let assets = common::root().join("assets/showcase");
    let a = assets.display().to_string().replace('\\', "/");
    let toml = format!(
        "[output]\nwidth = 90\nheight = 70\nbackground = \"transparent\"\n\
         [render]\nmsaa = 4\ntonemap = \"pbr-neutral\"\n\
         [animation]\nframes = 8\nturntable = {{ axis = [0.0, 1.0, 0.0], degrees = 360 }}\n\
         [[model]]\npath = \"{a}/sphere.obj\"\n\
         [[model]]\npath = \"{a}/torus.obj\"\ntranslate = [1.1, 0.2, 0.0]\n\
         [[light]]\nkind = \"directional\"\ndirection = [-0.4, -1.0, -0.6]\nirradiance = 1.3\n"
    );
    let scene = scene_in(&dir, &toml, &[]);
    let mut image = Image8::empty();
    same_bytes(&scene, &[0, 5], &mut image, "transparent, MSAA 4");
    assert_eq!(image.channels, 4);
    // Partly covered edge pixels: alpha strictly between 0 and 255.
    assert!(image.data.chunks(4).any(|p| p[3] > 0 && p[3] < 255));
}

/// A grey quad of side 4 seen from `eye_z` on +Z, under a white line 3
/// pixels wide from x = -3 to 3 at height `line_y` in front of it (and a
/// point) where `line`.
fn line_scene(name: &str, line_y: f32, eye_z: f32, line: bool) -> Scene {
    let dir = scratch(name);
    let lines = if line { "l 5 6\np 1\n" } else { "" };
    let obj = format!(
        "mtllib m.mtl\nv -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nusemtl grey\nf 1 2 3 4\n\
         usemtl white\nv -3 {line_y} 0.5\nv 3 {line_y} 0.5\n{lines}"
    );
    let mtl = "newmtl grey\nKd 0.3 0.3 0.3\nnewmtl white\nKd 1 1 1\n";
    let toml = format!(
        "[output]\nwidth = 64\nheight = 48\nbackground = [0.0, 0.0, 0.0]\n\
         [render]\nline_width = 3.0\n\
         [[model]]\npath = \"m.obj\"\n\
         [[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, -1.0]\nirradiance = 1.0\n\
         [[camera]]\neye = [0.0, 0.0, {eye_z}]\ntarget = [0.0, 0.0, 0.0]\n"
    );
    scene_in(&dir, &toml, &[("m.obj", &obj), ("m.mtl", mtl)])
}

#[test]
fn lines_drawn_after_the_bands_are_in_the_bytes() {
    let scene = line_scene("display-lines", 0.1, 5.0, true);
    let mut image = Image8::empty();
    same_bytes(&scene, &[0], &mut image, "a line over a quad");
    // The line is in the bytes: its row is brighter than the quad's.
    let w = image.width as usize;
    let row_sum = |y: usize| -> u32 { (0..w).map(|x| image.data[(y * w + x) * 3] as u32).sum() };
    let brightest = (0..image.height as usize)
        .max_by_key(|&y| row_sum(y))
        .unwrap();
    assert!(
        row_sum(brightest) > row_sum(5) + 100,
        "no line in the image"
    );
}

/// Frames rendered one after another into one `FrameSequence` (which
/// skips filling what the last frame left as background) equal frames
/// rendered fresh, bit for bit and byte for byte, while the turntable
/// moves the silhouette, the size, background colour, MSAA and AO change
/// between frames, and lines are drawn over the bands.
#[test]
fn a_sequence_of_frames_equals_fresh_frames() {
    use softraster::render::FrameSequence;
    let showcase = common::root().join("scenes/showcase.toml");
    let flat = [
        "output.width=96",
        "output.height=72",
        "animation.frames=8",
        "output.background=[0.2, 0.3, 0.4]",
        "render.ao.method=\"off\"",
        "render.msaa=1",
    ];
    let variants: &[&[&str]] = &[
        &[],
        &["output.background=[0.5, 0.1, 0.1]"],
        &["render.msaa=4"],
        &["output.width=80", "output.height=90"],
        &["render.ao.method=\"ssao\""],
        &["output.background=\"blurred\""],
        &[],
    ];
    let mut seq = FrameSequence::new();
    let mut image = Image8::empty();
    let same = |scene: &Scene, seq: &mut FrameSequence, image: &mut Image8, f: u32, what: &str| {
        let r = Renderer::new(scene);
        r.render_next(Shot::new(0, f), seq, Some(image)).unwrap();
        let mut fresh = Frame::new(0, 0);
        let mut want = Image8::empty();
        r.render_display(Shot::new(0, f), &mut fresh, &mut want)
            .unwrap();
        let got = seq.frame();
        assert_eq!(got.color.len(), fresh.color.len(), "{what}");
        for (i, (a, b)) in got.color.iter().zip(&fresh.color).enumerate() {
            assert!(
                a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits)
                    && got.depth[i].to_bits() == fresh.depth[i].to_bits(),
                "{what}, frame {f}, pixel {} {}: {a} depth {} against {b} depth {}",
                i as u32 % got.width,
                i as u32 / got.width,
                got.depth[i],
                fresh.depth[i]
            );
        }
        assert!(*image == want, "{what}, frame {f}: display bytes differ");
    };
    for (v, sets) in variants.iter().enumerate() {
        let all: Vec<&str> = flat.iter().chain(sets.iter()).copied().collect();
        let scene = load_with(&showcase, &all);
        for f in [0, 3, 5, 1] {
            same(
                &scene,
                &mut seq,
                &mut image,
                f,
                &format!("variant {v} {sets:?}"),
            );
        }
    }
    // Lines over the bands (wider than the quad under them), then frames
    // without them into the same buffer.
    let lines = line_scene("display-sequence-lines", 2.5, 9.0, true);
    let no_lines = line_scene("display-sequence-nolines", 2.5, 9.0, false);
    for (k, scene) in [&no_lines, &lines, &no_lines, &lines, &no_lines]
        .iter()
        .enumerate()
    {
        same(scene, &mut seq, &mut image, 0, &format!("lines, step {k}"));
    }
}
