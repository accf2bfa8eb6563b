"""The exact geometric queries: crossing counts through edges and vertices of closed meshes (known
answers: one crossing from inside a convex mesh, two along a line through it), the hit lists'
order, occupancy and distances against closed forms and a float64 brute force, bad input."""
import warnings

import numpy as np
import pytest
import toyrt
from query_meshes import aligned_rays, cube, cube_grid, icosphere


def scene_of(vertices, triangles, transform=None):
    s = toyrt.Scene()
    s.add_mesh(vertices, triangles, transform=transform)
    s.commit()
    return s


CLOSED = [
    ("cube", cube(2.0), (1, 1, 1)),
    ("cube-at-1e5", cube(2.0, (1e5, -1e5, 3e5)), (1e5 + 1, -1e5 + 1, 3e5 + 1)),
    ("cube-tiny", cube(2.0**-59), (2.0**-60,) * 3),
    ("icosphere", icosphere(4), (0.1, -0.2, 0.3)),
    ("icosphere-at-1e4", icosphere(3, 1.0, (1e4, 1e4, 1e4)), (1e4, 1e4, 1e4)),
    ("icosphere-tiny", icosphere(3, 1e-6), (0, 0, 0)),
]


@pytest.mark.parametrize("name,mesh,inside", CLOSED, ids=[c[0] for c in CLOSED])
def test_rays_through_vertices_and_edges_cross_a_convex_mesh_once(name, mesh, inside):
    s = scene_of(*mesh)
    o, d = aligned_rays(*mesh, inside)
    assert np.all(s.count_intersections(o, d) == 1)
    assert np.all(s.count_intersections(o, d, tnear=-np.inf) == 2)  # the whole line


def test_hit_lists_are_in_ray_then_distance_order_and_match_the_counts():
    v, f = icosphere(3)
    s = scene_of(v, f)
    rng = np.random.default_rng(1)
    o = np.column_stack([np.full(300, -3.0), rng.uniform(-1.2, 1.2, (300, 2))]).astype(np.float32)
    d = np.tile(np.float32([1, 0, 0]), (300, 1))
    counts = s.count_intersections(o, d)
    hits = s.list_intersections(o, d)
    assert np.array_equal(np.diff(hits["ray_splits"]), counts)
    assert set(np.unique(counts)) <= {0, 2} and counts.sum() > 100
    assert np.array_equal(hits["ray"], np.repeat(np.arange(300), counts))
    for i in np.flatnonzero(counts):
        t = hits["t"][hits["ray_splits"][i]:hits["ray_splits"][i + 1]]
        assert t[0] < t[1]
    # The crossing points lie on the sphere (radius 1 up to the facets' sag).
    p = o[hits["ray"]] + hits["t"][:, None] * d[hits["ray"]]
    assert np.all(np.abs(np.linalg.norm(p, axis=1) - 1.0) < 0.02)
    assert hits["t"].dtype == np.float32 and hits["prim"].dtype == np.int32


def test_hit_list_past_max_hits_is_refused():
    s = scene_of(*cube())
    o, d = np.float32([[0.5, 0.5, -1]] * 10), np.float32([[0, 0, 1]] * 10)
    assert len(s.list_intersections(o, d, max_hits=20)["t"]) == 20
    with pytest.raises(ValueError, match="max_hits"):
        s.list_intersections(o, d, max_hits=19)


@pytest.mark.parametrize("offset", [(0, 0, 0), (1e5, -2e5, 4e5)])
def test_cube_grid_occupancy_is_exact_on_and_off_the_faces(offset):
    s = scene_of(*cube(4.0, offset))
    points, inside = cube_grid(4, offset, 1)
    assert np.array_equal(s.compute_occupancy(points), inside)


def test_occupancy_of_points_along_rays_through_vertices_and_edges():
    v, f = icosphere(3)
    s = scene_of(v, f)
    _, d = aligned_rays(v, f, (0, 0, 0))
    for scale, want in ((0.5, True), (0.99, True), (1.01, False), (1.5, False)):
        assert np.all(s.compute_occupancy((np.float32(scale) * d).astype(np.float32)) == want)


def test_open_mesh_gets_the_parity_of_the_plus_x_ray():
    # A cube without its top: the +x ray from a point within still crosses the x = 1 wall once. A
    # cube without that wall: no crossing. Points outside the mesh's box are outside.
    v, f = cube()
    within = np.float32([[0.5, 0.5, 0.5], [0.25, 0.75, 0.9], [2, 0.5, 0.5]])
    no_top = [t for t in f.tolist() if not all(v[k][2] == 1 for k in t)]
    no_wall = [t for t in f.tolist() if not all(v[k][0] == 1 for k in t)]
    assert scene_of(v, np.uint32(no_top)).compute_occupancy(within).tolist() == [True, True, False]
    assert scene_of(v, np.uint32(no_wall)).compute_occupancy(within).tolist() == [False, False, False]


