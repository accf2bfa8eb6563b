"""A world's Sky Texture node -> an EnvironmentSpec whose map the add-on computes (sky.py,
sky_atmosphere.py), with a note for each sky type TOYRT draws by another model.

The map is computed once per set of settings (a small cache: the viewport syncs the world on
every edit) and goes to the core as any environment map, so the Background strength, a Mapping
node's rotation and the world's ray visibility apply as they do to an Environment Texture."""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from . import sky
from .materials import ImageKey, input_socket

# 1024 x 512 texels keeps the map within 0.05 % of the Preetham model away from the sun
# (tests/python/test_sky.py measures it; 512 x 256 is 0.17 %), and it is the largest grid the
# core's importance sampling uses (Environment::kMaxSamplingWidth).
MAP_WIDTH, MAP_HEIGHT = 1024, 512

# Blender's identifiers, per version: 3.4-4.x PREETHAM, HOSEK_WILKIE, NISHITA; 5.0 PREETHAM,
# HOSEK_WILKIE, SINGLE_SCATTERING, MULTIPLE_SCATTERING.
ANALYTIC = ("PREETHAM", "HOSEK_WILKIE")
# Hosek-Wilkie is drawn as Preetham at this brightness: Cycles' Hosek-Wilkie sky (its fitted
# dataset, in its own units) is 0.10-0.23 x its Preetham sky's mean luminance above the horizon
# for turbidity 2-8 and the sun 10-60 degrees up, 0.16 the geometric mean (measured from Cycles
# 3.4 renders of both; docs/lights.md). The distribution still differs (Hosek-Wilkie's brighter
# circumsolar region): 20-60 % mean difference after scaling.
HOSEK_AS_PREETHAM = 0.16
ATMOSPHERE = ("NISHITA", "SINGLE_SCATTERING", "MULTIPLE_SCATTERING")


def sky_settings(node) -> tuple:
    """What the map depends on, as plain values (the cache's key and the spec's comparison)."""
    kind = str(getattr(node, "sky_type", "PREETHAM"))
    if kind in ANALYTIC:
        return (kind, tuple(float(v) for v in node.sun_direction), float(node.turbidity))
    aerosol = getattr(node, "aerosol_density", None)   # 3.x/4.x call it dust_density
    if aerosol is None:
        aerosol = getattr(node, "dust_density", 1.0)
    return (kind, float(node.sun_elevation), float(node.sun_rotation), float(node.altitude),
            float(node.air_density), float(aerosol), float(node.ozone_density), bool(node.sun_disc),
            float(node.sun_size), float(node.sun_intensity))


@lru_cache(maxsize=4)
def sky_map(settings: tuple) -> np.ndarray:
    """The (MAP_HEIGHT, MAP_WIDTH, 3) float32 map of `settings` (sky_settings), read-only."""
    kind = settings[0]
    if kind in ANALYTIC:
        radiance = sky.Preetham.make(settings[1], settings[2]).radiance
        pixels = sky.bake(radiance, MAP_WIDTH, MAP_HEIGHT)
        if kind == "HOSEK_WILKIE":
            pixels *= np.float32(HOSEK_AS_PREETHAM)
    else:
        from .sky_atmosphere import atmosphere_map

        pixels = atmosphere_map(*settings[1:], width=MAP_WIDTH, height=MAP_HEIGHT,
                                multiple=kind == "MULTIPLE_SCATTERING")
    pixels.setflags(write=False)
    return pixels


def sky_notes(name: str, settings: tuple) -> list[str]:
    kind = settings[0]
    if kind == "HOSEK_WILKIE":
        return [f"world '{name}': Sky Texture Hosek-Wilkie drawn as Preetham (same sun and turbidity, "
                f"x {HOSEK_AS_PREETHAM} for Cycles' brightness)"]
    if kind == "MULTIPLE_SCATTERING":
        return [f"world '{name}': Sky Texture Multiple Scattering drawn by TOYRT's own atmosphere (single "
                "scattering + Hillaire's multiple-scattering approximation; not Blender's precomputed sky)"]
    if kind in ATMOSPHERE:
        return [f"world '{name}': Sky Texture {kind.replace('_', ' ').title()} drawn by TOYRT's own "
                "single-scattering atmosphere (Rayleigh + Mie; not Blender's precomputed sky)"]
    return []


def sky_environment(name: str, node, strength: float, notes: list):
    """The world's Sky Texture `node` feeding a Background of `strength`, as an EnvironmentSpec."""
    from .world import EnvironmentSpec, mapping_matrix

    kind = str(getattr(node, "sky_type", ""))
    settings = sky_settings(node) if kind in ANALYTIC + ATMOSPHERE else ("BLACK", kind)
    if settings[0] == "BLACK":
        notes.append(f"world '{name}': Sky Texture type {kind} (black)")
        pixels = np.zeros((1, 1, 3), np.float32)
    elif not all(math.isfinite(v) for v in _numbers(settings)):
        notes.append(f"world '{name}': Sky Texture with non-finite settings (black)")
        settings = ("BLACK", "non-finite")
        pixels = np.zeros((1, 1, 3), np.float32)
    else:
        notes.extend(sky_notes(name, settings))
        pixels = sky_map(settings)
    matrix = mapping_matrix(name, input_socket(node, "Vector"), notes)
    rows = tuple(tuple(float(v) for v in row) for row in matrix.tolist())
    # One texture per world, its pixels sent again when the settings change (sync_materials.py).
    return EnvironmentSpec(ImageKey("\0sky " + name, False), (strength,) * 3, rows, None, pixels, settings)


def _numbers(settings: tuple):
    for v in settings[1:]:
        if isinstance(v, tuple):
            yield from v
        elif not isinstance(v, bool):
            yield v
