"""The core's defaults are written once, in its structs: toyrt.defaults reports them, and the
signatures of render() and commit() use the same values (the add-on's property defaults can be
checked against toyrt.defaults). Scene.add_mesh(instance=False) stores a mesh without placing it."""
import ast
import re

import numpy as np
import pytest
import toyrt


def signature_defaults(method):
    """{argument: default} from a pybind11 docstring's first line (the signature)."""
    signature = method.__doc__.splitlines()[0]
    found = {}
    for name, value in re.findall(r"(\w+): [\w.\[\]]+ = (\([^)]*\)|[^,)]+)", signature):
        try:
            found[name] = ast.literal_eval(value)
        except ValueError:
            found[name] = value
    return found


def test_render_signature_defaults_are_the_core_defaults():
    render = signature_defaults(toyrt.Scene.render)
    for key in ("samples", "seed", "max_specular_depth", "area_light_sampling", "light_sampling", "threads",
                "tile_size", "first_sample", "split_depth"):
        assert render[key] == toyrt.defaults[key], key


def test_commit_and_material_signature_defaults_are_the_core_defaults():
    commit = signature_defaults(toyrt.Scene.commit)
    assert commit["builder"] == toyrt.defaults["builder"]
    material = signature_defaults(toyrt.Scene.add_material)
    # None: each kind's own colour, the diffuse kinds' being defaults["material_color"] (glass: white)
    assert material["color"] is None
    assert material["ior"] == toyrt.defaults["ior"]


def test_defaults_hold_the_documented_values():
    d = toyrt.defaults
    assert (d["samples"], d["max_specular_depth"], d["seed"], d["tile_size"]) == (16, 8, 0, 32)
    assert (d["area_light_sampling"], d["light_sampling"], d["builder"]) == ("solid_angle", "auto", "auto")
    assert d["all_lights_up_to"] == 4


def test_a_render_with_no_arguments_uses_the_defaults():
    s = toyrt.Scene()
    s.add_mesh(np.float32([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]), [[0, 1, 2], [0, 2, 3]])
    s.add_point_light((0, 0, 1), 100.0)
    s.commit()
    m = np.eye(4)
    m[2, 3] = 5.0
    cam = dict(type="ORTHO", ortho_scale=2.0, resolution_x=4, resolution_y=4, matrix_world=m)
    default = s.render(cam)
    assert s.last_render["samples"] == toyrt.defaults["samples"]
    explicit = s.render(cam, **{k: toyrt.defaults[k] for k in ("samples", "seed", "max_specular_depth",
                                                               "area_light_sampling", "light_sampling",
                                                               "tile_size", "first_sample", "split_depth")})
    np.testing.assert_array_equal(default, explicit)


TRI_V = np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]])


def test_add_mesh_without_an_instance_stores_it_unplaced():
    s = toyrt.Scene()
    mid = s.add_mesh(TRI_V, [[0, 1, 2]], instance=False)
    assert (s.mesh_count, s.instance_count) == (1, 0)
    s.commit()
    down = dict(origins=[[0.25, 0.25, 1.0]], directions=[[0.0, 0.0, -1.0]])
    assert s.intersect(**down)["prim"][0] == -1  # stored, not placed
    up = np.eye(4)
    up[2, 3] = 0.5
    assert s.add_instance(mid, up) == 0
    s.commit()
    hits = s.intersect(**down)
    assert hits["prim"][0] == 0 and hits["instance"][0] == 0 and hits["t"][0] == pytest.approx(0.5)


def test_add_mesh_without_an_instance_refuses_a_transform():
    s = toyrt.Scene()
    with pytest.raises(ValueError, match="instance=False"):
        s.add_mesh(TRI_V, [[0, 1, 2]], transform=np.eye(4), instance=False)
    assert s.mesh_count == 0



def _grid_scene(second_emits):
    """A 100 x 100 quad grid (20,000 triangles) and a copy 2 m above it, emissive or not."""
    v = np.float32([[x, y, 0.0] for y in range(101) for x in range(101)])
    i = np.arange(100)
    q = (i[:, None] * 101 + i[None, :]).ravel()
    t = np.concatenate([np.stack([q, q + 1, q + 102], 1), np.stack([q, q + 102, q + 101], 1)]).astype(np.uint32)
    s = toyrt.Scene()
    s.add_material("diffuse", color=(0.5, 0.5, 0.5))
    s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0) if second_emits else (0.0, 0.0, 0.0))
    s.add_mesh(v, t, material_ids=0)
    s.add_mesh(v + np.float32([0, 0, 2]), t, material_ids=1)
    s.commit()
    return s


def test_memory_bytes_counts_textures_the_environment_grid_and_emitters():
    # Each holds at least its own floats: a 64 x 128 RGB float texture 98,304 bytes; the
    # environment over it a grid of 64 x 128 densities and as many CDF values (65,536 bytes); the
    # 20,000 emissive triangles 4 Vec3 of geometry and a CDF float each (1,040,000 bytes).
    s = _grid_scene(second_emits=False)
    base = s.memory_bytes
    tid = s.add_texture(np.ones((64, 128, 3), np.float32), srgb=False)
    with_texture = s.memory_bytes
    assert with_texture - base >= 64 * 128 * 3 * 4
    s.set_environment(tid)
    s.commit()
    assert s.memory_bytes - with_texture >= 2 * 64 * 128 * 4
    assert _grid_scene(second_emits=True).memory_bytes - base >= 20000 * (4 * 12 + 4)
