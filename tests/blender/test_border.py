# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_border.py
# (`make test` runs it, also under the bpy module: tests/blender/run_with_bpy.py).
#
# Render region (Blender's border) with TOYRT through F12's operator, against a full render of
# the same scene at the same seed:
#   1. border without crop (use_border on, use_crop_to_border off): the saved image has the full
#      resolution, the border's pixels are those of the full render, every pixel outside it is
#      zero (RGBA 0: Blender leaves what no engine wrote transparent black);
#   2. border with crop: the saved image is the border's size and holds the same pixels.
# The border is chosen on whole pixels (Blender: pixel x from border_min_x * width to
# border_max_x * width), so the expected window is known exactly.
import os
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-border-")
W, H = 64, 48
BORDER = (0.25, 0.75, 0.25, 0.5)            # min x, max x, min y, max y
X0, X1, Y0, Y1 = 16, 48, 12, 24             # the same in pixels (rows from the bottom)


def build_scene():
    scene = kit.clear_scene()
    white = kit.diffuse("white", (0.8, 0.8, 0.8))
    kit.plane("floor", 20.0, white)
    kit.box("cube", 1.0, (0.3, 0.2, 0.5), white)
    kit.point_light("lamp", (2.0, -1.0, 4.0), 400.0, radius=0.5)      # a soft shadow: noise that must match too
    kit.camera((0, 0, 10), ortho_scale=6.0)
    kit.output(scene, W, H)
    r = scene.render
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = BORDER
    kit.float_exr(scene)
    kit.toyrt(scene, samples=8, seed=3)
    return scene


def render(scene, name, use_border, crop):
    scene.render.use_border = use_border
    scene.render.use_crop_to_border = crop
    path = os.path.join(TMP, name + ".exr")
    result, _ = render_still(path)
    return result, kit.read_image(path)                    # rows from the bottom


def main():
    scene = build_scene()
    _, full = render(scene, "full", False, False)
    check(full.shape == (H, W, 4) and full[..., :3].mean() > 0.05, f"full render: {full.shape[1]}x{full.shape[0]}, lit")
    inside = full[Y0:Y1, X0:X1]

    result, region = render(scene, "border", True, False)
    check(result == {"FINISHED"} and region.shape == (H, W, 4),
          f"border without crop: the image keeps the full size ({region.shape[1]}x{region.shape[0]})")
    diff = float(np.abs(region[Y0:Y1, X0:X1] - inside).max())
    check(diff <= 1e-6 and inside[..., :3].std() > 0.01,
          f"border without crop: the {X1 - X0}x{Y1 - Y0} region equals the full render's pixels there "
          f"(max difference {diff:.2e})")
    outside = np.ones((H, W), bool)
    outside[Y0:Y1, X0:X1] = False
    check(not np.any(region[outside]), f"border without crop: all {int(outside.sum())} pixels outside the border "
          f"are 0 in RGBA (max {float(np.abs(region[outside]).max()):.2e})")

    result, cropped = render(scene, "crop", True, True)
    check(result == {"FINISHED"} and cropped.shape == (Y1 - Y0, X1 - X0, 4),
          f"border with crop: the image is the border's size ({cropped.shape[1]}x{cropped.shape[0]}, "
          f"expected {X1 - X0}x{Y1 - Y0})")
    if cropped.shape == inside.shape:
        diff = float(np.abs(cropped - inside).max())
        check(diff <= 1e-6,
              f"border with crop: the same pixels as the full render's region (max difference {diff:.2e})")
    scene.render.use_border = False


run_script([main], "border", TMP)
