"""The bad-input catalogue of the native API (issue 7; table in docs/robustness.md): one test per
case, each pinning its outcome. Invalid input is refused with a ValueError or TypeError naming the
argument, and the scene is left as it was; input a batch API can answer (a zero direction, a NaN
origin, an empty batch) gets an answer: those rays miss. Nothing crashes or hangs.
tests/python/test_bad_input.py holds the older cases (shapes, dtypes, matrices, query arguments)."""
import os
import subprocess
import sys
import threading

import numpy as np
import pytest
import toyrt

# A unit right triangle in z = 0 and a ray straight down onto it at (0.25, 0.25).
TRI_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
TRI_T = np.array([[0, 1, 2]], np.uint32)
DOWN_ORG = np.array([[0.25, 0.25, 1.0]], np.float32)
DOWN_DIR = np.array([[0.0, 0.0, -1.0]], np.float32)


def committed(*meshes):
    s = toyrt.Scene()
    for v, t in meshes or [(TRI_V, TRI_T)]:
        s.add_mesh(v, t)
    s.commit()
    return s


def random_soup(seed, vertices, triangles, rays):
    """Random triangles on `vertices` points in [-1, 1]^3 ((V, 3) float32, (T, 3) int64 indices) and
    rays from [-2, 2]^3 in random directions ((R, 3) float32 origins and directions)."""
    rng = np.random.default_rng(seed)
    v = rng.uniform(-1, 1, (vertices, 3)).astype(np.float32)
    t = rng.integers(0, vertices, (triangles, 3))
    return v, t, rng.uniform(-2, 2, (rays, 3)).astype(np.float32), rng.normal(size=(rays, 3)).astype(np.float32)


def assert_misses(hits, blocked):
    assert np.all(np.isinf(hits["t"])) and np.all(hits["prim"] == -1) and np.all(hits["instance"] == -1)
    assert not np.any(blocked)


def refused(call, error, words):
    with pytest.raises(error) as info:
        call()
    assert words in str(info.value), str(info.value)


# ---- meshes -----------------------------------------------------------------------------------------

def test_nan_vertex_is_refused_naming_the_vertex():
    s = committed()
    v = TRI_V.copy()
    v[2, 1] = np.nan
    refused(lambda: s.add_mesh(v, TRI_T), ValueError, "vertex 2 is not finite")
    assert s.mesh_count == 1 and s.committed


def test_infinite_vertex_is_refused_naming_the_vertex():
    s = committed()
    v = TRI_V.copy()
    v[1, 0] = -np.inf
    refused(lambda: s.add_mesh(v, TRI_T), ValueError, "vertex 1 is not finite")


def test_float64_vertex_beyond_float32_range_is_refused_as_infinite():
    # Vertices are stored as float32: 1e39 would become inf, so it is refused, not silently kept.
    v = TRI_V.astype(np.float64)
    v[0, 0] = 1e39
    with np.errstate(over="ignore"):  # numpy's cast warns; the module must refuse, which is the point
        refused(lambda: toyrt.Scene().add_mesh(v, TRI_T), ValueError, "vertex 0 is not finite")


def test_index_past_the_last_vertex_is_refused():
    refused(lambda: toyrt.Scene().add_mesh(TRI_V, [[0, 1, 3]]), ValueError, "triangle 0 indexes a vertex out of range")


def test_index_past_the_last_vertex_is_refused_before_per_vertex_shading_reads_it():
    # Per-vertex normals and UVs are gathered per corner through the triangle indices: an index
    # past the vertices must be refused before that read (it read far past the buffer).
    for kw in (dict(normals=np.zeros((3, 3))), dict(uvs=np.zeros((3, 2)))):
        refused(lambda: toyrt.Scene().add_mesh(TRI_V, [[0, 1, 4_000_000_000]], **kw), ValueError,
                "triangle 0 indexes a vertex out of range (3 vertices)")


def test_negative_index_is_refused():
    refused(lambda: toyrt.Scene().add_mesh(TRI_V, np.array([[0, 1, 2], [0, -2, 1]])), ValueError,
            "triangle 1 has a negative vertex index")


