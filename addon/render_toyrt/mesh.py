"""An evaluated Blender object's geometry -> numpy arrays, the form toyrt.Scene.add_mesh takes.

Plain data only: nothing here touches the native scene (sync.py sends what these functions
return). Written against Debian's Blender 3.4 (tested) and kept valid on 4.x and 5.0: every API
that moved is reached through hasattr (split normals -> corner_normals in 4.1,
calc_normals_split removed in 4.1, use_smooth -> sharp_face).

Geometry goes through foreach_get into numpy buffers (no per-vertex Python loops). Meshes are
keyed by their evaluated data (plus the material list, see mesh_key), so linked duplicates and
collection, particle and geometry-node instances share one stored mesh."""
from __future__ import annotations

import hashlib
import math
from collections.abc import Callable
from dataclasses import dataclass
from itertools import chain

import numpy as np

from .light_linking import ALL

# The object types whose evaluated geometry is a mesh (to_mesh).
RENDERABLE = frozenset({"MESH", "CURVE", "SURFACE", "FONT", "META"})

Poll = Callable[[], bool] | None


class ExportCancelled(Exception):
    """A should_cancel poll answered true during a sync: the native scene is half updated."""


def stop_if(poll: Poll) -> None:
    """Between the stages of a mesh's conversion (each a few tens of ms per million triangles),
    so Esc on a million-triangle mesh is not held for its whole export."""
    if poll is not None and poll():
        raise ExportCancelled()


@dataclass(frozen=True, eq=False)
class MeshGeometry:
    """One evaluated object's triangles, as add_mesh / replace_mesh take them, except the
    material ids: `slots` says which slot each triangle uses and `materials` which Blender
    material (or None) each slot holds; sync.py maps them to its material ids."""
    vertices: np.ndarray            # (N, 3) float32
    triangles: np.ndarray           # (M, 3) uint32
    normals: np.ndarray | None      # None (flat), (N, 3) per vertex or (M, 3, 3) per corner
    uvs: np.ndarray | None          # (M, 3, 2) per corner
    slots: np.ndarray               # (M,) int32 material slot of each triangle, clipped to `materials`
    materials: tuple                # Blender material or None, one per slot (at least one)
    tangents: np.ndarray | None = None   # (M, 3, 4) per corner: for a tangent-space normal map


def to_array(matrix) -> np.ndarray:
    """A mathutils 4x4 Matrix (an instance's matrix_world) as a (4, 4) float64 array; 4x faster
    than np.array(matrix) (3 against 12 us, which counts at 10,000 instances)."""
    return np.fromiter(chain.from_iterable(matrix), np.float64, 16).reshape(4, 4)


def casts_shadow(inst, obj) -> bool:
    """Object.visible_shadow (Blender 3.0+; on by default), inherited from the instancer as in
    Cycles: an instance casts shadows when it and the object instancing it both do."""
    parent = inst.parent if inst.is_instance else None
    return bool(getattr(obj, "visible_shadow", True) and (parent is None or getattr(parent, "visible_shadow", True)))


RAY_VISIBILITY = ("visible_camera", "visible_diffuse", "visible_glossy", "visible_transmission")


def instance_flags(inst, obj, links) -> tuple:
    """add_instance's keywords for one object instance, as a hashable tuple: casts_shadow, the
    light-linking sets (links.instance_sets; (0, 0) without linking), the receiver sets it lights
    as an emitter (its own receiver collection's; all without one) and Object's ray visibility
    (camera, diffuse, glossy, transmission; Blender 3.0+), each inherited from the instancer as in
    Cycles (an instance is seen by a kind of ray when it and its instancer both are)."""
    parent = inst.parent if inst.is_instance else None
    seen = tuple(bool(getattr(obj, name, True) and (parent is None or getattr(parent, name, True)))
                 for name in RAY_VISIBILITY)
    sets = (0, 0, ALL) if links.empty else (*links.instance_sets(obj.name), links.receiver_sets.get(obj.name, ALL))
    return (casts_shadow(inst, obj), *sets, *seen)


