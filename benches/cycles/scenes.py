#!/usr/bin/env python3
"""The Cycles reference set's scenes: one glTF test scene per material
feature, plus FlightHelmet and CornellBox from ../shared/assets, each as a
softraster scene (TOML) lit by two HDRIs of ../shared/assets/hdri.

Standard library only. `python3 benches/cycles/scenes.py OUT` writes
OUT/models/*.gltf (and their PNG textures) and OUT/NAME-HDRI.toml; `run.py`
calls it.
"""
import base64
import json
import math
import os
import struct
import sys
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHARED = os.path.normpath(os.path.join(ROOT, "..", "shared", "assets"))
HDRIS = [("courtyard", 30.0), ("studio", 0.0)]
WIDTH, HEIGHT = 320, 240


# --- geometry ---------------------------------------------------------------

def sphere(radius=1.0, rings=48, segments=96):
    """A UV sphere: positions, normals, uvs, tangents (along +u), indices."""
    pos, nrm, uv, tan, idx = [], [], [], [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments + 1):
            ph = 2 * math.pi * j / segments
            n = (math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph))
            pos.append(tuple(radius * c for c in n))
            nrm.append(n)
            uv.append((j / segments, i / rings))
            tan.append((-math.sin(ph), 0.0, -math.cos(ph), 1.0))
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j
            b = a + segments + 1
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return {"pos": pos, "nrm": nrm, "uv": uv, "tan": tan, "idx": idx}


def grid(w, h, nx, ny, height=None):
    """A sheet in the XY plane facing +Z, optionally displaced along z by
    height(x, y) (normals from its slopes)."""
    pos, nrm, uv, tan, idx = [], [], [], [], []
    for i in range(ny + 1):
        for j in range(nx + 1):
            x, y = (j / nx - 0.5) * w, (i / ny - 0.5) * h
            z, dzx, dzy = height(x, y) if height else (0.0, 0.0, 0.0)
            n = (-dzx, -dzy, 1.0)
            ln = math.sqrt(sum(c * c for c in n))
            pos.append((x, y, z))
            nrm.append(tuple(c / ln for c in n))
            uv.append((j / nx, 1.0 - i / ny))
            tan.append((1.0, 0.0, 0.0, 1.0))
    for i in range(ny):
        for j in range(nx):
            a = i * (nx + 1) + j
            b = a + nx + 1
            idx += [a, a + 1, b, b, a + 1, b + 1]
    return {"pos": pos, "nrm": nrm, "uv": uv, "tan": tan, "idx": idx}


def disc(radius=1.0, segments=96):
    """A flat disc facing +Z, tangent +X, uv across its square."""
    pos, nrm, uv, tan, idx = [(0.0, 0.0, 0.0)], [(0, 0, 1)], [(0.5, 0.5)], [(1, 0, 0, 1)], []
    for j in range(segments + 1):
        ph = 2 * math.pi * j / segments
        x, y = radius * math.cos(ph), radius * math.sin(ph)
        pos.append((x, y, 0.0))
        nrm.append((0, 0, 1))
        uv.append((0.5 + x / (2 * radius), 0.5 - y / (2 * radius)))
        tan.append((1, 0, 0, 1))
    for j in range(segments):
        idx += [0, j + 1, j + 2]
    return {"pos": pos, "nrm": nrm, "uv": uv, "tan": tan, "idx": idx}


# --- images -----------------------------------------------------------------

def png(width, height, pixel):
    """An RGBA8 PNG of pixel(x, y) -> (r, g, b, a)."""
    rows = b"".join(
        b"\x00" + bytes(c for x in range(width) for c in pixel(x, y)) for y in range(height))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))
    head = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head)
            + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))


