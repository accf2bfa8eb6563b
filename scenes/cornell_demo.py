# The seed report's final scene, built with bpy: a Cornell box (red and green walls), a glass
# sphere on a checker-textured floor, a rectangular area light under the ceiling and two coloured
# point lights. Run by `make demo`:
#   blender -b --python scenes/cornell_demo.py -- OUTPUT.blend
# It saves the .blend; the Makefile then renders it with `blender -b OUTPUT.blend -E TOYRT -f 1`.
import math
import sys

import bpy


def diffuse(name, color, image=None):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    for n in list(nodes):
        if n.type != "OUTPUT_MATERIAL":
            nodes.remove(n)
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*color, 1.0)
    if image is not None:
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image
        links.new(tex.outputs["Color"], bsdf.inputs["Color"])
    links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


def glass(name, ior=1.5):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    for n in list(nodes):
        if n.type != "OUTPUT_MATERIAL":
            nodes.remove(n)
    bsdf = nodes.new("ShaderNodeBsdfGlass")
    bsdf.inputs["IOR"].default_value = ior
    mat.node_tree.links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


def checker_image(size=64, cells=8):
    img = bpy.data.images.new("checker", size, size)
    px = []
    for y in range(size):
        for x in range(size):
            on = ((x * cells // size) + (y * cells // size)) % 2
            px += [0.9, 0.9, 0.9, 1.0] if on else [0.15, 0.15, 0.2, 1.0]
    img.pixels[:] = px
    img.pack()
    return img


def wall(name, location, rotation, material, size=2.0):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location, rotation=rotation)
    obj = bpy.context.object
    obj.name = name
    obj.data.materials.append(material)
    return obj


def build(output):
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    scene = bpy.context.scene
    white = diffuse("white", (0.8, 0.8, 0.8))
    floor = diffuse("floor", (1, 1, 1), checker_image())
    red = diffuse("red", (0.8, 0.1, 0.1))
    green = diffuse("green", (0.1, 0.7, 0.1))
    # A 2 m box: floor at z = 0, open towards -Y where the camera stands.
    f = wall("floor", (0, 0, 0), (0, 0, 0), floor)
    uv = f.data.uv_layers.active.data
    for loop in uv:
        loop.uv = (loop.uv[0] * 2, loop.uv[1] * 2)
    wall("ceiling", (0, 0, 2), (math.pi, 0, 0), white)
    wall("back", (0, 1, 1), (math.pi / 2, 0, 0), white)
    wall("left", (-1, 0, 1), (0, math.pi / 2, 0), red)
    wall("right", (1, 0, 1), (0, -math.pi / 2, 0), green)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, location=(0.25, 0.2, 0.45), segments=64, ring_count=32)
    sphere = bpy.context.object
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(glass("glass"))
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(-0.45, 0.35, 0.25), rotation=(0, 0, 0.4))
    bpy.context.object.data.materials.append(white)

    area = bpy.data.lights.new("area", "AREA")
    area.shape = "RECTANGLE"
    area.size, area.size_y, area.energy = 0.6, 0.4, 60.0
    ao = bpy.data.objects.new("area", area)
    ao.location = (0, 0, 1.98)  # emits down (-Z)
    scene.collection.objects.link(ao)
    for name, loc, color in (("warm", (-0.6, -0.5, 1.5), (1.0, 0.6, 0.3)), ("cool", (0.6, -0.6, 1.2), (0.3, 0.5, 1.0))):
        light = bpy.data.lights.new(name, "POINT")
        light.energy, light.color, light.shadow_soft_size = 15.0, color, 0.0
        lo = bpy.data.objects.new(name, light)
        lo.location = loc
        scene.collection.objects.link(lo)

    cam = bpy.data.cameras.new("camera")
    cam.lens = 32
    co = bpy.data.objects.new("camera", cam)
    co.location = (0, -3.6, 1.0)
    co.rotation_euler = (math.pi / 2, 0, 0)
    scene.collection.objects.link(co)
    scene.camera = co
    scene.world = None
    scene.render.engine = "TOYRT"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 640, 480, 100
    scene.toyrt.samples = 64
    scene.view_settings.view_transform = "Standard"
    bpy.ops.wm.save_as_mainfile(filepath=output)


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    build(argv[0] if argv else "/tmp/toyrt_demo.blend")
