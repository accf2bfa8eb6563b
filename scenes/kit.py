"""The scene kit: the parts every bpy-built scene of TOYRT is made of (the demo, the benchmark
scenes in scenes/bench/, the Blender tests in tests/blender/ and the benchmarks in bench/), so a
plane, a point light or a Diffuse material is one thing everywhere and a fix reaches them all.

Runs inside Blender: Debian's 3.4 and the bpy module of 4.x/5.x (tests/blender/run_with_bpy.py).
Scripts put this folder on sys.path (Blender does not put a script's folder there) and
`import kit`. Where Blender's defaults differ between versions (the shading of new polygons, a
point light's radius), the kit sets the value itself, so a scene is the same in each.

Parts come from data (bpy.data.*.new, meshes from numpy arrays through foreach_set): unlike the
mesh operators they need no context and build a million triangles in a second.
"""
import sys

import bpy
import numpy as np
from cycles_like_toyrt import configure_cycles
from mathutils import Vector

# ---- the scene ----------------------------------------------------------------------------------


def clear_scene():
    """The current scene emptied: every object and collection, the data they leave behind (meshes,
    materials, lights, cameras, images, worlds, node groups, particle settings, actions) and linked
    libraries removed, no world. Returns the scene."""
    scene = bpy.context.scene
    # One batch: removing 10,000 objects one by one takes minutes (each removal updates relations).
    bpy.data.batch_remove(list(bpy.data.objects) + list(bpy.data.collections))
    for blocks in (bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras, bpy.data.images,
                   bpy.data.worlds, bpy.data.node_groups, bpy.data.particles, bpy.data.actions):
        for block in list(blocks):
            if block.name != "Render Result":
                try:
                    blocks.remove(block)
                except (RuntimeError, ReferenceError):
                    pass
    for lib in list(bpy.data.libraries):
        bpy.data.libraries.remove(lib)
    scene.world = None
    return scene


def link(obj, collection=None):
    """`obj` linked into `collection` (the scene's own collection by default)."""
    (collection or bpy.context.scene.collection).objects.link(obj)
    return obj


# ---- materials ----------------------------------------------------------------------------------

