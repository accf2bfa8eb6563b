# A room lit only by emissive meshes: a ceiling panel and a glowing sphere (Emission shaders,
# sampled as lights), a box and a floor; no lamp objects.
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
import kit  # noqa: E402


def build():
    scene = kit.clear_scene()
    white = kit.diffuse("white", (0.8, 0.8, 0.8))
    kit.plane("floor", 6.0, white)
    back = kit.plane("back", 6.0, white, (0.0, 3.0, 3.0))
    back.rotation_euler = (1.5708, 0.0, 0.0)
    panel = kit.plane("panel", 1.5, kit.emission("panel_glow", (1.0, 0.9, 0.75), 8.0), (0.0, 0.5, 2.8))
    panel.rotation_euler = (3.1416, 0.0, 0.0)  # facing down
    kit.uv_sphere("ball", 0.35, (1.2, -0.4, 0.35), kit.emission("ball_glow", (0.3, 0.6, 1.0), 4.0))
    kit.box("box", 0.8, (-0.8, 0.6, 0.4), kit.diffuse("red", (0.7, 0.2, 0.1)))
    kit.camera((0.0, -5.0, 2.2), (0, 0.5, 0.8), lens=30)
    kit.world((0.0, 0.0, 0.0))
    return scene


if __name__ == "__main__":
    kit.main(build)
