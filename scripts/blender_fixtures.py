"""Builds ptr's Blender test scene and exports it with Blender's own exporters:
glTF (.gltf with a separate .bin, and .glb, cameras included) and OBJ (with and
without its PBR extensions). tests/import/test_blender.c checks the imports
against the values set here.

Run through scripts/make-blender-fixtures.sh, or:
    blender -b --factory-startup --python scripts/blender_fixtures.py -- OUT_DIR
"""
import math
import os
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from blender_scene import blender_xyz, principled  # noqa: E402

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.resolution_x = 320
scene.render.resolution_y = 240


def sphere(name, centre, radius, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=radius,
                                         location=blender_xyz(*centre))
    obj = bpy.context.active_object
    obj.name = name
    obj.data.name = name
    obj.data.materials.append(mat)


# name, centre (+Y up), radius, material: the values the test checks.
sphere("GroundSphere", (0, -100, 0), 100, principled("Ground", (0.5, 0.5, 0.5), roughness=1.0))
sphere("DiffuseSphere", (0, 1, 0), 1, principled("Clay", (0.8, 0.2, 0.1)))
sphere("MetalSphere", (2.5, 1, 0), 1, principled("Brass", (0.9, 0.8, 0.6), metallic=1.0,
                                                     roughness=0.25))
sphere("GlassSphere", (-2.5, 1, 0), 1, principled("Glass", (1, 1, 1), roughness=0.0,
                                                      transmission=1.0, ior=1.45))
sphere("LampSphere", (0, 3.5, -2), 0.5, principled("Lamp", (0.1, 0.1, 0.1),
                                                      emission=(1.0, 0.9, 0.8), strength=4.0))

camera_data = bpy.data.cameras.new("Camera")
camera_data.sensor_fit = "VERTICAL"
camera_data.sensor_height = 24.0
camera_data.lens = 12.0 / math.tan(math.radians(40.0) / 2)  # 40 degrees vertically
camera = bpy.data.objects.new("Camera", camera_data)
scene.collection.objects.link(camera)
camera.location = blender_xyz(0, 2, 10)
look = Vector(blender_xyz(0, 1, 0)) - camera.location
camera.rotation_mode = "QUATERNION"
camera.rotation_quaternion = look.to_track_quat("-Z", "Y")
scene.camera = camera

bpy.ops.export_scene.gltf(filepath=f"{out}/spheres.gltf", export_format="GLTF_SEPARATE",
                          export_cameras=True, export_yup=True)
bpy.ops.export_scene.gltf(filepath=f"{out}/spheres.glb", export_format="GLB",
                          export_cameras=True, export_yup=True)
bpy.ops.wm.obj_export(filepath=f"{out}/spheres.obj", export_materials=True,
                      export_pbr_extensions=True, forward_axis="NEGATIVE_Z", up_axis="Y")
bpy.ops.wm.obj_export(filepath=f"{out}/spheres_nopbr.obj", export_materials=True,
                      export_pbr_extensions=False, forward_axis="NEGATIVE_Z", up_axis="Y")
