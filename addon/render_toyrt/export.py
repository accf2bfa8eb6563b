# Blender depsgraph -> toyrt.Scene. Converts and forwards; no rendering logic.
#
#   scene, camera, stats = export_scene(depsgraph, toyrt_module, report=self.report)
#   scene.commit(...)                      # left to the caller
#   image = scene.render(camera, ...)
#
# Written against Debian's Blender 3.4 (tested) and kept valid on 4.x: every API that moved is
# reached through hasattr (split normals -> corner_normals in 4.1, calc_normals_split removed in
# 4.1, Principled "Transmission" -> "Transmission Weight" in 4.0, use_smooth -> sharp_face).
#
# Geometry goes through foreach_get into numpy buffers (no per-vertex Python loops). Meshes are
# keyed by their original data (plus the material list), so linked duplicates and collection,
# particle and geometry-node instances become one add_mesh and one add_instance per copy.
import time

import numpy as np

DEFAULT_GREY = (0.8, 0.8, 0.8)   # Blender's default surface colour
MAGENTA = (1.0, 0.0, 1.0)        # placeholder for missing images
RENDERABLE = {"MESH", "CURVE", "SURFACE", "FONT", "META"}


# ---------------------------------------------------------------------------------------------
# small helpers

def _input(node, *names):
    """The first of the named input sockets the node has (names moved between versions)."""
    for n in names:
        sock = node.inputs.get(n)
        if sock is not None:
            return sock
    return None


def _linked_node(socket):
    """The node feeding `socket`, following reroutes; None when unlinked."""
    seen = 0
    while socket is not None and socket.is_linked and seen < 64:
        link = socket.links[0]
        if hasattr(link, "is_muted") and link.is_muted:
            return None
        node = link.from_node
        if node.type == "REROUTE":
            socket = node.inputs[0]
            seen += 1
            continue
        return node
    return None


def _output_node(ntree, output_type):
    """The active output node of a node tree for Cycles (or for all renderers)."""
    get = getattr(ntree, "get_output_node", None)
    if get is not None:
        for target in ("CYCLES", "ALL"):
            try:
                node = get(target)
            except (TypeError, ValueError):
                node = None
            if node is not None:
                return node
    candidates = [n for n in ntree.nodes if n.type == output_type]
    for n in candidates:
        if getattr(n, "is_active_output", False):
            return n
    return candidates[0] if candidates else None


def _rgb(value):
    return tuple(float(c) for c in tuple(value)[:3])


# ---------------------------------------------------------------------------------------------
# materials and textures

