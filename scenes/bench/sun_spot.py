# An exterior-style scene lit by a sun with a soft disc and a spot: a floor, a few boxes and a
# column, the sun low enough to cast long soft shadows, the spot's cone across them.
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
import kit  # noqa: E402


def build():
    scene = kit.clear_scene()
    grey = kit.diffuse("grey", (0.7, 0.7, 0.7))
    kit.plane("floor", 12.0, grey)
    for k, (x, y, h) in enumerate([(-1.5, 0.5, 1.0), (0.5, -0.5, 0.6), (1.8, 1.2, 1.6), (-0.3, 1.8, 0.4)]):
        kit.box(f"box{k}", (0.6, 0.6, h), (x, y, h / 2), kit.diffuse(f"c{k}", (0.8, 0.3 + 0.15 * k, 0.2)))
    kit.sun_light("sun", 3.0, (-0.6, 0.4, -0.5), angle=0.1)
    kit.spot_light("spot", (2.5, -2.5, 3.0), 800.0, 0.7, 0.2, radius=0.1, target=(0.0, 0.5, 0.0))
    kit.camera((0.0, -7.0, 4.5), (0, 0.3, 0.3), lens=35)
    kit.world((0.0, 0.0, 0.0))
    return scene


if __name__ == "__main__":
    kit.main(build)
