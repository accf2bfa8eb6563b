# A million triangles: a bumpy sphere (1,000 x 500 UV sphere, radius modulated so that it shadows
# itself) on a floor, under a rectangular area light (no world: Mitsuba cannot hide the light from
# the camera and show a world). What the BVH builders and the 1M-triangle render timings measure.
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
import kit  # noqa: E402

RINGS, SEGMENTS = 500, 1000  # 2 * SEGMENTS * (RINGS - 1) = 998,000 triangles, plus the floor


def build():
    scene = kit.clear_scene()
    grey = kit.diffuse("grey", (0.7, 0.7, 0.7))
    orange = kit.diffuse("orange", (0.8, 0.45, 0.15))
    kit.plane("floor", 8.0, grey)
    v, f = kit.uv_sphere_arrays(RINGS, SEGMENTS, radius=1.0, bumps=0.06, bump_freq=40, triangles=True)
    kit.mesh_object("bumpy", v, f, orange, location=(0, 0, 1.0))
    kit.area_light("key", (1.5, -1.0, 3.0), 150.0, 1.0, 0.6, rotation=(0.35, 0.45, 0), visible_camera=True)
    kit.camera((0.0, -4.5, 2.2), (0, 0, 0.9), lens=40)
    return scene


if __name__ == "__main__":
    kit.main(build)
