"""Blender's Sky Texture as an equirectangular float image for the world's environment map.

The sky models are evaluated here, vectorised over the map's texel centres, and the image goes
the way an Environment Texture's does (world.py -> sync.py -> toyrt.Scene.set_environment): the
core importance-samples it, applies the Mapping rotation and the Background strength, and camera
and glass rays see it. Plain numpy, no bpy: tests load this file on its own.

Preetham ("A Practical Analytic Model for Daylight", Preetham, Shirley and Smits 1999), as
Cycles evaluates it:
  - the sun at polar angle theta_s (from +Z) of the node's sun_direction;
  - per channel c of (Y, x, y) a Perez distribution F_c(theta, gamma) =
        (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2 gamma),
    theta the view direction's polar angle, gamma its angle to the sun, A..E linear in the
    turbidity T (the paper's table);
  - the zenith's values: luminance Y_z = (4.0453 T - 4.9710) tan(chi) - 0.2155 T + 2.4192 with
    chi = (4/9 - T/120)(pi - 2 theta_s), scaled by 0.06 (Cycles' choice, so a clear day is about
    1 in scene-linear units), and the chromaticities x_z, y_z as the paper's cubic polynomials
    in theta_s and quadratics in T;
  - the value in direction (theta, gamma) is c_z F_c(theta, gamma) / F_c(0, theta_s): the zenith
    (theta = 0, gamma = theta_s) has exactly the zenith's value;
  - below the horizon theta is held at pi/2 - 0.001 (gamma is not): the ground shows the
    horizon's sky, brighter towards the sun;
  - xyY -> XYZ -> linear Rec.709 (D65 white, as Cycles' XYZ), negative components clamped to 0.

Hosek-Wilkie needs the authors' fitted dataset (thousands of coefficients); TOYRT draws it as
Preetham with the same sun and turbidity. Nishita (Blender 2.90-4.x) and 5.0's Single and
Multiple Scattering precompute Blender's own atmosphere; TOYRT draws a single-scattering
Rayleigh + Mie integral of its own (nishita_radiance below). Both are noted where used
(world.py)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# CIE XYZ (D65 white) -> linear Rec.709 / sRGB primaries: the standard's matrix, which is what
# Cycles' xyz_to_rgb is with Blender's colour configuration.
XYZ_TO_REC709 = np.array([[3.2404542, -1.5371385, -0.4985314],
                          [-0.9692660, 1.8760108, 0.0415560],
                          [0.0556434, -0.2040259, 1.0572252]])

HORIZON_THETA = math.pi / 2 - 0.001   # Cycles' clamp of the view's polar angle


def perez(coefficients, cos_theta, gamma):
    """The Perez sky distribution for (A, B, C, D, E) at the view's cos(theta) and the angle
    gamma to the sun (arrays broadcast)."""
    a, b, c, d, e = coefficients
    cos_gamma = np.cos(gamma)
    return (1.0 + a * np.exp(b / cos_theta)) * (1.0 + c * np.exp(d * gamma) + e * cos_gamma * cos_gamma)


@dataclass(frozen=True)
class Preetham:
    """The model's state for one sun and turbidity: the sun's unit direction, the zenith's
    (Y, x, y) divided by each channel's Perez value at the zenith, and the Perez coefficients
    (rows Y, x, y)."""
    sun: tuple[float, float, float]
    zenith: tuple[float, float, float]        # (Y, x, y) at the zenith
    scale: tuple[float, float, float]         # zenith / F(0, theta_s), per channel
    coefficients: tuple[tuple[float, ...], ...]

    @staticmethod
    def make(sun_direction, turbidity: float) -> Preetham:
        s = np.asarray(sun_direction, float)
        n = float(np.linalg.norm(s))
        s = s / n if n > 0.0 and math.isfinite(n) else np.array([0.0, 0.0, 1.0])
        theta = math.acos(min(1.0, max(-1.0, float(s[2]))))
        t = float(turbidity)
        chi = (4.0 / 9.0 - t / 120.0) * (math.pi - 2.0 * theta)
        luminance = 0.06 * ((4.0453 * t - 4.9710) * math.tan(chi) - 0.2155 * t + 2.4192)
        th = np.array([theta ** 3, theta ** 2, theta, 1.0])
        # The zenith chromaticity: rows are the T^2, T and 1 factors of the theta polynomial.
        zx = np.array([[0.00166, -0.00375, 0.00209, 0.0],
                       [-0.02903, 0.06377, -0.03202, 0.00394],
                       [0.11693, -0.21196, 0.06052, 0.25886]])
        zy = np.array([[0.00275, -0.00610, 0.00317, 0.0],
                       [-0.04214, 0.08970, -0.04153, 0.00516],
                       [0.15346, -0.26756, 0.06670, 0.26688]])
        tt = np.array([t * t, t, 1.0])
        zenith = (luminance, float(tt @ zx @ th), float(tt @ zy @ th))
        # Perez coefficients (A..E) = slope * T + offset, for Y, x and y.
        slope = np.array([[0.1787, -0.3554, -0.0227, 0.1206, -0.0670],
                          [-0.0193, -0.0665, -0.0004, -0.0641, -0.0033],
                          [-0.0167, -0.0950, -0.0079, -0.0441, -0.0109]])
        offset = np.array([[-1.4630, 0.4275, 5.3251, -2.5771, 0.3703],
                           [-0.2592, 0.0008, 0.2125, -0.8989, 0.0452],
                           [-0.2608, 0.0092, 0.2102, -1.6537, 0.0529]])
        coefficients = slope * t + offset
        scale = tuple(z / float(perez(c, 1.0, theta)) for z, c in zip(zenith, coefficients))
        return Preetham(tuple(float(v) for v in s), zenith, scale,
                        tuple(tuple(float(v) for v in row) for row in coefficients))

    def xyY(self, directions: np.ndarray) -> np.ndarray:
        """(..., 3) unit directions -> (..., 3) as (Y, x, y)."""
        d = np.asarray(directions, float)
        gamma = np.arccos(np.clip(d @ np.array(self.sun), -1.0, 1.0))
        cos_theta = np.cos(np.minimum(np.arccos(np.clip(d[..., 2], -1.0, 1.0)), HORIZON_THETA))
        return np.stack([k * perez(c, cos_theta, gamma) for k, c in zip(self.scale, self.coefficients)], -1)

    def radiance(self, directions: np.ndarray) -> np.ndarray:
        """(..., 3) unit directions -> (..., 3) linear Rec.709 radiance."""
        return xyY_to_rec709(self.xyY(directions))


def xyY_to_rec709(yxy: np.ndarray) -> np.ndarray:
    """(Y, x, y) -> linear Rec.709, clamped at 0 (y = 0 leaves X = Z = 0, as Cycles' conversion)."""
    big_y, x, y = yxy[..., 0], yxy[..., 1], yxy[..., 2]
    safe = np.where(y != 0.0, y, 1.0)
    X = np.where(y != 0.0, x / safe * big_y, 0.0)
    Z = np.where((y != 0.0) & (big_y != 0.0), (1.0 - x - y) / safe * big_y, 0.0)
    return np.maximum(np.stack([X, big_y, Z], -1) @ XYZ_TO_REC709.T, 0.0)


def texel_directions(width: int, height: int) -> np.ndarray:
    """(height, width, 3) unit directions of an equirectangular map's texel centres, rows from
    the bottom, in the core's convention (native/scene/environment.h): u = 0.5 - atan2(y, x) /
    (2 pi), v = 0.5 + elevation / pi."""
    phi = (0.5 - (np.arange(width) + 0.5) / width) * 2.0 * math.pi
    elevation = ((np.arange(height) + 0.5) / height - 0.5) * math.pi
    el, ph = np.meshgrid(elevation, phi, indexing="ij")
    return np.stack([np.cos(el) * np.cos(ph), np.cos(el) * np.sin(ph), np.sin(el)], -1)


def bake(radiance, width: int, height: int) -> np.ndarray:
    """(height, width, 3) float32 map of `radiance` ((..., 3) directions -> (..., 3) RGB) at the
    texel centres, non-finite values as 0."""
    rgb = radiance(texel_directions(width, height))
    return np.nan_to_num(rgb, nan=0.0, posinf=0.0, neginf=0.0).astype(np.float32)
