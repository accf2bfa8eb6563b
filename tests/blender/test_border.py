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
import shutil
import sys
import tempfile
import traceback

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # for harness (see there)
from harness import RESULTS, check, finish  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-border-")
W, H = 64, 48
BORDER = (0.25, 0.75, 0.25, 0.5)            # min x, max x, min y, max y
X0, X1, Y0, Y1 = 16, 48, 12, 24             # the same in pixels (rows from the bottom)


def build_scene():
    scene = bpy.context.scene
    bpy.data.batch_remove(list(bpy.data.objects))
    scene.world = None
    mat = bpy.data.materials.new("white")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    mat.node_tree.links.new(bsdf.outputs[0], out.inputs["Surface"])
    bpy.ops.mesh.primitive_plane_add(size=20)
    bpy.context.object.data.materials.append(mat)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.3, 0.2, 0.5))
    bpy.context.object.data.materials.append(mat)
    light = bpy.data.lights.new("lamp", "POINT")
    light.energy, light.shadow_soft_size = 400.0, 0.5      # a soft shadow: noise that must match too
    lamp = bpy.data.objects.new("lamp", light)
    lamp.location = (2.0, -1.0, 4.0)
    scene.collection.objects.link(lamp)
    cam = bpy.data.cameras.new("cam")
    cam.type, cam.ortho_scale = "ORTHO", 6.0
    co = bpy.data.objects.new("cam", cam)
    co.location = (0, 0, 10)
    scene.collection.objects.link(co)
    scene.camera = co
    r = scene.render
    r.engine = "TOYRT"
    r.resolution_x, r.resolution_y, r.resolution_percentage = W, H, 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = BORDER
    r.film_transparent = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGBA"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.toyrt.samples = 8
    scene.toyrt.seed = 3
    return scene


def render(scene, name, use_border, crop):
    scene.render.use_border = use_border
    scene.render.use_crop_to_border = crop
    path = os.path.join(TMP, name + ".exr")
    scene.render.filepath = path
    result = bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size[:]
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(img)
    return result, px.reshape(h, w, 4)                     # rows from the bottom


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
        check(diff <= 1e-6, f"border with crop: the same pixels as the full render's region (max difference {diff:.2e})")
    scene.render.use_border = False


try:
    main()
except Exception:
    traceback.print_exc()
    RESULTS.append(False)
shutil.rmtree(TMP, ignore_errors=True)
finish("border")
