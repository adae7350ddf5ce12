//! Hostile inputs, one case per class: unbounded reads, hangs, tiny files
//! that claim huge sizes, writes outside the output folder, the default
//! memory budget, late exits, messages, and the sandbox. Every case runs
//! the binary under an address-space limit (`setrlimit`) and a timeout,
//! and checks the exit code, the message, and that nothing was written
//! outside the case's output folder. Inputs are made here: FIFOs, links
//! to `/dev/zero`, files whose headers lie.
#![cfg(target_os = "linux")]
//!
//! A test binary of its own, apart from `tests/it`: a child's peak memory
//! (`ru_maxrss`) starts at its parent's resident size when it is spawned
//! (Linux carries the old address space's high-water mark across `exec`),
//! so the parent must stay small. In the shared binary the other areas'
//! frames, rendered on other threads, raised every child's peak above
//! the 128 MiB these checks allow.

#[path = "../../tests/it/common/mod.rs"]
mod common;

// This binary uses only `BIN`, not `run`.
#[allow(dead_code)]
#[path = "it/binary.rs"]
mod binary;

use std::io::Read;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The address-space limit every case runs under.
const LIMIT: u64 = 3 << 30;
/// The longest a case may take: a hang fails the test instead of it.
const TIMEOUT: Duration = Duration::from_secs(60);

struct Outcome {
    code: i32,
    err: String,
    /// Peak resident memory, KiB.
    peak_kib: i64,
    seconds: f64,
}

impl Outcome {
    /// Exit status `code`, and a message with every one of `words`.
    fn expect(&self, code: i32, words: &[&str]) {
        assert_eq!(self.code, code, "{}", self.err);
        for w in words {
            assert!(self.err.contains(w), "no `{w}` in: {}", self.err);
        }
    }
}

