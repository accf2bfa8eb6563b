# Glossy reflections (issue 14's error-against-time scene): a row of Principled balls from nearly
# sharp to rough, a gold metal and a Glossy BSDF ball on a checker-free floor, lit by an area lamp
# and a dim world. Their highlights and the floor and neighbours seen in them are what low
# roughness makes noisy: lamps by next-event estimation with MIS against the lobe, paths
# continuing through the glossy lobes (depth 8), diffuse hits ending after their direct light.
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
import kit  # noqa: E402


def ball_row(glossy_roughness=0.1):
    """The floor, the six balls and the camera (glossy_hdri.py lights the same row its own way)."""
    kit.plane("floor", 12.0, kit.diffuse("floor", (0.6, 0.6, 0.6)))
    balls = [kit.principled_dielectric(f"principled{k}", (0.8, 0.25 + 0.12 * k, 0.15), r)
             for k, r in enumerate((0.05, 0.15, 0.3, 0.5))]
    balls.append(kit.metal("gold", (0.95, 0.7, 0.3), 0.2))
    balls.append(kit.glossy("glossy", (0.8, 0.8, 0.8), glossy_roughness))
    for k, mat in enumerate(balls):
        kit.uv_sphere(f"ball{k}", 0.42, (-2.25 + 0.9 * k, 0.0, 0.42), mat)
    kit.camera((0.0, -5.0, 2.0), (0.0, 0.0, 0.35), lens=32)


def build():
    scene = kit.clear_scene()
    ball_row()
    kit.area_light("panel", (1.5, -2.0, 3.0), 250.0, 2.0, 1.0, target=(0.0, 0.0, 0.0))
    kit.world((0.08, 0.08, 0.1))
    return scene


if __name__ == "__main__":
    kit.main(build)
