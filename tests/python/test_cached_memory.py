"""toyrt.cached_memory_bytes() and toyrt.release_cached_memory(): the arrays a commit frees (the
BVH's nodes and triangle blocks, the commit's temporaries: each mapped in huge pages when it
reaches 2 MB) are kept for the next commit, up to a bound, until released; a release gives back
exactly what was counted, and the next commit still builds the same tree."""
import numpy as np
import toyrt


def grid(n, z=0.0):
    """An n x n grid of quads in the unit square at height z: 2 n^2 triangles."""
    xs, ys = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    vertices = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, z)], axis=1).astype(np.float32)
    i = np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]
    a, b, c, d = i.ravel(), i.ravel() + 1, i.ravel() + n + 1, i.ravel() + n + 2
    triangles = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)]).astype(np.uint32)
    return vertices, triangles


def hits(scene):
    origins = np.array([[0.31, 0.47, 1.0], [0.9, 0.1, 1.0], [2.0, 2.0, 1.0]], np.float32)
    directions = np.tile(np.array([[0.0, 0.0, -1.0]], np.float32), (3, 1))
    return scene.intersect(origins, directions)


def test_a_release_gives_back_what_was_cached_and_commits_go_on():
    toyrt.release_cached_memory()
    assert toyrt.cached_memory_bytes() == 0
    scene = toyrt.Scene()
    # 200,000 triangles: triangle blocks of about 12 MB and wide nodes of about 3 MB, both mapped.
    mesh = scene.add_mesh(*grid(316))
    scene.commit(builder="lbvh")
    before = hits(scene)
    # A rebuild frees the first build's arrays; they are kept (the second build may have taken
    # some back for its own arrays, but not all: it frees as many as it makes).
    scene.replace_mesh(mesh, *grid(316))
    scene.commit(builder="lbvh")
    cached = toyrt.cached_memory_bytes()
    assert cached >= 2 << 20  # at least one huge page's worth
    assert cached % (2 << 20) == 0  # whole huge pages
    assert toyrt.release_cached_memory() == cached
    assert toyrt.cached_memory_bytes() == 0
    assert toyrt.release_cached_memory() == 0  # nothing left to give
    # The scene's own arrays were never in the cache: it still traces, and rebuilds the same.
    np.testing.assert_array_equal(hits(scene)["t"], before["t"])
    scene.replace_mesh(mesh, *grid(316))
    scene.commit(builder="lbvh")
    after = hits(scene)
    for key in ("t", "prim", "u", "v"):
        np.testing.assert_array_equal(after[key], before[key], key)
    assert before["t"][2] == np.inf  # the third ray passes beside the grid

