"""Denoising of the final render by Intel Open Image Denoise, through the pyoidn binding (PyPI, MIT),
with the Diffuse Color and Normal passes as its auxiliary images, as Cycles feeds OIDN its
denoising albedo and normal. pyoidn is optional: where Blender's Python cannot import it (Debian's
Blender 3.4 runs the system Python), the render is returned as it is and the caller notes it."""
from __future__ import annotations

import numpy as np

# The core passes the denoiser reads beside the image.
AUXILIARIES = ("diffuse_color", "normal")


def available() -> str | None:
    """None when the denoiser loads, else why it does not (for the one note)."""
    try:
        import pyoidn  # noqa: F401
    except Exception as err:  # ImportError, or its bundled library failing to load
        return f"denoising skipped: Open Image Denoise (the pyoidn package) is not available here ({err})"
    return None


def denoise(image: np.ndarray, passes: dict) -> np.ndarray:
    """The (h, w, 4) linear RGBA `image` with its RGB denoised (HDR: scene-linear values) using the
    core's `passes` (render(passes=AUXILIARIES)) as albedo and normal; alpha kept."""
    import pyoidn

    rgb = np.ascontiguousarray(image[..., :3], np.float32)
    albedo = np.ascontiguousarray(np.clip(passes["diffuse_color"], 0.0, 1.0), np.float32)
    normal = np.ascontiguousarray(passes["normal"], np.float32)
    out = image.copy()
    out[..., :3] = pyoidn.denoise(rgb, albedo, normal, hdr=True)
    return out
