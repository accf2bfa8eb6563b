"""TOYRT's own sky for Blender's Nishita (2.90-4.x) and 5.0's Single / Multiple Scattering types:
single scattering (and, for Multiple Scattering, an approximation of the rest) of sunlight in a
spherical atmosphere of air (Rayleigh) and aerosols (Mie), with ozone absorption, integrated here
from physical formulas and constants; not Blender's precomputation (its spectral tables are not
used), so its result differs (docs/lights.md).

  - Earth radius 6360 km, atmosphere top 6420 km, the viewer at the node's altitude;
  - air: scale height 8 km, scattering from the refractive index (Edlen's dispersion, at 0 C
    and 101325 Pa) by beta = 8 pi^3 (n^2 - 1)^2 / (3 N lambda^4) x the King factor 1.048, phase
    3 (1 + mu^2) / (16 pi);
  - aerosols: scale height 1.2 km, scattering 2e-5 / m (extinction 1.11 x), the Cornette-Shanks
    phase with g = 0.76;
  - ozone: a tent profile from 10 to 40 km (5e18 molecules / m^3 at its 25 km peak) absorbing in
    the Chappuis band, modelled as a Gaussian cross-section (4.8e-25 m^2 at 602 nm, sigma 45 nm);
  - the sun: a 5772 K black body giving the solar constant at the top of the atmosphere;
  - XYZ by the CIE 1931 matching functions in Wyman, Sloan and Shirley's multi-lobe Gaussian fit
    (JCGT 2013), 380-780 nm in 20 nm steps, then linear Rec.709 (sky.XYZ_TO_REC709).

The view ray is cut into 32 segments evaluated at their middles, each attenuated by the column up
to its far end (Blender's discretisation: near the horizon, where a segment is tens of kilometres
of dense air, it sets the colour, and the exact integral would be bluer than Cycles' sky); the
column towards the sun by a 12-point rule. The node's densities scale air, aerosols and ozone.
Single scattering factors into P_air(mu) R(view) + P_aerosol(mu) M(view), mu the cosine to the
sun, R and M smooth in the view's elevation and azimuth from the sun: they are tabulated on a grid
(denser towards the horizon) and interpolated, the phase functions evaluated exactly per texel.
Below the horizon the horizon's sky fades to black by (1 + 2.5 z)^3 (z > -0.4), as Blender's
Nishita does. The sun disc (sun_disc): the sun's transmitted radiance x sun_intensity over the
disc, limb darkening's mean 0.8 kept as energy; a disc narrower than two texels goes into the
texels around its centre (bilinear weights) with the same power, so it lights the scene right but
looks like a blurred dot.

For 5.0's Multiple Scattering (multiple=True) light scattered more than once is added
(sky_multiple.py), the rays below the horizon end at the ground (the air between the viewer and
the ground, no fade), and each segment is attenuated to its middle: the sky Cycles precomputes for
this type has the horizon of the exact integral."""
from __future__ import annotations

import math

import numpy as np

from .sky import XYZ_TO_REC709, texel_directions

EARTH, TOP = 6360e3, 6420e3
AIR_H, AEROSOL_H = 8e3, 1.2e3
AEROSOL_SCATTERING, AEROSOL_EXTINCTION, MIE_G = 2e-5, 1.11 * 2e-5, 0.76
LAMBDA = np.arange(380.0, 781.0, 20.0)                    # nm
STEP = 20.0


def _air_scattering(lam_nm):
    sigma2 = (1e3 / lam_nm) ** 2                          # (1 / micrometres)^2
    n1 = 1e-8 * (8342.13 + 2406030.0 / (130.0 - sigma2) + 15997.0 / (38.9 - sigma2))   # Edlen 1966, 15 C
    n1 *= 288.15 / 273.15                                 # n - 1 grows with the density: air at 0 C
    number = 2.687e25                                     # molecules / m^3 at 0 C, 101325 Pa
    lam = lam_nm * 1e-9
    return 8 * math.pi ** 3 * ((1 + n1) ** 2 - 1) ** 2 / (3 * number * lam ** 4) * 1.048


def _ozone_absorption(lam_nm):
    return 5e18 * 4.8e-25 * np.exp(-0.5 * ((lam_nm - 602.0) / 45.0) ** 2)