class _Materials:
    """Blender materials -> scene material ids, with their textures, cached by material."""

    def __init__(self, scene, approximated):
        self.scene = scene
        self.approx = approximated           # list of strings, shared with the exporter
        # Keyed by name, not pointer: a final render's depsgraph may hand out new copies of the same
        # material every frame, and the incremental cache (scene_cache.py) must find them again.
        self.by_material = {}                # material name ('': none) -> material id
        self.by_image = {}                   # (image name, srgb) -> texture id
        self.textures = 0
        self.missing = set()                 # by_image keys that got the placeholder

    def note(self, what):
        if what not in self.approx:
            self.approx.append(what)

    def default(self):
        return self.material_id(None)

    def material_id(self, mat):
        key = mat.name_full if mat is not None else ""
        mid = self.by_material.get(key)
        if mid is None:
            mid = self._convert(mat)
            self.by_material[key] = mid
        return mid

    def _diffuse(self, color):
        return self.scene.add_material("diffuse", color=color)

    def _convert(self, mat):
        if mat is None:
            return self._diffuse(DEFAULT_GREY)
        name = mat.name
        if not getattr(mat, "use_nodes", False) or mat.node_tree is None:
            # Cycles renders a node-less material as a diffuse of its viewport colour.
            return self._diffuse(_rgb(mat.diffuse_color))
        out = _output_node(mat.node_tree, "OUTPUT_MATERIAL")
        if out is None:
            self.note(f"material '{name}': no Material Output (grey diffuse)")
            return self._diffuse(DEFAULT_GREY)
        node = _linked_node(_input(out, "Surface"))
        if node is None:
            # Cycles renders an unconnected surface black; the nearest we have is a black diffuse.
            self.note(f"material '{name}': nothing linked to the Surface output (black)")
            return self._diffuse((0.0, 0.0, 0.0))
        t = node.type
        if t == "BSDF_DIFFUSE":
            rough = _input(node, "Roughness")
            if rough is not None and not rough.is_linked and rough.default_value > 0.0:
                self.note(f"material '{name}': Diffuse roughness (Lambert)")
            return self._color_material(name, _input(node, "Color"))
        if t == "BSDF_PRINCIPLED":
            return self._principled(name, node)
        if t == "BSDF_REFRACTION":
            self._check_sharp(name, node, "Refraction")
            return self.scene.add_material("refraction", ior=self._ior(name, node))
        if t == "BSDF_GLASS":
            self._check_sharp(name, node, "Glass")
            return self.scene.add_material("glass", ior=self._ior(name, node))
        # Anything else: the colour it has, as a diffuse, else grey.
        color = _input(node, "Color", "Base Color")
        if color is not None and not color.is_linked and hasattr(color.default_value, "__len__"):
            self.note(f"material '{name}': {node.bl_idname} (diffuse of its colour)")
            return self._diffuse(_rgb(color.default_value))
        self.note(f"material '{name}': {node.bl_idname} (grey diffuse)")
        return self._diffuse(DEFAULT_GREY)

    def _ior(self, name, node):
        sock = _input(node, "IOR")
        if sock is None:
            return 1.45
        if sock.is_linked:
            self.note(f"material '{name}': linked IOR (its constant value)")
        return float(sock.default_value)

    def _check_sharp(self, name, node, label):
        rough = _input(node, "Roughness")
        if rough is not None and (rough.is_linked or rough.default_value > 0.0):
            self.note(f"material '{name}': rough {label} (sharp)")
        color = _input(node, "Color")
        if color is not None and (color.is_linked or tuple(color.default_value)[:3] != (1.0, 1.0, 1.0)):
            self.note(f"material '{name}': {label} tint (white)")

    def _principled(self, name, node):
        trans = _input(node, "Transmission Weight", "Transmission")  # 4.0+ / 3.x
        if trans is not None and not trans.is_linked and trans.default_value >= 0.999:
            rough = _input(node, "Roughness")
            if rough is not None and (rough.is_linked or rough.default_value > 0.0):
                self.note(f"material '{name}': rough Principled transmission (sharp glass)")
            return self.scene.add_material("glass", ior=self._ior(name, node))
        extras = []
        metal = _input(node, "Metallic")
        if metal is not None and (metal.is_linked or metal.default_value > 0.0):
            extras.append("metallic")
        if trans is not None and (trans.is_linked or trans.default_value > 0.0):
            extras.append("partial transmission")
        spec = _input(node, "Specular IOR Level", "Specular")
        if spec is not None and (spec.is_linked or spec.default_value > 0.0):
            extras.append("specular")
        emis = _input(node, "Emission Color", "Emission")
        strength = _input(node, "Emission Strength")
        if (emis is not None and (emis.is_linked or any(c > 0 for c in tuple(emis.default_value)[:3]))
                and (strength is None or strength.is_linked or strength.default_value > 0.0)):
            extras.append("emission")
        if extras:
            self.note(f"material '{name}': Principled {', '.join(extras)} (Lambert base colour)")
        return self._color_material(name, _input(node, "Base Color"))

    def _color_material(self, name, sock):
        if sock is None:
            return self._diffuse(DEFAULT_GREY)
        src = _linked_node(sock)
        if src is None:
            return self._diffuse(_rgb(sock.default_value))
        if src.type == "TEX_IMAGE":
            tex = self._texture(name, src)
            return self.scene.add_material("diffuse", texture=tex)
        self.note(f"material '{name}': colour from {src.bl_idname} (its constant colour)")
        return self._diffuse(_rgb(sock.default_value))

    def _texture(self, name, node):
        image = node.image
        vec = _input(node, "Vector")
        if vec is not None and vec.is_linked:
            src = _linked_node(vec)
            if src is None or src.type not in ("UVMAP", "TEX_COORD"):
                self.note(f"material '{name}': texture coordinates from "
                          f"{src.bl_idname if src else 'a link'} (the mesh's UV map)")
        if getattr(node, "extension", "REPEAT") != "REPEAT":
            self.note(f"material '{name}': image extension {node.extension} (repeat)")
        if getattr(node, "interpolation", "Linear") not in ("Linear",):
            self.note(f"material '{name}': image interpolation {node.interpolation} (bilinear)")
        if getattr(node, "projection", "FLAT") != "FLAT":
            self.note(f"material '{name}': image projection {node.projection} (flat)")
        if image is None:
            self.note(f"material '{name}': Image Texture without an image (magenta)")
            return self._placeholder()
        # Blender keeps float images in scene-linear memory (converted from their colour space
        # when loaded) and 8-bit images as their file's bytes: only 8-bit sRGB needs decoding.
        srgb = image.colorspace_settings.name == "sRGB" and not image.is_float
        key = (image.name_full, srgb)
        tid = self.by_image.get(key)
        missing = f"missing image '{image.name}' ({image.filepath or 'no file'}): magenta placeholder"
        if tid is not None:
            if key in self.missing:
                self.note(missing)  # again: scene_cache.py collects the notes afresh for each render
            return tid
        pixels = self._pixels(image)
        if pixels is None:
            self.note(missing)
            self.missing.add(key)
            tid = self._placeholder()
        else:
            if not image.is_float and image.colorspace_settings.name not in (
                    "sRGB", "Linear", "Linear Rec.709", "Non-Color", "Raw"):
                self.note(f"image '{image.name}': colour space {image.colorspace_settings.name} (linear)")
            tid = self.scene.add_texture(pixels, srgb=srgb)
            self.textures += 1
        self.by_image[key] = tid
        return tid

    def _placeholder(self):
        key = ("placeholder",)
        tid = self.by_image.get(key)
        if tid is None:
            tid = self.scene.add_texture(np.array([[MAGENTA]], np.float32), srgb=False)
            self.by_image[key] = tid
            self.textures += 1
        return tid

    @staticmethod
    def _pixels(image):
        """(height, width, 3) pixels, rows from the bottom (uint8 for 8-bit images, float32 for
        float images); None if the image has no data."""
        try:
            w, h = image.size[:]            # reading the size loads the image (packed or on disk)
            channels = image.channels
            n = len(image.pixels)
        except (RuntimeError, ReferenceError):
            return None
        if w <= 0 or h <= 0 or channels <= 0 or n != w * h * channels:
            return None
        if hasattr(image, "has_data") and not image.has_data:
            return None
        buf = np.empty(n, np.float32)
        image.pixels.foreach_get(buf)
        buf = buf.reshape(h, w, channels)
        if channels == 1 or channels == 2:
            buf = np.repeat(buf[..., :1], 3, axis=2)
        buf = buf[..., :3]
        if not image.is_float:
            # An 8-bit image: pass its bytes (exact: Blender's pixels are byte / 255), a quarter of
            # the memory, and the core knows it is an 8-bit image (Cycles filters 8-bit sRGB
            # images before decoding them; see docs/parity.md).
            return np.ascontiguousarray(np.rint(np.clip(buf, 0.0, 1.0) * 255.0).astype(np.uint8))
        return np.ascontiguousarray(buf)