def test_every_index_dtype_gives_the_same_mesh_and_names_the_same_bad_triangle():
    # Each integer dtype is read as it is (uint32 and int32 in place); whatever the type, the mesh
    # is the same and a bad index is reported at the first triangle holding one.
    v, t, org, dirs = random_soup(5, 300, 2000, 500)
    want = committed((v, t)).intersect(org, dirs)
    dtypes = (np.int16, np.uint16, np.int32, np.uint32, np.int64, np.uint64, np.dtype(">i4"), np.dtype(">u8"))
    for dt in dtypes:
        for layout in (t.astype(dt), np.asfortranarray(t.astype(dt)), np.repeat(t.astype(dt), 2, axis=0)[::2]):
            got = committed((v, layout)).intersect(org, dirs)
            assert np.array_equal(got["prim"], want["prim"]) and np.array_equal(got["t"], want["t"]), dt
        assert committed((v, np.zeros((0, 3), dt))).triangle_count == 0
        past = t.astype(dt)
        past[1500, 2], past[1700, 0] = 300, 299  # 1700 is fine; 1500 names the vertex count
        refused(lambda: toyrt.Scene().add_mesh(v, past), ValueError,
                "triangle 1500 indexes a vertex out of range (300 vertices)")
        if np.dtype(dt).kind == "i":
            negative = t.astype(dt)
            negative[1900, 0], negative[1200, 1] = -3, -1  # the first, not the smallest
            refused(lambda: toyrt.Scene().add_mesh(v, negative), ValueError,
                    "triangle 1200 has a negative vertex index")
        if np.dtype(dt).itemsize == 8:
            huge = t.astype(dt)
            huge[1999, 1], huge[1300, 2] = 2**32 + 1, 2**32  # the first, not the largest
            refused(lambda: toyrt.Scene().add_mesh(v, huge), ValueError, "triangle 1300 has an index out of range")


def test_float_indices_are_refused_as_not_integers():
    refused(lambda: toyrt.Scene().add_mesh(TRI_V, TRI_T.astype(np.float32)), TypeError,
            "triangles must be an integer array")


def test_complex_vertices_are_refused_as_not_numbers():
    refused(lambda: toyrt.Scene().add_mesh(TRI_V.astype(np.complex64), TRI_T), TypeError, "vertices must hold numbers")


def test_none_inside_a_vertex_list_is_refused():
    refused(lambda: toyrt.Scene().add_mesh([[0, 0, 0], [1, 0, None], [0, 1, 0]], TRI_T), TypeError, "vertices")


def test_vertices_of_shape_n_by_4_are_refused_with_the_shape():
    refused(lambda: toyrt.Scene().add_mesh(np.zeros((3, 4)), TRI_T), ValueError,
            "vertices must have shape (N, 3), got (3, 4)")


def test_triangles_of_shape_m_by_4_are_refused_with_the_shape():
    refused(lambda: toyrt.Scene().add_mesh(TRI_V, [[0, 1, 2, 0]]), ValueError,
            "triangles must have shape (M, 3), got (1, 4)")


def test_lists_work_like_arrays():
    from_lists = committed((TRI_V.tolist(), TRI_T.tolist()))
    hits = from_lists.intersect(DOWN_ORG.tolist(), DOWN_DIR.tolist())
    assert hits["t"][0] == 1.0 and hits["prim"][0] == 0


def test_non_contiguous_and_fortran_arrays_give_the_answers_of_contiguous_ones():
    v, t, org, dirs = random_soup(7, 60, 80, 500)
    wide = np.zeros((60, 6), np.float32)
    wide[:, ::2] = v                            # every other column: a strided view
    t_fortran = np.asfortranarray(t)            # column-major
    org_strided = np.repeat(org, 2, axis=0)[::2]  # every other row
    dirs_reversed = dirs[::-1].copy()[::-1]       # negative stride
    a = committed((v, t)).intersect(org, dirs)
    b = committed((wide[:, ::2], t_fortran)).intersect(org_strided, dirs_reversed)
    assert not wide[:, ::2].flags.c_contiguous and not t_fortran.flags.c_contiguous
    assert np.any(a["prim"] >= 0)  # the comparison is about real hits
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])


def misaligned(a):
    """A C-contiguous view of a's values one byte past an aligned address: numpy's flags call it
    contiguous, but its elements are not aligned for their type."""
    raw = np.zeros(a.nbytes + 1, np.uint8)
    view = raw[1:].view(a.dtype).reshape(a.shape)
    view[...] = a
    assert view.flags.c_contiguous and not view.flags.aligned
    return view


