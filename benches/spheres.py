#!/usr/bin/env python3
"""The red spheres of the KHR-layer measurements (docs/performance.md):
a 36,864-triangle UV sphere as glTF files in DIR, plain, with
KHR_materials_clearcoat, with clearcoat, sheen, specular and
iridescence (constant factors, no maps), and with transmission and a
volume (`glass`; `glass-off` is the same with transmissionFactor 0). Render each as its one-line
scene and compare the steady per-frame medians:

    python3 benches/spheres.py /tmp/spheres
    for m in plain clearcoat layers glass glass-off; do
        target/release/softraster render /tmp/spheres/$m.gltf --set animation.frames=12 \\
            --set output.width=700 --set output.height=700 --set render.msaa=4 \\
            --out /tmp/spheres/out-$m --progress json
    done
"""
import base64
import json
import math
import os
import struct
import sys

RINGS, SEGMENTS = 96, 192


def sphere():
    pos, idx = [], []
    for i in range(RINGS + 1):
        th = math.pi * i / RINGS
        for j in range(SEGMENTS + 1):
            ph = 2 * math.pi * j / SEGMENTS
            pos += [math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)]
    for i in range(RINGS):
        for j in range(SEGMENTS):
            a = i * (SEGMENTS + 1) + j
            b = a + SEGMENTS + 1
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return pos, idx


def document(pos, idx, extensions):
    pb = struct.pack("<%df" % len(pos), *pos)
    ib = struct.pack("<%dI" % len(idx), *idx)
    blob = pb + pb + ib  # unit sphere: the normals are the positions
    n = len(pos) // 3
    material = {
        "name": "red",
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.05, 0.05, 1],
            "metallicFactor": 0.0,
            "roughnessFactor": 0.5,
        },
    }
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1},
                                    "indices": 2, "material": 0}]}],
        "materials": [material],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(blob).decode()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pb)},
            {"buffer": 0, "byteOffset": len(pb), "byteLength": len(pb)},
            {"buffer": 0, "byteOffset": 2 * len(pb), "byteLength": len(ib)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
        ],
    }
    if extensions:
        material["extensions"] = extensions
        doc["extensionsUsed"] = sorted(extensions)
    return doc


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "spheres"
    os.makedirs(out, exist_ok=True)
    pos, idx = sphere()
    coat = {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.1}
    volume = {"thicknessFactor": 0.5, "attenuationColor": [0.9, 0.6, 0.6],
              "attenuationDistance": 1.0}
    cases = {
        "plain": {},
        "clearcoat": {"KHR_materials_clearcoat": coat},
        "layers": {
            "KHR_materials_clearcoat": coat,
            "KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5],
                                    "sheenRoughnessFactor": 0.5},
            "KHR_materials_specular": {"specularFactor": 0.8,
                                       "specularColorFactor": [1, 0.9, 0.9]},
            "KHR_materials_iridescence": {"iridescenceFactor": 1.0, "iridescenceIor": 1.3,
                                          "iridescenceThicknessMaximum": 400},
        },
        # Transmission (with a volume), and the same file with
        # transmissionFactor 0: what transmission costs.
        "glass": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                  "KHR_materials_volume": volume},
        "glass-off": {"KHR_materials_transmission": {"transmissionFactor": 0.0},
                      "KHR_materials_volume": volume},
    }
    for name, ext in cases.items():
        with open(os.path.join(out, name + ".gltf"), "w") as f:
            json.dump(document(pos, idx, ext), f)
    print(f"{len(idx) // 3} triangles: {', '.join(cases)} in {out}")


if __name__ == "__main__":
    main()