def checker(light=(230, 230, 230, 255), dark=(40, 40, 40, 255), n=8, size=256):
    return png(size, size, lambda x, y: light if (x * n // size + y * n // size) % 2 == 0 else dark)


def letters(size=256):
    """A checker with a red arrow pointing up-right: shows flips and turns."""
    def pixel(x, y):
        u, v = x / size, 1.0 - y / size
        if abs(u - v) < 0.05 and 0.2 < u < 0.8 or (0.6 < u < 0.8 and 0.75 < v < 0.8) \
                or (0.75 < u < 0.8 and 0.6 < v < 0.8):
            return (220, 30, 30, 255)
        return (210, 210, 200, 255) if (x * 8 // size + y * 8 // size) % 2 == 0 else (60, 80, 120, 255)
    return png(size, size, pixel)


def holes(size=256):
    """White with round holes (alpha 0) for the alpha mask."""
    def pixel(x, y):
        cx, cy = (x % 64) - 32, (y % 64) - 32
        return (240, 200, 60, 0 if cx * cx + cy * cy < 400 else 255)
    return png(size, size, pixel)


def bumps(size=128, n=16):
    """A tangent-space normal map of n x n round bumps (hemispheres that
    fill their cells): detail that sparkles under a sharp light once a bump
    is a pixel or two on screen."""
    cell = size / n

    def pixel(x, y):
        dx = ((x + 0.5) % cell) / cell * 2 - 1
        dy = ((y + 0.5) % cell) / cell * 2 - 1
        r2 = dx * dx + dy * dy
        if r2 >= 0.81:
            return (128, 128, 255, 255)
        z = math.sqrt(1 - r2)
        # Image rows run down: +v (the bitangent) is up the image.
        return (round((dx + 1) * 127.5), round((-dy + 1) * 127.5), round((z + 1) * 127.5), 255)
    return png(size, size, pixel)


# --- glTF -------------------------------------------------------------------

class Gltf:
    def __init__(self):
        self.blob = bytearray()
        self.doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}],
                    "nodes": [], "meshes": [], "materials": [], "accessors": [],
                    "bufferViews": [], "buffers": []}
        self.used = set()
        self.geometry = {}

    def _view(self, data, target=None):
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.blob += data
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, rows, kind, minmax=False):
        flat = [c for r in rows for c in r]
        view = self._view(struct.pack("<%df" % len(flat), *flat), 34962)
        acc = {"bufferView": view, "componentType": 5126, "count": len(rows), "type": kind}
        if minmax:
            acc["min"] = [min(r[i] for r in rows) for i in range(len(rows[0]))]
            acc["max"] = [max(r[i] for r in rows) for i in range(len(rows[0]))]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name, base=(0.8, 0.8, 0.8, 1.0), metallic=0.0, roughness=0.5,
                 extensions=None, **extra):
        m = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": list(base), "metallicFactor": metallic,
            "roughnessFactor": roughness}}
        m.update(extra)
        if extensions:
            m["extensions"] = extensions
            self.used.update(extensions)
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def texture(self, png_bytes, transform=None):
        d = self.doc
        d.setdefault("images", []).append(
            {"uri": "data:image/png;base64," + base64.b64encode(png_bytes).decode()})
        d.setdefault("samplers", [{"magFilter": 9729, "minFilter": 9987}])
        d.setdefault("textures", []).append({"source": len(d["images"]) - 1, "sampler": 0})
        info = {"index": len(d["textures"]) - 1}
        if transform:
            info["extensions"] = {"KHR_texture_transform": transform}
            self.used.add("KHR_texture_transform")
        return info

    def _geometry(self, geo):
        """The accessors of geo, written once however many meshes use it."""
        key = id(geo)
        if key not in self.geometry:
            attrs = {"POSITION": self._accessor(geo["pos"], "VEC3", True),
                     "NORMAL": self._accessor(geo["nrm"], "VEC3"),
                     "TEXCOORD_0": self._accessor(geo["uv"], "VEC2"),
                     "TANGENT": self._accessor(geo["tan"], "VEC4")}
            view = self._view(struct.pack("<%dI" % len(geo["idx"]), *geo["idx"]), 34963)
            self.doc["accessors"].append({"bufferView": view, "componentType": 5125,
                                          "count": len(geo["idx"]), "type": "SCALAR"})
            # geo is kept alive with its accessors: a freed dict's id can be reused.
            self.geometry[key] = (attrs, len(self.doc["accessors"]) - 1, geo)
        attrs, indices, _ = self.geometry[key]
        return dict(attrs), indices

    def mesh(self, geo, material, translation=(0, 0, 0), rotation=None, colors=None):
        attrs, indices = self._geometry(geo)
        if colors:
            attrs["COLOR_0"] = self._accessor(colors, "VEC4")
        self.doc["meshes"].append({"primitives": [{
            "attributes": attrs, "indices": indices, "material": material}]})
        node = {"mesh": len(self.doc["meshes"]) - 1, "translation": list(translation)}
        if rotation:
            node["rotation"] = list(rotation)
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.blob), "uri":
                                "data:application/octet-stream;base64,"
                                + base64.b64encode(bytes(self.blob)).decode()}]
        if self.used:
            self.doc["extensionsUsed"] = sorted(self.used)
        with open(path, "w") as f:
            json.dump(self.doc, f)