def test_misaligned_arrays_give_the_answers_of_aligned_ones():
    # Read in place they would be read through misaligned pointers (UBSan's alignment check in
    # `make sanitize` stops at the first); the module copies them instead.
    v, t, org, dirs = random_soup(8, 60, 80, 500)
    t32 = t.astype(np.int32)
    tnear = np.linspace(0.0, 0.5, len(org), dtype=np.float32)
    tfar = np.linspace(2.0, 4.0, len(org), dtype=np.float32)
    a = committed((v, t32)).intersect(org, dirs, tnear=tnear, tfar=tfar)
    b = committed((misaligned(v), misaligned(t32))).intersect(misaligned(org), misaligned(dirs),
                                                              tnear=misaligned(tnear), tfar=misaligned(tfar))
    assert np.any(a["prim"] >= 0)
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])


def test_mesh_without_triangles_is_accepted_and_never_hit():
    s = committed((TRI_V, np.zeros((0, 3), np.uint32)), (np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int32)))
    assert s.mesh_count == 2 and s.triangle_count == 0
    assert_misses(s.intersect(DOWN_ORG, DOWN_DIR), s.occluded(DOWN_ORG, DOWN_DIR))


def test_empty_scene_commits_and_every_ray_misses():
    s = toyrt.Scene()
    s.commit()
    assert_misses(s.intersect(DOWN_ORG, DOWN_DIR), s.occluded(DOWN_ORG, DOWN_DIR))


def test_degenerate_triangles_keep_their_index_and_are_never_hit():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0], [3, 0, 0], [4, 0, 0]], np.float32)
    # 0: two equal vertices (x 2..3); 1: three collinear ones (x 2..4); 2: the real one (stays prim 2).
    t = np.array([[3, 3, 4], [3, 4, 5], [0, 1, 2]], np.uint32)
    s = committed((v, t))
    hits = s.intersect(np.array([[0.25, 0.25, 1], [2.5, 0, 1], [3.5, 0, 1]], np.float32), np.tile(DOWN_DIR, (3, 1)))
    assert list(hits["prim"]) == [2, -1, -1]


# ---- rays -------------------------------------------------------------------------------------------

def test_zero_direction_misses():
    s = committed()
    assert_misses(s.intersect(DOWN_ORG, np.zeros((1, 3))), s.occluded(DOWN_ORG, np.zeros((1, 3))))


def test_nan_or_infinite_origin_or_direction_misses_and_other_rays_still_hit():
    s = committed()
    org = np.repeat(DOWN_ORG, 4, axis=0)
    dirs = np.repeat(DOWN_DIR, 4, axis=0)
    org[0, 0] = np.nan
    org[1, 2] = np.inf
    dirs[2, 1] = np.nan
    hits = s.intersect(org, dirs)
    assert list(hits["prim"]) == [-1, -1, -1, 0]
    assert list(s.occluded(org, dirs)) == [False, False, False, True]


def test_tnear_greater_than_tfar_misses():
    s = committed()
    assert_misses(s.intersect(DOWN_ORG, DOWN_DIR, tnear=2.0, tfar=0.5),
                  s.occluded(DOWN_ORG, DOWN_DIR, tnear=2.0, tfar=0.5))


def test_nan_in_per_ray_tfar_misses_that_ray_only():
    s = committed()
    hits = s.intersect(np.repeat(DOWN_ORG, 2, axis=0), np.repeat(DOWN_DIR, 2, axis=0), tfar=np.array([np.nan, 5.0]))
    assert list(hits["prim"]) == [-1, 0]


def test_nan_scalar_tnear_is_refused():
    refused(lambda: committed().intersect(DOWN_ORG, DOWN_DIR, tnear=float("nan")), ValueError, "tnear is NaN")


def test_python_int_beyond_float_range_for_tfar_is_refused_naming_it():
    refused(lambda: committed().intersect(DOWN_ORG, DOWN_DIR, tfar=10**400), ValueError, "tfar is too large")


def test_float_beyond_float32_range_for_tfar_is_infinite():
    assert committed().intersect(DOWN_ORG, DOWN_DIR, tfar=1e300)["t"][0] == 1.0


