"""Closed meshes and the aligned query sets of the exact-query tests and of bench/queries_bench.py
(one kit for both): a cube split into triangles, an icosphere, rays from an interior point aimed
exactly at every vertex and edge point, grid points on and off a cube's faces."""
import numpy as np


def cube(size=1.0, offset=(0.0, 0.0, 0.0)):
    """[0, size]^3 + offset, two outward triangles per face: (vertices float32 (8, 3), triangles (12, 3))."""
    corners = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], np.float64)
    v = (np.float32(size) * corners.astype(np.float32) + np.asarray(offset, np.float32)).astype(np.float32)
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    tris = [[f[0], f[1], f[2]] for f in faces] + [[f[0], f[2], f[3]] for f in faces]
    return v, np.array(tris, np.uint32)


def icosphere(levels, radius=1.0, offset=(0.0, 0.0, 0.0)):
    """An icosahedron subdivided `levels` times onto the sphere: 20 * 4^levels triangles."""
    t = (1.0 + 5.0**0.5) / 2.0
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
         [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
         [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    v = np.array(v, np.float64)
    f = np.array(f, np.int64)
    for _ in range(levels):
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        unique, inverse = np.unique(edges, axis=0, return_inverse=True)
        mids = len(v) + inverse.reshape(3, -1).T  # per triangle: midpoints of (01, 12, 20)
        v = np.concatenate([v, 0.5 * (v[unique[:, 0]] + v[unique[:, 1]])])
        a, b, c = mids[:, 0], mids[:, 1], mids[:, 2]
        f = np.concatenate([np.stack([f[:, 0], a, c], 1), np.stack([f[:, 1], b, a], 1),
                            np.stack([f[:, 2], c, b], 1), np.stack([a, b, c], 1)])
    v = radius * v / np.linalg.norm(v, axis=1, keepdims=True) + np.asarray(offset)
    return v.astype(np.float32), f.astype(np.uint32)


def aligned_rays(vertices, triangles, inside, per_edge=2, seed=0):
    """Rays from `inside` aimed at every vertex, edge midpoint and `per_edge` random points of every
    edge (targets computed in float32): (origins, directions), float32 (N, 3)."""
    rng = np.random.default_rng(seed)
    edges = np.unique(np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                              triangles[:, [2, 0]]]), axis=1), axis=0)
    a, b = vertices[edges[:, 0]], vertices[edges[:, 1]]
    targets = [vertices, (np.float32(0.5) * (a + b)).astype(np.float32)]
    for _ in range(per_edge):
        s = rng.uniform(0, 1, (len(edges), 1)).astype(np.float32)
        targets.append((a + s * (b - a)).astype(np.float32))
    targets = np.concatenate(targets)
    origins = np.broadcast_to(np.asarray(inside, np.float32), targets.shape).copy()
    return origins, (targets - origins).astype(np.float32)


def cube_grid(size, offset, steps):
    """Grid points -1 .. size + 1 in integer steps around the cube [0, size]^3 + offset, and whether
    each lies in the closed cube: (points float32 (N, 3), inside bool (N,))."""
    k = np.arange(-1, size + 2, steps)
    g = np.stack(np.meshgrid(k, k, k, indexing="ij"), -1).reshape(-1, 3)
    inside = np.all((g >= 0) & (g <= size), axis=1)
    return (g.astype(np.float32) + np.asarray(offset, np.float32)).astype(np.float32), inside
