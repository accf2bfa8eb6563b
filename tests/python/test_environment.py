"""The world's environment map through the Python API: a uniform map lights an open floor as a
constant background does (albedo x L), a map with a small bright sun converges to the numerical
integral of its texels at few samples (importance sampling finds the sun), the camera sees the
map in Blender's equirectangular convention, and bad settings are refused."""
import numpy as np
import pytest
import toyrt
from test_render import camera_above, floor_scene


def texel_directions(w, h):
    """Unit direction, solid angle of every texel centre of a w x h equirectangular map (rows from the bottom)."""
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    phi = (0.5 - u) * 2 * np.pi
    theta = (1 - v) * np.pi
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    return d, np.sin(th) * (2 * np.pi / w) * (np.pi / h)


def test_a_uniform_map_lights_an_open_floor_with_albedo_times_its_radiance():
    L, albedo = 0.7, 0.6
    s = floor_scene(albedo, half=1e4)
    tid = s.add_texture(np.full((8, 16, 3), L, np.float32), srgb=False)
    s.set_environment(tid, strength=(2.0, 2.0, 2.0))
    s.commit()
    img = s.render(camera_above(size=2.0, resolution=8), samples=256)
    np.testing.assert_allclose(img[..., :3].mean(), albedo * 2.0 * L, rtol=0.01)


def test_a_small_bright_sun_in_the_map_is_found_at_few_samples():
    w, h = 64, 32
    sky = np.full((h, w, 3), 0.05, np.float32)
    sky[25, 40] = 2000.0                                     # one texel: a sun 2.8 degrees across
    d, omega = texel_directions(w, h)
    up = d[..., 2] > 0
    # Irradiance of an upward floor, summed over texel centres (the bilinear map's integral to well
    # under a per cent at this resolution, since the sun texel is well above the horizon).
    expected = float((sky[..., 0] * np.clip(d[..., 2], 0, None) * omega)[up].sum())
    s = floor_scene(1.0, half=1e4)
    s.set_environment(s.add_texture(sky, srgb=False))
    s.commit()
    img = s.render(camera_above(size=2.0, resolution=16), samples=16)
    assert img[..., 0].mean() == pytest.approx(expected / np.pi, rel=0.03)
    # The typical pixel (16 samples) is within 10 %: without importance sampling a one-texel sun is
    # hit by about one cosine sample in 1,300, and most pixels would miss it entirely (median ~0.05).
    assert np.median(img[..., 0]) == pytest.approx(expected / np.pi, rel=0.10)


def test_the_camera_sees_the_map_in_blenders_equirectangular_convention():
    # Column x of a 4 x 2 map has red = x, row y green = y; looking along the direction of texel
    # (1, 1)'s centre (u = 0.375, v = 0.75: azimuth 45 degrees, 45 degrees above the horizon).
    sky = np.zeros((2, 4, 3), np.float32)
    sky[..., 0] = np.arange(4)[None, :]
    sky[..., 1] = np.arange(2)[:, None]
    sky[..., 2] = 1.0
    s = toyrt.Scene()
    s.set_environment(s.add_texture(sky, srgb=False))
    s.commit()
    d = np.array([np.cos(np.pi / 4) * np.cos(np.pi / 4), np.cos(np.pi / 4) * np.sin(np.pi / 4), np.sin(np.pi / 4)])
    z = -d                                  # the camera looks along its -Z
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = x, np.cross(z, x), z
    img = s.render(dict(type="ORTHO", ortho_scale=1.0, resolution_x=2, resolution_y=2, matrix_world=m,
                        clip_start=0.1, clip_end=10.0), samples=1)
    np.testing.assert_allclose(img[..., :3], np.broadcast_to([1.0, 1.0, 1.0], img[..., :3].shape), atol=1e-4)


def test_bad_environment_settings_are_refused_and_minus_one_removes_it():
    s = toyrt.Scene()
    tid = s.add_texture(np.ones((1, 1, 3), np.float32), srgb=False)
    with pytest.raises(ValueError, match="unknown texture id 5"):
        s.set_environment(5)
    with pytest.raises(ValueError, match="strength"):
        s.set_environment(tid, strength=(float("nan"), 1.0, 1.0))
    with pytest.raises(ValueError, match="singular"):
        s.set_environment(tid, matrix=np.zeros((3, 3)))
    with pytest.raises(ValueError, match="matrix"):
        s.set_environment(tid, matrix=np.eye(2))
    s.set_environment(tid)      # a 1 x 1 map is a uniform world
    s.set_environment(-1)
    s.background = (0.25, 0.25, 0.25)
    s.commit()
    img = s.render(camera_above(resolution=2), samples=1)
    np.testing.assert_allclose(img[..., :3], 0.25)


def test_a_very_wide_map_renders():
    s = floor_scene(1.0, half=1e4)
    s.set_environment(s.add_texture(np.full((64, 32768, 3), 0.5, np.float32), srgb=False))
    s.commit()
    img = s.render(camera_above(size=2.0, resolution=4), samples=64)
    assert np.isfinite(img).all()
    assert img[..., 0].mean() == pytest.approx(0.5, rel=0.02)