def instance_arguments(flags: tuple) -> dict:
    """instance_flags as add_instance's keywords."""
    return dict(visible_shadow=flags[0], receiver_set=flags[1], blocker_set=flags[2],
                emitter_receiver_sets=flags[3], **dict(zip(RAY_VISIBILITY, flags[4:])))


def singular(matrix: np.ndarray) -> bool:
    """True when the core would refuse an instance's matrix: not finite, or (nearly) no volume,
    as an object scaled to zero along an axis has (a common way to hide an object in an
    animation, or to flatten one), or a matrix whose single-precision inverse would carry rays
    into object space with too large an error (the core's test: scene/instance_bounds.h). The
    margin is generous: such an object is baked (see evaluated_geometry's `bake`), which is
    always correct, only not shared. The tests here, each a superset of a refusal
    (tests/python/test_instance_transforms.py checks the whole): the determinant against the
    product of the axes' lengths (1 for location, rotation and scale, whatever the scales; a
    parent's non-uniform scale over a rotated child lowers it, to about 2/r for a ratio r of
    scales, and the core refuses from r of about 1e5, so these bake from r of about 2e4), and
    axes or a translation so far beyond float's range that the inverse would overflow. In
    Python floats: numpy's det costs 20 us a call here, this 2."""
    v = matrix.ravel().tolist()
    if not all(map(math.isfinite, v)):
        return True
    det = v[0] * (v[5] * v[10] - v[6] * v[9]) - v[1] * (v[4] * v[10] - v[6] * v[8]) + v[2] * (v[4] * v[9] - v[5] * v[8])
    if abs(det) < 1e-18:
        return True
    axes = (math.hypot(v[0], v[4], v[8]), math.hypot(v[1], v[5], v[9]), math.hypot(v[2], v[6], v[10]))
    shortest, longest = min(axes), max(axes)
    if shortest < 1e-30 or longest > 1e30 or max(abs(v[3]), abs(v[7]), abs(v[11])) > 1e30 * shortest:
        return True
    return abs(det) < 1e-4 * axes[0] * axes[1] * axes[2]


def mesh_key(obj) -> tuple:
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


def fingerprint(obj, bake: np.ndarray | None = None) -> bytes | None:
    """What a final render compares between frames to reuse a mesh: for mesh objects the
    evaluated vertex positions and the topology sizes (a deforming modifier or shape key moves
    vertices; a generating one changes counts), and the matrix a baked mesh was made with. Other
    types (curves, text) return None: always converted again."""
    if obj.type != "MESH" or obj.data is None:
        return None
    data = obj.data
    co = np.empty(len(data.vertices) * 3, np.float32)
    data.vertices.foreach_get("co", co)
    h = hashlib.blake2b(co.tobytes(), digest_size=16)
    h.update(np.array([len(data.vertices), len(data.loops), len(data.polygons)], np.int64).tobytes())
    # The materials are part of what is stored (material ids per triangle), and so are the tangents
    # a material's normal map asks for (a Normal Map added since the last frame needs them).
    from .material_normal import tangent_uv_map
    h.update("|".join(f"{s.material.name_full}:{tangent_uv_map(s.material)}" if s.material else ""
                      for s in obj.material_slots).encode())
    if bake is not None:
        h.update(np.ascontiguousarray(bake, np.float64).tobytes())
    return h.digest()


