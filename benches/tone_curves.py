#!/usr/bin/env python3.11
"""softraster's `render.tonemap = "agx"` against Blender's AgX view
transform (look None, sRGB display), on a grey ramp and the sRGB
primaries. Needs `pip install bpy==5.0.1` (Python 3.11) and a release
build:

    cargo build --release
    python3.11 benches/tone_curves.py [target/release/softraster]

Blender's values come from an image of the linear colours saved with the
scene's view transform (`Image.save_render`, 16-bit PNG). softraster's
come from frames whose background is each colour (a version-1 scene, so
nothing else lights or tints it). Both are read back as display-encoded
values; the table gives them in 1/255 steps and their difference.
"""
import json
import os
import subprocess
import sys
import tempfile

import bpy

COLOURS = (
    [[0.0, 0.0, 0.0]]
    # A grey ramp, one stop apart, 2^-10 to 2^6.
    + [[2.0**k] * 3 for k in range(-10, 7)]
    # The sRGB primaries and secondaries, from dark to overexposed.
    + [
        [v if c == "1" else 0.0 for c in mask]
        for mask in ("100", "010", "001", "110", "011", "101")
        for v in (0.05, 0.18, 1.0, 4.0, 16.0)
    ]
    + [[0.8, 0.2, 0.05], [0.1, 0.5, 0.9], [0.3, 0.02, 0.6]]
)


def read_png(path):
    """Display-encoded RGB of pixel (0, 0) of a PNG, through Blender."""
    img = bpy.data.images.load(path)
    img.colorspace_settings.name = "Non-Color"
    p = img.pixels[:4]
    bpy.data.images.remove(img)
    return p[:3]


def blender_agx(dir):
    scene = bpy.context.scene
    scene.display_settings.display_device = "sRGB"
    vs = scene.view_settings
    vs.view_transform = "AgX"
    vs.look = "None"
    vs.exposure = 0.0
    vs.gamma = 1.0
    img = bpy.data.images.new("probe", width=len(COLOURS), height=1, float_buffer=True)
    img.colorspace_settings.name = "Linear Rec.709"
    img.pixels = [v for c in COLOURS for v in (c[0], c[1], c[2], 1.0)]
    s = scene.render.image_settings
    s.file_format, s.color_depth, s.color_mode = "PNG", "16", "RGB"
    path = os.path.join(dir, "blender.png")
    img.save_render(path, scene=scene)
    back = bpy.data.images.load(path)
    back.colorspace_settings.name = "Non-Color"
    p = back.pixels[:]
    return [p[4 * i : 4 * i + 3] for i in range(len(COLOURS))]


def softraster_agx(binary, dir):
    sphere = os.path.join(os.path.dirname(__file__), "..", "assets", "showcase", "sphere.obj")
    out = []
    for i, c in enumerate(COLOURS):
        scene = os.path.join(dir, f"c{i}.toml")
        with open(scene, "w") as f:
            f.write(
                f"[output]\nwidth = 16\nheight = 16\nbackground = {json.dumps(c)}\n"
                f'[render]\ntonemap = "agx"\n[ambient]\ncolor = [0.0, 0.0, 0.0]\n'
                f'[[model]]\npath = "{os.path.abspath(sphere)}"\n'
            )
        subprocess.run(
            [binary, "render", scene, "--out", os.path.join(dir, f"o{i}"), "--quiet"],
            check=True,
        )
        out.append(read_png(os.path.join(dir, f"o{i}", "camera_0000.png")))
    return out


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else "target/release/softraster"
    with tempfile.TemporaryDirectory() as dir:
        ours = softraster_agx(binary, dir)
        theirs = blender_agx(dir)
    print("linear,softraster (1/255),blender (1/255),max difference (1/255)")
    worst = 0.0
    for c, a, b in zip(COLOURS, ours, theirs):
        d = max(abs(x - y) for x, y in zip(a, b)) * 255
        worst = max(worst, d)
        fmt = lambda v: " ".join(f"{x * 255:.1f}" for x in v)
        print(f"{' '.join(map(str, c))},{fmt(a)},{fmt(b)},{d:.1f}")
    print(f"worst: {worst:.1f}/255")


main()
