"""The Python ray API: answers with known values (closed forms, a float64 brute force),
instances, per-ray segments, dtype handling, and clear errors for every misuse."""
import threading

import numpy as np
import pytest
import toyrt


def one_mesh(vertices, triangles, **commit_options):
    """A scene of one mesh, committed."""
    s = toyrt.Scene()
    s.add_mesh(vertices, triangles)
    s.commit(**commit_options)
    return s


def quad_scene(z=0.0):
    """Two triangles covering [0, 1]^2 at height z."""
    v = np.array([[0, 0, z], [1, 0, z], [1, 1, z], [0, 1, z]], np.float32)
    return one_mesh(v, np.array([[0, 1, 2], [0, 2, 3]], np.uint32))


def random_soup(rng, count, size):
    """`count` separate triangles of about `size` scattered in the unit cube: (vertices, triangles)."""
    centres = rng.uniform(0, 1, (count, 1, 3))
    vertices = (centres + rng.uniform(-size, size, (count, 3, 3))).reshape(-1, 3).astype(np.float32)
    return vertices, np.arange(3 * count, dtype=np.uint32).reshape(-1, 3)


def brute_force(vertices, triangles, origins, directions):
    """Nearest hit of every ray against every triangle, in float64 (Moller-Trumbore)."""
    p0, p1, p2 = (vertices[triangles[:, k]].astype(np.float64) for k in range(3))
    e1, e2 = p1 - p0, p2 - p0
    best_t = np.full(len(origins), np.inf)
    best_prim = np.full(len(origins), -1)
    for i, (o, d) in enumerate(zip(origins.astype(np.float64), directions.astype(np.float64))):
        pv = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, pv)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            tv = o - p0
            u = np.einsum("ij,ij->i", tv, pv) * inv
            qv = np.cross(tv, e1)
            v = (qv @ d) * inv
            t = np.einsum("ij,ij->i", e2, qv) * inv
        ok = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0)
        if ok.any():
            k = np.argmin(np.where(ok, t, np.inf))
            best_t[i], best_prim[i] = t[k], k
    return best_t, best_prim


def test_distance_to_a_plane_is_the_closed_form():
    s = quad_scene(z=0.5)
    rng = np.random.default_rng(1)
    n = 5000
    org = np.column_stack([rng.uniform(0.1, 0.9, n), rng.uniform(0.1, 0.9, n), rng.uniform(1, 5, n)])
    target = np.column_stack([rng.uniform(0.05, 0.95, n), rng.uniform(0.05, 0.95, n), np.full(n, 0.5)])
    d = target - org
    hits = s.intersect(org, d)
    # The plane z = 0.5 is reached at t = 1 exactly (direction unnormalised).
    np.testing.assert_allclose(hits["t"], 1.0, rtol=1e-6)
    assert hits["t"].dtype == np.float32 and hits["prim"].dtype == np.int32
    assert set(np.unique(hits["prim"])) == {0, 1}
    assert (hits["instance"] == 0).all()


def test_barycentrics_follow_embree_convention():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0]], np.float32)
    s = one_mesh(v, np.array([[0, 1, 2]]))
    h = s.intersect([[0.5, 0.5, 1.0]], [[0, 0, -1.0]])
    # p = (1-u-v) p0 + u p1 + v p2 = (0.5, 0.5, 0)  =>  u = v = 0.25
    assert h["u"][0] == pytest.approx(0.25) and h["v"][0] == pytest.approx(0.25)


def test_agrees_with_float64_brute_force_on_a_random_soup():
    rng = np.random.default_rng(7)
    vertices, triangles = random_soup(rng, 300, 0.08)
    s = one_mesh(vertices, triangles)
    org = rng.uniform(-0.5, 1.5, (2000, 3)).astype(np.float32)
    d = (rng.uniform(0, 1, (2000, 3)) - org).astype(np.float32)
    hits = s.intersect(org, d)
    ref_t, ref_prim = brute_force(vertices, triangles, org, d)
    assert np.array_equal(np.isfinite(hits["t"]), np.isfinite(ref_t))
    hit = np.isfinite(ref_t)
    assert hit.sum() > 200
    np.testing.assert_allclose(hits["t"][hit], ref_t[hit], rtol=1e-5)
    assert (hits["prim"][hit] == ref_prim[hit]).mean() > 0.99  # ties at shared points may differ
    assert (hits["prim"][~hit] == -1).all() and np.isinf(hits["t"][~hit]).all()


