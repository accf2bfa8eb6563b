"""Every misuse of the Python API raises an exception that says what is wrong, and a failed call
leaves the scene as it was."""
import numpy as np
import pytest
import toyrt

TRI_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
TRI_T = np.array([[0, 1, 2]], np.uint32)


def committed():
    s = toyrt.Scene()
    s.add_mesh(TRI_V, TRI_T)
    s.commit()
    return s


@pytest.mark.parametrize(
    "vertices, triangles, error, words",
    [
        (np.array([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]]), TRI_T, ValueError, "not finite"),
        (np.array([[0, 0, np.inf], [1, 0, 0], [0, 1, 0]]), TRI_T, ValueError, "not finite"),
        (TRI_V, np.array([[0, 1, 3]]), ValueError, "out of range"),
        (TRI_V, np.array([[0, -1, 2]]), ValueError, "negative"),
        (TRI_V, np.array([[0.0, 1.0, 2.0]]), TypeError, "integer"),
        (TRI_V[:, :2], TRI_T, ValueError, "(N, 3)"),
        (TRI_V, TRI_T.reshape(1, 3, 1), ValueError, "(M, 3)"),
        (np.array([["a", "b", "c"]]), TRI_T, TypeError, "numbers"),
        ("not an array", TRI_T, TypeError, "vertices"),
        (TRI_V, np.array([[0, 1, 2**40]], np.uint64), ValueError, "out of range"),
    ],
)
def test_bad_meshes_are_refused_and_change_nothing(vertices, triangles, error, words):
    s = committed()
    with pytest.raises(error, match=None) as info:
        s.add_mesh(vertices, triangles)
    assert words in str(info.value)
    assert s.mesh_count == 1 and s.instance_count == 1 and s.committed


@pytest.mark.parametrize(
    "matrix, words",
    [
        (np.zeros((4, 4)), "affine"),
        (np.diag([1.0, 0.0, 1.0, 1.0]), "singular"),
        (np.full((4, 4), np.nan), "not finite"),
        (np.eye(3), "(4, 4)"),
    ],
)
def test_bad_transforms_are_refused(matrix, words):
    s = committed()
    with pytest.raises(ValueError) as info:
        s.add_instance(0, matrix)
    assert words in str(info.value)
    with pytest.raises(ValueError):
        s.add_mesh(TRI_V, TRI_T, transform=matrix)
    assert s.mesh_count == 1 and s.instance_count == 1


def test_unknown_mesh_and_builder():
    s = committed()
    with pytest.raises(ValueError, match="unknown mesh id 5"):
        s.add_instance(5, np.eye(4))
    with pytest.raises(ValueError, match="unknown mesh id -1"):
        s.add_instance(-1, np.eye(4))
    with pytest.raises(ValueError, match="unknown builder 'fast'"):
        s.commit(builder="fast")
    with pytest.raises(ValueError, match="expected_rays"):
        s.commit(expected_rays=-5)
    with pytest.raises(TypeError, match="expected_rays"):
        s.commit(expected_rays="many")
    with pytest.raises(ValueError, match="threads"):
        s.commit(threads=-1)


def test_queries_before_commit_say_so():
    s = toyrt.Scene()
    with pytest.raises(RuntimeError, match="commit"):
        s.intersect([[0, 0, 1]], [[0, 0, -1]])
    s.add_mesh(TRI_V, TRI_T)
    with pytest.raises(RuntimeError, match="commit"):
        s.occluded([[0, 0, 1]], [[0, 0, -1]])
    s.commit()
    s.add_instance(0, np.eye(4))
    with pytest.raises(RuntimeError, match="changed since the last commit"):
        s.intersect([[0, 0, 1]], [[0, 0, -1]])


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        (dict(origins=[[0, 0]], directions=[[0, 0, 1]]), ValueError, "origins must have shape (N, 3)"),
        (dict(origins=[[0, 0, 0]], directions=[[0, 0, 1], [0, 0, 1]]), ValueError, "same number of rays"),
        (dict(origins=[[0, 0, 0]], directions=[[0, 0, 1]], tnear=[0.0, 1.0]), ValueError,
         "tnear must be a number or have shape (1,)"),
        (dict(origins=[[0, 0, 0]], directions=[[0, 0, 1]], tfar="far"), TypeError, "tfar"),
        (dict(origins=[[0, 0, 0]], directions=[[0, 0, 1]], tnear=float("nan")), ValueError, "tnear is NaN"),
        (dict(origins=[[0, 0, 0]], directions=[[0, 0, 1]], threads=-2), ValueError, "threads"),
        (dict(origins=None, directions=[[0, 0, 1]]), TypeError, "origins"),
    ],
)
def test_bad_queries_are_refused(kwargs, error, words):
    s = committed()
    for query in (s.intersect, s.occluded):
        with pytest.raises(error) as info:
            query(**kwargs)
        assert words in str(info.value)


def test_offset_ray_origin_checks_shapes_and_survives_nan_normals():
    with pytest.raises(ValueError, match="same length"):
        toyrt.offset_ray_origin(np.zeros((2, 3)), np.zeros((1, 3)))
    q = toyrt.offset_ray_origin([[1.0, 2.0, 3.0]], [[np.nan, 1e30, 0.0]])  # no step where it cannot be taken
    assert q.shape == (1, 3) and np.isfinite(q).all()
