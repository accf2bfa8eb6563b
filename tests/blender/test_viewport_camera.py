# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_viewport_camera.py
# (`make test` runs it). viewport.view_camera reads a 3D view's camera back from its projection
# matrix; here it is given the projection Blender computes for a camera object
# (Object.calc_matrix_camera, the matrix the viewport's camera view uses) and its view matrix, and
# the image it renders must be the image of the camera itself (camera.export_camera): perspective
# with lens shift, horizontal and vertical sensor fit, and orthographic. Known answer: the same
# picture, to float rounding of the recovered parameters.
import os
import sys
import types

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, run_script  # noqa: E402


def main():
    import render_toyrt
    from render_toyrt import sync, viewport
    from render_toyrt.camera import export_camera

    toyrt = render_toyrt.native()
    scene = kit.clear_scene()
    kit.toyrt(scene)
    for x in (-2, 0, 2):
        kit.box(f"cube{x}", 0.8, (x, x * 0.5, 0.4))
    kit.plane("floor", 10.0)
    kit.point_light("lamp", (1, -2, 4), 400.0, radius=0.25)    # Blender 3.4's default radius
    co = kit.camera((1, -7, 4), rotation=(1.05, 0, 0.15))
    cam = co.data
    scene.render.resolution_percentage = 100
    depsgraph = bpy.context.evaluated_depsgraph_get()
    cache = sync.SceneSync(toyrt)
    cache.sync(depsgraph)
    cache.commit()

    cases = [
        ("perspective", dict(type="PERSP", lens=35, shift_x=0.0, shift_y=0.0), (64, 48)),
        ("perspective with lens shift", dict(type="PERSP", lens=50, shift_x=0.1, shift_y=-0.05), (64, 48)),
        ("perspective, portrait", dict(type="PERSP", lens=28, shift_x=0.0, shift_y=0.1), (40, 60)),
        ("orthographic", dict(type="ORTHO", ortho_scale=9.0, shift_x=0.05, shift_y=0.0), (64, 48)),
    ]
    for label, settings, (w, h) in cases:
        for k, v in settings.items():
            setattr(cam, k, v)
        scene.render.resolution_x, scene.render.resolution_y = w, h
        depsgraph = bpy.context.evaluated_depsgraph_get()
        co_eval = co.evaluated_get(depsgraph)
        region = types.SimpleNamespace(width=w, height=h)
        rv3d = types.SimpleNamespace(
            window_matrix=co_eval.calc_matrix_camera(depsgraph, x=w, y=h),
            view_matrix=co_eval.matrix_world.inverted(), is_perspective=cam.type == "PERSP")
        from_view = viewport.view_camera(region, rv3d)
        from_camera = export_camera(depsgraph)
        a = cache.scene.render(from_view, samples=4)
        b = cache.scene.render(from_camera, samples=4)
        diff = np.abs(a - b)
        # A recovered parameter off by float rounding moves a sample by far less than a pixel:
        # only pixels on an edge may differ, and few of them.
        changed = (diff.max(axis=2) > 1e-3).mean()
        check(a.shape == b.shape and changed < 0.02,
              f"{label}: the view's camera renders the camera's picture ({100 * changed:.2f} % of pixels differ)")


run_script([main], "viewport camera")
