# Many instances: 1,024 objects sharing one 2,000-triangle mesh (linked duplicates, which Blender's
# depsgraph and TOYRT's exporter both turn into instances of one stored mesh) on a floor, under an
# area light and a point light.
import sys
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
import kit  # noqa: E402

GRID = 32  # GRID x GRID instances


def build():
    scene = kit.clear_scene()
    grey = kit.diffuse("grey", (0.75, 0.75, 0.75))
    teal = kit.diffuse("teal", (0.1, 0.55, 0.5))
    kit.plane("floor", 12.0, grey)
    v, f = kit.uv_sphere_arrays(21, 50, radius=0.12, bumps=0.15, bump_freq=6, triangles=True)
    proto = kit.mesh_object("blob", v, f, teal, location=(0, 0, -5))
    proto.hide_render = True
    rng = np.random.default_rng(6)
    for k in range(GRID * GRID):
        obj = kit.link(bpy.data.objects.new(f"blob{k}", proto.data))
        x, y = (k % GRID - GRID / 2 + 0.5) * 0.3, (k // GRID - GRID / 2 + 0.5) * 0.3
        obj.location = (x, y, 0.12 + 0.1 * rng.random())
        obj.rotation_euler = tuple(rng.random(3) * 3.0)
        obj.scale = (1.0, 1.0, 0.6 + 0.8 * rng.random())
    kit.area_light("key", (0.0, -2.0, 4.0), 300.0, 2.0, 1.0, rotation=(0.4, 0, 0), visible_camera=True)
    kit.point_light("rim", (3.0, 3.0, 2.0), 200.0, color=(1.0, 0.8, 0.6))
    kit.camera((0.0, -6.5, 4.0), (0, 0, 0), lens=35)
    return scene


if __name__ == "__main__":
    kit.main(build)