def axis_angle(axis, degrees):
    s = math.sin(math.radians(degrees) / 2)
    return (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(math.radians(degrees) / 2))


def row(n, spacing):
    return [((i - (n - 1) / 2) * spacing, 0.0, 0.0) for i in range(n)]


# --- the scenes ---------------------------------------------------------------

def bumpy_metal(g):
    """A polished metal ball covered in small bumps (a normal map repeated
    4 x 2 times): the specular anti-aliasing case."""
    m = g.material("bumpy", (0.95, 0.64, 0.54, 1), 1.0, 0.15,
                   normalTexture=g.texture(bumps(), {"scale": [4.0, 2.0]}))
    g.mesh(sphere(1.0, 96, 192), m)
    return (0.0, 0.0, 3.4), (0.0, 0.0, 0.0), 40.0


def clearcoat_grid(g):
    ball = sphere(0.45)
    for i, factor in enumerate([0.25, 0.5, 1.0]):
        for j, rough in enumerate([0.0, 0.2, 0.5]):
            m = g.material(f"coat{i}{j}", (0.6, 0.05, 0.05, 1), 0.0, 0.6, {
                "KHR_materials_clearcoat": {"clearcoatFactor": factor,
                                            "clearcoatRoughnessFactor": rough}})
            g.mesh(ball, m, ((j - 1) * 1.05, (1 - i) * 1.05, 0))
    return (0.0, 0.0, 5.2), (0.0, 0.0, 0.0), 36.0


