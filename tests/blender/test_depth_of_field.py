# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_depth_of_field.py
# (`make test` runs it, also under the bpy module: tests/blender/run_with_bpy.py).
#
# The camera's depth of field (camera.dof) as the add-on exports it, rendered through F12: a black
# half-plane's edge 4 m in front of the camera, against a white world. Each pixel's value is the
# share of the aperture that sees past the edge, so the edge's profile across the columns is the
# aperture's projection, whose variance the thin lens fixes (tests/python/test_depth_of_field.py
# derives it):
#   1. a focus object on the plane but far off the view axis: the edge is sharp (the focus distance
#      is the object's depth along the view axis, as Cycles takes it, not its distance); the same
#      with an armature whose origin is 1 m deep and whose bone, named by dof.focus_subtarget, has
#      its head on the plane (Cycles 3.4 and 5.0 focus on the bone: checked by rendering with them),
#      while the armature without the subtarget blurs the edge;
#   2. a focus distance of 2 m, round aperture: the spread's variance is r^2 / 4 with the blur
#      radius r = A |d - f| / (d f) * lens * width / sensor pixels, A = lens / (2 f-stop);
#   3. six blades: the hexagon's (1 + 2 cos^2(pi / 6)) r^2 / 12;
#   4. use_dof off: sharp again, whatever the other settings.
import math
import os
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import bpy  # noqa: E402
import kit  # noqa: E402
from harness import check, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-dof-")
W, H, LENS, SENSOR, DEPTH, FSTOP = 64, 16, 50.0, 36.0, 4.0, 0.1


def build_scene():
    scene = kit.clear_scene()
    black = kit.diffuse("black", (0.0, 0.0, 0.0))
    kit.mesh_object("edge", [(0, -50, -DEPTH), (50, -50, -DEPTH), (50, 50, -DEPTH), (0, 50, -DEPTH)],
                    [(0, 1, 2, 3)], black)
    kit.world((1.0, 1.0, 1.0))
    cam = kit.camera((0, 0, 0), lens=LENS)
    cam.data.sensor_width = SENSOR
    kit.output(scene, W, H)
    kit.float_exr(scene)
    kit.toyrt(scene, samples=256, seed=1)
    return scene, cam


def render(name):
    path = os.path.join(TMP, name + ".exr")
    result, _ = render_still(path)
    check(result == {"FINISHED"}, f"{name}: rendered ({result})")
    return kit.read_image(path)[..., 0]


def spread_variance(e):
    """The edge's line spread (per row: the profile's drop from column to column), its variance in
    pixels, less the 2 / 12 the pixels' box filter and the differencing add; and its total."""
    lsf = -np.diff(e.astype(np.float64), axis=1)
    m = np.arange(1, W, dtype=np.float64)
    total = lsf.sum(axis=1)
    mean = (lsf * m).sum(axis=1) / total
    var = (lsf * (m - mean[:, None]) ** 2).sum(axis=1) / total - 2.0 / 12.0
    return float(var.mean()), float(var.std(ddof=1) / math.sqrt(len(var))), float(total.mean())


def sharp(e):
    """The edge lies between columns 31 and 32: every other column is all background or all plane."""
    return float(max(np.abs(e[:, :31] - 1.0).max(), np.abs(e[:, 33:]).max()))


def main():
    scene, cam = build_scene()
    dof = cam.data.dof
    dof.use_dof, dof.aperture_fstop = True, FSTOP
    target = kit.link(bpy.data.objects.new("focus", None))
    target.location = (6.0, 2.0, -DEPTH)  # 7.5 m away, 4 m deep
    dof.focus_object = target
    err = sharp(render("focus_object"))
    check(err < 1e-5, f"focus object on the plane, off axis: the edge is sharp (max deviation {err:.1e})")

    rig = kit.link(bpy.data.objects.new("rig", bpy.data.armatures.new("rig")))
    rig.location = (6.0, 2.0, -1.0)  # 1 m deep
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    bone = rig.data.edit_bones.new("aim")
    bone.head, bone.tail = (0.0, 0.0, -(DEPTH - 1.0)), (0.0, 0.5, -(DEPTH - 1.0))  # its head on the plane
    bpy.ops.object.mode_set(mode="OBJECT")
    dof.focus_object, dof.focus_subtarget = rig, "aim"
    err = sharp(render("focus_bone"))
    check(err < 1e-5,
          f"focus_subtarget: a bone's head on the plane, its armature 1 m deep: sharp (max deviation {err:.1e})")
    dof.focus_subtarget = ""
    err = sharp(render("focus_armature"))
    check(err > 0.1, f"the same armature without focus_subtarget focuses 1 m deep: blurred (max deviation {err:.2f})")

    dof.focus_object = None
    dof.focus_distance = 2.0
    radius = LENS * 1e-3 / (2 * FSTOP) * abs(DEPTH - 2.0) / (DEPTH * 2.0) * LENS / SENSOR * W
    for blades, second_moment in [(0, 0.25), (6, (1 + 2 * math.cos(math.pi / 6) ** 2) / 12)]:
        dof.aperture_blades, dof.aperture_rotation = blades, 0.3
        var, se, total = spread_variance(render(f"blades{blades}"))
        expected = radius**2 * second_moment
        # Rows are independent estimates: four standard errors, plus 1 % for whole-pixel sampling.
        check(abs(var - expected) < 4 * se + 0.01 * expected and abs(total - 1.0) < 1e-5,
              f"focus distance 2 m, {blades} blades: the edge spreads with variance {var:.3f} px^2, "
              f"the thin lens's {expected:.3f} (radius {radius:.2f} px; standard error {se:.3f})")

    dof.use_dof = False
    err = sharp(render("off"))
    check(err < 1e-5, f"use_dof off: the edge is sharp (max deviation {err:.1e})")


run_script([main], "depth of field", TMP)
