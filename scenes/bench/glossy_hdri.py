# Glossy reflections of an HDRI sky and an emissive panel (issue 13's lights at issue 14's glossy
# vertices): the glossy scene's balls, from nearly sharp Principled to a rough Glossy BSDF, in the
# hdri scene's sky with its small bright sun, beside a small Emission panel and no lamp. What each
# glossy vertex finds by sampling the map and the panel beside its lobe (docs/lights.md, "Emitters
# and the map at glossy and rough glass vertices").
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
sys.path.insert(0, str(Path(__file__).resolve().parent))  # the glossy scene's balls, the hdri scene's sky
import kit  # noqa: E402
from glossy import ball_row  # noqa: E402
from hdri import sky  # noqa: E402


def build():
    scene = kit.clear_scene()
    ball_row(glossy_roughness=0.4)
    panel = kit.plane("panel", 0.6, kit.emission("glow", (1.0, 0.9, 0.7), 20.0), (1.2, -1.2, 1.6))
    panel.rotation_euler = (2.4, 0.0, 0.4)
    kit.environment_world(sky(), 1.0, (0.0, 0.0, 0.4))
    return scene


if __name__ == "__main__":
    kit.main(build)
