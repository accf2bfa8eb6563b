"""Instance matrices the core refuses and the add-on's test for them (mesh.singular): every
matrix the core refuses must be one the add-on bakes into vertices instead, or a Blender scene
holding it would fail to render."""
import sys
from pathlib import Path

import numpy as np
import toyrt

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "addon"))
from render_toyrt.mesh import singular  # noqa: E402  (plain data: no bpy)


def scene_with_a_triangle():
    s = toyrt.Scene()
    s.add_mesh(np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.uint32([[0, 1, 2]]))
    return s


def core_refuses(s, m) -> bool:
    try:
        s.add_instance(0, m)
    except ValueError as e:
        assert "singular" in str(e)
        return True
    return False


def as_blender_gives_it(m):
    """Blender's matrices are single precision: the add-on reads them so, the core rounds them so."""
    return np.asarray(m, np.float32).astype(np.float64)


def random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def test_every_matrix_the_core_refuses_is_baked_by_the_addon():
    # Axes made nearly dependent by eta (1e-1 .. 1e-12), under random rotations and scales.
    rng = np.random.default_rng(3)
    s = scene_with_a_triangle()
    refused = baked = 0
    for _ in range(3000):
        a = rng.normal(size=3)
        b = a + 10.0 ** rng.uniform(-12, -1) * rng.normal(size=3)
        m = np.eye(4)
        m[:3, :3] = random_rotation(rng) @ np.column_stack([a, b, rng.normal(size=3)]) * 10.0 ** rng.uniform(-3, 3)
        m[:3, 3] = rng.uniform(-100, 100, 3)
        m = as_blender_gives_it(m)
        core = core_refuses(s, m)
        addon = singular(m)
        assert addon or not core, m
        refused += core
        baked += addon
    assert refused > 100  # the sweep reaches matrices the core refuses
    assert baked < 3000 - 100  # and many the add-on keeps as instances


def test_a_parents_scale_over_a_rotated_child_is_baked_before_the_core_refuses_it():
    # S R (rows scaled): the core's error bound grows with the ratio of the scales, and refuses
    # from about 1e5; the add-on must bake it first. Ratios 1 .. 1e8.
    rng = np.random.default_rng(5)
    s = scene_with_a_triangle()
    refused = 0
    for _ in range(2000):
        m = np.eye(4)
        m[:3, :3] = np.diag(10.0 ** rng.uniform(-4, 4, 3)) @ random_rotation(rng)
        m = as_blender_gives_it(m)
        core = core_refuses(s, m)
        assert singular(m) or not core, m
        refused += core
    assert refused > 50


def test_scales_and_translations_near_floats_limits_are_baked_or_kept():
    # Either the core keeps them or the add-on bakes them: never an instance the render refuses.
    # (A uniform scale of 1e13 once came back from the float inverse as zeros.)
    s = scene_with_a_triangle()
    cases = [np.diag([1e13, 1e13, 1e13, 1.0]), np.diag([1e-23, 1e-23, 1e36, 1.0]),
             np.diag([1e20, 1e20, 1e-10, 1.0]), np.diag([1e-12, 1e-12, 1e-12, 1.0]),
             np.diag([1e30, 1e30, 1e30, 1.0])]
    shifted = np.diag([1e-2, 1e-2, 1e-2, 1.0])
    shifted[:3, 3] = 1e37
    cases.append(shifted)
    for m in cases:
        m = as_blender_gives_it(m)
        assert singular(m) or not core_refuses(s, m), m
    assert not core_refuses(s, as_blender_gives_it(np.diag([1e13, 1e13, 1e13, 1.0])))


def test_rotations_and_scales_are_kept_whatever_the_scales():
    # Blender's location, rotation and scale give a matrix with orthogonal axes; its float inverse
    # is accurate whatever the scales (the adjugate's cross products of orthogonal axes do not
    # cancel), so neither side refuses it, down to 1e-6 and up to 1e6 in one matrix.
    rng = np.random.default_rng(4)
    s = scene_with_a_triangle()
    for _ in range(500):
        m = np.eye(4)
        m[:3, :3] = random_rotation(rng) @ np.diag(10.0 ** rng.uniform(-6, 6, 3))
        m = as_blender_gives_it(m)
        assert not singular(m), m
        assert not core_refuses(s, m), m


def test_the_fuzzers_dependent_rows_are_refused_with_their_reason():
    # tests/native/robustness_test.cpp has the same matrix: rows 0 and 1 equal, det of the
    # rounded products not exactly 0.
    c = float.fromhex("0x1.555558p+0")
    m = np.array([[c, c, c, -0.0],
                  [c, c, c, -float.fromhex("0x1.a8b9e8p-1")],
                  [float.fromhex("0x1.55555p+0"), c, -float.fromhex("0x1.b96df8p-1"), 2.5],
                  [0, 0, 0, 1]])
    s = scene_with_a_triangle()
    try:
        s.add_instance(0, m)
        raise AssertionError("accepted")
    except ValueError as e:
        assert "nearly singular" in str(e)
    assert singular(m)
