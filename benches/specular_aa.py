#!/usr/bin/env python3
"""Specular anti-aliasing against supersampling: error and flicker.

Renders a short, slow turntable of a normal-mapped model (default:
FlightHelmet, small on screen so that its normal-map detail is at pixel
scale) with `render.specular_aa` on and off at MSAA 1 and 4, and the same
frames at SSAA 8x8 without it (the reference: 64 shading samples a pixel).
Prints per variant the mean FLIP against the reference, the mean absolute
error (display values, 0..1), the flicker (the mean absolute change of the
error from one frame to the next: highlights that sparkle come and go between
frames where the reference's stay put), and the median frame time.

    cargo build --release
    python3 benches/specular_aa.py [--model PATH] [--size 200] [--frames 12]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

import numpy as np
from PIL import Image

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--softraster", default=os.path.join(ROOT, "target/release/softraster"))
    p.add_argument("--model", default=os.path.join(
        ROOT, "../shared/assets/gltf/FlightHelmet/FlightHelmet.gltf"),
                   help="a model file, or `bumps` (a generated bumpy metal ball: "
                   "benches/cycles/scenes.py bumpy_metal)")
    p.add_argument("--size", type=int, default=200)
    p.add_argument("--frames", type=int, default=12)
    p.add_argument("--degrees", type=float, default=30.0,
                   help="the turn over all frames (small: neighbouring frames nearly alike)")
    p.add_argument("--light", action="store_true",
                   help="add a directional key light to the studio look (sharp highlights)")
    p.add_argument("--hdri", default=None,
                   help="light with this HDR environment instead of the studio look")
    p.add_argument("--out", default=None, help="keep the frames here")
    return p.parse_args()


def scene(a, msaa, ssaa, specular_aa):
    return f"""[output]
width = {a.size}
height = {a.size}
[render]
msaa = {msaa}
ssaa = {ssaa}
specular_aa = {str(specular_aa).lower()}
[animation]
frames = {a.frames}
turntable = {{ axis = [0.0, 1.0, 0.0], degrees = {a.degrees} }}
[[model]]
path = "{os.path.abspath(a.model)}"
""" + (LIGHT if a.light else "") + (
        f'[environment]\npath = "{os.path.abspath(a.hdri)}"\n' if a.hdri else "")


LIGHT = """[[light]]
kind = "directional"
direction = [-0.4, -0.5, -1.0]
irradiance = 3.0
"""


def render(a, work, name, msaa, ssaa, specular_aa):
    d = os.path.join(work, name)
    os.makedirs(d, exist_ok=True)
    path = os.path.join(d, "scene.toml")
    with open(path, "w") as f:
        f.write(scene(a, msaa, ssaa, specular_aa))
    out = subprocess.run([a.softraster, "render", path, "--out", os.path.join(d, "frames"),
                          "--progress", "json"], capture_output=True, text=True, check=True)
    times = []
    for line in (out.stderr + out.stdout).splitlines():
        try:
            ev = json.loads(line)
        except json.JSONDecodeError:
            continue
        if isinstance(ev, dict) and ev.get("event") == "frame":
            times.append(1000.0 * ev["seconds"])
    frames = sorted(os.path.join(r, f) for r, _, fs in os.walk(os.path.join(d, "frames"))
                    for f in fs if f.endswith(".png"))
    return frames, (statistics.median(times[1:]) if len(times) > 1 else float("nan"))


def load(p):
    return np.asarray(Image.open(p).convert("RGB")).astype(np.float64) / 255.0


def flip(a, ref, test):
    out = subprocess.run([a.softraster, "compare", "--json", "--metric", "flip",
                          "--threshold", "1", ref, test], capture_output=True, text=True)
    return json.loads(out.stdout)["files"][0]["value"]


def main():
    a = parse_args()
    work = a.out or tempfile.mkdtemp(prefix="softraster-saa-")
    os.makedirs(work, exist_ok=True)
    if a.model == "bumps":
        sys.path.insert(0, os.path.join(ROOT, "benches/cycles"))
        import scenes
        g = scenes.Gltf()
        scenes.bumpy_metal(g)
        a.model = os.path.join(work, "bumpy_metal.gltf")
        g.write(a.model)
    if not os.path.exists(a.model):
        sys.exit(f"specular_aa: {a.model} is missing")
    ref, _ = render(a, work, "reference", 1, 8, False)
    refs = [load(p) for p in ref]
    print(f"{a.model}: {a.size}x{a.size}, {a.frames} frames over {a.degrees} degrees; "
          f"reference SSAA 8x8 without specular AA")
    print("| variant | FLIP | MAE | flicker | ms/frame |\n|---|---|---|---|---|")
    for msaa in (1, 4):
        for saa in (False, True):
            name = f"msaa{msaa}-{'saa' if saa else 'plain'}"
            frames, ms = render(a, work, name, msaa, 1, saa)
            imgs = [load(p) for p in frames]
            err = [i - r for i, r in zip(imgs, refs)]
            mae = statistics.mean(float(np.abs(e).mean()) for e in err)
            flicker = statistics.mean(float(np.abs(err[k + 1] - err[k]).mean())
                                      for k in range(len(err) - 1))
            fl = statistics.mean(flip(a, r, t) for r, t in zip(ref, frames))
            print(f"| MSAA {msaa}, specular_aa = {str(saa).lower()} | {fl:.4f} | {mae:.4f} | "
                  f"{flicker:.4f} | {ms:.1f} |")
    if not a.out:
        print(f"(frames in {work})")


if __name__ == "__main__":
    main()
