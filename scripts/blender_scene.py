"""What the scripts that build ptr's Blender fixtures share
(scripts/blender_fixtures.py, tests/fixtures/ecosystem/make_blender.py):
glTF's frame in Blender's, and a Principled BSDF material. Runs inside
Blender (bpy)."""
import bpy


def blender_xyz(x, y, z):
    """glTF and OBJ (as exported) are +Y up; Blender is +Z up."""
    return (x, -z, y)


def principled(name, base, metallic=0.0, roughness=0.5, transmission=0.0, ior=1.45,
             emission=(0, 0, 0), strength=0.0):
    """A material of the Principled BSDF with these inputs (Blender 3.x's
    names), the others at their defaults."""
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
