#!/usr/bin/env python3
"""softraster's environment lighting against Mitsuba 3, an independent path tracer.

A row of five spheres under a real HDRI, the environment as background, direct
light only (camera ray -> surface -> environment, with visibility), no other
light: a glTF dielectric (base colour 0.8, roughness 1) and four metals (base
colour 0.9, roughness 0.1, 0.3, 0.6, 1.0). softraster renders it with
`[environment] method = "prefiltered"` (the default), the same with ray-traced
AO (`prefiltered+ao`: the prefiltered method sees no other object, AO brings the
neighbours' occlusion) and `"sampled"`; Mitsuba 3
(`pip install mitsuba`, CPU variant scalar_rgb) renders the same meshes (the
OBJ this script writes) with its `principled` BSDF and the `path` integrator at
max_depth 2. Both images are clamped and sRGB-encoded the same way; the script
prints `softraster compare --metric flip` of each method against Mitsuba, for
the whole frame and for each sphere's square.

What differs on purpose (the models are not the same BRDF):
- Mitsuba's `principled` dielectric uses the Disney diffuse (retro-reflection
  at grazing angles), softraster the glTF model's Lambertian diffuse; the
  specular lobes are both GGX with alpha = roughness^2 and Schlick's Fresnel.
- Mitsuba's environment lookup is bilinear in the lat-long image, softraster's
  prefiltered method reads mip levels: the background matches at MSAA 4.

Usage (from the repository root, after `cargo build --release`):
    pip install mitsuba==3.5.2 numpy pillow
    python3 benches/mitsuba_env.py                       # all four HDRIs, ~4 min
    python3 benches/mitsuba_env.py --hdri courtyard --spp 256
    # The glossy metal row against softraster's own ray-traced reference
    # (no Mitsuba needed): close, then apart.
    python3 benches/mitsuba_env.py --spheres metals --reference sampled --samples 512
    python3 benches/mitsuba_env.py --spheres metals --reference sampled --samples 512 \
        --spacing 4.8 --width 1200 --height 320
"""
import argparse
import math
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SPHERES = [
    # (label, base colour, metallic, roughness)
    ("dielectric r1.0", 0.8, 0.0, 1.0),
    ("metal r0.1", 0.9, 1.0, 0.1),
    ("metal r0.3", 0.9, 1.0, 0.3),
    ("metal r0.6", 0.9, 1.0, 0.6),
    ("metal r1.0", 0.9, 1.0, 1.0),
]
SPACING = 2.4  # centre to centre; radius 1 (--spacing)
EYE = (0.0, 0.0, 9.0)  # moves back with the spacing, so the row fills the frame
FOV = 22.0


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--softraster", default=os.path.join(ROOT, "target/release/softraster"))
    p.add_argument("--hdri-dir", default=os.path.join(ROOT, "../shared/assets/hdri"))
    p.add_argument("--hdri", action="append",
                   help="studio, courtyard, sunset, city (repeatable; default all four)")
    p.add_argument("--out", default="/tmp/softraster-mitsuba")
    p.add_argument("--width", type=int, default=600)
    p.add_argument("--height", type=int, default=160)
    p.add_argument("--spp", type=int, default=512, help="Mitsuba samples per pixel")
    p.add_argument("--spacing", type=float, default=2.4,
                   help="sphere centres this far apart (radius 1): 2.4 puts them close, so each "
                        "hides part of the environment from its neighbours; 4.8 mostly measures "
                        "the lighting alone (use --width 1200 --height 320 to keep their size)")
    p.add_argument("--samples", type=int, default=256,
                   help="softraster's environment.samples for the sampled method")
    p.add_argument("--spheres", choices=["mixed", "metals"], default="mixed",
                   help="mixed: the dielectric and four metals above; metals: five metals "
                        "(base colour 0.9) of roughness 0, 0.25, 0.5, 0.75 and 1, the "
                        "issue's glossy sphere row")
    p.add_argument("--reference", choices=["mitsuba", "sampled"], default="mitsuba",
                   help="what the methods are measured against: Mitsuba 3, or softraster's "
                        "own `sampled` method at --samples (needs no Mitsuba)")
    return p.parse_args()


METALS = [(f"metal r{r}", 0.9, 1.0, r) for r in (0.0, 0.25, 0.5, 0.75, 1.0)]