def test_integer_arguments_beyond_64_bits_are_refused_with_the_signature():
    # pybind11's TypeError lists the signature, argument names and types included.
    refused(lambda: committed().intersect(DOWN_ORG, DOWN_DIR, threads=2**70), TypeError, "threads: int")
    refused(lambda: committed().add_instance(2**70, np.eye(4)), TypeError, "mesh: int")


def test_zero_rays_give_empty_results():
    s = committed()
    hits = s.intersect(np.zeros((0, 3)), np.zeros((0, 3)))
    assert all(a.shape == (0,) for a in hits.values())
    assert s.occluded(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0,)


def test_segments_before_the_origin_are_found_by_both_queries():
    # Regression (fuzzer): with tfar < 0, occluded() skipped the subtrees intersect() found hits in.
    rng = np.random.default_rng(3)
    centres = rng.uniform(-20, 20, (300, 3)).astype(np.float32)
    v = (centres[:, None, :] + np.float32([[0, 0, 0], [0.3, 0, 0], [0, 0.3, 0]])).reshape(-1, 3)
    s = committed((v, np.arange(900, dtype=np.uint32).reshape(300, 3)))
    org = centres + np.float32([0.05, 0.05, 30.0])
    dirs = np.tile(np.float32([0, 0, 1]), (300, 1))  # pointing away: every hit is at t = -30
    hits = s.intersect(org, dirs, tnear=-1e3, tfar=-1.0)
    assert np.all(hits["prim"] >= 0)
    np.testing.assert_allclose(hits["t"], -30.0, rtol=1e-5)
    assert np.all(s.occluded(org, dirs, tnear=-1e3, tfar=-1.0))


# ---- instances --------------------------------------------------------------------------------------

def test_singular_instance_matrix_is_refused():
    refused(lambda: committed().add_instance(0, np.diag([2.0, 2.0, 0.0, 1.0])), ValueError, "singular")


def test_non_finite_instance_matrix_is_refused():
    m = np.eye(4)
    m[0, 3] = np.inf
    refused(lambda: committed().add_instance(0, m), ValueError, "not finite")


def test_projective_instance_matrix_is_refused():
    m = np.eye(4)
    m[3, 2] = 0.5
    refused(lambda: committed().add_instance(0, m), ValueError, "affine")


def test_unknown_mesh_id_is_refused_with_the_mesh_count():
    s = committed()
    refused(lambda: s.add_instance(1, np.eye(4)), ValueError, "unknown mesh id 1 (the scene has 1 meshes)")
    assert s.instance_count == 1 and s.committed


def test_ray_overflowing_in_an_instances_object_space_misses_without_crashing():
    # Regression (fuzzer): a world direction of +-FLT_MAX through an instance scaled by 1e-12 is
    # NaN in object space; the traversal overflowed its stack (a segfault). Run in a child process
    # so that a regression fails this test instead of killing the test run.
    script = '''
import numpy as np, toyrt
rng = np.random.default_rng(1)
v = rng.uniform(-1, 1, (60, 3)).astype(np.float32)
to_world = np.eye(4)
to_world[:3, :3] = np.linalg.inv([[1, 1, 0], [1, 1, 1], [1, 2, 1]]) * 1e-12
s = toyrt.Scene()
s.add_mesh(v, np.arange(60).reshape(20, 3))
s.add_instance(0, to_world)
s.commit()
big = np.finfo(np.float32).max
hits = s.intersect([[0, 0, 0]], [[big, -big, 0]])
print(int(hits["prim"][0]), bool(s.occluded([[0, 0, 0]], [[big, -big, 0]])[0]))
'''
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["-1", "False"]


# ---- camera, lights, textures -----------------------------------------------------------------------

def camera(**settings):
    m = np.eye(4)
    m[2, 3] = 5.0
    cam = dict(type="ORTHO", ortho_scale=2.0, resolution_x=8, resolution_y=8, matrix_world=m)
    cam.update(settings)
    return cam


def test_resolution_zero_is_refused():
    refused(lambda: toyrt.camera_window(camera(resolution_x=0)), ValueError,
            "resolution_x and resolution_y must be positive")
    refused(lambda: committed().render(camera(resolution_y=0)), ValueError, "resolution")


