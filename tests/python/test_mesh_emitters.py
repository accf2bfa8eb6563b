"""Emissive meshes through the Python API, against closed forms: the camera sees an Emission
surface's colour x strength on both sides; a parallel emissive square lights the point below its
centre with pi L F (the configuration factor of a parallel square), the same whether it is two
triangles or 20,000, and whatever its emission_sampling; bad emission values."""
import numpy as np
import pytest
import toyrt
from test_render import camera_above


def square_irradiance_over_radiance(a, h):
    """E / L under the centre of a parallel a x a square at height h: four corner rectangles."""
    x = y = a / 2 / h
    corner = (x / np.sqrt(1 + x * x) * np.arctan(y / np.sqrt(1 + x * x))
              + y / np.sqrt(1 + y * y) * np.arctan(x / np.sqrt(1 + y * y))) / 2
    return 4 * corner


def grid(n, size, height, flip=False):
    """An n x n grid of quads (2 n^2 triangles) `size` wide at z = height, normals up (down if flip)."""
    c = np.linspace(-size / 2, size / 2, n + 1, dtype=np.float32)
    x, y = np.meshgrid(c, c)
    v = np.stack([x.ravel(), y.ravel(), np.full(x.size, height, np.float32)], 1)
    i = np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]
    a, b, cc, d = i, i + 1, i + n + 2, i + n + 1
    tris = np.concatenate([np.stack([a, b, cc], -1).reshape(-1, 3), np.stack([a, cc, d], -1).reshape(-1, 3)])
    return v, (tris[:, ::-1] if flip else tris)


def lit_floor(emitter_triangles, L=2.0, a=1.0, h=0.5, sampling="AUTO", flip=False):
    s = toyrt.Scene()
    s.add_material("diffuse", color=(1.0, 1.0, 1.0))                                    # 0: the floor
    s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(L, L, L), emission_sampling=sampling)  # 1
    fv, ft = grid(1, 40.0, 0.0)
    s.add_mesh(fv, ft, material_ids=0)
    n = int(round(np.sqrt(emitter_triangles / 2)))
    ev, et = grid(n, a, h, flip)
    s.add_mesh(ev, et, material_ids=1)
    s.commit()
    # The point below the centre, from a camera under the emitter (it looks down at the floor).
    return s.render(camera_above(height=0.25, size=0.002, resolution=2), samples=1024)[..., 0].mean()


@pytest.mark.parametrize("triangles", [2, 20000])
def test_an_emissive_square_lights_the_point_below_with_pi_L_F(triangles):
    L, a, h = 2.0, 1.0, 0.5
    expected = L * square_irradiance_over_radiance(a, h) / np.pi   # the pixel of a white floor: E / pi
    got = lit_floor(triangles, L, a, h)
    assert got == pytest.approx(expected, rel=0.01)


def test_a_wide_emissive_ceiling_is_picked_through_the_light_tree_with_the_same_closed_form():
    # A 30 m square of 3,200 triangles 0.5 m over the 40 m floor spans most of the scene: the
    # commit builds the emitter tree (docs/lights.md), and the point below still gets pi L F.
    L, a, h = 2.0, 30.0, 0.5
    s = toyrt.Scene()
    s.add_material("diffuse", color=(1.0, 1.0, 1.0))
    s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(L, L, L))
    fv, ft = grid(1, 40.0, 0.0)
    s.add_mesh(fv, ft, material_ids=0)
    ev, et = grid(40, a, h)
    s.add_mesh(ev, et, material_ids=1)
    s.commit()
    assert s.last_commit["emissive_triangles"] == 3200
    assert s.last_commit["emitter_tree_nodes"] > 0
    got = s.render(camera_above(height=0.25, size=0.002, resolution=2), samples=1024)[..., 0].mean()
    assert got == pytest.approx(L * square_irradiance_over_radiance(a, h) / np.pi, rel=0.01)


def test_the_camera_sees_colour_times_strength_on_both_sides():
    for flip in (False, True):
        s = toyrt.Scene()
        s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(0.5, 1.0, 2.0))
        v, t = grid(1, 4.0, 0.0, flip)
        s.add_mesh(v, t, material_ids=0)
        s.commit()
        img = s.render(camera_above(size=1.0, resolution=4), samples=1)
        np.testing.assert_allclose(img[..., :3], np.broadcast_to([0.5, 1.0, 2.0], img[..., :3].shape), rtol=1e-6)