def _solar_irradiance(lam_nm):
    """W / m^2 / nm at the top of the atmosphere: a 5772 K black body seen at 1 AU."""
    lam = lam_nm * 1e-9
    planck = 2 * 6.62607015e-34 * 2.99792458e8 ** 2 / lam ** 5 / np.expm1(1.438776877e-2 / (lam * 5772.0))
    return math.pi * planck * (6.957e8 / 1.495978707e11) ** 2 * 1e-9


def _cmf(lam):
    def g(mu, s1, s2):
        return np.exp(-0.5 * ((lam - mu) / np.where(lam < mu, s1, s2)) ** 2)
    x = 1.056 * g(599.8, 37.9, 31.0) + 0.362 * g(442.0, 16.0, 26.7) - 0.065 * g(501.1, 20.4, 26.2)
    y = 0.821 * g(568.8, 46.9, 40.5) + 0.286 * g(530.9, 16.3, 31.1)
    z = 1.217 * g(437.0, 11.8, 36.0) + 0.681 * g(459.0, 26.0, 13.8)
    return np.stack([x, y, z], -1)                        # (wavelengths, 3)


BETA_AIR, BETA_OZONE = _air_scattering(LAMBDA), _ozone_absorption(LAMBDA)
SUN_E, CMF = _solar_irradiance(LAMBDA), _cmf(LAMBDA)


def _densities(height, scale):
    height = np.maximum(height, 0.0)   # points inside the Earth (rays towards a set sun) are unlit anyway
    ozone = np.clip(np.where(height < 25e3, (height - 10e3) / 15e3, (40e3 - height) / 15e3), 0.0, None)
    return np.exp(-height / AIR_H) * scale[0], np.exp(-height / AEROSOL_H) * scale[1], ozone * scale[2]


def _to_top(origin, direction):
    """Distance from points `origin` (..., 3) along unit `direction` to the atmosphere's top."""
    b = (origin * direction).sum(-1)
    c = (origin * origin).sum(-1) - TOP * TOP
    return -b + np.sqrt(np.maximum(b * b - c, 0.0))


def _optical_depths(origin, direction, scale, n=12):
    """Column densities (air, aerosol, ozone) from `origin` to the top along `direction`, by a
    midpoint rule in x with distance L x^2 (samples crowd where the air is densest)."""
    length = _to_top(origin, direction)
    x = (np.arange(n) + 0.5) / n
    s = length[..., None] * x * x                                   # (..., n)
    p = origin[..., None, :] + s[..., None] * direction[..., None, :]
    d = _densities(np.linalg.norm(p, axis=-1) - EARTH, scale)
    w = 2.0 * length[..., None] * x / n                             # ds = 2 L x dx
    return tuple((di * w).sum(-1) for di in d)


def _transmittance(air, aerosol, ozone):
    """(..., wavelengths) transmittance of the column densities."""
    return np.exp(-(air[..., None] * BETA_AIR + aerosol[..., None] * AEROSOL_EXTINCTION
                    + ozone[..., None] * BETA_OZONE))


def _xyz(spectrum):
    return spectrum @ CMF * STEP


