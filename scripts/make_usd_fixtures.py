"""Writes the USD test files of tests/wild with Blender's own USD
exporter (pip install bpy==5.0.1; Python 3.11): cube.usda, cube.usdc and
cube.usdz, Blender's 2-unit cube turned 30 degrees about Z and moved up
1 unit (Z up, metres), with a UsdPreviewSurface whose diffuse colour is
a 64x64 checker of 8-texel red and white squares: beside the first two
as textures/usd_checker.png, inside the package for the third.

    python3 scripts/make_usd_fixtures.py tests/wild
"""
import os
import sys

import bpy

out = os.path.abspath(sys.argv[1]); os.makedirs(out, exist_ok=True)
bpy.ops.wm.read_factory_settings(use_empty=True)
img = bpy.data.images.new("checker", 64, 64)
px = []
for y in range(64):
    for x in range(64):
        px += [1.0, 0.0, 0.0, 1.0] if (x // 8 + y // 8) % 2 else [1.0, 1.0, 1.0, 1.0]
img.pixels = px
os.makedirs(os.path.join(out, "textures"), exist_ok=True)
img.filepath_raw = os.path.join(out, "textures", "usd_checker.png"); img.file_format = "PNG"; img.save()
bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0, 0, 1), rotation=(0, 0, 0.5236))
obj = bpy.context.active_object
mat = bpy.data.materials.new("checker_mat"); mat.use_nodes = True
t = mat.node_tree; b = t.nodes["Principled BSDF"]
tex = t.nodes.new("ShaderNodeTexImage"); tex.image = img; tex.interpolation = "Closest"
t.links.new(tex.outputs["Color"], b.inputs["Base Color"])
b.inputs["Roughness"].default_value = 0.4
obj.data.materials.append(mat)
bpy.ops.wm.usd_export(filepath=os.path.join(out, "cube.usdz"))
bpy.ops.wm.usd_export(filepath=os.path.join(out, "cube.usda"))
bpy.ops.wm.usd_export(filepath=os.path.join(out, "cube.usdc"))