def test_emission_sampling_changes_the_noise_not_the_light():
    # As in Cycles, emission sampling only chooses how emitters are found: sides that shadow rays
    # do not sample (None, or the floor behind a Front emitter) are found by a cosine ray, with
    # the same expectation and more noise. The grid faces up, away from the floor below it.
    sampled = lit_floor(2, sampling="FRONT_AND_BACK")
    assert lit_floor(2, sampling="BACK") == pytest.approx(sampled, rel=1e-6)  # the floor's side: same samples
    for sampling, flip in (("NONE", False), ("FRONT", False), ("BACK", True)):
        assert lit_floor(2, sampling=sampling, flip=flip) == pytest.approx(sampled, rel=0.03), (sampling, flip)


def test_bad_emission_is_refused():
    s = toyrt.Scene()
    with pytest.raises(ValueError, match="emission"):
        s.add_material("diffuse", emission=(float("nan"), 0.0, 0.0))
    with pytest.raises(ValueError, match="emission"):
        s.add_material("diffuse", emission=(-1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="emission_sampling"):
        s.add_material("diffuse", emission=(1.0, 1.0, 1.0), emission_sampling="SIDEWAYS")


def test_zero_area_emissive_triangles_light_nothing_and_leave_no_nan():
    s = toyrt.Scene()
    s.add_material("diffuse", color=(1.0, 1.0, 1.0))
    s.add_material("diffuse", emission=(5.0, 5.0, 5.0))
    fv, ft = grid(1, 40.0, 0.0)
    s.add_mesh(fv, ft, material_ids=0)
    s.add_mesh(np.array([[0, 0, 1], [1, 0, 1], [2, 0, 1]], np.float32), [[0, 1, 2]], material_ids=1)  # collinear
    s.commit()
    img = s.render(camera_above(size=2.0, resolution=4), samples=16)
    assert np.isfinite(img).all() and not img[..., :3].any()


def test_a_mesh_without_material_ids_is_default_grey_and_emits_nothing():
    # Material 0 emits, but a mesh given no material ids renders with the default grey: it is
    # neither seen glowing nor sampled as a light (the same answer on both paths).
    s = toyrt.Scene()
    s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(3.0, 3.0, 3.0))
    s.add_material("diffuse", color=(1.0, 1.0, 1.0))
    fv, ft = grid(1, 40.0, 0.0)
    s.add_mesh(fv, ft, material_ids=1)
    ev, et = grid(1, 1.0, 0.5)
    s.add_mesh(ev, et)                                    # no material ids
    s.commit()
    assert s.last_commit["emissive_triangles"] == 0
    assert s.last_commit["emitter_tree_nodes"] == 0
    img = s.render(camera_above(height=0.25, size=0.002, resolution=2), samples=16)
    assert not img[..., :3].any()


def textured_square(pixels, strength=2.0):
    """lit_floor's scene (a = 1 m at h = 0.5) with the square's colour an image over uv [0, 1]^2."""
    s = toyrt.Scene()
    s.add_material("diffuse", color=(1.0, 1.0, 1.0))
    tex = s.add_texture(np.asarray(pixels, np.float32), srgb=False)
    s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(strength,) * 3, emission_texture=tex)
    fv, ft = grid(1, 40.0, 0.0)
    s.add_mesh(fv, ft, material_ids=0)
    ev, et = grid(4, 1.0, 0.5)
    s.add_mesh(ev, et, uvs=ev[:, :2] + 0.5, material_ids=1)
    s.commit()
    return s, tex


def test_an_emission_image_lights_as_its_colour_and_an_edit_of_its_pixels_lights_anew():
    # A uniform image of colour c emits strength x c: the closed form pi L F per channel. New
    # pixels (a quarter as bright) weigh the triangles anew at the next commit: a quarter the light.
    c = np.array([0.25, 0.5, 1.0], np.float32)
    s, tex = textured_square(np.broadcast_to(c, (2, 2, 3)))
    cam = camera_above(height=0.25, size=0.002, resolution=2)
    expected = 2.0 * c * square_irradiance_over_radiance(1.0, 0.5) / np.pi
    np.testing.assert_allclose(s.render(cam, samples=1024)[..., :3].mean(axis=(0, 1)), expected, rtol=0.01)
    s.set_texture(tex, np.broadcast_to(c / 4, (2, 2, 3)).astype(np.float32), srgb=False)
    s.commit()
    np.testing.assert_allclose(s.render(cam, samples=1024)[..., :3].mean(axis=(0, 1)), expected / 4, rtol=0.01)


def test_an_unknown_emission_texture_is_refused():
    s = toyrt.Scene()
    with pytest.raises(ValueError, match="emission_texture"):
        s.add_material("diffuse", emission=(1.0, 1.0, 1.0), emission_texture=3)
