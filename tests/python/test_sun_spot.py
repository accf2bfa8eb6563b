"""Sun and spot lights, soft falloff and the per-light switches through the Python API, against
closed forms in Blender's units: a sun's S cos / pi on a white floor, its disc's radiance seen
by the camera, a spot's cone edge, a round light 1 m from the floor as a disk (I / (d^2 + R^2))
and as a sphere (I / d^2), and what cast_shadow and visible_diffuse turn off."""
import numpy as np
import pytest
import toyrt
from test_render import box_average, camera_above, floor_scene, pixel_centres


def aimed(down, position=(0.0, 0.0, 0.0)):
    """A light object's (4, 4) world matrix whose local -Z points along `down`."""
    z = -np.asarray(down, float) / np.linalg.norm(down)
    helper = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, np.cross(z, x), z, position
    return m


def add_occluder(s, half=0.5, height=1.0):
    v = np.array([[-half, -half, height], [half, -half, height], [half, half, height], [-half, half, height]],
                 np.float32)
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=0)


@pytest.mark.parametrize("tilt", [0.0, 0.6])
def test_delta_sun_lights_a_floor_with_strength_cos_over_pi(tilt):
    strength, albedo = 3.0, 0.8
    s = floor_scene(albedo)
    s.add_light("SUN", matrix=aimed((np.sin(tilt), 0.0, -np.cos(tilt))), strength=strength, angle=0.0)
    s.commit()
    img = s.render(camera_above(size=3.0, resolution=16), samples=4)
    np.testing.assert_allclose(img[..., :3], albedo / np.pi * strength * np.cos(tilt), rtol=1e-5)


@pytest.mark.parametrize("disc", ["CONE", "TANGENT_DISK"])
def test_camera_sees_the_sun_disc_with_its_radiance(disc):
    strength, angle = 2.0, 0.2
    s = toyrt.Scene()
    s.background = (0.1, 0.1, 0.1)
    s.add_light("SUN", matrix=np.eye(4), strength=strength, angle=angle, disc=disc)  # shines down: the sun is up
    s.commit()
    up = np.diag([1.0, -1.0, -1.0, 1.0])  # an orthographic camera looking straight up (+Z)
    up[2, 3] = -5.0
    img = s.render(dict(type="ORTHO", ortho_scale=1.0, resolution_x=4, resolution_y=4, matrix_world=up,
                        clip_start=0.1, clip_end=100.0), samples=2)
    h = angle / 2
    radiance = strength / (np.pi * np.sin(h) ** 2) if disc == "CONE" else strength / (np.pi * np.tan(h) ** 2)
    # Lights do not hide the world behind them (as in Cycles): the disc adds to the background.
    np.testing.assert_allclose(img[..., :3], radiance + 0.1, rtol=1e-4)


def test_cast_shadow_and_visible_diffuse_switch_the_sun_off_where_blender_says():
    strength = 2.0
    results = {}
    for cast_shadow, visible_diffuse in [(True, True), (False, True), (True, False)]:
        s = floor_scene(1.0)
        add_occluder(s)
        s.add_light("SUN", matrix=np.eye(4), strength=strength, angle=0.0, cast_shadow=cast_shadow,
                    visible_diffuse=visible_diffuse)
        s.commit()
        # Below the occluder, looking up from under it is not possible: look at the floor from
        # below the occluder's height, at the centre (shadowed) and a corner (lit).
        cam = camera_above(height=0.5, size=3.0, resolution=12)
        results[(cast_shadow, visible_diffuse)] = s.render(cam, samples=4)[..., 0]
    lit = strength / np.pi
    shadowed = results[(True, True)]
    assert shadowed[6, 6] == 0.0 and shadowed[0, 0] == pytest.approx(lit, rel=1e-5)
    np.testing.assert_allclose(results[(False, True)], lit, rtol=1e-5)      # no shadow anywhere
    assert (results[(True, False)] == 0.0).all()                              # lights no diffuse surface


@pytest.mark.parametrize("falloff", ["SMOOTHSTEP", "COSINE_SMOOTHSTEP"])
def test_spot_cone_edge_on_a_floor_matches_cycles_falloff(falloff):
    power, height, size, blend = 200.0, 2.0, np.radians(50.0), 0.5
    s = floor_scene(1.0)
    s.add_light("SPOT", matrix=aimed((0, 0, -1), (0.0, 0.0, height)), power=power, spot_size=size,
                spot_blend=blend, falloff=falloff)
    s.commit()
    cam = camera_above(size=4.0, resolution=24)
    img = s.render(cam, samples=64)
    x, y, sub = pixel_centres(cam)
    r2 = x**2 + y**2 + height**2
    c = height / np.sqrt(r2)                      # cosine to the axis = the floor's cosine
    cos_half = np.cos(size / 2)
    t = np.clip((c - cos_half) / ((1 - cos_half) * blend), 0, 1)
    factor = t * t * (3 - 2 * t)
    if falloff == "COSINE_SMOOTHSTEP":
        factor = factor * c
    expected = box_average(power / (4 * np.pi) * factor * c / r2 / np.pi, 24, sub)
    np.testing.assert_allclose(img[..., 0], expected, rtol=5e-3, atol=2e-3 * expected.max())


def test_round_light_near_the_floor_is_a_disk_with_soft_falloff_and_a_sphere_without():
    power, height, radius = 100.0, 2.0, 1.0
    intensity = power / (4 * np.pi)
    centre = {}
    for soft in (True, False):
        s = floor_scene(1.0)
        s.add_light("POINT", position=(0, 0, height), power=power, radius=radius, soft_falloff=soft,
                    visible_camera=False)
        s.commit()
        img = s.render(camera_above(size=0.02, resolution=2), samples=4096)
        centre[soft] = float(img[..., 0].mean())
    assert centre[True] == pytest.approx(intensity / (height**2 + radius**2) / np.pi, rel=0.01)
    assert centre[False] == pytest.approx(intensity / height**2 / np.pi, rel=0.01)