def test_resolution_percentage_that_rounds_to_zero_pixels_is_refused():
    refused(lambda: toyrt.camera_window(camera(resolution_x=1, resolution_percentage=50)), ValueError, "render size")


def test_render_larger_than_memory_is_refused_before_allocating():
    # 1e6 x 1e6 RGBA float pixels: 16 TB for the framebuffer alone; refused by an estimate first.
    with pytest.raises(MemoryError) as info:
        committed().render(camera(resolution_x=1_000_000, resolution_y=1_000_000))
    assert "1000000 x 1000000" in str(info.value)


@pytest.mark.parametrize("key, value", [("resolution_x", 1e12), ("resolution_y", float("nan")),
                                        ("resolution_percentage", 2.0**40), ("resolution_x", 2.5),
                                        ("resolution_x", -3)])
def test_camera_counts_outside_int_range_or_fractional_are_refused_by_name(key, value):
    # Converted to int only after the check: a double beyond int's range is undefined behaviour.
    refused(lambda: toyrt.camera_window(camera(**{key: value})), ValueError, f"'{key}' must be a whole number")


@pytest.mark.parametrize("power", [-1.0, float("nan"), float("inf")])
def test_negative_or_non_finite_point_light_power_is_refused(power):
    refused(lambda: toyrt.Scene().add_point_light((0, 0, 1), power), ValueError, "power must be finite and >= 0")


@pytest.mark.parametrize("power", [-1.0, float("nan")])
def test_negative_or_nan_area_light_power_is_refused(power):
    refused(lambda: toyrt.Scene().add_area_light(np.eye(4), power=power), ValueError, "power must be finite and >= 0")


@pytest.mark.parametrize("size, size_y", [(0.0, None), (1.0, 0.0), (-1.0, None), (float("nan"), None)])
def test_zero_size_area_light_is_refused(size, size_y):
    refused(lambda: toyrt.Scene().add_area_light(np.eye(4), shape="RECTANGLE", size=size, size_y=size_y), ValueError,
            "size must be positive and finite")


@pytest.mark.parametrize("spread", [0.0, -0.5, float("nan"), float("inf")])
def test_area_light_spread_that_is_not_a_positive_angle_is_refused(spread):
    refused(lambda: toyrt.Scene().add_area_light(np.eye(4), spread=spread), ValueError, "spread must be positive")
    refused(lambda: toyrt.Scene().add_light("AREA", matrix=np.eye(4), spread=spread), ValueError, "spread")


def test_zero_power_light_is_accepted_and_lights_nothing():
    s = toyrt.Scene()
    s.add_mesh(np.float32([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]), [[0, 1, 2], [0, 2, 3]])
    s.add_point_light((0, 0, 1), 0.0)
    s.background = (0, 0, 0)
    s.commit()
    assert np.all(s.render(camera(), samples=1)[..., :3] == 0.0)


@pytest.mark.parametrize("shape", [(0, 4, 3), (4, 0, 4), (0, 0, 3)])
def test_texture_of_size_zero_is_refused(shape):
    refused(lambda: toyrt.Scene().add_texture(np.zeros(shape, np.float32)), ValueError,
            "width and height must be positive")


@pytest.mark.parametrize("channels", [1, 2, 5])
def test_texture_with_other_than_3_or_4_channels_is_refused(channels):
    refused(lambda: toyrt.Scene().add_texture(np.zeros((2, 2, channels), np.float32)), ValueError, "3 or 4")


def test_texture_of_16_bit_integers_is_refused_with_the_dtype():
    refused(lambda: toyrt.Scene().add_texture(np.zeros((2, 2, 3), np.uint16)), TypeError, "uint16")