# ---------------------------------------------------------------------------------------------
# meshes

class ExportCancelled(Exception):
    """A should_cancel poll answered true during an export."""


def _stop_if(poll):
    """Between the stages of a mesh's export (each a few tens of ms per million triangles), so
    Esc on a million-triangle mesh is not held for its whole export."""
    if poll is not None and poll():
        raise ExportCancelled()


def _mesh_arrays(mesh, poll=None):
    """Vertices (N,3) f32, triangles (M,3) u32, normals, corner UVs (M,3,2) f32 or None, material
    indices (M,) i32, from an evaluated mesh, through foreach_get.

    Normals come in the cheapest form that says the same thing (see _mesh_normals): None when
    every face is flat (the core then uses each triangle's own normal, as Cycles does for flat
    faces), (N,3) per vertex when every face is smooth without custom or auto-smooth normals,
    (M,3,3) per corner otherwise. Measured on a 1M-triangle mesh, see docs/blender.md."""
    mesh.calc_loop_triangles()
    nv = len(mesh.vertices)
    nt = len(mesh.loop_triangles)
    verts = np.empty(nv * 3, np.float32)
    mesh.vertices.foreach_get("co", verts)
    # uint32 buffers: Blender 3.4 copies these in bulk only when the buffer matches its unsigned
    # storage (4x faster than int32 here: 0.03 s against 0.14 s per million triangles).
    tris = np.empty(nt * 3, np.uint32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    verts, tris = verts.reshape(nv, 3), tris.reshape(nt, 3)
    if nt == 0:
        return verts, tris, None, None, np.zeros(0, np.int32)
    _stop_if(poll)

    loops = None  # triangle corners -> mesh loops, read only when something per corner needs it

    def corner_loops():
        nonlocal loops
        if loops is None:
            loops = np.empty(nt * 3, np.uint32)
            mesh.loop_triangles.foreach_get("loops", loops)
        return loops

    normals = _mesh_normals(mesh, nt, corner_loops)
    _stop_if(poll)

    uvs = None
    layers = mesh.uv_layers
    if len(layers):
        # Cycles' Image Texture without a Vector link reads the render-active UV map.
        layer = next((l for l in layers if getattr(l, "active_render", False)), None) or layers.active
        if layer is not None and len(layer.data) == len(mesh.loops):
            uv = np.empty(len(mesh.loops) * 2, np.float32)
            layer.data.foreach_get("uv", uv)
            # np.take, not uv[...] fancy indexing: 3x faster on a million triangles.
            uvs = np.take(uv.reshape(-1, 2), corner_loops(), axis=0).reshape(nt, 3, 2)

    _stop_if(poll)
    if len(getattr(mesh, "materials", ())) <= 1:
        # One slot or none: every index maps to slot 0 (the caller clips), no need to read them.
        mat_idx = np.zeros(nt, np.int32)
    else:
        mat_idx = np.empty(nt, np.uint32)
        try:
            mesh.loop_triangles.foreach_get("material_index", mat_idx)
        except (AttributeError, TypeError, RuntimeError):
            # Newer versions: from the polygons' material_index through the triangles' polygons.
            pm = np.zeros(len(mesh.polygons), np.int32)
            mesh.polygons.foreach_get("material_index", pm)
            mat_idx = pm[_triangle_polygons(mesh, nt)]
        mat_idx = mat_idx.view(np.int32) if mat_idx.dtype == np.uint32 else mat_idx

    if not np.isfinite(verts).all():
        verts, tris, normals, uvs, mat_idx = _drop_nonfinite(verts, tris, normals, uvs, mat_idx)
    return verts, tris, normals, uvs, mat_idx


def _mesh_key(obj):
    """Identity of the geometry an evaluated object shows, plus its material list: objects and
    instances with the same key share one stored mesh.

    Measured on Blender 3.4: the depsgraph keeps one evaluated copy per original mesh, so the
    evaluated `obj.data` of linked duplicates and of collection instances is the same data block
    (the evaluated stand-in for the original data; `data.original` returns that same block), an
    object with modifiers gets its own result mesh, and geometry-node instances of one geometry
    share its mesh. `inst.object` is a temporary object for instances (use it, not
    `instance_object`, which for geometry-node instances is the instancer)."""
    if obj.type == "MESH":
        base = ("data", obj.data.as_pointer())
    else:
        # Curves, surfaces, text, metaballs: the tessellation depends on the object.
        orig = getattr(obj, "original", None) or obj
        base = ("object", orig.as_pointer(), obj.data.as_pointer() if obj.data is not None else 0)
    mats = tuple(s.material.as_pointer() if s.material is not None else 0 for s in obj.material_slots)
    return base + mats


def _object_materials(obj, mesh, materials):
    """Material slot index -> scene material id for this object (Blender's slot rules)."""
    mats = [s.material for s in obj.material_slots]
    extra = list(getattr(mesh, "materials", []) or [])
    if len(extra) > len(mats):
        mats += extra[len(mats):]
    if not mats:
        return np.array([materials.default()], np.int32)
    return np.array([materials.material_id(m) for m in mats], np.int32)


# ---------------------------------------------------------------------------------------------
# lights, world, camera

def _export_light(scene, obj, matrix, approx):
    light = obj.data
    color = _light_color(light)             # Blender 4.x: colour temperature (helper at the end)
    power = _light_power(light, matrix)     # Blender 4.x: exposure, area-light units, normalize
    if getattr(light, "use_nodes", False):
        what = f"light '{obj.name}': node setup (its colour and power)"
        if what not in approx:
            approx.append(what)
    # Ray visibility of the light object (Blender 3.0+; all visible by default, as in Cycles):
    # TOYRT's specular rays are Cycles' glossy and transmission rays.
    visible = dict(visible_camera=bool(getattr(obj, "visible_camera", True)),
                   visible_specular=bool(getattr(obj, "visible_glossy", True) and getattr(obj, "visible_transmission", True)))
    if light.type == "POINT":
        scene.add_point_light(tuple(matrix[:3, 3]), power, color=color, radius=float(light.shadow_soft_size), **visible)
        return True
    if light.type == "AREA":
        shape = light.shape
        size_y = float(light.size_y) if shape in ("RECTANGLE", "ELLIPSE") else None
        scene.add_area_light(matrix, shape=shape, size=float(light.size), size_y=size_y, power=power, color=color,
                             **visible)
        return True
    what = f"{light.type.lower()} light '{obj.name}' (skipped)"
    if what not in approx:
        approx.append(what)
    return False


def _export_world(scene, bl_scene, approx):
    world = bl_scene.world
    if world is None:
        scene.background = (0.0, 0.0, 0.0)
        return
    # Cycles lights diffuse surfaces with the world unless its diffuse ray visibility is off.
    visibility = getattr(world, "cycles_visibility", None)
    scene.background_lighting = bool(getattr(visibility, "diffuse", True))
    if not getattr(world, "use_nodes", False) or world.node_tree is None:
        scene.background = _rgb(world.color)
        return
    out = _output_node(world.node_tree, "OUTPUT_WORLD")
    node = _linked_node(_input(out, "Surface")) if out is not None else None
    if node is not None and node.type == "BACKGROUND":
        color, strength = _input(node, "Color"), _input(node, "Strength")
        if not color.is_linked and not strength.is_linked:
            s = float(strength.default_value)
            scene.background = tuple(c * s for c in _rgb(color.default_value))
            return
    scene.background = (0.0, 0.0, 0.0)
    approx.append(f"world '{world.name}': not a plain colour (black)")


def export_camera(depsgraph, camera_object=None):
    """The dict for toyrt.Scene.render(camera=...) from the scene's (or the given) camera."""
    bl_scene = depsgraph.scene
    cam = camera_object if camera_object is not None else bl_scene.camera
    if cam is None:
        # The original scene's camera, if the evaluated one is unset for some reason.
        orig = getattr(bl_scene, "original", None)
        cam = getattr(orig, "camera", None)
    if cam is None:
        raise RuntimeError(f"TOYRT: scene '{bl_scene.name}' has no camera; add one and make it the scene camera")
    cam = cam.evaluated_get(depsgraph) if hasattr(cam, "evaluated_get") else cam
    r = bl_scene.render
    d = dict(
        matrix_world=np.array(cam.matrix_world, np.float64),
        resolution_x=int(r.resolution_x), resolution_y=int(r.resolution_y),
        resolution_percentage=int(r.resolution_percentage),
        pixel_aspect_x=float(r.pixel_aspect_x), pixel_aspect_y=float(r.pixel_aspect_y),
        use_border=bool(r.use_border),
        border_min_x=float(r.border_min_x), border_min_y=float(r.border_min_y),
        border_max_x=float(r.border_max_x), border_max_y=float(r.border_max_y),
    )
    if cam.type == "CAMERA":
        c = cam.data
        d.update(type="ORTHO" if c.type == "ORTHO" else "PERSP", lens=float(c.lens),
                 sensor_width=float(c.sensor_width), sensor_height=float(c.sensor_height),
                 sensor_fit=c.sensor_fit, shift_x=float(c.shift_x), shift_y=float(c.shift_y),
                 clip_start=float(c.clip_start), clip_end=float(c.clip_end), ortho_scale=float(c.ortho_scale))
    else:
        # Blender renders through a non-camera object with the default camera settings.
        d.update(type="PERSP", lens=50.0, sensor_width=36.0, sensor_height=24.0, sensor_fit="AUTO",
                 shift_x=0.0, shift_y=0.0, clip_start=0.1, clip_end=1000.0, ortho_scale=6.0)
    return d


# ---------------------------------------------------------------------------------------------

def export_scene(depsgraph, toyrt_module, *, report=None, camera_object=None):
    """Blender depsgraph -> (toyrt.Scene, camera dict, stats). The caller commits the scene.

    stats: export_s, meshes, instances, lights, materials, textures, triangles_stored (each mesh
    once), triangles_instanced (= triangles: over all instances), approximated (list of strings). With `report` (a RenderEngine's or an
    operator's report), one WARNING lists what was approximated.
    """
    t0 = time.perf_counter()
    camera = export_camera(depsgraph, camera_object)  # fail early, before any work
    scene = toyrt_module.Scene()
    approx = []
    materials = _Materials(scene, approx)
    meshes = {}           # key -> (mesh id, triangle count)
    n_instances = n_lights = tri_instanced = tri_stored = 0

    for inst in depsgraph.object_instances:
        obj = inst.object  # for instances: a temporary object showing the instanced geometry
        if obj is None:
            continue
        otype = obj.type
        if otype == "LIGHT":
            if _export_light(scene, obj, np.array(inst.matrix_world, np.float64), approx):
                n_lights += 1
            continue
        if otype not in RENDERABLE:
            continue
        if not inst.is_instance and not inst.show_self:
            continue  # e.g. a particle emitter with "show emitter" off
        matrix = np.array(inst.matrix_world, np.float64)
        if _singular(matrix):  # scaled to zero: the core cannot invert it (helpers at the end)
            entry = _add_baked_mesh(scene, obj, matrix, materials, depsgraph)
            if entry[0] >= 0:
                meshes[("baked", n_instances)] = entry
                tri_stored += entry[1]
                n_instances += 1
                tri_instanced += entry[1]
            continue
        key = _mesh_key(obj)
        entry = meshes.get(key)
        if entry is None:
            entry = _add_mesh(scene, obj, matrix, materials, depsgraph)
            meshes[key] = entry
            if entry[0] >= 0:
                tri_stored += entry[1]
                n_instances += 1
                tri_instanced += entry[1]
            continue
        if entry[0] < 0:
            continue  # empty geometry
        scene.add_instance(entry[0], matrix)
        n_instances += 1
        tri_instanced += entry[1]

    _export_world(scene, depsgraph.scene, approx)

    stats = dict(export_s=time.perf_counter() - t0, meshes=len([e for e in meshes.values() if e[0] >= 0]),
                 instances=n_instances, lights=n_lights, materials=len(materials.by_material),
                 textures=materials.textures, triangles_stored=tri_stored,
                 triangles_instanced=tri_instanced, triangles=tri_instanced, approximated=list(approx))
    if approx and report is not None:
        report({"WARNING"}, "TOYRT approximated: " + "; ".join(approx))
    return scene, camera, stats


def _add_mesh(scene, obj, matrix, materials, depsgraph):
    """Convert an evaluated object's geometry; returns (mesh id or -1 if empty, triangle count)."""
    data = mesh_data(obj, materials, depsgraph)
    if data is None:
        return (-1, 0)
    verts, tris, normals, uvs, mat_ids = data
    mid = scene.add_mesh(verts, tris, transform=matrix, normals=normals, uvs=uvs, material_ids=mat_ids)
    return (mid, len(tris))


def mesh_data(obj, materials, depsgraph, poll=None):
    """An evaluated object's geometry as the arrays add_mesh / replace_mesh take: (vertices,
    triangles, normals, uvs, material ids), or None when it has no triangles. poll(): asked
    between stages; when it answers true, ExportCancelled is raised."""
    try:
        mesh = obj.to_mesh(preserve_all_data_layers=False, depsgraph=depsgraph)
    except TypeError:
        mesh = obj.to_mesh()
    except RuntimeError:
        mesh = None
    if mesh is None:
        return None
    try:
        _stop_if(poll)
        verts, tris, normals, uvs, mat_idx = _mesh_arrays(mesh, poll)
        if len(tris) == 0:
            return None
        slot_map = _object_materials(obj, mesh, materials)
        mat_ids = slot_map[np.clip(mat_idx, 0, len(slot_map) - 1)]
        return verts, tris, normals, uvs, mat_ids
    finally:
        obj.to_mesh_clear()


# ---------------------------------------------------------------------------------------------
# mesh helpers (for _mesh_arrays)

def _triangle_polygons(mesh, nt):
    """(M,) polygon index of each loop triangle (4.1+ keeps them in loop_triangle_polygons)."""
    poly = np.empty(nt, np.uint32)
    if hasattr(mesh, "loop_triangle_polygons"):
        mesh.loop_triangle_polygons.foreach_get("value", poly.view(np.int32))
    else:
        mesh.loop_triangles.foreach_get("polygon_index", poly)
    return poly


def _mesh_normals(mesh, nt, corner_loops):
    """The shading normals of a mesh: None (all faces flat), (N,3) per vertex (all smooth, no
    custom or auto-smooth normals) or (M,3,3) per corner; None also if Blender's are not finite.

    Blender 4.1+ says which with normals_domain (FACE, POINT, CORNER). Before, flat/smooth is
    per polygon (use_smooth), and custom normals or auto smooth make them per corner."""
    domain = getattr(mesh, "normals_domain", None)                 # 4.1+
    if domain is None:
        custom = bool(getattr(mesh, "has_custom_normals", False))
        auto = bool(getattr(mesh, "use_auto_smooth", False))
        smooth = np.empty(len(mesh.polygons), bool)
        mesh.polygons.foreach_get("use_smooth", smooth)
        if not smooth.any() and not custom:
            domain = "FACE"       # auto smooth only ever smooths faces marked smooth
        elif smooth.all() and not custom and not auto:
            domain = "POINT"
        else:
            domain = "CORNER"
    if domain == "FACE":
        return None
    if domain == "POINT":
        normals = np.empty(len(mesh.vertices) * 3, np.float32)
        if hasattr(mesh, "vertex_normals"):                        # 3.5+
            mesh.vertex_normals.foreach_get("vector", normals)
        else:
            mesh.vertices.foreach_get("normal", normals)
        normals = normals.reshape(-1, 3)
    elif hasattr(mesh, "corner_normals"):                           # 4.1+
        cn = np.empty(len(mesh.loops) * 3, np.float32)
        mesh.corner_normals.foreach_get("vector", cn)
        normals = np.take(cn.reshape(-1, 3), corner_loops(), axis=0).reshape(nt, 3, 3)
    else:
        if hasattr(mesh, "calc_normals_split"):                     # 3.x, 4.0: compute first
            mesh.calc_normals_split()
        normals = np.empty(nt * 9, np.float32)
        mesh.loop_triangles.foreach_get("split_normals", normals)
        normals = normals.reshape(nt, 3, 3)
    return normals if np.isfinite(normals).all() else None


def _drop_nonfinite(verts, tris, normals, uvs, mat_idx):
    """Blender can hold NaN or infinite coordinates (a script, a driver, a modifier dividing by
    zero), which the core refuses: drop the triangles that use such a vertex and park the vertex
    at the origin (unused), so the rest of the mesh still renders."""
    bad_vertex = ~np.isfinite(verts).all(axis=1)
    keep = ~bad_vertex[tris].any(axis=1)
    verts = np.where(bad_vertex[:, None], np.float32(0.0), verts)
    tris = np.ascontiguousarray(tris[keep])
    if normals is not None and normals.ndim == 3:
        normals = np.ascontiguousarray(normals[keep])
    elif normals is not None:
        normals = np.where(bad_vertex[:, None], np.float32(0.0), normals)
    if uvs is not None:
        uvs = np.ascontiguousarray(uvs[keep])
    return verts, tris, normals, uvs, np.ascontiguousarray(mat_idx[keep])


# ---------------------------------------------------------------------------------------------
# light units across Blender versions (for _export_light)

def _blender_version():
    try:
        import bpy
        return tuple(bpy.app.version)
    except ImportError:      # outside Blender (the exporter's arrays are also used by scripts)
        return (3, 4, 0)


def _light_color(light):
    """The light's colour, times its blackbody colour when "use temperature" is on (4.5+)."""
    color = _rgb(light.color)
    if getattr(light, "use_temperature", False):
        color = tuple(a * b for a, b in zip(color, _rgb(light.temperature_color)))
    return color


def _light_power(light, matrix):
    """The power to give the core, whose area light has Blender 3.x's radiance P / (4 area)
    (docs/render.md).

    Measured against Cycles on the same scene (bpy 4.2.0, 4.5.4 and 5.0.1 against Debian's
    3.4.1): from 4.x on, Cycles' area lights of every shape are 4 / pi brighter at the same power,
    i.e. radiance P / (pi area), a Lambertian emitter of exitance P / area; so 4.x's watts become
    4 / pi times as many in 3.x's units. 4.x also scales every light by 2^exposure, and an area
    light with "normalize" off is not divided by its area (its power is per square metre)."""
    power = float(light.energy) * 2.0 ** float(getattr(light, "exposure", 0.0))
    if light.type == "AREA":
        if _blender_version() >= (4, 0, 0):
            power *= 4.0 / np.pi
        if not getattr(light, "normalize", True):
            sx = float(np.linalg.norm(matrix[:3, 0]))
            sy = float(np.linalg.norm(matrix[:3, 1]))
            w = float(light.size)
            h = float(light.size_y) if light.shape in ("RECTANGLE", "ELLIPSE") else w
            area = w * h * (np.pi / 4.0 if light.shape in ("DISK", "ELLIPSE") else 1.0)
            power *= area * sx * sy
    return power


# ---------------------------------------------------------------------------------------------
# instances the core cannot place (for export_scene)

def _singular(matrix):
    """True when the core would refuse an instance's matrix: not finite, or (nearly) no volume,
    as an object scaled to zero along an axis has (a common way to hide an object in an
    animation, or to flatten one). The margin is generous: such an object is baked (below),
    which is always correct, only not shared."""
    if not np.isfinite(matrix).all():
        return True
    return abs(float(np.linalg.det(matrix[:3, :3]))) < 1e-18


def _add_baked_mesh(scene, obj, matrix, materials, depsgraph):
    """An object whose matrix the core cannot invert, as its own mesh with the matrix applied
    to its vertices here (scaled to zero: every triangle degenerates to a point or a line and is
    never hit, as in Cycles; flattened: a flat copy). A matrix that is not finite (a driver
    dividing by zero) shows nothing. Returns (mesh id or -1, triangle count)."""
    if not np.isfinite(matrix).all():
        return (-1, 0)
    try:
        mesh = obj.to_mesh(preserve_all_data_layers=False, depsgraph=depsgraph)
    except TypeError:
        mesh = obj.to_mesh()
    except RuntimeError:
        mesh = None
    if mesh is None:
        return (-1, 0)
    try:
        verts, tris, _normals, uvs, mat_idx = _mesh_arrays(mesh)
        if len(tris) == 0:
            return (-1, 0)
        world = (verts.astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]).astype(np.float32)
        slot_map = _object_materials(obj, mesh, materials)
        mat_ids = slot_map[np.clip(mat_idx, 0, len(slot_map) - 1)]
        # No shading normals: a singular matrix has no normal transform (the core uses each
        # triangle's own normal).
        mid = scene.add_mesh(world, tris, transform=None, normals=None, uvs=uvs, material_ids=mat_ids)
        return (mid, len(tris))
    finally:
        obj.to_mesh_clear()
