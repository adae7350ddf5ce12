//! `output.video` and `softraster video`: the MP4 read back with an
//! independent reader (the `mp4` crate), its H.264 decoded with OpenH264,
//! every frame compared with the PNG the same render wrote.

use crate::common;

use std::path::{Path, PathBuf};

use crate::binary::run;
use softraster::output::video::yuv420_to_rgb;

/// The showcase at an odd size (the 4:2:0 stream pads it), 12 frames.
fn write_scene(dir: &Path, extra: &str) -> PathBuf {
    let root = common::root();
    let text = std::fs::read_to_string(root.join("scenes/showcase.toml"))
        .unwrap()
        .replace("../assets/", &format!("{}/assets/", root.display()))
        .replace("video = \"showcase.mp4\"", "")
        .replace("width = 640", "width = 641")
        .replace("height = 480", "height = 481")
        .replace("frames = 48", "frames = 12");
    let text = text.replace("gif_delay_ms = 60", &format!("gif_delay_ms = 60\n{extra}"));
    let p = dir.join("turntable.toml");
    std::fs::write(&p, text).unwrap();
    p
}

struct Decoded {
    width: u32,
    height: u32,
    /// Per sample: start time and duration in the track's timescale.
    times: Vec<(u64, u32)>,
    timescale: u32,
    /// RGB frames, the stream's size.
    frames: Vec<Vec<u8>>,
    key_frames: usize,
}

/// Reads the MP4's one video track and decodes every sample.
fn decode(path: &Path) -> Decoded {
    let bytes = std::fs::read(path).unwrap();
    // Fast start: the index (moov) comes before the media data (mdat).
    let moov = bytes.windows(4).position(|w| w == b"moov").unwrap();
    let mdat = bytes.windows(4).position(|w| w == b"mdat").unwrap();
    assert!(moov < mdat, "the index is not first");
    let size = bytes.len() as u64;
    let mut r = mp4::Mp4Reader::read_header(std::io::Cursor::new(bytes), size).unwrap();
    assert_eq!(r.tracks().len(), 1);
    let track = r.tracks().values().next().unwrap();
    assert_eq!(track.media_type().unwrap(), mp4::MediaType::H264);
    let id = track.track_id();
    let (width, height) = (track.width() as u32, track.height() as u32);
    let timescale = track.timescale();
    let start_code = [0u8, 0, 0, 1];
    let mut header = Vec::new();
    for ps in [
        track.sequence_parameter_set().unwrap(),
        track.picture_parameter_set().unwrap(),
    ] {
        header.extend_from_slice(&start_code);
        header.extend_from_slice(ps);
    }
    let n = r.sample_count(id).unwrap();
    let mut decoder = openh264::decoder::Decoder::new().unwrap();
    let (mut times, mut frames, mut key_frames) = (Vec::new(), Vec::new(), 0);
    for i in 1..=n {
        let s = r.read_sample(id, i).unwrap().unwrap();
        times.push((s.start_time, s.duration));
        key_frames += s.is_sync as usize;
        // Length-prefixed NAL units to Annex B.
        let mut annexb = if i == 1 { header.clone() } else { Vec::new() };
        let mut rest = &s.bytes[..];
        while rest.len() >= 4 {
            let len = u32::from_be_bytes([rest[0], rest[1], rest[2], rest[3]]) as usize;
            annexb.extend_from_slice(&start_code);
            annexb.extend_from_slice(&rest[4..4 + len]);
            rest = &rest[4 + len..];
        }
        let yuv = decoder
            .decode(&annexb)
            .unwrap()
            .expect("one picture per sample");
        use openh264::formats::YUVSource;
        let (w, h) = yuv.dimensions();
        assert_eq!((w as u32, h as u32), (width, height));
        frames.push(yuv420_to_rgb(
            (yuv.y(), yuv.u(), yuv.v()),
            yuv.strides(),
            w,
            h,
        ));
    }
    Decoded {
        width,
        height,
        times,
        timescale,
        frames,
        key_frames,
    }
}

/// PSNR of `png` against the decoded frame's top-left corner.
fn psnr(png: &Path, decoded: &[u8], stream_width: u32) -> f64 {
    let img = image::open(png).unwrap().to_rgb8();
    let mut se = 0.0f64;
    for (x, y, p) in img.enumerate_pixels() {
        let i = ((y * stream_width + x) * 3) as usize;
        for k in 0..3 {
            let d = p[k] as f64 - decoded[i + k] as f64;
            se += d * d;
        }
    }
    let mse = se / (img.width() * img.height() * 3) as f64;
    10.0 * (255.0f64 * 255.0 / mse.max(1e-12)).log10()
}