@pytest.mark.parametrize("dtype", [np.float32, np.uint8])
def test_an_image_too_large_for_memory_is_a_memory_error_and_the_scene_keeps_its_textures(dtype):
    # A broadcast view costs nothing, but its copy would take 0.5-1 TB: MemoryError naming the
    # argument (the copy's null array was dereferenced before: a crash), and the scene goes on,
    # the next texture taking the next id and the map still rendering.
    s = toyrt.Scene()
    first = s.add_texture(np.full((2, 4, 3), 0.5, np.float32), srgb=False)
    huge = np.broadcast_to(dtype(1), (300_000, 400_000, 4))
    refused(lambda: s.add_texture(huge), MemoryError, "pixels: no memory")
    refused(lambda: s.set_texture(first, huge), MemoryError, "pixels: no memory")
    assert s.add_texture(np.full((2, 4, 3), 0.5, np.float32), srgb=False) == first + 1
    s.set_environment(first)
    s.commit()
    img = s.render({"type": "ORTHO", "ortho_scale": 1.0, "resolution_x": 2, "resolution_y": 2,
                    "matrix_world": np.eye(4)}, samples=1)
    np.testing.assert_allclose(img[..., :3], 0.5, rtol=1e-6)


def test_rays_too_many_for_memory_are_a_memory_error():
    s = toyrt.Scene()
    s.add_mesh(np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]])
    s.commit()
    rays = np.broadcast_to(np.float64(1), (10**11, 3))   # float64: a float32 copy is needed
    refused(lambda: s.intersect(rays, rays), MemoryError, "no memory")
    assert s.intersect(np.float32([[0.2, 0.2, 1]]), np.float32([[0, 0, -1]]))["t"][0] == 1.0


def test_a_pass_index_table_too_large_for_memory_is_a_memory_error():
    # float64 needs a float32 copy: 400 GB. Refused naming the table; the scene still renders.
    s = committed()
    huge = np.broadcast_to(np.float64(1), (10**11,))
    refused(lambda: s.render(camera(), samples=1, object_index=huge), MemoryError, "pass-index table: no memory")
    refused(lambda: s.render(camera(), samples=1, object_index="abc"), TypeError, "array of numbers")
    assert np.isfinite(s.render(camera(), samples=1)).all()


def test_an_environment_matrix_of_no_numbers_is_a_type_error():
    s = toyrt.Scene()
    tid = s.add_texture(np.full((2, 4, 3), 0.5, np.float32), srgb=False)
    words = [["a", "b", "c"]] * 3
    refused(lambda: s.set_environment(tid, matrix=words), TypeError, "matrix must be an array of numbers")
    s.set_environment(tid, matrix=np.eye(3))


def test_texture_with_nan_texels_is_refused():
    px = np.zeros((2, 2, 4), np.float32)
    px[1, 1, 2] = np.nan
    refused(lambda: toyrt.Scene().add_texture(px), ValueError, "finite")


# ---- several Python threads at once -----------------------------------------------------------------

def test_eight_threads_querying_while_another_commits_get_single_threaded_answers():
    v, t, org, dirs = random_soup(11, 400, 600, 2000)
    s = committed((v, t.astype(np.uint32)))
    expected_hits, expected_blocked = s.intersect(org, dirs, threads=1), s.occluded(org, dirs, threads=1)
    assert np.any(expected_hits["prim"] >= 0)

    far = np.eye(4)
    failures, answered, stop = [], [0] * 8, threading.Event()

    def reader(k):
        while not stop.is_set() or answered[k] == 0:
            try:
                hits, blocked = s.intersect(org, dirs), s.occluded(org, dirs)
            except RuntimeError as e:  # between the writer's add_instance and its commit
                if "commit" not in str(e):
                    failures.append(repr(e))
                continue
            for key in hits:
                if not np.array_equal(hits[key], expected_hits[key]):
                    failures.append(f"{key} differs")
            if not np.array_equal(blocked, expected_blocked):
                failures.append("occluded differs")
            answered[k] += 1

    def writer():
        for i in range(20):
            far[0, 3] = 1000.0 + 10 * i  # new instances far from every ray: the answers stay the same
            s.add_instance(0, far)
            s.commit()
        stop.set()

    threads = [threading.Thread(target=reader, args=(k,)) for k in range(8)] + [threading.Thread(target=writer)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not failures, failures[:5]
    assert s.instance_count == 21 and all(n > 0 for n in answered)


def test_eight_threads_adding_meshes_get_distinct_ids():
    s = toyrt.Scene()
    ids, lock = [], threading.Lock()

    def add():
        for _ in range(10):
            i = s.add_mesh(TRI_V, TRI_T)
            with lock:
                ids.append(i)

    threads = [threading.Thread(target=add) for _ in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert sorted(ids) == list(range(80)) and s.mesh_count == 80 and s.instance_count == 80
