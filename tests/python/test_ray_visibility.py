"""Blender's Object ray visibility (add_instance's visible_camera / visible_diffuse / visible_glossy /
visible_transmission), against closed forms and the scene without the hidden object: camera rays
pass an object hidden from them, diffuse rays (the world's and emitters' cosine rays) pass one
hidden from them, an emitter hidden from diffuse rays lights no diffuse surface (as Cycles' mesh
lights) while one hidden from the camera still lights the floor, glossy and glass rays pass
objects hidden from them; the ray queries see every object."""
import numpy as np
import pytest
import toyrt
from test_mesh_emitters import grid, square_irradiance_over_radiance
from test_render import camera_above, floor_scene

EYE = np.eye(4)


def square(s, material, size, height, **visibility):
    """A size x size square at z = height, facing up, placed with the given visibility flags."""
    v, t = grid(1, size, height)
    mid = s.add_mesh(v, t, material_ids=material, instance=False)
    return s.add_instance(mid, EYE, **visibility)


def test_camera_rays_pass_an_object_hidden_from_them_and_see_the_floor_as_without_it():
    # A black board 3 m above a floor lit by a lamp 1 m above it (below the board: no shadow).
    images = []
    for board in (None, False, True):
        s = floor_scene(albedo=0.5)
        s.add_light("POINT", position=(0.0, 0.0, 1.0), power=100.0, radius=0.0)
        if board is not None:
            s.add_material("diffuse", color=(0.0, 0.0, 0.0))
            square(s, 1, 4.0, 3.0, visible_camera=board)
        s.commit()
        images.append(s.render(camera_above(size=1.0, resolution=8), samples=4))
    without, hidden, seen = images
    assert without[..., 0].min() > 0.0
    np.testing.assert_array_equal(hidden, without)
    assert seen[..., :3].max() == 0.0


def test_diffuse_rays_pass_a_roof_hidden_from_them_so_the_floor_sees_the_whole_sky():
    # Under a constant world L a floor of albedo a shows a L exactly (cosine sampling), when the
    # roof over it is hidden from diffuse rays; seen by them, the roof darkens it.
    L, a = 0.8, 0.5
    pixels = {}
    for roof in (False, True):
        s = floor_scene(albedo=a)
        s.background = (L, L, L)
        s.add_material("diffuse", color=(0.9, 0.9, 0.9))
        square(s, 1, 6.0, 1.0, visible_diffuse=roof)
        s.commit()
        pixels[roof] = s.render(camera_above(height=0.5, size=0.5, resolution=4), samples=64)[..., 0]
    np.testing.assert_allclose(pixels[False], a * L, rtol=1e-6)
    assert pixels[True].mean() < 0.5 * a * L


@pytest.mark.parametrize("hidden", ["visible_camera", "visible_diffuse"])
def test_an_emitter_hidden_from_the_camera_still_lights_the_floor_and_one_hidden_from_diffuse_does_not(hidden):
    # A 1 m emissive square 0.5 m over a white floor, the camera above both looking down.
    L = 2.0
    s = toyrt.Scene()
    s.add_material("diffuse", color=(1.0, 1.0, 1.0))
    s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(L, L, L))
    fv, ft = grid(1, 40.0, 0.0)
    s.add_mesh(fv, ft, material_ids=0)
    square(s, 1, 1.0, 0.5, **{hidden: False})
    s.commit()
    img = s.render(camera_above(height=5.0, size=0.002, resolution=2), samples=1024)[..., 0]
    if hidden == "visible_camera":
        # The floor under its centre, lit by pi L F: the square is not seen, yet it lights.
        assert s.last_commit["emissive_triangles"] == 2
        assert img.mean() == pytest.approx(L * square_irradiance_over_radiance(1.0, 0.5) / np.pi, rel=0.01)
    else:
        # The camera sees the square's emission, and no diffuse surface is lit by it.
        assert s.last_commit["emissive_triangles"] == 0
        np.testing.assert_allclose(img, L, rtol=1e-6)
        under = s.render(camera_above(height=0.25, size=0.002, resolution=2), samples=64)
        assert under[..., :3].max() == 0.0


@pytest.mark.parametrize("kind,material", [("visible_glossy", dict(kind="glossy", color=(1.0, 1.0, 1.0),
                                                                    roughness=0.0)),
                                           ("visible_transmission", dict(kind="refraction", ior=1.0))])
def test_glossy_and_glass_rays_pass_an_emitter_hidden_from_them(kind, material):
    # A mirror (or a refraction of IOR 1) floor; above it, seen through the floor's mirror (or
    # below it, through the glass) an emitter of radiance L: seen, L; hidden from that kind, black.
    L = 3.0
    got = {}
    for visible in (True, False):
        s = toyrt.Scene()
        s.add_material(**material)
        s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(L, L, L), emission_sampling="NONE")
        fv, ft = grid(1, 40.0, 0.0)
        s.add_mesh(fv, ft, material_ids=0)
        if kind == "visible_glossy":
            square(s, 1, 4.0, 1.0, **{kind: visible, "visible_camera": False})
            cam = camera_above(height=0.5, size=0.01, resolution=2)
        else:
            square(s, 1, 4.0, -1.0, **{kind: visible})
            cam = camera_above(height=1.0, size=0.01, resolution=2)
        s.commit()
        got[visible] = s.render(cam, samples=4)[..., 0]
    assert got[True].min() == pytest.approx(L, rel=1e-3)
    assert got[False].max() == 0.0


def test_the_ray_queries_see_every_object():
    s = toyrt.Scene()
    s.add_material("diffuse")
    square(s, 0, 2.0, 1.0, visible_camera=False, visible_diffuse=False, visible_glossy=False,
           visible_transmission=False)
    s.commit()
    hits = s.intersect(np.array([[0.0, 0.0, 5.0]], np.float32), np.array([[0.0, 0.0, -1.0]], np.float32))
    assert hits["t"][0] == pytest.approx(4.0)