def evaluated_geometry(obj, depsgraph, poll: Poll = None, bake: np.ndarray | None = None,
                       tangents_for: Callable[[tuple], str | None] | None = None) -> MeshGeometry | None:
    """An evaluated object's geometry, or None when it has no triangles. poll(): asked between
    stages; when it answers true, ExportCancelled is raised.

    tangents_for(materials): the UV map whose tangents the slots' materials read ('': the
    render-active one), or None for no tangents; only then are they computed (mesh_tangents.py).

    bake: a matrix the core cannot place (singular() is true): it is applied to the vertices
    here, for an instance with the identity. Scaled to zero, every triangle degenerates to a
    point or a line and is never hit, as in Cycles; flattened, a flat copy that Cycles renders
    too. A matrix that is not finite (a driver dividing by zero) shows nothing. A baked mesh has
    no shading normals: a singular matrix has no normal transform (the core uses each
    triangle's own normal)."""
    if bake is not None and not np.isfinite(bake).all():
        return None
    try:
        data = obj.to_mesh(preserve_all_data_layers=False, depsgraph=depsgraph)
    except TypeError:
        data = obj.to_mesh()
    except RuntimeError:
        data = None
    if data is None:
        return None
    try:
        stop_if(poll)
        verts, tris, normals, uvs, slots = mesh_arrays(data, poll)
        if len(tris) == 0:
            return None
        materials = _slot_materials(obj, data)
        uv_name = tangents_for(materials) if tangents_for is not None and bake is None else None
        tangents = _tangents(data, uv_name, normals, len(tris)) if uv_name is not None else None
    finally:
        obj.to_mesh_clear()
    if bake is not None:
        verts = (verts.astype(np.float64) @ bake[:3, :3].T + bake[:3, 3]).astype(np.float32)
        normals = None
    slots = np.clip(slots, 0, len(materials) - 1).astype(np.int32, copy=False)
    return MeshGeometry(verts, tris, normals, uvs, slots, materials, tangents)


def _tangents(data, uv_name: str, normals, exported: int) -> np.ndarray | None:
    """The corner tangents of `data`'s loop triangles (mesh_tangents.py); None when the UV map is
    missing or triangles were dropped (mesh_arrays' non-finite vertices: the order no longer
    matches), and the normal map then keeps the surface normal, as Cycles without tangents."""
    from .mesh_tangents import corner_tangents
    nt = len(data.loop_triangles)
    if nt != exported:
        return None
    loops = np.empty(nt * 3, np.uint32)
    data.loop_triangles.foreach_get("loops", loops)
    return corner_tangents(data, uv_name, loops, normals)


def _slot_materials(obj, data) -> tuple:
    """The material of each slot, by Blender's slot rules (the object's slots, then the mesh's
    extra materials); one None slot when there is none."""
    mats = [s.material for s in obj.material_slots]
    extra = list(getattr(data, "materials", []) or [])
    if len(extra) > len(mats):
        mats += extra[len(mats):]
    return tuple(mats) if mats else (None,)


