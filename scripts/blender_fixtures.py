"""Builds ptr's Blender test scene and exports it with Blender's own exporters:
glTF (.gltf with a separate .bin, and .glb, cameras included) and OBJ (with and
without its PBR extensions). tests/import/test_blender.c checks the imports
against the values set here.

Run through scripts/make-blender-fixtures.sh, or:
    blender -b --factory-startup --python scripts/blender_fixtures.py -- OUT_DIR
"""
import math
import sys

import bpy
from mathutils import Vector

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.resolution_x = 320
scene.render.resolution_y = 240


def blender_xyz(x, y, z):
    """glTF and OBJ (as exported) are +Y up; Blender is +Z up."""
    return (x, -z, y)


def material(name, base, metallic=0.0, roughness=0.5, transmission=0.0, ior=1.45,
             emission=(0, 0, 0), strength=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*base, 1.0)
    p.inputs["Metallic"].default_value = metallic
    p.inputs["Roughness"].default_value = roughness
    p.inputs["Transmission"].default_value = transmission
    p.inputs["IOR"].default_value = ior
    p.inputs["Emission"].default_value = (*emission, 1.0)
    p.inputs["Emission Strength"].default_value = strength
    return m


def sphere(name, centre, radius, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=radius,
                                         location=blender_xyz(*centre))
    obj = bpy.context.active_object
    obj.name = name
    obj.data.name = name
    obj.data.materials.append(mat)


# name, centre (+Y up), radius, material: the values the test checks.
sphere("GroundSphere", (0, -100, 0), 100, material("Ground", (0.5, 0.5, 0.5), roughness=1.0))
sphere("DiffuseSphere", (0, 1, 0), 1, material("Clay", (0.8, 0.2, 0.1)))
sphere("MetalSphere", (2.5, 1, 0), 1, material("Brass", (0.9, 0.8, 0.6), metallic=1.0,
                                                   roughness=0.25))
sphere("GlassSphere", (-2.5, 1, 0), 1, material("Glass", (1, 1, 1), roughness=0.0,
                                                    transmission=1.0, ior=1.45))
sphere("LampSphere", (0, 3.5, -2), 0.5, material("Lamp", (0.1, 0.1, 0.1),
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