#[test]
fn the_scene_video_decodes_to_its_frames_at_its_rate() {
    let dir = common::scratch("video_scene");
    let scene = write_scene(&dir, "video = \"spin.mp4\"\nvideo_fps = 12");
    let out = dir.join("out");
    let (code, _, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("video: "), "{err}");
    let d = decode(&out.join("spin.mp4"));
    // 641x481 padded to even, declared as what the stream holds.
    assert_eq!((d.width, d.height), (642, 482));
    assert_eq!(d.frames.len(), 12);
    // Constant frame rate: every sample lasts 1/12 s and starts where the
    // previous one ended.
    let step = d.timescale / 12;
    assert_eq!(step * 12, d.timescale);
    for (i, &(start, dur)) in d.times.iter().enumerate() {
        assert_eq!((start, dur), (i as u64 * step as u64, step), "sample {i}");
    }
    // A key frame every two seconds: frame 0 only in one second.
    assert_eq!(d.key_frames, 1);
    let mut worst = f64::INFINITY;
    for (i, f) in d.frames.iter().enumerate() {
        let p = psnr(&out.join(format!("front_{i:04}.png")), f, d.width);
        worst = worst.min(p);
    }
    println!("worst frame PSNR against its PNG: {worst:.2} dB");
    assert!(worst >= 35.0, "worst frame PSNR {worst:.2} dB");
    // The padding repeats the last column and row.
    let last = &d.frames[0];
    let at = |x: u32, y: u32| {
        let i = ((y * d.width + x) * 3) as usize;
        [last[i], last[i + 1], last[i + 2]]
    };
    for y in 0..481 {
        let (a, b) = (at(640, y), at(641, y));
        for k in 0..3 {
            assert!(
                (a[k] as i32 - b[k] as i32).abs() <= 12,
                "row {y}: {a:?} {b:?}"
            );
        }
    }

    // `softraster video` on the same PNGs with the same settings writes the
    // same bytes: the render streams into the same encoder.
    let frames: Vec<String> = (0..12)
        .map(|i| out.join(format!("front_{i:04}.png")).display().to_string())
        .collect();
    let assembled = dir.join("assembled.mp4");
    let mut args = vec!["video", "-o", assembled.to_str().unwrap(), "--fps", "12"];
    args.extend(frames.iter().map(|s| s.as_str()));
    let (code, _, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    assert!(
        std::fs::read(&assembled).unwrap() == std::fs::read(out.join("spin.mp4")).unwrap(),
        "softraster video and the render's video differ"
    );

    // A lower quality makes a smaller file that still decodes; a bitrate
    // is a quality too.
    let small = dir.join("small.mp4");
    let mut args = vec![
        "video",
        "-o",
        small.to_str().unwrap(),
        "--fps",
        "12",
        "--quality",
        "20",
    ];
    args.extend(frames.iter().map(|s| s.as_str()));
    let (code, _, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    let (a, b) = (
        std::fs::metadata(&small).unwrap().len(),
        std::fs::metadata(&assembled).unwrap().len(),
    );
    assert!(a < b, "quality 20: {a} bytes, quality 75: {b} bytes");
    assert_eq!(decode(&small).frames.len(), 12);
}

#[test]
fn video_rate_defaults_follow_the_animation_then_the_gif() {
    let dir = common::scratch("video_rate");
    // No video_fps: animation.fps wins; without it, 1000 / gif_delay_ms.
    for (animation_fps, want) in [(Some(30.0), 30.0), (None, 1000.0 / 60.0)] {
        let scene = write_scene(&dir, "video = \"v.mp4\"");
        // No GIF: it would need the colour PNGs this render leaves out.
        let mut text = std::fs::read_to_string(&scene)
            .unwrap()
            .replace("gif = \"showcase.gif\"", "");
        if let Some(f) = animation_fps {
            text = text.replace("[animation]\n", &format!("[animation]\nfps = {f:.1}\n"));
        }
        std::fs::write(&scene, text).unwrap();
        let out = dir.join(format!("out{want:.0}"));
        let (code, _, err) = run(&[
            "render",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
            "--set",
            "animation.frames=3",
            "--set",
            "output.color=false",
        ]);
        assert_eq!(code, 0, "{err}");
        let d = decode(&out.join("v.mp4"));
        assert_eq!(d.frames.len(), 3);
        let rate = d.timescale as f64 / d.times[1].1 as f64;
        assert!((rate - want).abs() < 0.01, "{animation_fps:?}: {rate} fps");
        // Colour PNGs off: the video still has the frames.
        assert!(!out.join("front_0000.png").exists());
    }
}

#[test]
fn bad_video_settings_name_the_key() {
    let dir = common::scratch("video_bad");
    for (extra, want) in [
        (
            "video = \"spin.avi\"",
            "expected a file name ending in .mp4",
        ),
        (
            "video = \"spin.mp4\"\nvideo_quality = 0",
            "output.video_quality = 0",
        ),
        (
            "video = \"spin.mp4\"\nvideo_quality = \"fast\"",
            "output.video_quality = \"fast\"",
        ),
        ("video = \"spin.mp4\"\nvideo_fps = 0.0", "output.video_fps"),
    ] {
        let scene = write_scene(&dir, extra);
        let (code, _, err) = run(&["render", scene.to_str().unwrap(), "--quiet"]);
        assert_eq!(code, 2, "{extra}: {err}");
        assert!(err.contains(want), "{extra}: {err}");
        // file:line:column
        assert!(err.contains("turntable.toml:"), "{err}");
    }
    // A transparent background cannot go into H.264.
    let scene = write_scene(&dir, "video = \"spin.mp4\"");
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("background = \"blurred\"", "background = \"transparent\"");
    std::fs::write(&scene, text).unwrap();
    let (code, _, err) = run(&["render", scene.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("transparent") && err.contains("turntable.toml:"),
        "{err}"
    );
    // A partial run writes no video and says why.
    let scene = write_scene(&dir, "video = \"spin.mp4\"");
    let out = dir.join("partial");
    let (code, _, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--frames",
        "0..2",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("output.video not written"), "{err}");
    assert!(!out.join("spin.mp4").exists());
    // The command refuses other extensions.
    let (code, _, err) = run(&["video", "-o", "x.webm", "a.png"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(".mp4"), "{err}");
}