def scattering_tables(sun, altitude, scale, n_elevation=64, n_azimuth=33, steps=32, multiple=None):
    """XYZ of the air's and the aerosols' single scattering without their phase functions, on a
    grid of view elevations (0 .. pi/2, as (k / (n - 1))^2) x azimuths from the sun (0 .. pi):
    two (n_elevation, n_azimuth, 3) arrays; with `multiple` (sky_multiple's table) a third, the
    light scattered more than once (isotropic: no phase function to apply)."""
    el = (math.pi / 2) * (np.arange(n_elevation) / (n_elevation - 1)) ** 2
    if multiple is not None:   # also below the horizon: -el .. el, (2 n_elevation - 1) rows
        el = np.concatenate([-el[:0:-1], el])
    az = np.linspace(0.0, math.pi, n_azimuth) + math.atan2(sun[1], sun[0])
    e, a = np.meshgrid(el, az, indexing="ij")
    view = np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], -1)
    origin = np.array([0.0, 0.0, EARTH + altitude])
    # A ray ends at the top of the atmosphere, or at the ground below the horizon.
    b = view @ origin
    disc = b * b - (origin @ origin - EARTH * EARTH)
    length = np.where((disc > 0) & (b < 0), -b - np.sqrt(np.maximum(disc, 0.0)), _to_top(origin, view))
    ds = length / steps
    s = (np.arange(steps) + 0.5)[None, None, :] * ds[..., None]
    p = origin + s[..., None] * view[..., None, :]                  # (E, A, steps, 3)
    dens = _densities(np.linalg.norm(p, axis=-1) - EARTH, scale)
    # Column densities from the viewer through each sample's segment (see the module docstring).
    to_viewer = [np.cumsum(d, -1) * ds[..., None] - (0.0 if multiple is None else 0.5) * d * ds[..., None]
                 for d in dens]
    sun_dir = np.broadcast_to(np.asarray(sun, float), p.shape)
    to_sun = _optical_depths(p, sun_dir, scale)
    # The Earth's shadow: the sun below a sample's horizon (its ray meets the ground).
    b = (p * sun_dir).sum(-1)
    lit = ~((b < 0) & ((p * p).sum(-1) - b * b < EARTH * EARTH))
    t = _transmittance(*(v + u for v, u in zip(to_viewer, to_sun))) * lit[..., None]
    weight = (t * SUN_E) * ds[..., None, None]                      # (E, A, steps, wavelengths)
    air = _xyz((weight * dens[0][..., None]).sum(2) * BETA_AIR)
    aerosol = _xyz((weight * dens[1][..., None]).sum(2) * AEROSOL_SCATTERING)
    if multiple is None:
        return air, aerosol
    from .sky_multiple import lookup

    r = np.linalg.norm(p, axis=-1)
    psi = lookup(multiple, r - EARTH, (p * sun_dir).sum(-1) / r)
    sigma = dens[0][..., None] * BETA_AIR + dens[1][..., None] * AEROSOL_SCATTERING
    view_t = _transmittance(*to_viewer)
    return air, aerosol, _xyz((view_t * sigma * psi).sum(2) * ds[..., None])


def phase_air(mu):
    return 3.0 / (16.0 * math.pi) * (1.0 + mu * mu)


def phase_aerosol(mu):
    g2 = MIE_G * MIE_G
    return 3.0 * (1.0 - g2) * (1.0 + mu * mu) / (8.0 * math.pi * (2.0 + g2) * (1.0 + g2 - 2.0 * MIE_G * mu) ** 1.5)


def sun_direction(elevation, rotation):
    """Blender's sun_elevation / sun_rotation as a unit vector: rotation 0 towards +Y, turning
    towards +X (clockwise seen from above), as Cycles places it."""
    return np.array([math.cos(elevation) * math.sin(rotation), math.cos(elevation) * math.cos(rotation),
                     math.sin(elevation)])


def sun_radiance(sun, altitude, scale) -> np.ndarray:
    """XYZ radiance of the sun's disc centre per steradian of a 1 sr sun: its transmitted
    spectral irradiance (divide by the disc's solid angle for radiance). As Blender's, the
    sun's light is dimmed by air and aerosols, not by ozone."""
    origin = np.array([0.0, 0.0, EARTH + altitude])
    depths = _optical_depths(origin[None], np.asarray(sun, float)[None], (scale[0], scale[1], 0.0))
    return _xyz(_transmittance(*depths)[0] * SUN_E)


