# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_engine_renders.py
# The TOYRT engine end to end, as a user meets it: a bpy-built scene rendered with F12's operator
# and from the command line (`blender -b file.blend -E TOYRT -f 1`), checked against the closed
# form of a point light over a white Diffuse plane in Blender's units; a render error must fail
# the command (non-zero exit, no image), as a render farm needs.
import os
import subprocess
import sys
import tempfile

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, run_script  # noqa: E402


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


def main():
    # getattr: 4.x registers abstract engine bases (HydraRenderEngine) without a bl_idname.
    engines = {getattr(cls, "bl_idname", None) for cls in bpy.types.RenderEngine.__subclasses__()}
    check("TOYRT" in engines, "the TOYRT engine is registered")
    s = build_scene()
    check(hasattr(s, "toyrt") and s.toyrt.samples == 16, "settings live at scene.toyrt")
    out = os.path.join(tempfile.mkdtemp(), "f12.exr")
    s.render.filepath = out
    s.render.image_settings.file_format = "OPEN_EXR"
    bpy.ops.render.render(write_still=True)
    px = kit.read_image(out)
    err = np.abs(px[..., 0] - expected_image()).max() / expected_image().max()
    check(err < 0.01, f"F12 render matches I cos / r^2 in Blender's units (max error {err:.4f} of the peak)")

    # The command line a farm runs, on a saved file. The bpy module from PyPI has no blender
    # executable (tests/blender/run_with_bpy.py sets TOYRT_NO_BLENDER_BINARY).
    if os.environ.get("TOYRT_NO_BLENDER_BINARY") or not bpy.app.binary_path:
        print("  skipped: the command-line checks (bpy module: no blender executable of this version)", flush=True)
        return
    blend = os.path.join(tempfile.mkdtemp(), "scene.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    frame_out = os.path.join(os.path.dirname(blend), "frame_")
    run = subprocess.run([bpy.app.binary_path, "-b", blend, "-E", "TOYRT", "-o", frame_out, "-F", "PNG", "-f", "1"],
                         capture_output=True, text=True)
    check(run.returncode == 0 and os.path.exists(frame_out + "0001.png"),
          "blender -b file.blend -E TOYRT -f 1 writes the frame")

    # A render error (no camera) fails the command and writes nothing.
    build_scene(with_camera=False)
    bad = os.path.join(tempfile.mkdtemp(), "nocam.blend")
    bpy.ops.wm.save_as_mainfile(filepath=bad)
    bad_out = os.path.join(os.path.dirname(bad), "frame_")
    run = subprocess.run([bpy.app.binary_path, "-b", bad, "-E", "TOYRT", "-o", bad_out, "-F", "PNG", "-f", "1"],
                         capture_output=True, text=True)
    check(run.returncode != 0 and not os.path.exists(bad_out + "0001.png"),
          f"a scene without a camera fails the frame (exit {run.returncode}) and saves no image")
    check("camera" in (run.stdout + run.stderr).lower(), "the error says what is wrong")


run_script([main], "engine")
