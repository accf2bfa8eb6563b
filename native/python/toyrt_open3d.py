"""Open3D's RaycastingScene on TOYRT's exact queries, for Open3D users who switch by changing an import:

    from toyrt_open3d import RaycastingScene   # instead of open3d.t.geometry.RaycastingScene

Rays are (..., 6) arrays [ox, oy, oz, dx, dy, dz], points (..., 3); answers keep the leading shape and
Open3D's keys and dtypes (geometry and primitive ids uint32 with INVALID_ID on a miss, occupancy
float32). Results are numpy arrays that also answer `.numpy()`, as Open3D's tensors do. Each
add_triangles call is one geometry (a TOYRT mesh with one untransformed instance), committed lazily
before the next query. The differences are TOYRT's: counts, lists and occupancy are exact at shared
edges and vertices (docs/queries.md), so `nsamples` is accepted and ignored.
"""
import numpy as np
import toyrt


class _Array(np.ndarray):
    """A numpy array with Open3D Tensor's `.numpy()`."""

    def numpy(self):
        return np.asarray(self)


def _out(a):
    return np.asarray(a).view(_Array)


def _numpy(x):
    return np.asarray(x.numpy() if hasattr(x, "numpy") else x)


class RaycastingScene:
    INVALID_ID = np.iinfo(np.uint32).max

    def __init__(self, nthreads=0, device=None):
        self._scene = toyrt.Scene()
        self._normals = []  # per geometry: unit geometric normal per triangle
        self._dirty = True

    def add_triangles(self, vertex_positions, triangle_indices=None):
        """(vertices (N, 3), triangles (M, 3)), or an Open3D TriangleMesh (legacy or tensor); returns its id."""
        if triangle_indices is None:
            mesh = vertex_positions
            if hasattr(mesh, "vertex"):  # open3d.t.geometry.TriangleMesh
                vertex_positions, triangle_indices = mesh.vertex["positions"], mesh.triangle["indices"]
            else:  # open3d.geometry.TriangleMesh
                vertex_positions, triangle_indices = mesh.vertices, mesh.triangles
        v = np.ascontiguousarray(_numpy(vertex_positions), np.float32)
        f = np.ascontiguousarray(_numpy(triangle_indices), np.int64)
        gid = self._scene.add_mesh(v, f)
        p = v[f].astype(np.float64) if len(f) else np.zeros((0, 3, 3))
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        with np.errstate(invalid="ignore", divide="ignore"):
            n = n / np.linalg.norm(n, axis=1, keepdims=True)
        self._normals.append(np.nan_to_num(n).astype(np.float32))
        self._dirty = True
        return gid

    def _ready(self):
        if self._dirty:
            self._scene.commit()
            self._dirty = False

    def _rays(self, rays):
        r = np.asarray(_numpy(rays), np.float32)
        if r.ndim < 2 or r.shape[-1] != 6:
            raise ValueError(f"rays must have shape (..., 6), got {r.shape}")
        flat = r.reshape(-1, 6)
        self._ready()
        return r.shape[:-1], np.ascontiguousarray(flat[:, :3]), np.ascontiguousarray(flat[:, 3:])

    def _points(self, query_points):
        p = np.asarray(_numpy(query_points), np.float32)
        if p.ndim < 2 or p.shape[-1] != 3:
            raise ValueError(f"query_points must have shape (..., 3), got {p.shape}")
        self._ready()
        return p.shape[:-1], np.ascontiguousarray(p.reshape(-1, 3))

    def _ids(self, ids):
        return np.where(ids < 0, self.INVALID_ID, ids).astype(np.uint32)

    def _normals_of(self, mesh, prim):
        out = np.zeros((len(prim), 3), np.float32)
        for g, normals in enumerate(self._normals):
            sel = mesh == g
            out[sel] = normals[prim[sel]]
        return out

    def cast_rays(self, rays, nthreads=0):
        shape, o, d = self._rays(rays)
        h = self._scene.intersect(o, d, threads=nthreads)
        mesh = np.full(len(o), -1, np.int64)
        found = h["instance"] >= 0
        mesh[found] = h["instance"][found]  # one instance per geometry, in order: instance id = mesh id
        return {"t_hit": _out(h["t"].reshape(shape)),
                "geometry_ids": _out(self._ids(mesh).reshape(shape)),
                "primitive_ids": _out(self._ids(h["prim"]).reshape(shape)),
                "primitive_uvs": _out(np.where(found[:, None], np.stack([h["u"], h["v"]], 1), 0)
                                      .astype(np.float32).reshape(shape + (2,))),
                "primitive_normals": _out(self._normals_of(mesh, np.maximum(h["prim"], 0)).reshape(shape + (3,)))}

    def test_occlusions(self, rays, tnear=0.0, tfar=np.inf, nthreads=0):
        shape, o, d = self._rays(rays)
        return _out(self._scene.occluded(o, d, tnear=tnear, tfar=tfar, threads=nthreads).reshape(shape))

    def count_intersections(self, rays, nthreads=0):
        shape, o, d = self._rays(rays)
        return _out(self._scene.count_intersections(o, d, threads=nthreads).astype(np.int32).reshape(shape))

    def list_intersections(self, rays, nthreads=0):
        _, o, d = self._rays(rays)
        h = self._scene.list_intersections(o, d, threads=nthreads)
        return {"ray_splits": _out(h["ray_splits"].astype(np.uint32)), "ray_ids": _out(h["ray"]),
                "t_hit": _out(h["t"]), "geometry_ids": _out(h["mesh"].astype(np.uint32)),
                "primitive_ids": _out(h["prim"].astype(np.uint32)),
                "primitive_uvs": _out(np.stack([h["u"], h["v"]], 1).astype(np.float32)),
                "primitive_normals": _out(self._normals_of(h["mesh"], h["prim"]))}

    def compute_closest_points(self, query_points, nthreads=0):
        shape, p = self._points(query_points)
        c = self._scene.compute_closest_points(p, threads=nthreads)
        return {"points": _out(c["points"].reshape(shape + (3,))),
                "geometry_ids": _out(self._ids(c["mesh"]).reshape(shape)),
                "primitive_ids": _out(self._ids(c["prim"]).reshape(shape)),
                "primitive_uvs": _out(np.stack([c["u"], c["v"]], 1).reshape(shape + (2,))),
                "primitive_normals": _out(c["normal"].reshape(shape + (3,)))}

    def compute_distance(self, query_points, nthreads=0):
        shape, p = self._points(query_points)
        return _out(self._scene.compute_distance(p, threads=nthreads).reshape(shape))

    def compute_signed_distance(self, query_points, nthreads=0, nsamples=1):
        shape, p = self._points(query_points)
        return _out(self._scene.compute_signed_distance(p, threads=nthreads).reshape(shape))

    def compute_occupancy(self, query_points, nthreads=0, nsamples=1):
        shape, p = self._points(query_points)
        return _out(self._scene.compute_occupancy(p, threads=nthreads).astype(np.float32).reshape(shape))