/// Runs the binary in `cwd` under `LIMIT` and `TIMEOUT`. The child is
/// reaped by `wait4` (which also gives its peak memory), which clippy
/// cannot see.
#[allow(clippy::zombie_processes)]
fn run_in(cwd: &Path, args: &[&str]) -> Outcome {
    let t0 = Instant::now();
    let mut cmd = std::process::Command::new(crate::binary::BIN);
    cmd.args(args)
        .current_dir(cwd)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped());
    // SAFETY: setrlimit is async-signal-safe; the closure touches nothing
    // else of the parent.
    unsafe {
        cmd.pre_exec(|| {
            let r = libc::rlimit {
                rlim_cur: LIMIT,
                rlim_max: LIMIT,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &r) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let mut child = cmd.spawn().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let pid = child.id() as libc::pid_t;
    let (mut status, mut usage): (libc::c_int, libc::rusage) = (0, unsafe { std::mem::zeroed() });
    loop {
        // SAFETY: wait4 on our own child, with valid out-pointers.
        let r = unsafe { libc::wait4(pid, &mut status, libc::WNOHANG, &mut usage) };
        if r == pid {
            break;
        }
        if t0.elapsed() > TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            panic!("softraster {args:?} hung: killed after {TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let code = if libc::WIFEXITED(status) {
        libc::WEXITSTATUS(status)
    } else {
        128 + libc::WTERMSIG(status)
    };
    Outcome {
        code,
        err: reader.join().unwrap(),
        peak_kib: usage.ru_maxrss,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// A case's folder: `case/` holds the inputs, `case/out/` the output;
/// `outside()` lists what is beside `case/` (nothing may appear there).
struct Case {
    root: PathBuf,
    dir: PathBuf,
}

impl Case {
    fn new(name: &str) -> Case {
        let root = common::scratch(&format!("hostile-{name}"));
        let dir = root.join("case");
        std::fs::create_dir_all(&dir).unwrap();
        Case { root, dir }
    }

    fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }

    fn fifo(&self, name: &str) {
        let p = std::ffi::CString::new(self.dir.join(name).to_str().unwrap()).unwrap();
        // SAFETY: a valid C string.
        assert_eq!(unsafe { libc::mkfifo(p.as_ptr(), 0o644) }, 0);
    }

    fn link(&self, name: &str, to: &str) {
        std::os::unix::fs::symlink(to, self.dir.join(name)).unwrap();
    }

    /// `render SCENE --out out` (plus `extra`) in the case folder.
    fn render(&self, scene: &str, extra: &[&str]) -> Outcome {
        let mut args = vec!["render", scene, "--out", "out", "--quiet"];
        args.extend_from_slice(extra);
        let before = self.beside();
        let o = run_in(&self.dir, &args);
        eprintln!(
            "{scene} {extra:?}: exit {} in {:.2} s, peak {} MiB: {}",
            o.code,
            o.seconds,
            o.peak_kib / 1024,
            o.err.lines().next().unwrap_or("")
        );
        assert_eq!(self.beside(), before, "written outside the case folder");
        self.assert_nothing_outside();
        o
    }

    /// What is beside `case/` (the test may plant files there).
    fn beside(&self) -> Vec<String> {
        let mut names: Vec<_> = std::fs::read_dir(&self.root)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    /// Nothing but `case/` and what the test planted beside it, and no
    /// temporary file anywhere.
    fn assert_nothing_outside(&self) {
        let beside = self.beside();
        assert!(
            beside.iter().all(|n| n == "case" || n == "secret.png"),
            "written outside the case folder: {beside:?}"
        );
        let mut stack = vec![self.dir.clone()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                assert!(!name.contains(".tmp-"), "temporary file left: {name}");
                if e.file_type().unwrap().is_dir() {
                    stack.push(e.path());
                }
            }
        }
    }

    fn frames(&self) -> usize {
        std::fs::read_dir(self.dir.join("out"))
            .map(|r| r.flatten().count())
            .unwrap_or(0)
    }
}

const TRIANGLE: &str = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";

fn scene(model: &str, extra: &str) -> String {
    format!("[output]\nwidth = 32\nheight = 32\n{extra}\n[[model]]\npath = \"{model}\"\n")
}

/// A textured triangle as glTF: positions and texture coordinates in a
/// data URI, the buffer `buffer` (a file name: replaces the data URI
/// with one of `length` bytes), the image `image`, the cameras `cameras`.
fn gltf(buffer: Option<(&str, usize)>, image: &str, extra: &str) -> String {
    use base64::Engine;
    let mut bin = Vec::new();
    for v in [[-1.0f32, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]] {
        v.iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    for v in [[0.0f32, 0.0], [1.0, 0.0], [0.0, 1.0]] {
        v.iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    let (uri, len) = match buffer {
        Some((name, len)) => (name.to_string(), len),
        None => (
            format!(
                "data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&bin)
            ),
            bin.len(),
        ),
    };
    format!(
        r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"uri": "{uri}", "byteLength": {len}}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 24}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}}{extra}],
  "images": [{{"uri": "{image}"}}],
  "textures": [{{"source": 0}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "material": 0}}]}}],
  "nodes": [{{"mesh": 0}}, {{"camera": 0, "name": "../../x", "translation": [0, 0, 4]}}],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "znear": 0.1}}}}],
  "scenes": [{{"nodes": [0, 1]}}]
}}"#
    )
}

#[test]
fn unbounded_reads_stop_at_what_the_file_declares() {
    let c = Case::new("unbounded");
    c.link("zero.mtl", "/dev/zero");
    c.link("zero.bin", "/dev/zero");
    c.write("tri.obj", format!("mtllib zero.mtl\n{TRIANGLE}"));
    c.write("obj.toml", scene("tri.obj", ""));
    // A material library: lenient, a warning naming what it is.
    let o = c.render("obj.toml", &[]);
    assert_eq!(o.code, 0, "{}", o.err);
    let o = run_in(&c.dir, &["render", "obj.toml", "--out", "out"]);
    assert!(o.err.contains("a device, not a regular file"), "{}", o.err);
    // A glTF buffer: an error, at once.
    c.write("buf.gltf", gltf(Some(("zero.bin", 60)), "none.png", ""));
    c.write("buf.toml", scene("buf.gltf", ""));
    let o = c.render("buf.toml", &[]);
    o.expect(2, &["zero.bin", "a device"]);
    assert!(o.peak_kib < 512 << 10, "peak {} KiB", o.peak_kib);
}

