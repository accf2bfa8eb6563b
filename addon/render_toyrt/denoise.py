"""Denoising of the final render by Intel Open Image Denoise, through the pyoidn binding (PyPI, MIT),
with the Diffuse Color and Normal passes as its auxiliary images, as Cycles feeds OIDN its
denoising albedo and normal. Where Blender's Python has no pyoidn of its own (Debian's Blender 3.4
runs the system Python, blender.org's 3.4-4.1 their own), the legacy add-on and `make setup` carry
it in vendor/ beside this file (scripts/vendor-pyoidn.py); the extension installs it from its
wheels. pyoidn is optional: without it the render is returned as it is and the caller notes it."""
from __future__ import annotations

import functools
import os
import sys

import numpy as np

VENDOR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "vendor")

# The core passes the denoiser reads beside the image.
AUXILIARIES = ("diffuse_color", "normal")


@functools.cache
def available() -> str | None:
    """None when the denoiser loads, else why it does not (for the one note). Asked once per
    session: the viewport asks at every draw, and a failed import would search the path each time."""
    # First on the path: the vendored cffi must meet its own compiled half, not a system's
    # (Debian has python3-cffi-backend 1.15 without the cffi package).
    if os.path.isdir(VENDOR) and VENDOR not in sys.path:
        sys.path.insert(0, VENDOR)
    # No thread pinning: OIDN's CPU device pins its threads through TBB's tbbbind, which inside
    # Debian's Blender 3.4 (its system TBB and hwloc loaded first) aborts the whole process
    # ("double free or corruption", at the device's commit; fine in a plain Python). Pinning only
    # pays on many-socket machines; the variable is read when the device is made, and a user's own
    # setting is kept.
    os.environ.setdefault("OIDN_SET_AFFINITY", "0")
    try:
        import pyoidn  # noqa: F401
    except Exception as err:  # ImportError, or its bundled library failing to load
        return f"denoising skipped: Open Image Denoise (the pyoidn package) is not available here ({err})"
    return None


def albedo(diffuse_color: np.ndarray) -> np.ndarray:
    """The denoiser's albedo from the core's Diffuse Color: within [0, 1], as OIDN asks."""
    return np.ascontiguousarray(np.clip(diffuse_color, 0.0, 1.0), np.float32)


def denoise(image: np.ndarray, passes: dict) -> np.ndarray:
    """The (h, w, 4) linear RGBA `image` with its RGB denoised (HDR: scene-linear values) using the
    core's `passes` (render(passes=AUXILIARIES)) as albedo and normal; alpha kept."""
    import pyoidn

    rgb = np.ascontiguousarray(image[..., :3], np.float32)
    normal = np.ascontiguousarray(passes["normal"], np.float32)
    out = image.copy()
    out[..., :3] = pyoidn.denoise(rgb, albedo(passes["diffuse_color"]), normal, hdr=True)
    return out