def surface(name, shader):
    """A node material whose surface is one new shader node of type `shader`: (material, node).
    More nodes can be added and linked to it; the output node is "Material Output"."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    node = nodes.new(shader)
    mat.node_tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat, node


def diffuse(name, color=(0.8, 0.8, 0.8), image=None):
    """A Diffuse BSDF material of linear RGB `color`, or of an image (an Image Texture node, bilinear
    and repeating: Blender's defaults, spelled out because TOYRT filters the same way)."""
    mat, bsdf = surface(name, "ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*color, 1.0)
    if image is not None:
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.interpolation, tex.extension = "Linear", "REPEAT"
        mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Color"])
    return mat


def glass(name, ior=1.5):
    """A smooth, white Glass BSDF: what TOYRT's Fresnel dielectric renders."""
    mat, bsdf = surface(name, "ShaderNodeBsdfGlass")
    if "SHARP" in bsdf.bl_rna.properties["distribution"].enum_items.keys():
        bsdf.distribution = "SHARP"      # 3.x; 4.0 removed it: GGX at roughness 0 is sharp there
    bsdf.inputs["Roughness"].default_value = 0.0
    bsdf.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bsdf.inputs["IOR"].default_value = ior
    return mat


def glossy(name, color, roughness, distribution="GGX"):
    """A Glossy BSDF (4.0+: the node is ShaderNodeBsdfAnisotropic, anisotropy 0), GGX by default:
    what TOYRT's glossy material renders (4.x/5.x default to Multiscatter GGX, which it does not)."""
    mat, bsdf = surface(name, "ShaderNodeBsdfGlossy")
    bsdf.distribution = distribution
    bsdf.inputs["Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    return mat


def diffuse_and_glossy(name, diffuse_color, glossy_color, roughness, fac=None):
    """A Mix Shader (factor fac) or, with fac None, an Add Shader of a Diffuse BSDF and a GGX
    Glossy BSDF (TOYRT: its 'diffuse_glossy' material)."""
    mat, mix = surface(name, "ShaderNodeAddShader" if fac is None else "ShaderNodeMixShader")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    first = 0 if fac is None else 1
    if fac is not None:
        mix.inputs[0].default_value = fac
    d = nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (*diffuse_color, 1.0)
    g = nodes.new("ShaderNodeBsdfGlossy")
    g.distribution = "GGX"
    g.inputs["Color"].default_value = (*glossy_color, 1.0)
    g.inputs["Roughness"].default_value = roughness
    links.new(d.outputs[0], mix.inputs[first])
    links.new(g.outputs[0], mix.inputs[first + 1])
    return mat


def metal(name, color, roughness):
    """A Principled BSDF with Metallic 1 (TOYRT: a glossy of its base colour, noted)."""
    mat, bsdf = surface(name, "ShaderNodeBsdfPrincipled")
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Metallic"].default_value = 1.0
    bsdf.inputs["Roughness"].default_value = roughness
    return mat


def emission(name, color, strength=1.0, sampling=None, image=None):
    """An Emission shader: a surface of radiance colour x strength on both sides, black itself.
    sampling: whether Cycles samples it as a light (4.x+ emission_sampling names; 3.x reads
    'NONE' as sample_as_light off); None leaves Blender's default (sampled). image: the colour
    is this image's (an Image Texture node's Color)."""
    mat, node = surface(name, "ShaderNodeEmission")
    node.inputs["Color"].default_value = (*color, 1.0)
    node.inputs["Strength"].default_value = strength
    if image is not None:
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.interpolation, tex.extension = "Linear", "REPEAT"
        mat.node_tree.links.new(tex.outputs["Color"], node.inputs["Color"])
    if sampling is not None:
        if hasattr(mat.cycles, "emission_sampling"):
            mat.cycles.emission_sampling = sampling
        else:
            mat.cycles.sample_as_light = sampling != "NONE"
    return mat


def input_of(node, *names):
    """The first of the named input sockets `node` has (Blender renamed some in 4.0)."""
    for n in names:
        if n in node.inputs:
            return node.inputs[n]
    raise KeyError(f"{node.bl_idname} has none of the inputs {names}")


def cut_out(name, color, image, kind="mix"):
    """A leaf-like cut-out of linear RGB `color` masked by `image`'s alpha: kind "mix", a Mix Shader
    whose Fac is the Image Texture's Alpha, a Transparent BSDF in its first input and a Diffuse
    BSDF in its second (the classic leaf material); kind "principled", a Principled BSDF whose
    Alpha is the image's Alpha."""
    if kind == "principled":
        mat = principled(name, color)
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        alpha = bsdf.inputs["Alpha"]
    else:
        mat, mix = surface(name, "ShaderNodeMixShader")
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        links.new(nodes.new("ShaderNodeBsdfTransparent").outputs[0], mix.inputs[1])
        bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Color"].default_value = (*color, 1.0)
        links.new(bsdf.outputs[0], mix.inputs[2])
        alpha = mix.inputs[0]
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation, tex.extension = "Linear", "REPEAT"
    mat.node_tree.links.new(tex.outputs["Alpha"], alpha)
    return mat


def _shader_and_image(mat, image, shader):
    """(the shader node: `shader`, or the one linked to the material's output when None; a new
    Image Texture node of `image`, bilinear and repeating)."""
    nodes = mat.node_tree.nodes
    if shader is None:
        out = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
        shader = out.inputs["Surface"].links[0].from_node
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation, tex.extension = "Linear", "REPEAT"
    return shader, tex


def normal_map(mat, image, strength=1.0, space="TANGENT", uv_map="", shader=None):
    """Wire an Image Texture of `image` (Non-Color data) through a Normal Map node (`space`,
    `strength`, `uv_map`: '' for the render-active UV map) into the Normal input of `shader` (the
    node linked to the material's output when None). Returns the Normal Map node."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    shader, tex = _shader_and_image(mat, image, shader)
    node = nodes.new("ShaderNodeNormalMap")
    node.space, node.uv_map = space, uv_map
    node.inputs["Strength"].default_value = strength
    links.new(tex.outputs["Color"], node.inputs["Color"])
    links.new(node.outputs["Normal"], shader.inputs["Normal"])
    return node


def bump(mat, image, strength=1.0, distance=1.0, invert=False, shader=None):
    """Wire an Image Texture of `image` (its Color as the height) through a Bump node into the
    Normal input of `shader` (the node linked to the material's output when None). Returns the
    Bump node."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    shader, tex = _shader_and_image(mat, image, shader)
    node = nodes.new("ShaderNodeBump")
    node.invert = invert
    node.inputs["Strength"].default_value = strength
    node.inputs["Distance"].default_value = distance
    links.new(tex.outputs["Color"], node.inputs["Height"])
    links.new(node.outputs["Normal"], shader.inputs["Normal"])
    return node


def height_image(name, size=256, cycles=3):
    """A float, Non-Color height field h = 0.5 + 0.5 sin(2 pi c u) sin(2 pi c v) over the unit UV
    square (c = `cycles`, tileable), grey."""
    u = (np.arange(size) + 0.5) / size
    su, sv = np.meshgrid(u, u)                      # rows: v, from the bottom (Blender's order)
    w = 2 * np.pi * cycles
    h = 0.5 + 0.5 * np.sin(w * su) * np.sin(w * sv)
    rgba = np.stack([h, h, h, np.ones_like(h)], -1)
    return image(name, rgba, float_buffer=True, colorspace="Non-Color")


def bump_normal_image(name, size=64, cycles=3, slope=0.5):
    """A float, Non-Color tangent-space normal map of the height h = a sin(2 pi c u) sin(2 pi c v)
    over the unit UV square (c = `cycles`, tileable), with the largest slope `slope`: each texel
    (n + 1) / 2 of n = normalize(-dh/du, -dh/dv, 1)."""
    u = (np.arange(size) + 0.5) / size
    su, sv = np.meshgrid(u, u)                      # rows: v, from the bottom (Blender's order)
    w = 2 * np.pi * cycles
    dhdu = slope * np.cos(w * su) * np.sin(w * sv)
    dhdv = slope * np.sin(w * su) * np.cos(w * sv)
    n = np.stack([-dhdu, -dhdv, np.ones_like(su)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    rgba = np.concatenate([0.5 * (n + 1.0), np.ones((size, size, 1))], -1)
    return image(name, rgba, float_buffer=True, colorspace="Non-Color")


def principled(name, color):
    """Blender's default node material, a Principled BSDF, of base colour `color`: what most
    users' materials are (the add-on renders it as a diffuse of that colour)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    return mat


def principled_dielectric(name, color, roughness, specular=0.5, tint=None, distribution=None):
    """A Principled BSDF (Metallic 0) with a specular layer of reflectance 0.08 x `specular` at
    normal incidence on every Blender: 3.x's Specular socket, 4.0+'s Specular IOR Level at IOR 1.5
    (F0 = 0.04 x 2 x level). `tint`: 3.x's scalar Specular Tint, or 4.0+'s colour. `distribution`
    None keeps the version's default (3.x GGX, 4.0+ Multiscatter GGX)."""
    mat = principled(name, color)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = roughness
    if "Specular IOR Level" in bsdf.inputs:
        bsdf.inputs["Specular IOR Level"].default_value = specular
        bsdf.inputs["IOR"].default_value = 1.5
        if tint is not None:
            bsdf.inputs["Specular Tint"].default_value = (*tint, 1.0)
    else:
        bsdf.inputs["Specular"].default_value = specular
        if tint is not None:
            bsdf.inputs["Specular Tint"].default_value = tint
    if distribution is not None:
        bsdf.distribution = distribution
    return mat


def image(name, rgba, float_buffer=False, colorspace=None, alpha=False):
    """A packed image of an (h, w, 4) array, rows from the bottom (Blender's order): 8-bit, or float
    with float_buffer. `colorspace` names how Blender decodes the values (default: sRGB for 8-bit,
    linear for float). alpha: the image keeps its alpha channel (a cut-out's mask)."""
    rgba = np.asarray(rgba, np.float32)
    img = bpy.data.images.new(name, rgba.shape[1], rgba.shape[0], alpha=alpha, float_buffer=float_buffer)
    img.pixels.foreach_set(rgba.ravel())
    img.pack()
    if colorspace is not None:
        img.colorspace_settings.name = colorspace
    return img


# ---- geometry -----------------------------------------------------------------------------------

def mesh_data(name, vertices, faces=(), edges=(), uvs=None, smooth=False):
    """A mesh datablock from arrays: vertices (N, 3); faces an (M, k) array of vertex indices, or a
    list of such arrays (blocks of polygons of different sizes, in order); loose edges (E, 2); uvs
    (corners, 2), one per face corner in the order of `faces`, as the UV map "UVMap". Polygons are
    flat unless `smooth` (set either way: Blender 3.4 makes new polygons flat, 4.1 and later smooth)."""
    co = np.asarray(vertices, np.float32).reshape(-1, 3)
    blocks = faces if isinstance(faces, list) and faces and isinstance(faces[0], np.ndarray) else [faces]
    blocks = [np.asarray(b, np.int32).reshape(len(b), -1) for b in blocks if len(b)]
    loops = np.concatenate([b.ravel() for b in blocks] or [np.zeros(0, np.int32)])
    sizes = np.concatenate([np.full(len(b), b.shape[1], np.int32) for b in blocks] or [np.zeros(0, np.int32)])
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(co))
    me.vertices.foreach_set("co", co.ravel())
    if len(edges):
        me.edges.add(len(edges))
        me.edges.foreach_set("vertices", np.asarray(edges, np.int32).ravel())
    me.loops.add(len(loops))
    me.loops.foreach_set("vertex_index", loops)
    me.polygons.add(len(sizes))
    me.polygons.foreach_set("loop_start", (np.cumsum(sizes) - sizes).astype(np.int32))
    me.polygons.foreach_set("loop_total", sizes)
    me.polygons.foreach_set("use_smooth", np.full(len(sizes), smooth, bool))
    me.update(calc_edges=len(sizes) > 0, calc_edges_loose=len(edges) > 0)
    if uvs is not None:
        me.uv_layers.new(name="UVMap").data.foreach_set("uv", np.asarray(uvs, np.float32).ravel())
    return me


def mesh_object(name, vertices, faces=(), material=None, location=(0, 0, 0), **options):
    """An object of a mesh_data(name, vertices, faces, **options) with `material`, in the scene."""
    me = mesh_data(name, vertices, faces, **options)
    if material is not None:
        me.materials.append(material)
    obj = link(bpy.data.objects.new(name, me))
    obj.location = location
    return obj


def plane(name, size, material=None, location=(0, 0, 0), uv_repeat=1.0):
    """A square of side `size` in the object's XY plane, facing +Z; UVs from 0 to uv_repeat."""
    h = size / 2
    uvs = np.float32([(0, 0), (1, 0), (1, 1), (0, 1)]) * uv_repeat
    return mesh_object(name, [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [(0, 1, 2, 3)], material, location,
                       uvs=uvs)


def box(name, size, location=(0, 0, 0), material=None, rotation_z=0.0):
    """A cube of side `size`, or a box of sides (sx, sy, sz), centred on `location`, six quads."""
    sx, sy, sz = (size, size, size) if np.isscalar(size) else size
    v = [(x, y, z) for x in (-sx / 2, sx / 2) for y in (-sy / 2, sy / 2) for z in (-sz / 2, sz / 2)]
    f = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    obj = mesh_object(name, v, f, material, location)
    obj.rotation_euler = (0, 0, rotation_z)
    return obj


def uv_sphere_arrays(rings, segments, radius=1.0, bumps=0.0, bump_freq=12, triangles=False):
    """Vertices and faces of a closed UV sphere with the topology of Blender's UV sphere: a triangle
    fan at each pole and quads between (2 * segments * (rings - 1) triangles); faces as mesh_data
    takes them, or with `triangles` one (F, 3) array, each quad (a, b, c, d) as (a, b, c), (a, c, d).
    bumps > 0 modulates the radius: a detailed, non-convex surface that shadows itself."""
    th = np.pi * np.arange(1, rings) / rings
    ph = 2 * np.pi * np.arange(segments) / segments
    T, P = np.meshgrid(th, ph, indexing="ij")
    r = radius * (1 + bumps * np.sin(bump_freq * T) * np.sin(bump_freq * P))
    ring_v = np.stack([r * np.sin(T) * np.cos(P), r * np.sin(T) * np.sin(P), r * np.cos(T)], -1).reshape(-1, 3)
    v = np.vstack([[0, 0, radius], ring_v, [0, 0, -radius]])
    idx = lambda i, j: 1 + i * segments + (j % segments)  # noqa: E731  ring i (0-based), segment j
    j = np.arange(segments)
    i = np.arange(rings - 2)[:, None]
    top = np.stack([np.zeros(segments, int), idx(0, j), idx(0, j + 1)], 1)
    quads = np.stack([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)], -1)   # (rings - 2, segments, 4)
    bottom = np.stack([idx(rings - 2, j), np.full(segments, len(v) - 1), idx(rings - 2, j + 1)], 1)
    if triangles:   # a ring of quads at a time: its (a, b, c) halves, then its (a, c, d) halves
        middle = np.concatenate([quads[..., [0, 1, 2]], quads[..., [0, 2, 3]]], axis=1).reshape(-1, 3)
        return v, np.vstack([top, middle, bottom])
    return v, [top, quads.reshape(-1, 4), bottom]


def uv_sphere(name, radius, location, material, segments=48, rings=24, smooth=True):
    """A UV sphere object (uv_sphere_arrays), smooth-shaded by default."""
    v, f = uv_sphere_arrays(rings, segments, radius)
    return mesh_object(name, v, f, material, location, smooth=smooth)


# ---- lights and camera --------------------------------------------------------------------------

def look_at(obj, target):
    """Turns `obj` so that its -Z axis points at `target`, +Y up (cameras and area lights)."""
    obj.rotation_euler = (Vector(target) - obj.location).to_track_quat("-Z", "Y").to_euler()


def point_light(name, location, power, color=(1, 1, 1), radius=0.0, soft_falloff=True):
    """A point light of `power` watts; radius 0 (a true point: the closed forms and TOYRT's light)
    unless given (Blender's default is 0.25 m in 3.4, 0 in 5.0). soft_falloff=False: a true sphere
    (Blender 4.0+; 3.x has no such switch and ignores it)."""
    light = bpy.data.lights.new(name, "POINT")
    light.energy, light.color, light.shadow_soft_size = power, color, radius
    if hasattr(light, "use_soft_falloff"):
        light.use_soft_falloff = soft_falloff
    obj = link(bpy.data.objects.new(name, light))
    obj.location = location
    return obj


def spot_light(name, location, power, spot_size, spot_blend=0.15, radius=0.0, target=(0, 0, 0), scale=(1, 1, 1),
               soft_falloff=True):
    """A spot light of `power` watts at `location` pointing at `target`, its cone `spot_size`
    radians wide (full angle), the object scaled by `scale` (Cycles 4.x follows it)."""
    light = bpy.data.lights.new(name, "SPOT")
    light.energy, light.shadow_soft_size = power, radius
    light.spot_size, light.spot_blend = spot_size, spot_blend
    if hasattr(light, "use_soft_falloff"):
        light.use_soft_falloff = soft_falloff
    obj = link(bpy.data.objects.new(name, light))
    obj.location = location
    look_at(obj, target)
    obj.scale = scale
    return obj


def sun_light(name, strength, direction, angle=0.0, color=(1, 1, 1)):
    """A sun of `strength` W/m^2 shining along `direction`, its disc `angle` radians across
    (0: hard shadows; Blender's default is 0.526 degrees)."""
    light = bpy.data.lights.new(name, "SUN")
    light.energy, light.angle, light.color = strength, angle, color
    obj = link(bpy.data.objects.new(name, light))
    obj.rotation_euler = Vector(direction).to_track_quat("-Z", "Y").to_euler()
    return obj


def area_light(name, location, power, size, size_y=None, color=(1, 1, 1), rotation=(0, 0, 0), target=None,
               shape="RECTANGLE", visible_camera=False):
    """An area light of `power` watts, `size` by `size_y` (size_y = size if not given), emitting along
    its local -Z: turned by `rotation`, or towards `target`. visible_camera: whether camera rays
    see it (False is Blender's default for a light made by bpy.data.objects.new)."""
    light = bpy.data.lights.new(name, "AREA")
    light.shape = shape
    light.size, light.size_y = size, size if size_y is None else size_y
    light.energy, light.color = power, color
    obj = link(bpy.data.objects.new(name, light))
    obj.location, obj.rotation_euler = location, rotation
    if target is not None:
        look_at(obj, target)
    obj.visible_camera = visible_camera
    return obj


def camera(location, target=None, rotation=(0, 0, 0), lens=50.0, ortho_scale=None, clip=(0.1, 1000.0)):
    """The scene's camera at `location`, looking along -Z turned by `rotation`, or at `target`:
    perspective with a `lens` mm lens (Blender's 36 mm sensor, fit to the larger side), or
    orthographic `ortho_scale` wide. Blender's defaults for lens and clipping."""
    cam = bpy.data.cameras.new("camera")
    if ortho_scale is not None:
        cam.type, cam.ortho_scale = "ORTHO", ortho_scale
    cam.lens = lens
    cam.clip_start, cam.clip_end = clip
    obj = link(bpy.data.objects.new("camera", cam))
    obj.location, obj.rotation_euler = location, rotation
    if target is not None:
        look_at(obj, target)
    bpy.context.scene.camera = obj
    return obj


def _texture_world(name, strength, texture_type):
    """A new world whose Background (of `strength`) takes its colour from a new node of
    `texture_type`, made the scene's world: (world, texture node)."""
    world = bpy.data.worlds.new(name)
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = nodes.get("Background") or nodes.new("ShaderNodeBackground")
    background.inputs["Strength"].default_value = strength
    texture = nodes.new(texture_type)
    links.new(texture.outputs["Color"], background.inputs["Color"])
    output = nodes.get("World Output") or nodes.new("ShaderNodeOutputWorld")
    links.new(background.outputs["Background"], output.inputs["Surface"])
    bpy.context.scene.world = world
    return world, texture


def environment_world(image, strength=1.0, rotation=(0.0, 0.0, 0.0)):
    """The world as an Environment Texture of `image` (equirectangular) into a Background of
    `strength`, its directions turned by a Mapping node's `rotation` (Euler XYZ, radians)."""
    world, texture = _texture_world("environment", strength, "ShaderNodeTexEnvironment")
    texture.image = image
    nodes, links = world.node_tree.nodes, world.node_tree.links
    mapping = nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = rotation
    coords = nodes.new("ShaderNodeTexCoord")
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    return world


def sky_world(sky_type, strength=1.0, **settings):
    """The world as a Sky Texture of `sky_type` (Blender's identifiers: PREETHAM, HOSEK_WILKIE,
    NISHITA; 5.0 SINGLE_SCATTERING, MULTIPLE_SCATTERING) into a Background of `strength`, with
    the node's settings by their property names (sun_direction, turbidity, sun_elevation, ...)."""
    world, texture = _texture_world("sky", strength, "ShaderNodeTexSky")
    texture.sky_type = sky_type
    for key, value in settings.items():
        setattr(texture, key, value)
    return world


def world(color, lights_diffuse=True):
    """A constant background of linear RGB `color`, or none (black, lighting nothing) for None.
    lights_diffuse=False: seen by camera, glossy and transmission rays but lighting no diffuse
    surface (the world's diffuse ray visibility, which the exporter passes on)."""
    scene = bpy.context.scene
    if color is None:
        scene.world = None
        return None
    w = bpy.data.worlds.new("world")
    w.use_nodes = True
    bg = w.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    if not lights_diffuse:
        w.cycles_visibility.diffuse = False
    scene.world = w
    return w


# ---- render settings ----------------------------------------------------------------------------

def standard_view(scene):
    """The Standard view transform, no look, exposure 0, gamma 1: linear values straight to the
    display and to 8-bit files (Filmic in 3.4 and AgX in 4.x, the defaults, reshape them)."""
    v = scene.view_settings
    v.view_transform, v.look, v.exposure, v.gamma = "Standard", "None", 0.0, 1.0


def output(scene, width, height):
    """The whole frame at width x height pixels (100 %, square pixels, no border), opaque film,
    Standard view: what both engines are compared on."""
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.use_border = False
    r.film_transparent = False
    standard_view(scene)


def float_exr(scene):
    """Stills written as 32-bit float RGBA OpenEXR: linear values, read back exactly."""
    s = scene.render.image_settings
    s.file_format, s.color_depth, s.color_mode = "OPEN_EXR", "32", "RGBA"


def multilayer_exr(scene):
    """Stills written as 32-bit float multilayer OpenEXR: every pass of every view layer."""
    st = scene.render.image_settings
    if hasattr(st, "media_type"):
        st.media_type = "MULTI_LAYER_IMAGE"  # 5.x: before the format, which it filters
    st.file_format, st.color_depth = "OPEN_EXR_MULTILAYER", "32"


def toyrt(scene, **settings):
    """The TOYRT engine, with `settings` of scene.toyrt (samples=16, seed=0, builder="sah", ...)."""
    scene.render.engine = "TOYRT"
    for name, value in settings.items():
        setattr(scene.toyrt, name, value)


def cycles(scene, samples, specular_depth):
    """Cycles restricted to TOYRT's light transport (scenes/cycles_like_toyrt.py), float EXR stills."""
    configure_cycles(scene, samples, specular_depth)
    float_exr(scene)


def read_image(path):
    """(h, w, 4) float32 pixels of an image file as Blender loads it (EXR linear, 8-bit files their
    stored values / 255), rows from the bottom."""
    img = bpy.data.images.load(str(path), check_existing=False)
    try:
        w, h = img.size[:]
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(img)
    return px.reshape(h, w, 4)


def main(build):
    """A scene script's entry: build(), the Standard view, then save the .blend to the path after
    `--`, if any:  blender -b --python scenes/SCRIPT.py -- OUT.blend"""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    standard_view(build())
    if argv:
        bpy.ops.wm.save_as_mainfile(filepath=argv[0])