def test_cube_distances_have_closed_forms():
    s = scene_of(*cube(2.0))
    p = np.float32([[1, 1, 1], [5, 1, 1], [4, 4, 4], [1, 1, 2], [-1, 3, 1]])
    want = np.float32([-1, 3, 2 * np.sqrt(3), 0, np.sqrt(2)])
    assert np.allclose(s.compute_signed_distance(p), want, rtol=1e-7, atol=0)
    assert np.allclose(s.compute_distance(p), np.abs(want), rtol=1e-7, atol=0)
    c = s.compute_closest_points(p)
    assert np.allclose(c["points"][1:], [[2, 1, 1], [2, 2, 2], [1, 1, 2], [0, 2, 1]], atol=1e-6)  # [0]: a tie
    assert np.allclose(np.linalg.norm(c["normal"], axis=1), 1.0)


def test_closest_points_match_a_float64_brute_force_under_a_transform():
    v, f = icosphere(2, 2.0)
    m = np.eye(4)
    m[:3, :3] = np.diag([1.0, 0.5, 2.0])
    m[:3, 3] = [1, 2, 3]
    s = scene_of(v, f, transform=m)
    rng = np.random.default_rng(4)
    q = rng.uniform(-4, 4, (400, 3)).astype(np.float32) + np.float32([1, 2, 3])
    c = s.compute_closest_points(q)
    w = v.astype(np.float64) @ m[:3, :3].T + m[:3, 3]
    p0, p1, p2 = (w[f[:, k]] for k in range(3))
    # The brute force samples each triangle densely enough to bound the answer from above, and the
    # reported point must lie on its triangle: together they pin the distance.
    got = c["points"].astype(np.float64)
    bary = (1 - c["u"] - c["v"])[:, None] * p0[c["prim"]] + c["u"][:, None] * p1[c["prim"]] + \
        c["v"][:, None] * p2[c["prim"]]
    assert np.allclose(got, bary, atol=1e-5)
    assert np.all((c["u"] >= 0) & (c["v"] >= 0) & (c["u"] + c["v"] <= 1 + 1e-6))
    s_grid = np.linspace(0, 1, 12)
    uu, vv = np.meshgrid(s_grid, s_grid)
    keep = uu + vv <= 1
    uu, vv = uu[keep], vv[keep]
    samples = ((1 - uu - vv)[None, :, None] * p0[:, None] + uu[None, :, None] * p1[:, None] +
               vv[None, :, None] * p2[:, None]).reshape(-1, 3)
    upper = np.min(np.linalg.norm(q[:, None].astype(np.float64) - samples[None], axis=2), axis=1)
    assert np.all(c["distance"] <= upper + 1e-6)
    assert np.allclose(c["distance"], np.linalg.norm(q - got, axis=1), rtol=0, atol=1e-5)


def test_bad_input_is_refused_clearly():
    s = scene_of(*cube())
    with pytest.raises(ValueError, match="not finite"):
        s.compute_occupancy(np.float32([[0, np.nan, 0]]))
    with pytest.raises(ValueError, match="not finite"):
        s.compute_signed_distance(np.float32([[np.inf, 0, 0]]))
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        s.compute_closest_points(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="same number"):
        s.count_intersections(np.zeros((2, 3)), np.zeros((3, 3)))
    # Rays that are not rays cross nothing.
    bad_dirs = np.float32([[0, 0, 0], [np.nan, 0, 1]])
    assert s.count_intersections(np.float32([[0.5, 0.5, -1]] * 2), bad_dirs).tolist() == [0, 0]
    uncommitted = toyrt.Scene()
    uncommitted.add_mesh(*cube())
    with pytest.raises(RuntimeError, match="commit"):
        uncommitted.compute_occupancy(np.zeros((1, 3)))


def test_empty_scene_answers_nothing():
    s = toyrt.Scene()
    s.commit()
    assert s.count_intersections(np.zeros((2, 3)), np.ones((2, 3))).tolist() == [0, 0]
    assert s.compute_distance(np.zeros((1, 3))).tolist() == [np.inf]
    assert s.compute_closest_points(np.zeros((1, 3)))["prim"].tolist() == [-1]
    assert s.compute_occupancy(np.zeros((1, 3))).tolist() == [False]


