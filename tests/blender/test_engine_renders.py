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

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
import numpy as np  # noqa: E402
from closed_form import build_scene, expected_image, render_error  # noqa: E402  (closed_form imports the kit)
from harness import check, run_script  # noqa: E402


def main():
    # getattr: 4.x registers abstract engine bases (HydraRenderEngine) without a bl_idname.
    engines = {getattr(cls, "bl_idname", None) for cls in bpy.types.RenderEngine.__subclasses__()}
    check("TOYRT" in engines, "the TOYRT engine is registered")
    s = build_scene()
    check(hasattr(s, "toyrt") and s.toyrt.samples == 16, "settings live at scene.toyrt")
    err = render_error(os.path.join(tempfile.mkdtemp(), "f12.exr"))
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


def render_red(name):
    """F12's operator into an EXR still: the red channel, rows from the bottom."""
    path = os.path.join(tempfile.mkdtemp(), name + ".exr")
    bpy.context.scene.render.filepath = path
    bpy.context.scene.render.image_settings.file_format = "OPEN_EXR"
    bpy.ops.render.render(write_still=True)
    return kit.read_image(path)[..., 0]


def instanced_by_an_empty(obj, group_name, empty_name):
    """Moves `obj` into a new collection placed by a new empty (a collection instance); the empty."""
    group = bpy.data.collections.new(group_name)
    for coll in obj.users_collection:
        coll.objects.unlink(obj)
    group.objects.link(obj)
    empty = kit.link(bpy.data.objects.new(empty_name, None))
    empty.instance_type = "COLLECTION"
    empty.instance_collection = group
    return empty


def objects_without_shadows():
    """Object.visible_shadow off: a 0.2 m square 0.75 m above the plane, under the point light at
    1 m, shades a 0.8 m square of the plane, of which the camera sees all but the middle 0.2 m
    (the square itself). On that ring of pixels the render is black when the square casts shadows
    and the open plane's closed form when it does not, also when the square is instanced by an
    empty (a collection instance) whose own visible_shadow is off: Cycles' instances inherit it."""
    c = (np.arange(32) + 0.5) / 32 * 2.0 - 1.0
    x, y = np.meshgrid(c, c)
    ring = (np.maximum(abs(x), abs(y)) > 0.15) & (np.maximum(abs(x), abs(y)) < 0.35)

    def ring_of(name):
        return render_red(name)[ring]

    build_scene()
    blocker = kit.plane("blocker", 0.2, kit.diffuse("blocker_white", (1, 1, 1)), location=(0, 0, 0.75))
    lit = expected_image()[ring]
    dark = ring_of("casting")
    check(dark.max() < 1e-6 * lit.max(), f"casting shadows, the ring is black (max {dark.max():.3g})")
    blocker.visible_shadow = False
    bright = ring_of("not_casting")
    err = abs(bright - lit).max() / lit.max()
    check(err < 0.01, f"with visible_shadow off the ring is the open plane's I cos / r^2 (max error {err:.4f})")

    # The same square in a collection placed by an empty; the square casts shadows, the empty not.
    blocker.visible_shadow = True
    empty = instanced_by_an_empty(blocker, "shadowless_group", "instancer")
    empty.visible_shadow = False
    inherited = ring_of("instanced")
    err = abs(inherited - lit).max() / lit.max()
    check(err < 0.01, f"an instance of it under an empty without shadows casts none either (max error {err:.4f})")
    empty.visible_shadow = True
    dark = ring_of("instanced_casting")
    check(dark.max() < 1e-6 * lit.max(), f"the empty casting shadows, the ring is black again ({dark.max():.3g})")


def objects_hidden_from_the_camera():
    """Object.visible_camera off (Ray Visibility > Camera): the 0.2 m square 0.75 m above the plane,
    without shadows either, leaves the open plane's closed form in every pixel; casting shadows,
    the camera sees through it to its shadow (black in the middle); under an empty hidden from the
    camera an instance of it is hidden too (Cycles' instances inherit the instancer's visibility)."""
    build_scene()
    square = kit.plane("hidden", 0.2, kit.diffuse("hidden_white", (1, 1, 1)), location=(0, 0, 0.75))
    lit = expected_image()
    middle = np.s_[14:18, 14:18]
    seen = render_red("seen")
    check(seen[middle].min() > 0.0, "seen by the camera, the square is in the middle of the image")
    square.visible_camera = False
    square.visible_shadow = False
    err = abs(render_red("hidden") - lit).max() / lit.max()
    check(err < 0.01, f"hidden from the camera and casting no shadow: the open plane (max error {err:.4f})")
    square.visible_shadow = True
    through = render_red("hidden_casting")
    check(through[middle].max() < 1e-6 * lit.max(),
          f"the camera sees its shadow through it ({through[middle].max():.3g})")
    square.visible_camera = square.visible_shadow = True
    empty = instanced_by_an_empty(square, "hidden_group", "hidden_instancer")
    empty.visible_camera = False
    empty.visible_shadow = False
    err = abs(render_red("instanced_hidden") - lit).max() / lit.max()
    check(err < 0.01, f"an instance under an empty hidden from the camera is hidden too (max error {err:.4f})")


run_script([main, objects_without_shadows, objects_hidden_from_the_camera], "engine")
