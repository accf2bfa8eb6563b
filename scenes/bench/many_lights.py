# Many lights: 64 coloured point lights and 4 small area lights over a floor with a grid of boxes,
# where a shadow ray to every light is the expensive way and picking one light per hit
# (light_sampling="one") the cheap, noisier one.
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

POINTS, AREAS = 64, 4


def build():
    common.clear()
    grey = common.diffuse("grey", (0.75, 0.75, 0.75))
    common.plane("floor", 10.0, (0, 0, 0), grey)
    rng = common.np.random.default_rng(64)
    for k in range(36):
        x, y = (k % 6 - 2.5) * 1.2, (k // 6 - 2.5) * 1.2
        h = 0.2 + 0.8 * rng.random()
        common.box(f"box{k}", (0.5, 0.5, h), (x, y, h / 2), grey, rotation_z=rng.random())
    for k in range(POINTS):
        x, y = rng.uniform(-4, 4, 2)
        color = tuple(0.3 + 0.7 * rng.random(3))
        # At least 0.6 m above the tallest box: lights grazing a surface make fireflies that no
        # renderer's reference converges in minutes.
        common.point_light(f"p{k}", (x, y, 1.6 + 1.0 * rng.random()), 10.0 + 30.0 * rng.random(), color=color)
    for k in range(AREAS):
        common.area_light(f"a{k}", ((k % 2 - 0.5) * 5, (k // 2 - 0.5) * 5, 3.0), 0.5, 0.5, 80.0)
    common.world(None)
    common.camera((0.0, -8.0, 6.0), (0, 0, 0), lens=30)
    return common.finish()


if __name__ == "__main__":
    common.main(build)
