"""The scene with a known answer that the engine test (test_engine_renders.py) and the install
tests (tests/package/) render: a white Diffuse plane under a point light, whose image is the closed
form albedo/pi * P/(4 pi) * cos / r^2 in Blender's units. Not a test itself (no test_ prefix).
Needs the scene kit on sys.path (see harness)."""
import kit
import numpy as np


def build_scene(with_camera=True):
    """A white Diffuse plane 10 m wide, a 100 W point light 1 m above its centre, and (with_camera)
    an orthographic camera seeing the middle 2 m from above, 32 x 32 pixels."""
    s = kit.clear_scene()
    kit.plane("plane", 10.0, kit.diffuse("white_diffuse", (1, 1, 1)))
    kit.point_light("point", (0, 0, 1), 100.0)
    if with_camera:
        kit.camera((0, 0, 5), ortho_scale=2.0)
    else:
        s.camera = None
    kit.output(s, 32, 32)
    kit.toyrt(s, samples=16)
    return s


def expected_image(n=32, size=2.0, power=100.0, height=1.0, sub=8):
    """Pixel averages of albedo/pi * P/(4 pi) * cos / r^2 (rows from the bottom, as Blender)."""
    c = (np.arange(n * sub) + 0.5) / (n * sub) * size - size / 2
    x, y = np.meshgrid(c, c)
    r2 = x * x + y * y + height * height
    v = 1 / np.pi * power / (4 * np.pi) * (height / np.sqrt(r2)) / r2
    return v.reshape(n, sub, n, sub).mean(axis=(1, 3))


def render_error(path):
    """Renders the current scene with F12's operator to the OpenEXR file `path` and returns the
    largest deviation of its red channel from expected_image(), as a fraction of the peak."""
    import bpy

    s = bpy.context.scene
    s.render.filepath = str(path)
    s.render.image_settings.file_format = "OPEN_EXR"
    bpy.ops.render.render(write_still=True)
    px = kit.read_image(path)
    return np.abs(px[..., 0] - expected_image()).max() / expected_image().max()


def denoiser_lowers_noise(addon_module: str):
    """(ok, where pyoidn was imported from, noise before / after) for the installed add-on's denoiser:
    Open Image Denoise, as the add-on loads it (its vendor/ folder or the extension's wheels), takes a
    flat grey image with Gaussian noise of 0.2 to well under a quarter of that noise."""
    import importlib

    denoise = importlib.import_module(f"{addon_module}.denoise")
    why = denoise.available()
    if why is not None:
        return False, why, (0.0, 0.0)
    import pyoidn

    rng = np.random.default_rng(7)
    noisy = (0.5 + 0.2 * rng.standard_normal((64, 64, 3))).astype(np.float32)
    out = pyoidn.denoise(noisy, hdr=True)
    before, after = float(np.std(noisy - 0.5)), float(np.std(out - 0.5))
    return after < 0.25 * before, pyoidn.__file__, (before, after)
