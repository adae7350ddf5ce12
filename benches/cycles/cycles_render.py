#!/usr/bin/env python3.11
"""Render one softraster scene with Blender Cycles: the path-traced reference.

Reads the scene's TOML (python3.11's tomllib) and builds the same shot in
Blender, headless through `pip install bpy==5.0.1` (Python 3.11, CPU):

- every `[[model]]` glTF through Blender's own glTF importer;
- the first `[[camera]]` (explicit `eye`, `target`, optional `up` and `fov`,
  vertical degrees, as the scene format says);
- `[environment]` `path`, `intensity` and `rotation` as the world, seen as
  the background;
- `output.width` x `output.height`.

Writes OUT.exr (linear, the render's scene-referred radiance) and OUT.png
(the "Standard" view transform: sRGB of the clamped linear value, which is
softraster's `render.tonemap = "clamp"` at `exposure = 0`).

Coordinates: glTF and softraster are +Y up, Blender +Z up; Blender's glTF
importer maps (x, y, z) to (x, -z, y) and so does this script. softraster's
lat-long lookup is u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi; Blender's
is u = 0.5 - atan2(y, x) / 2pi in its own axes, so the world's lookup
vector is turned by -90 degrees about +Z, less the scene's `rotation`.

What Blender's importer does not read is set on the Principled BSDF here:
`KHR_materials_iridescence` (thin film thickness and IOR) and
`KHR_materials_dispersion`. `KHR_materials_anisotropy` is read by the
importer, but into Principled's own anisotropy (alpha_x = r^2 / aspect,
alpha_y = r^2 aspect, aspect = sqrt(1 - 0.9 anisotropic), with the
strength as `anisotropic`), which is not the extension's lobe (alpha_t =
mix(alpha, 1, strength^2) along the direction, alpha_b = alpha across
it): a strength of 0.8 at roughness 0.35 gave alphas of 0.23 and 0.06
where the extension says 0.68 and 0.12. Where strength and roughness are
plain factors, roughness and anisotropic are set here so that Cycles'
alphas are the extension's. Without an anisotropy texture the importer
also leaves Principled's tangent unlinked, and Cycles then turns the
lobe around the object's vertical axis (its default radial tangent); the
extension's direction starts from the glTF tangent, +u, which a UV-map
Tangent node gives, as the importer links when there is a texture.
Anything else it lacks renders as Blender reads
it, and the table says so.

Usage: python3.11 cycles_render.py SCENE.toml OUT [--samples 128] [--no-denoise]

(--no-denoise with 1024 samples: FLIP 0.015-0.030 from the denoised
128-sample frame on five scenes of the set, and softraster's FLIP against
either within 0.002.)
"""
import argparse
import json
import math
import os
import sys
import tomllib

import bpy
from mathutils import Vector


def to_blender(v):
    return Vector((v[0], -v[2], v[1]))


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def import_models(scene, base):
    for model in scene.get("model", []):
        path = os.path.join(base, model["path"])
        before = set(bpy.data.materials)
        bpy.ops.import_scene.gltf(filepath=path)
        patch_materials(path, set(bpy.data.materials) - before)