def test_answers_do_not_depend_on_the_thread_count():
    v, f = icosphere(3)
    s = scene_of(v, f)
    o, d = aligned_rays(v, f, (0.1, 0.1, 0.1))
    assert np.array_equal(s.count_intersections(o, d, threads=1), s.count_intersections(o, d, threads=2))
    assert np.array_equal(s.compute_distance(d, threads=1), s.compute_distance(d, threads=2))


def test_image_shaped_rays_come_back_in_their_shape_with_opt_in_normals_and_mesh_ids():
    s = toyrt.Scene()
    s.add_mesh(*cube())  # mesh 0, instance 0
    m = s.add_mesh(*cube(), instance=False)
    shift = np.eye(4)
    shift[:3, :3] *= 2.0
    shift[0, 3] = 5.0
    s.add_instance(m, shift)  # instance 1: mesh 1, scaled 2x at x = 5
    s.commit()
    xs = np.float32([0.5, 6.0, 20.0])
    o = np.stack(np.meshgrid(xs, np.float32([0.25, 0.75]), indexing="ij"), -1)
    o = np.concatenate([o, np.full(o.shape[:2] + (1,), -1, np.float32)], -1)  # (3, 2, 3)
    d = np.broadcast_to(np.float32([0, 0, 1]), o.shape)
    h = s.intersect(o, d, normals=True, mesh_ids=True)
    assert h["t"].shape == (3, 2) and h["normal"].shape == (3, 2, 3)
    assert h["mesh"].tolist() == [[0, 0], [1, 1], [-1, -1]]
    assert np.allclose(h["normal"][:2], [0, 0, -1])  # the bottom faces' winding: outward, also scaled
    assert np.all(h["normal"][2] == 0)
    assert "normal" not in s.intersect(o, d)  # opt-in: the plain query is unchanged
    assert s.occluded(o, d).shape == (3, 2)
    assert s.count_intersections(o, d).tolist() == [[2, 2], [2, 2], [0, 0]]
    assert s.compute_occupancy(o + np.float32([0, 0, 1.5])).shape == (3, 2)


def test_open3d_adaptor_speaks_open3d():
    from toyrt_open3d import RaycastingScene

    v, f = cube()
    scene = RaycastingScene()
    assert scene.add_triangles(v, f) == 0
    rays = np.float32([[[0.5, 0.5, -1, 0, 0, 1], [0.0, 0.0, -1, 1, 1, 1], [5, 5, -1, 0, 0, 1]]])  # (1, 3, 6)
    ans = scene.cast_rays(rays)
    assert set(ans) == {"t_hit", "geometry_ids", "primitive_ids", "primitive_uvs", "primitive_normals"}
    assert ans["t_hit"].shape == (1, 3) and ans["primitive_uvs"].shape == (1, 3, 2)
    assert ans["geometry_ids"].numpy().tolist() == [[0, 0, RaycastingScene.INVALID_ID]]
    assert ans["geometry_ids"].dtype == np.uint32
    assert np.allclose(np.abs(ans["primitive_normals"].numpy()[0, 0]), [0, 0, 1])
    assert scene.count_intersections(rays).numpy().tolist() == [[2, 0, 0]]
    lx = scene.list_intersections(rays)
    assert lx["ray_splits"].numpy().tolist() == [0, 2, 2, 2] and lx["ray_ids"].tolist() == [0, 0]
    assert set(lx) == {"ray_splits", "ray_ids", "t_hit", "geometry_ids", "primitive_ids", "primitive_uvs",
                       "primitive_normals"}
    q = np.float32([[0.5, 0.5, 0.5], [2, 0.5, 0.5]])
    assert scene.compute_occupancy(q).tolist() == [1.0, 0.0]
    assert np.allclose(scene.compute_signed_distance(q).numpy(), [-0.5, 1])
    cp = scene.compute_closest_points(q)
    assert set(cp) == {"points", "geometry_ids", "primitive_ids", "primitive_uvs", "primitive_normals"}
    assert np.allclose(cp["points"].numpy()[1], [1, 0.5, 0.5])
    with pytest.raises(ValueError, match=r"\(\.\.\., 6\)"):
        scene.cast_rays(np.zeros((2, 3), np.float32))


def test_lbvh_built_meshes_answer_as_the_sah_ones():
    v, f = icosphere(3)
    o, d = aligned_rays(v, f, (0.1, 0.0, -0.1))
    answers = []
    for builder in ("sah", "lbvh"):
        s = toyrt.Scene()
        s.add_mesh(v, f)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # no OpenCL device: SAH stands in
            s.commit(builder=builder)
        answers.append((s.count_intersections(o, d), s.compute_distance(d), s.compute_occupancy(o + 0.9 * d)))
    for a, b in zip(*answers):
        assert np.array_equal(a, b)
    assert np.all(answers[0][0] == 1) and np.all(answers[0][2])
