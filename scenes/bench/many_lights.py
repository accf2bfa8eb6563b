# Many lights: 64 coloured point lights and 4 small area lights over a floor with a grid of boxes,
# where a shadow ray to every light is the expensive way and picking one light per hit
# (light_sampling="one") the cheap, noisier one.
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
import kit  # noqa: E402

POINTS, AREAS = 64, 4


def build():
    scene = kit.clear_scene()
    grey = kit.diffuse("grey", (0.75, 0.75, 0.75))
    kit.plane("floor", 10.0, grey)
    rng = np.random.default_rng(64)
    for k in range(36):
        x, y = (k % 6 - 2.5) * 1.2, (k // 6 - 2.5) * 1.2
        h = 0.2 + 0.8 * rng.random()
        kit.box(f"box{k}", (0.5, 0.5, h), (x, y, h / 2), grey, rotation_z=rng.random())
    for k in range(POINTS):
        x, y = rng.uniform(-4, 4, 2)
        color = tuple(0.3 + 0.7 * rng.random(3))
        # At least 0.6 m above the tallest box: lights grazing a surface make fireflies that no
        # renderer's reference converges in minutes.
        kit.point_light(f"p{k}", (x, y, 1.6 + 1.0 * rng.random()), 10.0 + 30.0 * rng.random(), color=color)
    for k in range(AREAS):
        kit.area_light(f"a{k}", ((k % 2 - 0.5) * 5, (k // 2 - 0.5) * 5, 3.0), 80.0, 0.5, 0.5, visible_camera=True)
    kit.camera((0.0, -8.0, 6.0), (0, 0, 0), lens=30)
    return scene


if __name__ == "__main__":
    kit.main(build)