def test_instances_with_rotation_and_non_uniform_scale_match_transformed_geometry():
    rng = np.random.default_rng(3)
    vertices = rng.uniform(-1, 1, (60, 3)).astype(np.float32)
    triangles = rng.integers(0, 60, (40, 3)).astype(np.uint32)
    theta = 0.7
    rot = np.array([[np.cos(theta), -np.sin(theta), 0], [np.sin(theta), np.cos(theta), 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3] = rot @ np.diag([2.0, 0.5, 1.3])
    m[:3, 3] = [5.0, -2.0, 1.0]
    s = toyrt.Scene()
    mesh = s.add_mesh(vertices, triangles)
    inst = s.add_instance(mesh, m)
    assert (mesh, inst) == (0, 1)
    s.commit()
    world = (vertices.astype(np.float64) @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
    org = rng.uniform(-3, 8, (1500, 3)).astype(np.float32)
    d = (rng.uniform([3, -4, -1], [7, 0, 3], (1500, 3)) - org).astype(np.float32)
    hits = s.intersect(org, d)
    on_instance = hits["instance"] == 1
    ref_t, ref_prim = brute_force(world, triangles, org, d)
    assert on_instance.sum() > 100
    np.testing.assert_allclose(hits["t"][on_instance], ref_t[on_instance], rtol=1e-4)
    # Rays that miss the original mesh and its instance miss entirely.
    plain_t, _ = brute_force(vertices, triangles, org, d)
    both_miss = ~np.isfinite(ref_t) & ~np.isfinite(plain_t)
    assert np.isinf(hits["t"][both_miss]).all()


def test_occluded_agrees_with_intersect_with_per_ray_segments():
    s = quad_scene(z=0.0)
    rng = np.random.default_rng(2)
    n = 4000
    org = np.column_stack([rng.uniform(-0.5, 1.5, n), rng.uniform(-0.5, 1.5, n), np.full(n, 1.0)])
    d = np.tile([0.0, 0.0, -1.0], (n, 1))
    tfar = rng.uniform(0.5, 1.5, n)
    tnear = rng.uniform(0.0, 0.5, n)
    hits = s.intersect(org, d, tnear=tnear, tfar=tfar)
    blocked = s.occluded(org, d, tnear=tnear, tfar=tfar)
    assert blocked.dtype == np.bool_
    assert np.array_equal(blocked, np.isfinite(hits["t"]))
    inside = (org[:, 0] > 0) & (org[:, 0] < 1) & (org[:, 1] > 0) & (org[:, 1] < 1)
    assert np.array_equal(blocked, inside & (tfar > 1.0))
    # A segment that starts past the surface sees nothing.
    assert not s.occluded(org, d, tnear=1.01).any()


def test_other_dtypes_are_converted_and_give_the_same_answers():
    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    s = toyrt.Scene()
    s.add_mesh(np.array(v, np.float64), np.array([[0, 1, 2]], np.int64))
    s.add_instance(0, np.eye(4, dtype=np.float32) + np.array([[0, 0, 0, 3]] + [[0] * 4] * 3))
    s.commit()
    a = s.intersect([[0.2, 0.2, 1]], [[0, 0, -1]])                        # lists of ints/floats
    b = s.intersect(np.array([[0.2, 0.2, 1]], np.float64), np.array([[0, 0, -1]], np.int32))
    c = s.intersect(np.asfortranarray([[0.2, 0.2, 1.0]]), [[0, 0, -1.0]])  # non-contiguous layouts
    for h in (b, c):
        for k in a:
            assert np.array_equal(a[k], h[k])
    assert a["t"][0] == pytest.approx(1.0)


def test_results_do_not_depend_on_thread_count():
    rng = np.random.default_rng(5)
    vertices = rng.uniform(0, 1, (3000, 3)).astype(np.float32)
    triangles = rng.integers(0, 3000, (5000, 3)).astype(np.uint32)
    s = one_mesh(vertices, triangles, threads=1)
    org = rng.uniform(-1, 2, (20000, 3)).astype(np.float32)
    d = rng.normal(size=(20000, 3)).astype(np.float32)
    one, two = s.intersect(org, d, threads=1), s.intersect(org, d, threads=2)
    for k in one:
        assert np.array_equal(one[k], two[k])


def test_empty_batches_and_scenes():
    s = toyrt.Scene()
    s.commit()
    h = s.intersect(np.zeros((0, 3)), np.zeros((0, 3)))
    assert all(len(a) == 0 for a in h.values())
    h = s.intersect([[0, 0, 0]], [[1, 0, 0]])
    assert np.isinf(h["t"][0]) and h["prim"][0] == -1 and h["instance"][0] == -1


def test_rays_that_cannot_hit_miss_quietly():
    s = quad_scene()
    org = np.array([[0.5, 0.5, 1], [np.nan, 0.5, 1], [0.5, 0.5, 1], [0.5, 0.5, 1]], np.float32)
    d = np.array([[0, 0, 0], [0, 0, -1], [np.inf, 0, -1], [0, 0, -1]], np.float32)
    h = s.intersect(org, d, tfar=np.array([np.inf, np.inf, np.inf, 0.5], np.float32))
    assert np.isinf(h["t"]).all() and (h["prim"] == -1).all()
    # tnear > tfar: an empty segment.
    assert not s.occluded([[0.5, 0.5, 1]], [[0, 0, -1]], tnear=2.0, tfar=1.0).any()


def test_degenerate_triangles_are_kept_in_numbering_but_never_hit():
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], np.float32)
    s = one_mesh(v, np.array([[0, 1, 2], [0, 1, 3]]))  # the first is a line
    h = s.intersect([[0.2, 0.2, 1], [0.5, 0.0, 1]], [[0, 0, -1], [0, 0, -1]])
    assert h["prim"][0] == 1                                  # index of the input, not of a compacted list
    assert h["prim"][1] in (-1, 1)                            # on the shared edge: only the real triangle


def test_offset_ray_origin_moves_off_the_surface_at_any_distance():
    for scale in (1.0, 1e3, 1e5):
        p = np.array([[scale, scale * 0.5, -scale * 0.25]], np.float32)
        n = np.array([[0.0, 0.0, 1.0]], np.float32)
        q = toyrt.offset_ray_origin(p, n)
        assert q[0, 2] > p[0, 2]
        assert q[0, 0] == p[0, 0] and q[0, 1] == p[0, 1]
        assert q[0, 2] - p[0, 2] < 1e-4 * max(1.0, scale)


def test_queries_release_the_gil():
    """A long batch in one thread leaves the interpreter free for another."""
    rng = np.random.default_rng(9)
    vertices, triangles = random_soup(rng, 50000, 0.01)
    s = one_mesh(vertices, triangles)
    org = rng.uniform(0, 1, (400000, 3)).astype(np.float32)
    d = rng.normal(size=(400000, 3)).astype(np.float32)
    started = threading.Event()

    def work():
        started.set()
        s.intersect(org, d, threads=1)

    worker = threading.Thread(target=work)
    worker.start()
    started.wait()
    ticks = 0
    while worker.is_alive():
        ticks += 1
    worker.join()
    # Holding the GIL for the whole call would leave this loop a handful of turns.
    assert ticks > 10000


def test_queries_from_several_threads_while_another_adds_meshes():
    s = quad_scene()
    errors = []

    def query():
        for _ in range(200):
            try:
                s.intersect([[0.5, 0.5, 1]], [[0, 0, -1]])
            except RuntimeError as e:  # a commit pending from the writer is a clear error, not a crash
                assert "commit" in str(e)
            except Exception as e:  # noqa: BLE001 - any other exception is a failure
                errors.append(e)

    def write():
        for i in range(50):
            s.add_mesh(np.array([[0, 0, i], [1, 0, i], [0, 1, i]], np.float32), np.array([[0, 1, 2]]))
            s.commit()

    threads = [threading.Thread(target=query) for _ in range(3)] + [threading.Thread(target=write)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert s.mesh_count == 51
    h = s.intersect([[0.2, 0.2, 100]], [[0, 0, -1]])
    assert h["t"][0] == pytest.approx(51.0) and h["instance"][0] == 50


def test_stats_report_the_trees():
    s = quad_scene()
    # Two triangles make one leaf: no wide node, depth 0; the top level is one binary leaf.
    stats = s.bvh_stats(0)
    assert (stats["nodes"], stats["leaves"], stats["triangles"], stats["depth"]) == (0, 1, 2, 0)
    assert stats["children_per_node"] == 0.0 and stats["sah_cost"] > 0
    top = s.bvh_stats()
    assert (top["nodes"], top["leaves"], top["depth"], top["children_per_node"]) == (1, 1, 1, 0.0)
    assert s.triangle_count == 2 and s.instance_count == 1 and s.committed
    assert s.build_ms >= 0.0


@pytest.mark.parametrize("builder", ["sah", "lbvh"])
def test_stats_describe_the_wide_tree(builder):
    rng = np.random.default_rng(13)
    n = 5000
    vertices, triangles = random_soup(rng, n, 0.02)
    triangles = np.vstack([triangles, [[0, 0, 1]]]).astype(np.uint32)  # a degenerate one: in no leaf
    stats = one_mesh(vertices, triangles, builder=builder).bvh_stats(0)
    nodes, leaves = stats["nodes"], stats["leaves"]
    assert stats["triangles"] == n  # every triangle that can be hit, in exactly one leaf
    assert leaves >= -(-n // 8)  # a leaf is one block of at most 8 triangles
    # Every node but the root is a used slot, and so is every leaf: the mean follows exactly.
    assert stats["children_per_node"] == pytest.approx((nodes - 1 + leaves) / nodes, rel=1e-12)
    assert leaves <= 7 * nodes + 1  # nodes of at most 8 children
    assert 8 ** stats["depth"] >= leaves and stats["depth"] <= nodes
    assert stats["sah_cost"] > 0


def test_lbvh_builder_gives_the_same_hits_as_sah():
    rng = np.random.default_rng(11)
    vertices, triangles = random_soup(rng, 20000, 0.02)
    org = rng.uniform(-0.5, 1.5, (20000, 3)).astype(np.float32)
    d = (rng.uniform(0, 1, (20000, 3)) - org).astype(np.float32)
    hits = {}
    for builder in ("sah", "lbvh"):
        s = one_mesh(vertices, triangles, builder=builder)
        assert s.last_commit[f"{builder}_meshes"] == 1 and s.last_commit["warning"] == ""
        hits[builder] = s.intersect(org, d)
    assert np.array_equal(np.isfinite(hits["sah"]["t"]), np.isfinite(hits["lbvh"]["t"]))
    np.testing.assert_array_equal(hits["sah"]["t"], hits["lbvh"]["t"])  # same triangles, same double refinement


def test_auto_builder_follows_the_expected_ray_count():
    rng = np.random.default_rng(12)
    vertices = rng.uniform(0, 1, (30000, 3)).astype(np.float32)
    triangles = np.arange(30000, dtype=np.uint32).reshape(-1, 3)
    s = one_mesh(vertices, triangles, builder="auto")  # no estimate: the faster-tracing SAH tree
    assert s.last_commit["sah_meshes"] == 1
    s.add_mesh(vertices, triangles)
    s.commit(builder="auto", expected_rays=1000)  # a handful of rays: the cheaper build
    assert s.last_commit["lbvh_meshes"] == 1
    s.add_mesh(vertices, triangles)
    s.commit(builder="auto", expected_rays=1e9)
    assert s.last_commit["sah_meshes"] == 1


def test_lbvh_without_opencl_builds_on_the_host_without_a_warning():
    # The LBVH runs its kernels on an OpenCL GPU only; without OpenCL (as on a CPU device) the host
    # builds it, so nothing falls back and nothing is said.
    import subprocess
    import sys
    code = (
        "import warnings, numpy as np, toyrt\n"
        "s = toyrt.Scene()\n"
        "v = np.random.default_rng(1).uniform(0, 1, (300, 3)).astype(np.float32)\n"
        "s.add_mesh(v, np.arange(300).reshape(-1, 3)); s.add_mesh(v, np.arange(300).reshape(-1, 3))\n"
        "with warnings.catch_warnings(record=True) as w:\n"
        "    warnings.simplefilter('always')\n"
        "    s.commit(builder='lbvh')\n"
        "print(len(w), s.last_commit['lbvh_meshes'], s.last_commit['sah_meshes'])\n"
    )
    import os
    env = dict(os.environ, TOYRT_OPENCL="off", PYTHONPATH=os.pathsep.join(sys.path))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    assert out.splitlines()[0] == "0 2 0"
