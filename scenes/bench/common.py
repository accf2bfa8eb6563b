# Helpers shared by the benchmark scenes (scenes/bench/*.py), run inside Blender. Every scene is
# built from nothing by bpy so that `make bench` needs no .blend file in git; each scene module has
# build(**options) and, run as a script, saves a .blend:
#     blender -b --python scenes/bench/mesh_1m.py -- OUT.blend
import sys

import bpy
import numpy as np


def clear():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for blocks in (bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras, bpy.data.images):
        for block in list(blocks):
            if block.name != "Render Result" and block.users == 0:
                blocks.remove(block)
    return bpy.context.scene


def link(obj):
    bpy.context.scene.collection.objects.link(obj)
    return obj


def diffuse(name, color, image=None):
    """A Diffuse BSDF material (the only surface TOYRT's direct lighting shades), optionally textured."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*color, 1.0)
    if image is not None:
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.interpolation = "Linear"
        links.new(tex.outputs["Color"], bsdf.inputs["Color"])
    links.new(bsdf.outputs[0], out.inputs["Surface"])
    return mat


def mesh_object(name, vertices, faces, material, location=(0, 0, 0), smooth=False):
    """A mesh from numpy arrays (vertices (N, 3), triangles or quads (M, k)) through foreach_set,
    which builds a million triangles in a second where from_pydata takes a minute."""
    vertices = np.asarray(vertices, np.float32)
    faces = np.asarray(faces, np.int32)
    k = faces.shape[1]
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(vertices))
    me.vertices.foreach_set("co", vertices.ravel())
    me.loops.add(faces.size)
    me.loops.foreach_set("vertex_index", faces.ravel())
    me.polygons.add(len(faces))
    me.polygons.foreach_set("loop_start", np.arange(0, faces.size, k, dtype=np.int32))
    me.polygons.foreach_set("loop_total", np.full(len(faces), k, np.int32))
    me.polygons.foreach_set("use_smooth", np.full(len(faces), smooth, bool))
    me.update(calc_edges=True)
    me.validate()
    if material is not None:
        me.materials.append(material)
    obj = link(bpy.data.objects.new(name, me))
    obj.location = location
    return obj


def box(name, size, location, material, rotation_z=0.0):
    sx, sy, sz = (size, size, size) if np.isscalar(size) else size
    v = np.array([(x, y, z) for x in (-sx / 2, sx / 2) for y in (-sy / 2, sy / 2) for z in (-sz / 2, sz / 2)])
    f = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    obj = mesh_object(name, v, f, material, location)
    obj.rotation_euler = (0, 0, rotation_z)
    return obj


def plane(name, size, location, material):
    h = size / 2
    return mesh_object(name, [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [(0, 1, 2, 3)], material, location)


def uv_sphere_arrays(rings, segments, radius=1.0, bumps=0.0, bump_freq=12):
    """Vertices and triangles of a closed UV sphere; bumps > 0 modulates the radius (a detailed,
    non-convex surface that shadows itself)."""
    th = np.pi * np.arange(1, rings) / rings
    ph = 2 * np.pi * np.arange(segments) / segments
    T, P = np.meshgrid(th, ph, indexing="ij")
    r = radius * (1 + bumps * np.sin(bump_freq * T) * np.sin(bump_freq * P))
    ring_v = np.stack([r * np.sin(T) * np.cos(P), r * np.sin(T) * np.sin(P), r * np.cos(T)], -1).reshape(-1, 3)
    v = np.vstack([[0, 0, radius], ring_v, [0, 0, -radius]])
    idx = lambda i, j: 1 + i * segments + (j % segments)  # noqa: E731  ring i (0-based), segment j
    j = np.arange(segments)
    tris = [np.stack([np.zeros(segments, int), idx(0, j), idx(0, j + 1)], 1)]
    for i in range(rings - 2):
        a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
        tris += [np.stack([a, b, c], 1), np.stack([a, c, d], 1)]
    last = len(v) - 1
    tris.append(np.stack([idx(rings - 2, j), np.full(segments, last), idx(rings - 2, j + 1)], 1))
    return v, np.vstack(tris)


def point_light(name, location, power, color=(1, 1, 1)):
    light = bpy.data.lights.new(name, "POINT")
    light.energy, light.color, light.shadow_soft_size = power, color, 0.0  # radius 0: a true point
    obj = link(bpy.data.objects.new(name, light))
    obj.location = location
    return obj


def area_light(name, location, size, size_y, power, color=(1, 1, 1), rotation=(0, 0, 0)):
    light = bpy.data.lights.new(name, "AREA")
    light.shape = "RECTANGLE"
    light.size, light.size_y, light.energy, light.color = size, size_y, power, color
    obj = link(bpy.data.objects.new(name, light))
    obj.location, obj.rotation_euler = location, rotation  # emits along local -Z
    # Seen by the camera, as in Cycles' default (bpy.data.objects.new leaves it off in 3.4): Mitsuba
    # can only hide every emitter at once, so the benchmark scenes show them all.
    obj.visible_camera = True
    return obj


def camera(location, target, lens=35.0):
    from mathutils import Vector
    cam = bpy.data.cameras.new("camera")
    cam.lens, cam.sensor_fit = lens, "AUTO"
    obj = link(bpy.data.objects.new("camera", cam))
    obj.location = location
    obj.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = obj
    return obj


def world(color):
    scene = bpy.context.scene
    if color is None:
        scene.world = None  # black, and nothing lights the surfaces
        return
    w = bpy.data.worlds.new("world")
    w.use_nodes = True
    w.node_tree.nodes["Background"].inputs["Color"].default_value = (*color, 1.0)
    scene.world = w


def finish():
    scene = bpy.context.scene
    scene.view_settings.view_transform = "Standard"  # linear values straight to the file
    return scene


def main(build):
    """Run as a script: build(), then save to the path after `--` (if any)."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    build()
    if argv:
        bpy.ops.wm.save_as_mainfile(filepath=argv[0])

