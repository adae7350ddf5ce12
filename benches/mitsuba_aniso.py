#!/usr/bin/env python3
"""KHR_materials_anisotropy against Mitsuba 3's anisotropic GGX.

The Cycles set's anisotropy discs (benches/cycles/scenes.py: four metal discs
tilted 35 degrees, roughness 0.35, anisotropy 0.8 at 0, 45 and 90 degrees
and 0) under an HDRI. Blender's glTF importer maps the extension to its own
anisotropy (alpha along the tangent r^2 / sqrt(1 - 0.9 s), across r^2
sqrt(1 - 0.9 s)), which is not the extension's lobe; Mitsuba's
`roughconductor` takes the extension's alphas directly: alpha_t =
lerp(r^2, 1, s^2) along the direction (the disc's u, turned by the
rotation), alpha_b = r^2 across. Its conductor is a mirror of the base colour
(`material = "none"`, Fresnel 1 times the colour) where the glTF metal is
Schlick's Fresnel from the base colour: the same at normal incidence,
slightly brighter towards grazing angles in softraster.

softraster renders the set's TOML with `prefiltered` (the default) and
`sampled`; the script prints `softraster compare --metric flip` of each
against Mitsuba (path, max_depth 2: environment light with visibility).

Usage (from the repository root, after `cargo build --release`):
    pip install mitsuba==3.5.2 numpy pillow
    python3 benches/cycles/run.py --only anisotropy-discs   # writes the scenes
    python3 benches/mitsuba_aniso.py --hdri studio
"""
import argparse
import math
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mitsuba_env import flip, srgb8  # noqa: E402  (the same display transform and metric)
DISCS = [(0, 0.8), (45, 0.8), (90, 0.8), (0, 0.0)]
RADIUS, SEGMENTS, TILT, ROUGH = 0.55, 96, -35.0, 0.35
BASE = (0.95, 0.93, 0.88)


def write_disc(path, index, rotation):
    """Disc `index` of the set, placed, its u along the turned direction."""
    x0, y0 = (index % 2 - 0.5) * 1.25, (0.5 - index // 2) * 1.25
    c, s = math.cos(math.radians(rotation)), math.sin(math.radians(rotation))
    ct, st = math.cos(math.radians(TILT)), math.sin(math.radians(TILT))
    lines = []
    pts = [(0.0, 0.0)] + [(RADIUS * math.cos(2 * math.pi * j / SEGMENTS),
                           RADIUS * math.sin(2 * math.pi * j / SEGMENTS))
                          for j in range(SEGMENTS)]
    for x, y in pts:
        # About X by the tilt, then moved to the disc's place.
        lines.append(f"v {x + x0} {y * ct + y0} {y * st}")
        lines.append(f"vt {0.5 + (c * x + s * y) / (2 * RADIUS)} "
                     f"{0.5 + (-s * x + c * y) / (2 * RADIUS)}")
    lines.append(f"vn 0 {-st} {ct}")
    for j in range(SEGMENTS):
        a, b = j + 2, (j + 1) % SEGMENTS + 2
        lines.append(f"f 1/1/1 {a}/{a}/1 {b}/{b}/1")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def render_mitsuba(a, hdri, rotation, png):
    import mitsuba as mi
    import numpy as np
    from PIL import Image
    mi.set_variant("scalar_rgb")
    T = mi.ScalarTransform4f
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2, "hide_emitters": False},
        "sensor": {
            "type": "perspective", "fov": 36.0, "fov_axis": "y",
            "to_world": T.look_at(origin=[0, 0, 4.4], target=[0, 0, 0], up=[0, 1, 0]),
            "sampler": {"type": "independent", "sample_count": a.spp},
            "film": {"type": "hdrfilm", "width": 320, "height": 240,
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        },
        # Mitsuba reads u = atan2(x, -z) / 2pi, the scene format
        # 0.5 + atan2(x, -z) / 2pi: half a turn about up apart; then the
        # scene's rotation.
        "env": {"type": "envmap", "filename": hdri,
                "to_world": T.rotate([0, 1, 0], 180 + rotation)},
    }
    alpha = ROUGH * ROUGH
    for i, (rotation, strength) in enumerate(DISCS):
        obj = os.path.join(a.out, f"disc{i}.obj")
        write_disc(obj, i, rotation)
        scene[f"disc{i}"] = {
            "type": "obj", "filename": obj, "face_normals": False,
            "bsdf": {
                "type": "roughconductor", "distribution": "ggx", "material": "none",
                "alpha_u": alpha + (1 - alpha) * strength * strength, "alpha_v": alpha,
                "specular_reflectance": {"type": "rgb", "value": list(BASE)},
            },
        }
    img = mi.render(mi.load_dict(scene))
    Image.fromarray(srgb8(np.array(img))).save(png)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scenes", default="/tmp/softraster-cycles",
                   help="where benches/cycles/run.py wrote the set")
    p.add_argument("--out", default="/tmp/softraster-mitsuba-aniso")
    p.add_argument("--hdri", default="studio")
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--samples", type=int, default=256, help="softraster's sampled method")
    p.add_argument("--softraster", default=os.path.join(ROOT, "target/release/softraster"))
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scene = os.path.join(a.scenes, f"anisotropy-discs-{a.hdri}.toml")
    if not os.path.exists(scene):
        sys.exit(f"{scene} is missing: run benches/cycles/run.py --only anisotropy-discs first")
    hdri = os.path.join(ROOT, "..", "shared", "assets", "hdri", f"{a.hdri}.exr")
    ref = os.path.join(a.out, f"mitsuba-{a.hdri}.png")
    m = re.search(r"^rotation = ([-0-9.]+)", open(scene).read(), re.M)
    render_mitsuba(a, hdri, float(m.group(1)) if m else 0.0, ref)
    for method, sets in [("prefiltered", []),
                         ("sampled", ["--set", "environment.method=sampled",
                                      "--set", f"environment.samples={a.samples}"])]:
        out = os.path.join(a.out, f"{method}-{a.hdri}")
        subprocess.run([a.softraster, "render", scene, "--out", out, *sets], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        png = os.path.join(out, sorted(f for f in os.listdir(out) if f.endswith(".png"))[0])
        print(f"{a.hdri} {method}: FLIP against Mitsuba {flip(a, ref, png):.4f}  ({png})")
    print(f"Mitsuba: {ref}")


if __name__ == "__main__":
    main()
