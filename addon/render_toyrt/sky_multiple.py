"""Light scattered more than once in TOYRT's atmosphere (sky_atmosphere.py), for Blender 5.0's
Multiple Scattering sky: Hillaire's approximation ("A Scalable and Production Ready Sky and
Atmosphere Rendering Technique", EGSR 2020), written for this model.

At a point of the atmosphere (its height, the sun's zenith cosine there) the light arriving after
two scatterings, isotropically averaged over all directions, is L2 = mean over directions of the
single-scattered light (isotropic phase) plus the sunlit ground's reflection (albedo 0.3,
Lambert); the fraction of light a point's surroundings scatter back to it is f = mean over
directions of the scattering along the ray. Every further order repeats the same transfer, so
all orders >= 2 sum to Psi = L2 / (1 - f), an isotropic radiance per unit scattering coefficient:
a view ray's sample adds sigma_s x Psi. Psi is tabulated over 16 heights x 16 sun cosines from
32 directions (a Fibonacci sphere) of 16 segments each."""
from __future__ import annotations

import math

import numpy as np

from . import sky_atmosphere as atm

GROUND_ALBEDO = 0.3


def multiple_scattering_table(scale, albedo=GROUND_ALBEDO, n_height=16, n_mu=16, n_dir=32, steps=16):
    """Psi: (n_height, n_mu, wavelengths), heights 0 .. the top, sun zenith cosines -1 .. 1."""
    heights = np.linspace(0.0, atm.TOP - atm.EARTH - 1.0, n_height)
    mus = np.linspace(-1.0, 1.0, n_mu)
    k = np.arange(n_dir) + 0.5
    z = 1.0 - 2.0 * k / n_dir
    phi = k * math.pi * (3.0 - math.sqrt(5.0))
    dirs = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], -1)
    origin = np.zeros((n_height, 1, 1, 3))
    origin[..., 2] = atm.EARTH + heights[:, None, None]
    d = np.broadcast_to(dirs, (n_height, n_mu, n_dir, 3))
    o = np.broadcast_to(origin, d.shape)
    sun = np.stack([np.sqrt(1 - mus * mus), np.zeros_like(mus), mus], -1)[None, :, None, :]
    # Each direction's ray ends at the ground or the top of the atmosphere.
    b = (o * d).sum(-1)
    disc = b * b - ((o * o).sum(-1) - atm.EARTH ** 2)
    ground = (disc > 0) & (b < 0)
    length = np.where(ground, -b - np.sqrt(np.maximum(disc, 0.0)), atm._to_top(o, d))
    ds = length / steps
    s = (np.arange(steps) + 0.5) * ds[..., None]
    p = o[..., None, :] + s[..., None] * d[..., None, :]                       # (H, M, D, S, 3)
    dens = atm._densities(np.linalg.norm(p, axis=-1) - atm.EARTH, scale)
    to_point = [np.cumsum(x, -1) * ds[..., None] - 0.5 * x * ds[..., None] for x in dens]
    sun_p = np.broadcast_to(sun[..., None, :], p.shape)
    to_sun = atm._optical_depths(p, sun_p, scale, n=8)
    bb = (p * sun_p).sum(-1)
    lit = ~((bb < 0) & ((p * p).sum(-1) - bb * bb < atm.EARTH ** 2))
    view_t = atm._transmittance(*to_point)                                     # (H, M, D, S, L)
    sigma = dens[0][..., None] * atm.BETA_AIR + dens[1][..., None] * atm.AEROSOL_SCATTERING
    sun_t = atm._transmittance(*to_sun) * lit[..., None]
    single = (view_t * sigma * sun_t).sum(-2) * ds[..., None] * atm.SUN_E / (4 * math.pi)
    transfer = (view_t * sigma).sum(-2) * ds[..., None]
    # The ground's Lambert reflection of the sun where a direction meets it.
    end = o + length[..., None] * d
    normal = end / np.linalg.norm(end, axis=-1, keepdims=True)
    cos_sun = np.clip((normal * sun).sum(-1), 0.0, None)
    full = [x.sum(-1) * ds for x in dens]
    to_ground_sun = atm._optical_depths(end + normal * 1.0, np.broadcast_to(sun, end.shape), scale, n=8)
    reflected = (atm._transmittance(*full) * atm._transmittance(*to_ground_sun) * atm.SUN_E
                 * (albedo / math.pi * cos_sun * ground)[..., None])
    second = (single + reflected).mean(2)
    f = transfer.mean(2)
    return second / np.maximum(1.0 - f, 1e-3)


def lookup(table, height, mu):
    """Psi at heights and sun cosines (arrays of one shape): (..., wavelengths), bilinear."""
    n_h, n_mu = table.shape[:2]
    fh = np.clip(height / (atm.TOP - atm.EARTH) * (n_h - 1), 0.0, n_h - 1.0)
    fm = np.clip((mu + 1.0) * 0.5 * (n_mu - 1), 0.0, n_mu - 1.0)
    h0 = np.minimum(np.floor(fh).astype(int), n_h - 2)
    m0 = np.minimum(np.floor(fm).astype(int), n_mu - 2)
    th, tm = (fh - h0)[..., None], (fm - m0)[..., None]
    return ((table[h0, m0] * (1 - tm) + table[h0, m0 + 1] * tm) * (1 - th)
            + (table[h0 + 1, m0] * (1 - tm) + table[h0 + 1, m0 + 1] * tm) * th)