def write_sphere(path, seg=128, rings=64):
    """A UV sphere of radius 1 with unit vertex normals (smooth shading)."""
    lines = ["# UV sphere for benches/mitsuba_env.py"]
    for j in range(rings + 1):
        th = math.pi * j / rings
        for i in range(seg + 1):
            ph = 2 * math.pi * i / seg
            x, y, z = math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)
            lines.append(f"v {x:.7f} {y:.7f} {z:.7f}")
            lines.append(f"vn {x:.7f} {y:.7f} {z:.7f}")
    w = seg + 1
    for j in range(rings):
        for i in range(seg):
            a, b, c, d = j * w + i + 1, j * w + i + 2, (j + 1) * w + i + 2, (j + 1) * w + i + 1
            # Counter-clockwise seen from outside.
            if j > 0:
                lines.append(f"f {a}//{a} {d}//{d} {b}//{b}")
            if j < rings - 1:
                lines.append(f"f {b}//{b} {d}//{d} {c}//{c}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def centers():
    n = len(SPHERES)
    return [((i - (n - 1) / 2) * SPACING, 0.0, 0.0) for i in range(n)]


METHODS = {
    # name: (environment.method, extra [render] lines)
    "prefiltered": ("prefiltered", []),
    "prefiltered+ao": ("prefiltered", ['ao = { method = "raytraced", radius = 3.0, samples = 64 }']),
    "sampled": ("sampled", []),
}


def write_scene(path, a, hdri, obj, variant):
    method, extra = METHODS[variant]
    out = [
        "[output]",
        f"width = {a.width}",
        f"height = {a.height}",
        'background = "environment"',
        "[render]",
        'shading = "pbr"',
        'tonemap = "clamp"',
        "msaa = 4",
        *extra,
        "[environment]",
        f'path = "{hdri}"',
        f'method = "{method}"',
    ]
    if method == "sampled":
        out.append(f"samples = {a.samples}")
    for (label, base, metallic, rough), c in zip(SPHERES, centers()):
        out += [
            f"# {label}",
            "[[model]]",
            f'path = "{obj}"',
            f"translate = [{c[0]}, {c[1]}, {c[2]}]",
            "[model.material]",
            f"kd = [{base}, {base}, {base}]",
            f"metallic = {metallic}",
            f"roughness = {rough}",
        ]
    out += ["[[camera]]", f"eye = {list(EYE)}", "target = [0.0, 0.0, 0.0]", f"fov = {FOV}"]
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def render_softraster(a, scene, outdir):
    os.makedirs(outdir, exist_ok=True)
    subprocess.run([a.softraster, "render", scene, "--out", outdir], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    pngs = sorted(f for f in os.listdir(outdir) if f.endswith(".png"))
    return os.path.join(outdir, pngs[0])


def srgb8(x):
    import numpy as np
    x = np.clip(x, 0.0, 1.0)
    s = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return np.round(s * 255.0).astype(np.uint8)


def render_mitsuba(a, hdri, obj, png):
    import mitsuba as mi
    import numpy as np
    from PIL import Image
    mi.set_variant("scalar_rgb")
    T = mi.ScalarTransform4f
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2, "hide_emitters": False},
        "sensor": {
            "type": "perspective",
            "fov": FOV,
            "fov_axis": "y",
            "to_world": T.look_at(origin=list(EYE), target=[0, 0, 0], up=[0, 1, 0]),
            "sampler": {"type": "independent", "sample_count": a.spp},
            "film": {"type": "hdrfilm", "width": a.width, "height": a.height,
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        },
        # Mitsuba reads u = atan2(x, -z) / 2pi; the scene format reads
        # u = 0.5 + atan2(x, -z) / 2pi: half a turn about up apart.
        "env": {"type": "envmap", "filename": hdri, "to_world": T.rotate([0, 1, 0], 180)},
    }
    for k, ((label, base, metallic, rough), c) in enumerate(zip(SPHERES, centers())):
        scene[f"sphere{k}"] = {
            "type": "obj",
            "filename": obj,
            "face_normals": False,
            "to_world": T.translate(list(c)),
            "bsdf": {
                "type": "principled",
                "base_color": {"type": "rgb", "value": [base] * 3},
                "metallic": metallic,
                "roughness": rough,
                "specular": 0.5,  # F0 = 0.04, glTF's dielectric
            },
        }
    img = mi.render(mi.load_dict(scene))
    Image.fromarray(srgb8(np.array(img))).save(png)


def crop(src, box, dst):
    from PIL import Image
    Image.open(src).crop(box).save(dst)


def flip(a, ref, test):
    r = subprocess.run([a.softraster, "compare", ref, test, "--metric", "flip",
                        "--threshold", "1"], capture_output=True, text=True)
    m = re.search(r"flip=([0-9.]+)", r.stdout + r.stderr)
    if not m:
        sys.exit(f"compare printed no flip value:\n{r.stdout}{r.stderr}")
    return float(m.group(1))


def sphere_boxes(a):
    """Each sphere's square on screen (projected centre +- its radius)."""
    f = 1 / math.tan(math.radians(FOV) / 2)
    boxes = []
    for c in centers():
        z = EYE[2] - c[2]
        cx = a.width / 2 + c[0] / z * f * a.height / 2
        r = 1.1 / (z - 1.0) * f * a.height / 2
        boxes.append((int(cx - r), int(a.height / 2 - r), int(cx + r + 1), int(a.height / 2 + r + 1)))
    return boxes


def main():
    global SPACING, EYE, SPHERES
    a = parse_args()
    if a.spheres == "metals":
        SPHERES = METALS
    methods = list(METHODS) if a.reference == "mitsuba" else ["prefiltered", "prefiltered+ao"]
    SPACING = a.spacing
    EYE = (0.0, 0.0, 9.0 * a.spacing / 2.4)
    names = a.hdri or ["studio", "courtyard", "sunset", "city"]
    os.makedirs(a.out, exist_ok=True)
    obj = os.path.join(a.out, "sphere.obj")
    write_sphere(obj)
    rows = []
    for name in names:
        hdri = os.path.abspath(os.path.join(a.hdri_dir, f"{name}.exr"))
        if not os.path.exists(hdri):
            sys.exit(f"missing environment: {hdri}")
        if a.reference == "mitsuba":
            ref = os.path.join(a.out, f"{name}_{a.spheres}_mitsuba.png")
            if not os.path.exists(ref):
                render_mitsuba(a, hdri, obj, ref)
        else:
            scene = os.path.join(a.out, f"{name}_{a.spheres}_reference.toml")
            write_scene(scene, a, hdri, obj, "sampled")
            ref = render_softraster(a, scene, os.path.join(a.out, f"{name}_{a.spheres}_reference"))
        result = {}
        for method in methods:
            tag = a.spheres + "_" + method.replace("+", "_")
            scene = os.path.join(a.out, f"{name}_{tag}.toml")
            write_scene(scene, a, hdri, obj, method)
            png = render_softraster(a, scene, os.path.join(a.out, f"{name}_{tag}"))
            whole = flip(a, ref, png)
            parts = []
            for k, box in enumerate(sphere_boxes(a)):
                rc = os.path.join(a.out, f"{name}_{a.spheres}_{a.reference}_s{k}.png")
                tc = os.path.join(a.out, f"{name}_{tag}_s{k}.png")
                crop(ref, box, rc)
                crop(png, box, tc)
                parts.append(flip(a, rc, tc))
            result[method] = (whole, parts)
        rows.append((name, result))
        print(f"{name}: " + ", ".join(f"{m} {result[m][0]:.4f}" for m in methods), flush=True)
    print()
    print("| environment | method | whole frame | " + " | ".join(s[0] for s in SPHERES) + " |")
    print("|---|---|---|" + "---|" * len(SPHERES))
    for name, result in rows:
        for method in methods:
            whole, parts = result[method]
            print(f"| {name} | {method} | {whole:.4f} | " +
                  " | ".join(f"{p:.4f}" for p in parts) + " |")
    against = (f"Mitsuba 3 ({a.spp} spp, path max_depth 2)" if a.reference == "mitsuba"
               else f"softraster's sampled method ({a.samples} samples)")
    print(f"\nmean FLIP against {against}; softraster sampled at {a.samples} samples; "
          f"images in {a.out}")


if __name__ == "__main__":
    main()
