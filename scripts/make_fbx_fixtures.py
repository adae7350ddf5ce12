"""Writes the FBX test files of tests/data/fbx with Blender's own FBX
exporter (pip install bpy==5.0.1; Python 3.11):

- cube_embedded.fbx: a 2-unit cube, its faces quads, turned 30 degrees
  about Z and moved up 1 unit, with a material whose base colour is a
  64x64 checker of 8-texel red and white squares embedded in the file,
  and vertex colours (every other corner green halved);
- cube_external.fbx: the same without vertex colours, the checker as
  fbx_checker.png beside it;
- rigged.fbx: a cylinder skinned to a two-bone armature with a 10-frame
  bend;
- lit_camera.fbx: a cube with a camera, a point, a sun and a spot light;
- shape_keys.fbx: a cube whose keyed shape key raises its top.

    python3 scripts/make_fbx_fixtures.py tests/wild
"""
import os
import sys

import bpy

out = os.path.abspath(sys.argv[1])
os.makedirs(out, exist_ok=True)


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def checker():
    img = bpy.data.images.new("checker", 64, 64)
    px = []
    for y in range(64):
        for x in range(64):
            px += [1.0, 0.0, 0.0, 1.0] if (x // 8 + y // 8) % 2 else [1.0, 1.0, 1.0, 1.0]
    img.pixels = px
    img.filepath_raw = os.path.join(out, "fbx_checker.png")
    img.file_format = "PNG"
    img.save()
    return img


def cube(img, colours):
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0, 0, 1), rotation=(0, 0, 0.5236))
    obj = bpy.context.active_object
    mat = bpy.data.materials.new("checker_mat")
    mat.use_nodes = True
    tree = mat.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = "Closest"
    tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    bsdf.inputs["Roughness"].default_value = 0.4
    obj.data.materials.append(mat)
    if colours:
        col = obj.data.color_attributes.new("Col", "FLOAT_COLOR", "CORNER")
        for k, c in enumerate(col.data):
            c.color = (1.0, 1.0 if k % 2 else 0.5, 1.0, 1.0)
    return obj


reset()
img = checker()
cube(img, True)
bpy.ops.export_scene.fbx(filepath=os.path.join(out, "cube_embedded.fbx"), path_mode="COPY", embed_textures=True)
reset()
img = checker()
cube(img, False)
bpy.ops.export_scene.fbx(filepath=os.path.join(out, "cube_external.fbx"), path_mode="RELATIVE")

reset()
bpy.ops.mesh.primitive_cylinder_add(vertices=12, radius=0.3, depth=2.0, location=(0, 0, 1))
body = bpy.context.active_object
bpy.ops.object.armature_add(location=(0, 0, 0))
arm = bpy.context.active_object
bpy.ops.object.mode_set(mode="EDIT")
b0 = arm.data.edit_bones[0]
b0.head, b0.tail = (0, 0, 0), (0, 0, 1)
b1 = arm.data.edit_bones.new("Bone.001")
b1.head, b1.tail, b1.parent = (0, 0, 1), (0, 0, 2), b0
bpy.ops.object.mode_set(mode="OBJECT")
body.select_set(True)
arm.select_set(True)
bpy.context.view_layer.objects.active = arm
bpy.ops.object.parent_set(type="ARMATURE_AUTO")
bpy.context.view_layer.objects.active = arm
bpy.ops.object.mode_set(mode="POSE")
pb = arm.pose.bones["Bone.001"]
pb.rotation_mode = "XYZ"
for f, angle in [(1, 0.0), (10, 0.8)]:
    pb.rotation_euler = (angle, 0, 0)
    pb.keyframe_insert("rotation_euler", frame=f)
bpy.ops.object.mode_set(mode="OBJECT")
bpy.ops.export_scene.fbx(filepath=os.path.join(out, "rigged.fbx"), bake_anim=True)
print("wrote", sorted(os.listdir(out)))

# lit_camera.fbx: a 2-unit cube at the origin, a camera 10 units in front
# of it (Blender -Y, 45-degree vertical field of view) looking at it, a
# 1000 W point light 4 units above it, a sun pointing straight down and a
# spot light at +X pointing at the cube (cone 60 degrees, blend 0.25).
reset()
bpy.ops.mesh.primitive_cube_add(size=2.0)
bpy.ops.object.camera_add(location=(0, -10, 0), rotation=(1.5707963, 0, 0))
cam = bpy.context.active_object
cam.data.sensor_fit = "VERTICAL"
cam.data.angle = 0.7853982
bpy.ops.object.light_add(type="POINT", location=(0, 0, 4))
bpy.context.active_object.data.energy = 1000.0
bpy.ops.object.light_add(type="SUN", location=(0, 0, 6), rotation=(0, 0, 0))
bpy.context.active_object.data.energy = 3.0
bpy.ops.object.light_add(type="SPOT", location=(6, 0, 0), rotation=(0, 1.5707963, 0))
spot = bpy.context.active_object
spot.data.energy = 500.0
spot.data.spot_size = 1.0471976
spot.data.spot_blend = 0.25
bpy.ops.export_scene.fbx(filepath=os.path.join(out, "lit_camera.fbx"))
print("wrote lit_camera.fbx")

# shape_keys.fbx: a 2-unit cube whose shape key "Up" raises its top four
# vertices by 1 unit (Blender Z), its value keyed from 0 at frame 1 to 1 at
# frame 11.
reset()
bpy.ops.mesh.primitive_cube_add(size=2.0)
box = bpy.context.active_object
box.shape_key_add(name="Basis")
up = box.shape_key_add(name="Up")
for v in up.data:
    if v.co.z > 0:
        v.co.z += 1.0
up.value = 0.0
up.keyframe_insert("value", frame=1)
up.value = 1.0
up.keyframe_insert("value", frame=11)
up.value = 0.0
# The exporter writes a stack for objects with keys of their own.
box.keyframe_insert("location", frame=1)
box.keyframe_insert("location", frame=11)
bpy.ops.export_scene.fbx(filepath=os.path.join(out, "shape_keys.fbx"), bake_anim=True)
print("wrote shape_keys.fbx")
