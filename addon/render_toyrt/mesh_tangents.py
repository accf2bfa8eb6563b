"""MikkTSpace tangents per triangle corner, for a tangent-space Normal Map (the core's
render/normal_mapping.h): Blender's own MikkTSpace (Mesh.calc_tangents) run over the triangles
TOYRT renders, as Cycles runs it over its triangles.

calc_tangents refuses n-gons, and on quads MikkTSpace would split them itself. So it runs on a
temporary mesh made of the mesh's loop triangles, corner for corner (loop i of the copy is corner
i of the exported triangles), with each corner's shading normal as the one TOYRT renders with
(the copy's custom normals) and the UV map's coordinates: the tangents MikkTSpace derives from
positions, normals and UVs are then those of the triangles rendered. Only meshes whose material
has a tangent-space normal map get here (mesh.evaluated_geometry's tangents_for)."""
from __future__ import annotations

import numpy as np


def uv_layer(data, name: str):
    """The UV map `name`, or for '' the render-active one (the active one if none is marked)."""
    layers = data.uv_layers
    if name:
        return layers.get(name)
    return next((uv for uv in layers if getattr(uv, "active_render", False)), None) or layers.active


def corner_tangents(data, name: str, corner_loops: np.ndarray, normals) -> np.ndarray | None:
    """(M, 3, 4) float32: per corner of data.loop_triangles (corner_loops: their M * 3 loops) the
    unit object-space tangent and the bitangent sign (+-1) of UV map `name`; None when the mesh
    has no such UV map. normals: the exported shading normals (mesh.mesh_arrays: None for flat,
    (N, 3) per vertex or (M, 3, 3) per corner)."""
    import bpy
    layer = uv_layer(data, name)
    if layer is None or len(layer.data) != len(data.loops):
        return None
    nt = len(corner_loops) // 3
    if nt == 0:
        return np.zeros((0, 3, 4), np.float32)
    nv = len(data.vertices)
    co = np.empty(nv * 3, np.float32)
    data.vertices.foreach_get("co", co)
    tri_verts = np.empty(nt * 3, np.uint32)
    data.loop_triangles.foreach_get("vertices", tri_verts)
    uv = np.empty(len(data.loops) * 2, np.float32)
    layer.data.foreach_get("uv", uv)
    corner_uv = np.take(uv.reshape(-1, 2), corner_loops, axis=0)

    copy = bpy.data.meshes.new("toyrt-tangents")
    try:
        copy.vertices.add(nv)
        copy.vertices.foreach_set("co", co)
        copy.loops.add(nt * 3)
        copy.loops.foreach_set("vertex_index", tri_verts.astype(np.int32))
        copy.polygons.add(nt)
        copy.polygons.foreach_set("loop_start", np.arange(0, 3 * nt, 3, dtype=np.int32))
        total = copy.polygons[0].bl_rna.properties.get("loop_total")
        if total is not None and not total.is_readonly:            # 3.x; 4.x derives it from loop_start
            copy.polygons.foreach_set("loop_total", np.full(nt, 3, np.int32))
        copy.update(calc_edges=True)
        copy.uv_layers.new(name="UVMap")
        copy.uv_layers[0].data.foreach_set("uv", corner_uv.ravel())
        _set_normals(copy, nt, normals, tri_verts)
        copy.calc_tangents(uvmap="UVMap")
        tangent = np.empty(nt * 9, np.float32)
        copy.loops.foreach_get("tangent", tangent)
        sign = np.empty(nt * 3, np.float32)
        copy.loops.foreach_get("bitangent_sign", sign)
    finally:
        bpy.data.meshes.remove(copy)
    out = np.concatenate([tangent.reshape(-1, 3), sign.reshape(-1, 1)], axis=1).reshape(nt, 3, 4)
    return np.ascontiguousarray(np.nan_to_num(out, nan=0.0, posinf=0.0, neginf=0.0))


def _set_normals(copy, nt, normals, tri_verts) -> None:
    """The copy's corner normals: flat faces when the mesh is flat (MikkTSpace then reads each
    triangle's own normal, as the core does), else every face smooth with the exported normals as
    custom normals."""
    smooth = normals is not None
    copy.polygons.foreach_set("use_smooth", np.full(nt, smooth, bool))
    if not smooth:
        return
    if normals.ndim == 2:                          # per vertex
        corner = normals[tri_verts.astype(np.int64)]
    else:                                          # per corner
        corner = normals.reshape(-1, 3)
    if hasattr(copy, "use_auto_smooth"):           # 3.x, 4.0: custom normals need auto smooth
        copy.use_auto_smooth = True
    copy.normals_split_custom_set(corner.astype(np.float64).tolist())