def patch_materials(path, materials):
    """The extensions Blender's importer skips, set on the Principled BSDF."""
    if not path.endswith(".gltf"):
        return
    with open(path) as f:
        doc = json.load(f)
    by_name = {m.get("name"): m for m in doc.get("materials", [])}
    for mat in materials:
        gltf_mat = by_name.get(mat.name)
        if not gltf_mat or not mat.node_tree:
            continue
        ext = gltf_mat.get("extensions", {})
        bsdf = next((n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
        if bsdf is None:
            continue
        irid = ext.get("KHR_materials_iridescence")
        if irid and irid.get("iridescenceFactor", 0.0) > 0.0:
            thickness = irid.get("iridescenceThicknessMaximum", 400.0)
            bsdf.inputs["Thin Film Thickness"].default_value = thickness
            bsdf.inputs["Thin Film IOR"].default_value = irid.get("iridescenceIor", 1.3)
        disp = ext.get("KHR_materials_dispersion")
        if disp:
            # glTF's dispersion is 20 / Abbe number; Blender's input is 1 / Abbe.
            bsdf.inputs["Dispersion"].default_value = disp.get("dispersion", 0.0) / 20.0
        aniso = ext.get("KHR_materials_anisotropy")
        if aniso:
            anisotropy(bsdf, gltf_mat, aniso)


def anisotropy(bsdf, gltf_mat, ext):
    """Principled's roughness and anisotropic for the extension's alphas:
    r^2 = sqrt(alpha_t alpha_b), aspect^2 = alpha_b / alpha_t. Skipped
    where a texture drives either (the importer's node graph stays)."""
    pbr = gltf_mat.get("pbrMetallicRoughness", {})
    strength = ext.get("anisotropyStrength", 0.0)
    rough_in, aniso_in = bsdf.inputs["Roughness"], bsdf.inputs["Anisotropic"]
    if strength <= 0.0 or "anisotropyTexture" in ext or "metallicRoughnessTexture" in pbr \
            or rough_in.is_linked or aniso_in.is_linked:
        return
    alpha = pbr.get("roughnessFactor", 1.0) ** 2
    alpha_t = alpha + (1.0 - alpha) * strength * strength
    # Principled's aspect reaches sqrt(0.1) at most: beyond that the
    # lobe keeps the extension's area and is as long as Cycles allows.
    ratio = max(alpha / alpha_t, 0.1)
    rough_in.default_value = (alpha_t * alpha) ** 0.25
    aniso_in.default_value = (1.0 - ratio) / 0.9
    tangent_in = bsdf.inputs["Tangent"]
    if not tangent_in.is_linked:
        tree = bsdf.id_data
        node = tree.nodes.new("ShaderNodeTangent")
        node.direction_type = "UV_MAP"
        node.uv_map = "UVMap"
        tree.links.new(tangent_in, node.outputs["Tangent"])


def camera(scene):
    cams = scene.get("camera", [])
    if not cams or "eye" not in cams[0]:
        sys.exit("cycles_render: the scene needs a [[camera]] with eye and target")
    c = cams[0]
    eye, target = to_blender(c["eye"]), to_blender(c["target"])
    up = to_blender(c.get("up", [0.0, 1.0, 0.0]))
    data = bpy.data.cameras.new("cam")
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(c.get("fov", 45.0))
    data.clip_start = 0.01
    data.clip_end = 1.0e5
    obj = bpy.data.objects.new("cam", data)
    bpy.context.scene.collection.objects.link(obj)
    forward = (target - eye).normalized()
    right = forward.cross(up).normalized()
    true_up = right.cross(forward)
    from mathutils import Matrix
    rot = Matrix((right, true_up, -forward)).transposed()
    obj.matrix_world = Matrix.Translation(eye) @ rot.to_4x4()
    bpy.context.scene.camera = obj


def world(scene, base):
    env = scene.get("environment", {})
    if "path" not in env:
        sys.exit("cycles_render: the scene needs [environment] path")
    w = bpy.data.worlds.new("world")
    bpy.context.scene.world = w
    w.use_nodes = True
    nt = w.node_tree
    nt.nodes.clear()
    coord = nt.nodes.new("ShaderNodeTexCoord")
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = (
        0.0, 0.0, math.radians(-90.0 - env.get("rotation", 0.0)))
    tex = nt.nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(os.path.join(base, env["path"]))
    tex.interpolation = "Linear"
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Strength"].default_value = env.get("intensity", 1.0)
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    nt.links.new(tex.outputs["Color"], bg.inputs["Color"])
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])


def settings(scene, samples, denoise=True):
    s = bpy.context.scene
    out = scene.get("output", {})
    s.render.engine = "CYCLES"
    s.cycles.device = "CPU"
    s.cycles.samples = samples
    s.cycles.use_denoising = denoise
    s.cycles.seed = 1
    s.render.resolution_x = out.get("width", 256)
    s.render.resolution_y = out.get("height", 256)
    s.render.resolution_percentage = 100
    s.render.film_transparent = False
    s.view_settings.view_transform = "Standard"
    s.view_settings.look = "None"
    s.view_settings.exposure = 0.0
    s.view_settings.gamma = 1.0
    s.render.threads_mode = "AUTO"


def write(out):
    s = bpy.context.scene
    s.render.image_settings.file_format = "OPEN_EXR"
    s.render.image_settings.color_depth = "32"
    s.render.filepath = out + ".exr"
    bpy.ops.render.render(write_still=True)
    # The same render through the Standard view transform, as a PNG.
    img = bpy.data.images["Render Result"]
    s.render.image_settings.file_format = "PNG"
    s.render.image_settings.color_depth = "8"
    s.render.image_settings.color_mode = "RGB"
    img.save_render(out + ".png", scene=s)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scene")
    p.add_argument("out")
    p.add_argument("--samples", type=int, default=128)
    p.add_argument("--no-denoise", action="store_true",
                   help="leave the denoiser out (a converged reference needs many samples)")
    a = p.parse_args()
    with open(a.scene, "rb") as f:
        scene = tomllib.load(f)
    base = os.path.dirname(os.path.abspath(a.scene))
    reset()
    import_models(scene, base)
    camera(scene)
    world(scene, base)
    settings(scene, a.samples, not a.no_denoise)
    write(os.path.abspath(a.out))


if __name__ == "__main__":
    main()