def sheen_cloth(g):
    def folds(x, y):
        return (0.12 * math.sin(3 * x) * math.cos(2 * y), 0.36 * math.cos(3 * x) * math.cos(2 * y),
                -0.24 * math.sin(3 * x) * math.sin(2 * y))
    cloth = g.material("velvet", (0.05, 0.05, 0.25, 1), 0.0, 0.8, {
        "KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.5, 0.8], "sheenRoughnessFactor": 0.4}})
    g.mesh(grid(3.2, 2.0, 96, 60, folds), cloth, (0, 0.35, -0.3),
           axis_angle((1, 0, 0), -25))
    ball = sphere(0.45)
    for x, rough in [(-0.8, 0.3), (0.8, 0.8)]:
        m = g.material(f"sheen{rough}", (0.2, 0.02, 0.02, 1), 0.0, 0.9, {
            "KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0],
                                    "sheenRoughnessFactor": rough}})
        g.mesh(ball, m, (x, -0.75, 0.4))
    return (0.0, 0.6, 4.6), (0.0, -0.1, 0.0), 36.0


def transmission_volume(g):
    cases = [
        # Solid clear glass: Blender's importer renders every transmissive
        # glTF material as a solid (its thin walls included).
        ("clear", 0.0, {"thicknessFactor": 1.0}),
        ("clear_rough", 0.3, {"thicknessFactor": 1.0}),
        ("green_volume", 0.0, {"thicknessFactor": 1.0, "attenuationColor": [0.3, 0.9, 0.4],
                               "attenuationDistance": 0.6}),
        ("amber_volume_rough", 0.2, {"thicknessFactor": 1.0, "attenuationColor": [0.9, 0.6, 0.2],
                                     "attenuationDistance": 0.8}),
    ]
    ball = sphere(0.5)
    for (name, rough, volume), at in zip(cases, row(4, 1.1)):
        ext = {"KHR_materials_transmission": {"transmissionFactor": 1.0}}
        if volume:
            ext["KHR_materials_volume"] = volume
        g.mesh(ball, g.material(name, (1, 1, 1, 1), 0.0, rough, ext), at)
    return (0.0, 0.5, 6.0), (0.0, 0.0, 0.0), 30.0


def glass_backdrop(g):
    backdrop = g.material("checker", (1, 1, 1, 1), 0.0, 0.7)
    g.doc["materials"][backdrop]["pbrMetallicRoughness"]["baseColorTexture"] = \
        g.texture(letters())
    g.mesh(grid(3.0, 3.0, 1, 1), backdrop, (0, 0, -1.0))
    glass = g.material("glass", (1, 1, 1, 1), 0.0, 0.0, {
        "KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_volume": {"thicknessFactor": 1.2},
        "KHR_materials_ior": {"ior": 1.5}})
    g.mesh(sphere(0.6), glass, (0, 0, 0.2))
    return (0.0, 0.0, 4.0), (0.0, 0.0, 0.0), 38.0


def anisotropy_discs(g):
    plate = disc(0.55)
    for i, (rot, strength) in enumerate([(0, 0.8), (45, 0.8), (90, 0.8), (0, 0.0)]):
        m = g.material(f"brushed{i}", (0.95, 0.93, 0.88, 1), 1.0, 0.35, {
            "KHR_materials_anisotropy": {"anisotropyStrength": strength,
                                         "anisotropyRotation": math.radians(rot)}})
        x, y = (i % 2 - 0.5) * 1.25, (0.5 - i // 2) * 1.25
        g.mesh(plate, m, (x, y, 0), axis_angle((1, 0, 0), -35))
    return (0.0, 0.0, 4.4), (0.0, 0.0, 0.0), 36.0


def iridescence(g):
    ball = sphere(0.5)
    for thick, at in zip([250, 400, 600], row(3, 1.15)):
        m = g.material(f"film{thick}", (0.05, 0.05, 0.05, 1), 0.0, 0.15, {
            "KHR_materials_iridescence": {"iridescenceFactor": 1.0, "iridescenceIor": 1.33,
                                          "iridescenceThicknessMinimum": thick,
                                          "iridescenceThicknessMaximum": thick}})
        g.mesh(ball, m, at)
    return (0.0, 0.4, 4.2), (0.0, 0.0, 0.0), 32.0


def specular_ior(g):
    cases = [("ior1.2", {"KHR_materials_ior": {"ior": 1.2}}),
             ("ior1.5", {"KHR_materials_ior": {"ior": 1.5}}),
             ("ior2.0", {"KHR_materials_ior": {"ior": 2.0}}),
             ("specular_tint", {"KHR_materials_specular": {
                 "specularFactor": 1.0, "specularColorFactor": [1.0, 0.5, 0.2]}}),
             ("specular_half", {"KHR_materials_specular": {"specularFactor": 0.5}})]
    ball = sphere(0.45)
    for (name, ext), at in zip(cases, row(5, 1.05)):
        g.mesh(ball, g.material(name, (0.1, 0.2, 0.5, 1), 0.0, 0.25, ext), at)
    return (0.0, 0.3, 6.0), (0.0, 0.0, 0.0), 30.0


def emissive_strength(g):
    ball = sphere(0.5)
    for s, at in zip([1.0, 4.0, 10.0], row(3, 1.15)):
        m = g.material(f"glow{s}", (0.2, 0.2, 0.2, 1), 0.0, 0.5,
                       {"KHR_materials_emissive_strength": {"emissiveStrength": s}}
                       if s != 1.0 else None, emissiveFactor=[1.0, 0.4, 0.1])
        g.mesh(ball, m, at)
    return (0.0, 0.4, 5.0), (0.0, 0.0, 0.0), 32.0


def texture_transform(g):
    quad = grid(1.4, 1.4, 1, 1)
    for i, transform in enumerate([None, {"offset": [0.25, 0.0], "rotation": 0.5,
                                          "scale": [2.0, 1.5]}]):
        m = g.material(f"tt{i}", (1, 1, 1, 1), 0.0, 0.6)
        g.doc["materials"][m]["pbrMetallicRoughness"]["baseColorTexture"] = \
            g.texture(letters(), transform)
        g.mesh(quad, m, ((i - 0.5) * 1.6, 0, 0), axis_angle((1, 0, 0), -20))
    return (0.0, 0.3, 4.0), (0.0, 0.0, 0.0), 36.0


def alpha_modes(g):
    g.mesh(sphere(0.55), g.material("behind", (0.7, 0.7, 0.7, 1), 0.0, 0.4), (0, 0, -0.8))
    blend = g.material("blend", (0.9, 0.1, 0.1, 0.5), 0.0, 0.4, alphaMode="BLEND")
    g.mesh(grid(1.2, 1.2, 1, 1), blend, (-0.7, 0, 0))
    mask = g.material("mask", (1, 1, 1, 1), 0.0, 0.5, alphaMode="MASK", alphaCutoff=0.5,
                      doubleSided=True)
    g.doc["materials"][mask]["pbrMetallicRoughness"]["baseColorTexture"] = g.texture(holes())
    g.mesh(grid(1.2, 1.2, 1, 1), mask, (0.7, 0, 0))
    return (0.0, 0.3, 3.6), (0.0, 0.0, -0.2), 36.0


def vertex_colors(g):
    ball = sphere(0.7)
    colors = [(0.5 + 0.5 * n[0], 0.5 + 0.5 * n[1], 0.5 + 0.5 * n[2], 1.0) for n in ball["nrm"]]
    g.mesh(ball, g.material("painted", (1, 1, 1, 1), 0.0, 0.5), (-0.8, 0, 0), colors=colors)
    flat = grid(1.2, 1.2, 8, 8)
    ramp = [((p[0] + 0.6) / 1.2, 0.2, (p[1] + 0.6) / 1.2, 1.0) for p in flat["pos"]]
    g.mesh(flat, g.material("ramp", (1, 1, 1, 1), 0.0, 0.7), (0.8, 0, 0), colors=ramp)
    return (0.0, 0.3, 4.0), (0.0, 0.0, 0.0), 34.0


GENERATED = {
    "clearcoat-grid": clearcoat_grid,
    "sheen-cloth": sheen_cloth,
    "transmission-volume": transmission_volume,
    "glass-backdrop": glass_backdrop,
    "anisotropy-discs": anisotropy_discs,
    "iridescence": iridescence,
    "specular-ior": specular_ior,
    "emissive-strength": emissive_strength,
    "texture-transform": texture_transform,
    "alpha-blend-mask": alpha_modes,
    "vertex-colors": vertex_colors,
    "bumpy-metal": bumpy_metal,
}
SHARED_MODELS = {
    "flighthelmet": ("gltf/FlightHelmet/FlightHelmet.gltf",
                     (0.5, 0.45, 1.2), (0.0, 0.3, 0.0), 30.0),
    "cornellbox": ("gltf/CornellBox.glb", (-278.0, 273.0, 1050.0), (-278.0, 273.0, -280.0), 38.0),
}


def scene_toml(model, eye, target, fov, hdri, rotation):
    return f"""# The Cycles reference set (benches/cycles): written by scenes.py.
[output]
width = {WIDTH}
height = {HEIGHT}
background = "environment"

[render]
tonemap = "clamp"
exposure = 0.0
msaa = 4

[environment]
path = "{os.path.join(SHARED, 'hdri', hdri + '.exr')}"
rotation = {rotation}

[[model]]
path = "{model}"

[[camera]]
eye = {list(eye)}
target = {list(target)}
fov = {fov}
"""


def write_all(out):
    """Writes every scene; returns [(scene name, hdri, toml path)]."""
    models = os.path.join(out, "models")
    os.makedirs(models, exist_ok=True)
    views = {}
    for name, build in GENERATED.items():
        g = Gltf()
        views[name] = (os.path.join(models, name + ".gltf"),) + build(g)
        g.write(views[name][0])
    for name, (path, eye, target, fov) in SHARED_MODELS.items():
        views[name] = (os.path.join(SHARED, path), eye, target, fov)
    scenes = []
    for name, (model, eye, target, fov) in views.items():
        for hdri, rotation in HDRIS:
            path = os.path.join(out, f"{name}-{hdri}.toml")
            with open(path, "w") as f:
                f.write(scene_toml(model, eye, target, fov, hdri, rotation))
            scenes.append((name, hdri, path))
    return scenes


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "/tmp/softraster-cycles"
    for s in write_all(out):
        print(s[2])
