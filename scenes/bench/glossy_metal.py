# Glossy reflections with nothing diffuse (issue 14's scene against Mitsuba 3 as well as Cycles):
# a row of Glossy BSDF balls from nearly sharp to rough (GGX roughness 0.05 to 0.6), some tinted
# like metals, on a Glossy floor of roughness 0.3, lit by an area lamp and a constant world. With
# no diffuse surface, TOYRT's transport (direct light at every vertex, the path continuing through
# the glossy lobe up to depth 8) is plain path tracing to that depth, which Cycles (glossy bounces 8,
# scenes/cycles_like_toyrt.py) and Mitsuba's `path` integrator (max_depth 10) compute as well; the
# glossy and glossy_hdri scenes have a diffuse floor, whose paths end at it in TOYRT and Cycles but
# not in any Mitsuba integrator. The lamp is out of the camera's view, but made visible to camera
# rays: Mitsuba can hide either every emitter from the camera or none, and the world is in view.
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
import kit  # noqa: E402

# (name, colour, roughness): silver, gold, copper, a white, a blue-tinted and a grey Glossy BSDF.
BALLS = [
    ("silver", (0.95, 0.93, 0.88), 0.05),
    ("gold", (1.0, 0.78, 0.34), 0.1),
    ("copper", (0.95, 0.64, 0.54), 0.2),
    ("white", (0.8, 0.8, 0.8), 0.3),
    ("blue", (0.45, 0.55, 0.85), 0.45),
    ("grey", (0.7, 0.7, 0.7), 0.6),
]


def build():
    scene = kit.clear_scene()
    kit.plane("floor", 12.0, kit.glossy("floor", (0.6, 0.6, 0.6), 0.3))
    for k, (name, color, roughness) in enumerate(BALLS):
        kit.uv_sphere(f"ball{k}", 0.42, (-2.25 + 0.9 * k, 0.0, 0.42), kit.glossy(name, color, roughness))
    kit.camera((0.0, -5.0, 2.0), (0.0, 0.0, 0.35), lens=32)
    kit.area_light("panel", (1.5, -2.0, 3.0), 400.0, 3.0, 2.0, target=(0.0, 0.0, 0.0), visible_camera=True)
    kit.world((0.2, 0.2, 0.24))
    return scene


if __name__ == "__main__":
    kit.main(build)
