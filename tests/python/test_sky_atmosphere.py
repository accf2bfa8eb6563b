"""TOYRT's single-scattering atmosphere (addon/render_toyrt/sky_atmosphere.py, the stand-in for
Blender's Nishita / Single / Multiple Scattering skies) against closed forms: the optically thin
limit, the sun disc's power, the symmetry about the sun's vertical, the fade below the horizon."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "addon"))
from render_toyrt import sky  # noqa: E402
from render_toyrt import sky_atmosphere as atm  # noqa: E402
from render_toyrt import sky_multiple as multiple  # noqa: E402

W, H = 256, 128


def texel_solid_angles(w, h):
    el = ((np.arange(h) + 0.5) / h - 0.5) * np.pi
    return np.broadcast_to((np.cos(el) * (2 * np.pi / w) * (np.pi / h))[:, None], (h, w))


def test_a_thin_atmosphere_scatters_the_column_of_air_times_the_phase():
    # Sun and view at the zenith, air at 1e-4 of its density, no aerosols or ozone: no extinction
    # to speak of, so the zenith's XYZ is P(1) x the air column x sum(cmf x beta x E) d lambda.
    density = 1e-4
    air, aerosol = atm.scattering_tables(np.array([0.0, 0.0, 1.0]), 0.0, (density, 0.0, 0.0))
    column = atm.AIR_H * (1 - math.exp(-(atm.TOP - atm.EARTH) / atm.AIR_H)) * density
    expected = column * (atm.BETA_AIR * atm.SUN_E) @ atm.CMF * atm.STEP
    np.testing.assert_allclose(air[-1, 0], expected, rtol=5e-3)
    assert not aerosol.any()


@pytest.mark.parametrize("size", [math.radians(0.545), math.radians(6.0)])
def test_the_sun_disc_carries_the_suns_irradiance_times_the_mean_limb_darkening(size):
    # An empty atmosphere: the sky is black and the map's power is the sun's, 0.8 x its XYZ
    # irradiance (the mean of the limb darkening over the disc) x the intensity; a small disc
    # goes into four texels, a large one is drawn.
    img = atm.atmosphere_map(math.radians(35), math.radians(20), 0.0, 0.0, 0.0, 0.0, True, size, 2.0,
                             width=W, height=H)
    power = (img * texel_solid_angles(W, H)[..., None]).sum((0, 1))
    expected = 0.8 * 2.0 * np.maximum((atm.SUN_E @ atm.CMF * atm.STEP) @ sky.XYZ_TO_REC709.T, 0)
    np.testing.assert_allclose(power, expected, rtol=1e-3)
    lit = np.argwhere(img[..., 1] > 0)
    assert len(lit) == 4 if size < 0.02 else len(lit) > 10   # 6 degrees: about 17 texels of 1.4


def test_the_sun_rotation_turns_from_plus_y_towards_plus_x_as_in_cycles():
    np.testing.assert_allclose(atm.sun_direction(0.0, 0.0), [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(atm.sun_direction(0.0, math.pi / 2), [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(atm.sun_direction(math.pi / 2, 1.0), [0, 0, 1], atol=1e-12)
    # Past the zenith the sun comes down on the other side (Cycles wraps the angles so).
    np.testing.assert_allclose(atm.sun_direction(math.radians(120), 0.3),
                               atm.sun_direction(math.radians(60), 0.3 + math.pi), atol=1e-12)


def test_the_sky_is_symmetric_about_the_suns_vertical_and_blue_at_the_zenith():
    img = atm.atmosphere_map(math.radians(25), 0.0, 0.0, 1.0, 1.0, 1.0, False, 0.01, 1.0, width=W, height=H)
    # The sun towards +Y: mirroring x -> -x maps column i to column W/2 - 1 - i.
    mirrored = img[:, (W // 2 - 1 - np.arange(W)) % W]
    np.testing.assert_allclose(mirrored, img, rtol=1e-5, atol=1e-6)
    zenith = img[-1].mean(0)
    assert zenith[2] > zenith[1] > zenith[0] > 0


def test_below_the_horizon_the_horizons_sky_fades_to_black():
    img = atm.atmosphere_map(math.radians(25), 0.3, 0.0, 1.0, 1.0, 1.0, False, 0.01, 1.0, width=W, height=H)
    z = sky.texel_directions(W, H)[:, 0, 2]
    # Every row down to z = -0.4 is the horizon's sky (per azimuth) x (1 + 2.5 z)^3.
    rows = [int(np.argmin(np.abs(z - t))) for t in (-0.01, -0.1, -0.3)]
    undone = [img[r] / (1 + 2.5 * z[r]) ** 3 for r in rows]
    for u in undone[1:]:
        np.testing.assert_allclose(u, undone[0], rtol=1e-4)
    assert undone[0].min() > 0 and not img[z < -0.4].any() and np.all(np.isfinite(img))


def test_multiple_scattering_scales_with_the_density_and_the_ground():
    # Psi (light arriving after two or more scatterings, per unit scattering coefficient): in a thin
    # atmosphere over a black ground it is light scattered once on the way, so it doubles with the
    # density; over a bright ground it is mostly the ground's reflection of the sun, which does not.
    def psi(density, albedo):
        return multiple.multiple_scattering_table((density, density, density), albedo)[0, 12]  # sea level, sun up
    black = psi(2e-3, 0.0) / psi(1e-3, 0.0)
    np.testing.assert_allclose(black, 2.0, rtol=0.01)
    bright = psi(2e-3, 0.3) / psi(1e-3, 0.3)
    assert np.all(np.abs(bright - 1.0) < 0.1)
    assert np.all(multiple.multiple_scattering_table((1.0, 1.0, 1.0)) >= 0)


def test_multiple_scattering_adds_light_bluer_than_single_scattering():
    def maps(density):
        args = (math.radians(30), 0.4, 100.0, density, density, density, False, 0.01, 1.0)
        return [atm.atmosphere_map(*args, width=W, height=H, multiple=m) for m in (False, True)]
    z = sky.texel_directions(W, H)[..., 2]
    up = z > 0.05
    single, more = maps(1.0)
    assert np.all(more[up] >= single[up] * (1 - 1e-6))
    gain = more[-1].mean(0) / single[-1].mean(0) - 1
    assert np.all(gain > 0.3) and gain[2] > gain[0]
    # The ground below the horizon: the air between the viewer (100 m up) and the ground.
    assert np.all(np.isfinite(more)) and more[z < -0.05].mean() > 0
