"""The Sky Texture's Preetham model (addon/render_toyrt/sky.py) against its closed forms and
invariants, the baked map against the model (the resolution's accuracy), and the map through the
core: a floor under it gets the irradiance the model integrates to."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from test_render import camera_above, floor_scene

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "addon"))
from render_toyrt import sky, world_sky  # noqa: E402  (plain numpy modules: no bpy)


def sun(elevation_deg, azimuth_deg=90.0):
    el, az = math.radians(elevation_deg), math.radians(azimuth_deg)
    return (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_directions(n, seed=1):
    return unit(np.random.default_rng(seed).normal(size=(n, 3)))


def bilinear(img, d):
    """The core's lookup of an equirectangular map (environment.cpp + Texture::lookup): columns
    wrap, rows clamp to the outer rows' centres, bilinear between texel centres."""
    h, w, _ = img.shape
    u = 0.5 - np.arctan2(d[..., 1], d[..., 0]) / (2 * np.pi)
    u -= np.floor(u)
    v = np.clip(0.5 + np.arctan2(d[..., 2], np.hypot(d[..., 0], d[..., 1])) / np.pi, 0.5 / h, 1 - 0.5 / h)
    x, y = u * w - 0.5, v * h - 0.5
    fx, fy = np.floor(x), np.floor(y)
    tx, ty = (x - fx)[..., None], (y - fy)[..., None]
    x0, y0 = fx.astype(int) % w, fy.astype(int) % h
    x1, y1 = (x0 + 1) % w, np.minimum(y0 + 1, h - 1)
    bottom = img[y0, x0] * (1 - tx) + img[y0, x1] * tx
    top = img[y1, x0] * (1 - tx) + img[y1, x1] * tx
    return bottom * (1 - ty) + top * ty


@pytest.mark.parametrize("elevation,turbidity", [(60, 2.2), (20, 3.0), (5, 6.0), (85, 10.0)])
def test_the_zenith_has_the_zenith_formulas_values(elevation, turbidity):
    p = sky.Preetham.make(sun(elevation), turbidity)
    theta, t = math.radians(90 - elevation), turbidity
    # Preetham et al.'s zenith luminance (kcd/m^2) x Cycles' 0.06, and the x chromaticity's fit.
    chi = (4 / 9 - t / 120) * (math.pi - 2 * theta)
    y_zenith = 0.06 * ((4.0453 * t - 4.9710) * math.tan(chi) - 0.2155 * t + 2.4192)
    x_zenith = ((0.00166 * theta ** 3 - 0.00375 * theta ** 2 + 0.00209 * theta) * t * t
                + (-0.02903 * theta ** 3 + 0.06377 * theta ** 2 - 0.03202 * theta + 0.00394) * t
                + (0.11693 * theta ** 3 - 0.21196 * theta ** 2 + 0.06052 * theta + 0.25886))
    np.testing.assert_allclose(p.xyY(np.array([0.0, 0.0, 1.0])), p.zenith, rtol=1e-12)
    assert p.zenith[0] == pytest.approx(y_zenith, rel=1e-12)
    assert p.zenith[1] == pytest.approx(x_zenith, rel=1e-12)
    # A clear sky's zenith chromaticity is bluish-white: x, y near 0.25-0.3.
    assert 0.2 < p.zenith[1] < 0.35 and 0.2 < p.zenith[2] < 0.35


def test_the_perez_function_relative_to_the_zenith_is_one_there_and_falls_away_from_the_sun():
    p = sky.Preetham.make(sun(30), 2.2)
    theta_s = math.radians(60)
    for c in p.coefficients:
        assert sky.perez(c, 1.0, theta_s) / sky.perez(c, math.cos(0.0), theta_s) == 1.0
    # Luminance along the sun's vertical at 30 degrees elevation: brightest towards the sun.
    d = np.array([sun(30, az) for az in (90, 60, 0, -90)])
    y = p.xyY(d)[:, 0]
    assert np.all(np.diff(y) < 0)


def test_the_sky_is_symmetric_about_the_suns_vertical_plane():
    s = sun(25, 37.0)
    p = sky.Preetham.make(s, 3.0)
    d = random_directions(2000)
    # Reflect across the vertical plane through the sun: n is its normal.
    n = unit(np.cross([0.0, 0.0, 1.0], s))
    mirrored = d - 2 * (d @ n)[:, None] * n
    np.testing.assert_allclose(p.radiance(mirrored), p.radiance(d), rtol=1e-9, atol=1e-12)