def atmosphere_map(elevation, rotation, altitude, air, aerosol, ozone, disc, size, intensity, *, width, height,
                   multiple=False):
    """The (height, width, 3) float32 equirectangular map of the sky (module docstring); with
    `multiple`, light scattered more than once added (sky_multiple.py)."""
    sun = sun_direction(elevation, rotation)
    altitude = min(max(altitude, 0.0), 59e3)
    scale = (max(air, 0.0), max(aerosol, 0.0), max(ozone, 0.0))
    if multiple:
        from .sky_multiple import multiple_scattering_table

        air_t, aerosol_t, ms_t = scattering_tables(sun, altitude, scale, multiple=multiple_scattering_table(scale))
    else:
        air_t, aerosol_t = scattering_tables(sun, altitude, scale)
        ms_t = np.zeros_like(air_t)
    d = texel_directions(width, height).astype(np.float32)
    # The tables' elevation index depends on the texel's row only and the azimuth index on its
    # column only: interpolate along rows, then columns. Below the horizon: the horizon's row
    # (single scattering, faded below) or the rays to the ground (multiple).
    el = np.arcsin(np.clip(d[:, 0, 2], -1.0, 1.0))
    if multiple:
        n = (air_t.shape[0] + 1) // 2
        fi = (n - 1) * (1.0 + np.sign(el) * np.sqrt(np.abs(el) / (math.pi / 2)))
    else:
        fi = np.sqrt(np.maximum(el, 4e-4) / (math.pi / 2)) * (air_t.shape[0] - 1)
    i0 = np.clip(np.floor(fi).astype(int), 0, air_t.shape[0] - 2)
    ti = (fi - i0)[:, None, None]
    tables = np.concatenate([air_t, aerosol_t, ms_t], -1)
    rows = (tables[i0] * (1 - ti) + tables[i0 + 1] * ti).astype(np.float32)   # (height, azimuths, 9)
    azimuth = np.arctan2(d[0, :, 1], d[0, :, 0])
    rel = np.abs(np.angle(np.exp(1j * (azimuth - math.atan2(sun[1], sun[0])))))
    fj = rel / math.pi * (air_t.shape[1] - 1)
    j0 = np.clip(np.floor(fj).astype(int), 0, air_t.shape[1] - 2)
    tj = (fj - j0)[None, :, None].astype(np.float32)
    xyz9 = rows[:, j0] * (1 - tj) + rows[:, j0 + 1] * tj                        # (height, width, 9)
    # Below the horizon the horizon's sky at the same azimuth, its phase functions included.
    horizontal = np.stack([np.cos(azimuth), np.sin(azimuth)], -1) @ np.asarray(sun[:2])
    below = (d[..., 2] < math.sin(4e-4)) & (not multiple)
    mu = np.where(below, horizontal[None, :], d @ sun.astype(np.float32))
    xyz = phase_air(mu)[..., None] * xyz9[..., :3] + phase_aerosol(mu)[..., None] * xyz9[..., 3:6] + xyz9[..., 6:]
    fade = np.where((d[..., 2] < 0.0) & (not multiple), np.clip(1.0 + 2.5 * d[..., 2], 0.0, None) ** 3, 1.0)
    rgb = np.maximum(xyz @ XYZ_TO_REC709.T, 0.0) * fade[..., None]
    if disc and sun[2] > 0.0 and size > 0.0:   # (an elevation past 90 degrees turns the sun round, as in Cycles)
        _add_sun(rgb, d, sun, sun_radiance(sun, altitude, scale) @ XYZ_TO_REC709.T * intensity, size)
    return np.nan_to_num(rgb, nan=0.0, posinf=0.0, neginf=0.0).astype(np.float32)


def _add_sun(rgb, d, sun, irradiance, size):
    """Adds a sun of angular diameter `size` and (limb-darkening-free) spectral irradiance
    `irradiance` (RGB, W / m^2 as the map's units x sr): its power is 0.8 x irradiance."""
    h, w, _ = rgb.shape
    solid = np.cos(np.arcsin(d[:, 0, 2]))[:, None] * (2 * math.pi / w) * (math.pi / h)   # per row
    solid = np.broadcast_to(solid, (h, w))
    power = 0.8 * np.maximum(irradiance, 0.0)
    r = np.arccos(np.clip((d * sun).sum(-1), -1.0, 1.0)) / (0.5 * size)
    inside = r < 1.0
    if inside.sum() >= 4:
        limb = 1.0 - 0.6 * (1.0 - np.sqrt(np.clip(1.0 - r[inside] ** 2, 0.0, None)))
        shape = limb / (limb * solid[inside]).sum()                 # integrates to 1 over the disc
        rgb[inside] += shape[:, None] * power
        return
    u = (0.5 - math.atan2(sun[1], sun[0]) / (2 * math.pi)) % 1.0
    v = 0.5 + math.asin(min(1.0, sun[2])) / math.pi
    x, y = u * w - 0.5, min(max(v * h - 0.5, 0.0), h - 1.0)
    x0, y0 = math.floor(x), min(math.floor(y), h - 2)
    tx, ty = x - x0, y - y0
    for (i, j, k) in ((x0, y0, (1 - tx) * (1 - ty)), (x0 + 1, y0, tx * (1 - ty)),
                      (x0, y0 + 1, (1 - tx) * ty), (x0 + 1, y0 + 1, tx * ty)):
        rgb[j, i % w] += k * power / solid[j, i % w]