#[test]
fn fifos_are_refused_without_blocking() {
    let c = Case::new("fifo");
    for f in ["lib.mtl", "map.png", "buf.bin", "img.png", "model.obj"] {
        c.fifo(f);
    }
    c.write("a.obj", format!("mtllib lib.mtl\n{TRIANGLE}"));
    c.write("b.mtl", "newmtl m\nmap_Kd map.png\n");
    c.write("b.obj", format!("mtllib b.mtl\nusemtl m\n{TRIANGLE}"));
    c.write("buf.gltf", gltf(Some(("buf.bin", 60)), "img.png", ""));
    c.write("img.gltf", gltf(None, "img.png", ""));
    for (model, code) in [
        ("a.obj", 0),
        ("b.obj", 0),
        ("buf.gltf", 2),
        ("img.gltf", 0),
        ("model.obj", 2),
    ] {
        let scene_name = format!("{model}.toml");
        c.write(&scene_name, scene(model, ""));
        let o = run_in(&c.dir, &["render", &scene_name, "--out", "out"]);
        assert_eq!(o.code, code, "{model}: {}", o.err);
        assert!(
            o.err.contains("a FIFO, not a regular file"),
            "{model}: {}",
            o.err
        );
        c.assert_nothing_outside();
    }
}

/// A PNG of `w` x `h` grey pixels, all zero: tiny on disk, huge decoded.
fn grey_png(w: u32, h: u32) -> Vec<u8> {
    use std::io::Write;
    fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
        out.extend((data.len() as u32).to_be_bytes());
        let start = out.len();
        out.extend(kind);
        out.extend(data);
        let crc = crc32(&out[start..]);
        out.extend(crc.to_be_bytes());
    }
    fn crc32(b: &[u8]) -> u32 {
        let mut c = !0u32;
        for &x in b {
            c ^= x as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    chunk(&mut out, b"IHDR", &ihdr);
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    let row = vec![0u8; w as usize + 1];
    for _ in 0..h {
        z.write_all(&row).unwrap();
    }
    chunk(&mut out, b"IDAT", &z.finish().unwrap());
    chunk(&mut out, b"IEND", &[]);
    out
}

/// An OpenEXR header of one RGB float layer claiming `w` x `h`, and no
/// pixels.
fn exr_header(w: i32, h: i32) -> Vec<u8> {
    let mut b = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
    let mut attr = |name: &str, kind: &str, value: &[u8]| {
        b.extend(name.as_bytes());
        b.push(0);
        b.extend(kind.as_bytes());
        b.push(0);
        b.extend((value.len() as i32).to_le_bytes());
        b.extend(value);
    };
    let mut ch = Vec::new();
    for c in ["B", "G", "R"] {
        ch.extend(c.as_bytes());
        ch.push(0);
        ch.extend(2i32.to_le_bytes()); // FLOAT
        ch.extend([0, 0, 0, 0]);
        ch.extend(1i32.to_le_bytes());
        ch.extend(1i32.to_le_bytes());
    }
    ch.push(0);
    attr("channels", "chlist", &ch);
    attr("compression", "compression", &[0]);
    let window: Vec<u8> = [0, 0, w - 1, h - 1]
        .iter()
        .flat_map(|x: &i32| x.to_le_bytes())
        .collect();
    attr("dataWindow", "box2i", &window);
    attr("displayWindow", "box2i", &window);
    attr("lineOrder", "lineOrder", &[0]);
    attr("pixelAspectRatio", "float", &1f32.to_le_bytes());
    attr("screenWindowCenter", "v2f", &[0; 8]);
    attr("screenWindowWidth", "float", &1f32.to_le_bytes());
    b.push(0);
    b
}

#[test]
fn tiny_files_claiming_huge_sizes_are_refused_before_allocating() {
    let c = Case::new("huge");
    // A sparse accessor of 2^31 elements with no buffer view.
    let sparse = r#", {"componentType": 5126, "count": 2147483648, "type": "VEC3",
        "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5125}, "values": {"bufferView": 0}}}"#;
    c.write("sparse.gltf", gltf(None, "none.png", sparse));
    c.write("sparse.toml", scene("sparse.gltf", ""));
    let o = c.render("sparse.toml", &[]);
    o.expect(2, &["accessor 2", "memory budget"]);
    // An EXR environment whose header claims 100000x50000.
    c.write("tri.obj", TRIANGLE);
    c.write("huge.exr", exr_header(100_000, 50_000));
    c.write(
        "exr.toml",
        scene("tri.obj", "[environment]\npath = \"huge.exr\"\n"),
    );
    let o = c.render("exr.toml", &[]);
    o.expect(2, &["huge.exr", "memory budget"]);
    // A greyscale PNG within the image library's own limit, whose RGBA
    // expansion and mip chain are not: refused from its header, with or
    // without --max-memory (the default budget comes from the
    // address-space limit).
    c.write("grey.png", grey_png(23_000, 23_000));
    c.write("grey.mtl", "newmtl m\nmap_Kd grey.png\n");
    c.write("grey.obj", format!("mtllib grey.mtl\nusemtl m\n{TRIANGLE}"));
    c.write("grey.toml", scene("grey.obj", ""));
    for extra in [&[][..], &["--max-memory", "256M"][..]] {
        let o = c.render("grey.toml", extra);
        o.expect(2, &["grey.png", "memory budget"]);
        assert!(o.peak_kib < 256 << 10, "peak {} KiB", o.peak_kib);
    }
}

#[test]
fn nothing_is_written_outside_the_output_folder() {
    let c = Case::new("outside");
    c.write("tri.obj", TRIANGLE);
    // Names that come from files: (an [output] key, a table after the
    // model, the key the message names).
    for (output, tail, key) in [
        ("", "[[camera]]\nname = \"../../x\"\n", "camera.name"),
        ("", "[[camera]]\nname = \"a/b\"\n", "camera.name"),
        ("gif = \"../x.gif\"", "", "output.gif"),
        ("gif = \"/tmp/softraster-x.gif\"", "", "output.gif"),
        ("video = \"../../s.toml.mp4\"", "", "output.video"),
        ("gif = \"../s.toml\"", "", "output.gif"),
    ] {
        c.write("s.toml", scene("tri.obj", output) + tail);
        let o = c.render("s.toml", &[]);
        o.expect(2, &[key]);
        assert_eq!(
            c.frames(),
            0,
            "{output}{tail}: frames written before the refusal"
        );
        assert!(c.dir.join("s.toml").is_file());
    }
    // A glTF camera's name, imported.
    c.write("cam.gltf", gltf(None, "none.png", ""));
    c.write(
        "cam.toml",
        "[output]\nwidth = 32\nheight = 32\n[[model]]\npath = \"cam.gltf\"\ncameras = true\n",
    );
    let o = c.render("cam.toml", &[]);
    o.expect(2, &["\"../../x\""]);
    // A FIFO where a frame goes is refused, not replaced.
    std::fs::create_dir_all(c.dir.join("out")).unwrap();
    let p = std::ffi::CString::new(c.dir.join("out/camera_0000.png").to_str().unwrap()).unwrap();
    // SAFETY: a valid C string.
    assert_eq!(unsafe { libc::mkfifo(p.as_ptr(), 0o644) }, 0);
    c.write("plain.toml", scene("tri.obj", ""));
    let o = c.render("plain.toml", &[]);
    o.expect(1, &["a FIFO"]);
    use std::os::unix::fs::FileTypeExt;
    let t = std::fs::symlink_metadata(c.dir.join("out/camera_0000.png")).unwrap();
    assert!(t.file_type().is_fifo());
}

#[test]
fn without_max_memory_the_budget_is_what_the_process_may_have() {
    let c = Case::new("budget");
    c.write("tri.obj", TRIANGLE);
    c.write(
        "big.toml",
        "[output]\nwidth = 16384\nheight = 16384\n[render]\nmsaa = 4\n[[model]]\npath = \"tri.obj\"\n",
    );
    let o = c.render("big.toml", &[]);
    o.expect(2, &["the render needs about", "default budget"]);
    assert_eq!(c.frames(), 0);
}

#[test]
fn bad_output_settings_exit_2_at_load_and_empty_compares_fail() {
    let c = Case::new("late");
    c.write("tri.obj", TRIANGLE);
    c.write("file", "not a folder");
    for (extra, key) in [
        ("gif = \"\"", "output.gif"),
        ("gif = \".\"", "output.gif"),
        ("gif = \"sub/\"", "output.gif"),
        ("dir = \"file\"", "output.dir"),
    ] {
        c.write("s.toml", scene("tri.obj", extra));
        let o = run_in(&c.dir, &["render", "s.toml", "--quiet"]);
        o.expect(2, &[key]);
        assert!(!c.dir.join("out").exists() || c.frames() == 0);
    }
    // `compare` with nothing on either side is not a pass.
    std::fs::create_dir_all(c.dir.join("a")).unwrap();
    std::fs::create_dir_all(c.dir.join("b")).unwrap();
    let o = run_in(&c.dir, &["compare", "a", "b"]);
    o.expect(1, &["nothing to compare"]);
    // A frame too large for a video: refused from its header.
    c.write("big.png", grey_png(8000, 8000));
    let o = run_in(&c.dir, &["video", "big.png", "-o", "v.mp4"]);
    o.expect(2, &["3840x2160"]);
    assert!(o.peak_kib < 128 << 10, "peak {} KiB", o.peak_kib);
    c.assert_nothing_outside();
}

#[test]
fn messages_name_what_a_path_is() {
    let c = Case::new("messages");
    std::fs::create_dir_all(c.dir.join("folder.obj")).unwrap();
    c.link("zero.obj", "/dev/zero");
    for (model, what) in [
        ("folder.obj", "a directory"),
        ("zero.obj", "a device"),
        ("nothing.obj", "not found"),
    ] {
        c.write("s.toml", scene(model, ""));
        let o = c.render("s.toml", &[]);
        o.expect(2, &[what]);
    }
    // A deeply nested value: the error quotes the place, not the line.
    let deep = format!("a = {}1{}\n", "[".repeat(100_000), "]".repeat(100_000));
    c.write("deep.toml", deep);
    let o = c.render("deep.toml", &[]);
    assert_eq!(o.code, 2);
    assert!(o.err.len() < 2_000, "{} bytes of message", o.err.len());
}

#[test]
fn the_sandbox_keeps_reads_in_the_scene_folder() {
    let c = Case::new("sandbox");
    std::fs::write(c.root.join("secret.png"), grey_png(4, 4)).unwrap();
    std::fs::create_dir_all(c.dir.join("sub")).unwrap();
    c.write("m.gltf", gltf(None, "../secret.png", ""));
    c.write("s.toml", scene("m.gltf", ""));
    // Without --sandbox: read as a desktop tool would.
    let o = c.render("s.toml", &[]);
    assert_eq!(o.code, 0, "{}", o.err);
    // With it: refused, naming the path and the file that asked.
    for flags in [&["--sandbox"][..], &["--set", "render.sandbox=true"][..]] {
        let o = c.render("s.toml", flags);
        o.expect(2, &["secret.png", "--sandbox", "m.gltf"]);
    }
    // A link inside the folder that leads out, and a model named by an
    // absolute path.
    std::os::unix::fs::symlink(c.root.join("secret.png"), c.dir.join("sub/in.png")).unwrap();
    c.write("l.gltf", gltf(None, "sub/in.png", ""));
    c.write("l.toml", scene("l.gltf", ""));
    let o = c.render("l.toml", &["--sandbox"]);
    o.expect(2, &["leads outside"]);
    let abs = c.dir.join("l.gltf");
    c.write("a.toml", scene(abs.to_str().unwrap(), ""));
    let o = c.render("a.toml", &["--sandbox"]);
    o.expect(2, &["absolute path"]);
}

#[test]
fn a_killed_video_render_leaves_no_partial_file() {
    let c = Case::new("kill");
    c.write("tri.obj", TRIANGLE);
    c.write(
        "v.toml",
        "[output]\nwidth = 256\nheight = 256\nvideo = \"v.mp4\"\n[animation]\nframes = 1000\n[animation.turntable]\n[[model]]\npath = \"tri.obj\"\n",
    );
    let mut child = std::process::Command::new(crate::binary::BIN)
        .args(["render", "v.toml", "--out", "out", "--quiet"])
        .current_dir(&c.dir)
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while c.frames() < 20 && t0.elapsed() < TIMEOUT {
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert!(
        !status.success(),
        "the render finished before it was killed"
    );
    // The video is muxed in memory: no file of it, whole or partial.
    let left: Vec<_> = std::fs::read_dir(c.dir.join("out"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("mp4"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}