def mesh_arrays(data, poll: Poll = None) -> tuple:
    """Vertices (N,3) f32, triangles (M,3) u32, normals, corner UVs (M,3,2) f32 or None, material
    indices (M,) i32, from an evaluated mesh datablock, through foreach_get.

    Normals come in the cheapest form that says the same thing (see _mesh_normals): None when
    every face is flat (the core then uses each triangle's own normal, as Cycles does for flat
    faces), (N,3) per vertex when every face is smooth without custom or auto-smooth normals,
    (M,3,3) per corner otherwise. Measured on a 1M-triangle mesh, see docs/blender.md."""
    data.calc_loop_triangles()
    nv = len(data.vertices)
    nt = len(data.loop_triangles)
    verts = np.empty(nv * 3, np.float32)
    data.vertices.foreach_get("co", verts)
    # uint32 buffers: Blender 3.4 copies these in bulk only when the buffer matches its unsigned
    # storage (4x faster than int32 here: 0.03 s against 0.14 s per million triangles).
    tris = np.empty(nt * 3, np.uint32)
    data.loop_triangles.foreach_get("vertices", tris)
    verts, tris = verts.reshape(nv, 3), tris.reshape(nt, 3)
    if nt == 0:
        return verts, tris, None, None, np.zeros(0, np.int32)
    stop_if(poll)

    loops = None  # triangle corners -> mesh loops, read only when something per corner needs it

    def corner_loops():
        nonlocal loops
        if loops is None:
            loops = np.empty(nt * 3, np.uint32)
            data.loop_triangles.foreach_get("loops", loops)
        return loops

    normals = _mesh_normals(data, nt, corner_loops)
    stop_if(poll)

    uvs = None
    layers = data.uv_layers
    if len(layers):
        # Cycles' Image Texture without a Vector link reads the render-active UV map.
        layer = next((uv for uv in layers if getattr(uv, "active_render", False)), None) or layers.active
        if layer is not None and len(layer.data) == len(data.loops):
            uv = np.empty(len(data.loops) * 2, np.float32)
            layer.data.foreach_get("uv", uv)
            # np.take, not uv[...] fancy indexing: 3x faster on a million triangles.
            uvs = np.take(uv.reshape(-1, 2), corner_loops(), axis=0).reshape(nt, 3, 2)

    stop_if(poll)
    if len(getattr(data, "materials", ())) <= 1:
        # One slot or none: every index maps to slot 0 (the caller clips), no need to read them.
        mat_idx = np.zeros(nt, np.int32)
    else:
        mat_idx = np.empty(nt, np.uint32)
        try:
            data.loop_triangles.foreach_get("material_index", mat_idx)
        except (AttributeError, TypeError, RuntimeError):
            # Newer versions: from the polygons' material_index through the triangles' polygons.
            pm = np.zeros(len(data.polygons), np.int32)
            data.polygons.foreach_get("material_index", pm)
            mat_idx = pm[_triangle_polygons(data, nt)]
        mat_idx = mat_idx.view(np.int32) if mat_idx.dtype == np.uint32 else mat_idx

    if not np.isfinite(verts).all():
        verts, tris, normals, uvs, mat_idx = _drop_nonfinite(verts, tris, normals, uvs, mat_idx)
    return verts, tris, normals, uvs, mat_idx


def _triangle_polygons(data, nt):
    """(M,) polygon index of each loop triangle (4.1+ keeps them in loop_triangle_polygons)."""
    poly = np.empty(nt, np.uint32)
    if hasattr(data, "loop_triangle_polygons"):
        data.loop_triangle_polygons.foreach_get("value", poly.view(np.int32))
    else:
        data.loop_triangles.foreach_get("polygon_index", poly)
    return poly


def _mesh_normals(data, nt, corner_loops):
    """The shading normals of a mesh: None (all faces flat), (N,3) per vertex (all smooth, no
    custom or auto-smooth normals) or (M,3,3) per corner; None also if Blender's are not finite.

    Blender 4.1+ says which with normals_domain (FACE, POINT, CORNER). Before, flat/smooth is
    per polygon (use_smooth), and custom normals or auto smooth make them per corner."""
    domain = getattr(data, "normals_domain", None)                 # 4.1+
    if domain is None:
        custom = bool(getattr(data, "has_custom_normals", False))
        auto = bool(getattr(data, "use_auto_smooth", False))
        smooth = np.empty(len(data.polygons), bool)
        data.polygons.foreach_get("use_smooth", smooth)
        if not smooth.any() and not custom:
            domain = "FACE"       # auto smooth only ever smooths faces marked smooth
        elif smooth.all() and not custom and not auto:
            domain = "POINT"
        else:
            domain = "CORNER"
    if domain == "FACE":
        return None
    if domain == "POINT":
        normals = np.empty(len(data.vertices) * 3, np.float32)
        if hasattr(data, "vertex_normals"):                        # 3.5+
            data.vertex_normals.foreach_get("vector", normals)
        else:
            data.vertices.foreach_get("normal", normals)
        normals = normals.reshape(-1, 3)
    elif hasattr(data, "corner_normals"):                           # 4.1+
        cn = np.empty(len(data.loops) * 3, np.float32)
        data.corner_normals.foreach_get("vector", cn)
        normals = np.take(cn.reshape(-1, 3), corner_loops(), axis=0).reshape(nt, 3, 3)
    else:
        if hasattr(data, "calc_normals_split"):                     # 3.x, 4.0: compute first
            data.calc_normals_split()
        normals = np.empty(nt * 9, np.float32)
        data.loop_triangles.foreach_get("split_normals", normals)
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