def test_the_d65_white_point_is_rgb_white_and_chromaticity_y_zero_keeps_only_luminance():
    xyz = np.array([0.95047, 1.0, 1.08883])                  # D65's tristimulus values, Y = 1
    white = sky.xyY_to_rec709(np.array([1.0, xyz[0] / xyz.sum(), xyz[1] / xyz.sum()]))
    np.testing.assert_allclose(white, [1.0, 1.0, 1.0], atol=1e-4)
    # Cycles' xyY -> XYZ sets X = Z = 0 when y = 0 (no division by zero): Y alone, then clamped RGB.
    np.testing.assert_allclose(sky.xyY_to_rec709(np.array([1.0, 0.3, 0.0])), [0.0, 1.8760108, 0.0])


def test_below_the_horizon_is_the_horizons_sky_and_a_sun_below_it_is_a_dim_glow():
    p = sky.Preetham.make(sun(20), 2.2)
    above, below = unit([[1.0, 0.3, 1e-4]]), unit([[1.0, 0.3, -1e-4]])
    np.testing.assert_allclose(p.radiance(below), p.radiance(above), rtol=1e-3)
    assert np.all(p.radiance(unit([[0.2, 0.5, -0.9]])) > 0.05)   # the ground is not black
    # The zenith formula stays positive for a sun 30 degrees down: a faint red glow (as in Cycles).
    night = sky.Preetham.make(sun(-30), 2.2).radiance(random_directions(1000))
    assert np.all(np.isfinite(night)) and night.max() < 0.5 * p.radiance(np.array([0.0, 0.0, 1.0])).max()
    assert night[:, 0].mean() > night[:, 2].mean()


@pytest.mark.parametrize("elevation,turbidity", [(45, 2.2), (10, 4.0), (2, 2.0), (80, 8.0)])
def test_the_baked_map_is_within_a_thousandth_of_the_model_away_from_the_sun(elevation, turbidity):
    s = sun(elevation, 20.0)
    p = sky.Preetham.make(s, turbidity)
    img = world_sky.sky_map(("PREETHAM", s, turbidity))
    assert img.shape == (world_sky.MAP_HEIGHT, world_sky.MAP_WIDTH, 3) and img.dtype == np.float32
    d = random_directions(100_000, seed=elevation)
    far = np.degrees(np.arccos(np.clip(d @ np.array(s), -1, 1))) > 5.0
    exact, baked = p.radiance(d[far]), bilinear(img, d[far])
    error = np.abs(baked - exact).max(-1) / exact.max(-1)
    assert error.max() < 1e-3
    # Near the sun the Perez glow's cusp (gamma = 0) is rounded by the bilinear lookup: 1 % there.
    near = ~far
    assert (np.abs(bilinear(img, d[near]) - p.radiance(d[near])).max(-1) / p.radiance(d[near]).max(-1)).max() < 0.01


def test_a_floor_under_the_baked_sky_gets_the_models_irradiance():
    s = sun(40, 10.0)
    p = sky.Preetham.make(s, 2.5)
    img = world_sky.sky_map(("PREETHAM", s, 2.5))
    # The model's irradiance on an upward floor, by a fine midpoint rule over the hemisphere.
    n_t, n_p = 400, 800
    theta = (np.arange(n_t) + 0.5) / n_t * (np.pi / 2)
    phi = (np.arange(n_p) + 0.5) / n_p * 2 * np.pi
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    weight = (np.cos(th) * np.sin(th))[..., None] * (np.pi / 2 / n_t) * (2 * np.pi / n_p)
    irradiance = (p.radiance(d) * weight).sum((0, 1))
    scene = floor_scene(1.0, half=1e4)
    scene.set_environment(scene.add_texture(img, srgb=False))
    scene.commit()
    out = scene.render(camera_above(size=2.0, resolution=8), samples=128)
    np.testing.assert_allclose(out[..., :3].mean((0, 1)), irradiance / np.pi, rtol=0.01)


def test_non_finite_settings_and_unknown_types_are_noted_and_black():
    class Node:
        sky_type, sun_direction, turbidity = "PREETHAM", (0.0, float("nan"), 1.0), 2.2
        inputs = {}
    notes = []
    env = world_sky.sky_environment("w", Node(), 1.0, notes)
    assert notes == ["world 'w': Sky Texture with non-finite settings (black)"]
    assert np.all(np.isfinite(env.pixels)) and not env.pixels.any()
    Node.sky_type = "A_FUTURE_SKY"
    notes.clear()
    env = world_sky.sky_environment("w", Node(), 1.0, notes)
    assert notes == ["world 'w': Sky Texture type A_FUTURE_SKY (black)"] and not env.pixels.any()
