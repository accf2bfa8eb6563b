# The seed's Cornell box (scenes/cornell_demo.py, `make demo`'s scene) for the benchmark, with its
# features switchable one at a time for the economy chart (docs/results.md, section 4):
#   build()                               the seed's final scene: glass sphere, checker floor,
#                                         an area light and two coloured point lights
#   build(glass=False)                    the same with a white diffuse sphere (no refraction:
#                                         what Mitsuba's `direct` integrator can render too)
#   build(texture=False, glass=None, point_lights=0)   the economy chart's bare box
#   world="constant" or "map", sun=True, emitter=True    the lights issue's additions, one at a
#                                         time: a grey world, the hdri scene's sky map instead, a
#                                         sun through the open side, a glowing panel on the back wall
import sys
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit and the seed's scene
sys.path.insert(0, str(Path(__file__).resolve().parent))  # the hdri scene's sky
import cornell_demo  # noqa: E402
import kit  # noqa: E402


def build(glass=True, texture=True, point_lights=2, extra_lights=0, instances=0, world=None, sun=False,
          emitter=False):
    """glass: True (the seed's glass sphere), False (a diffuse sphere), None (no sphere). world: None
    (black), "constant" (grey) or "map" (the hdri scene's sky, importance-sampled)."""
    # The seed's scene, unchanged, then edited: its script is the one source of truth.
    scene = cornell_demo.build()
    objects = bpy.data.objects
    # Camera-visible, as Cycles' default light (bpy.data.objects.new leaves it hidden in 3.4):
    # Mitsuba can hide emitters only all at once, so every renderer sees the light here.
    objects["area"].visible_camera = True
    white = bpy.data.materials["white"]
    if not texture:
        objects["floor"].data.materials[0] = white
    sphere = next(o for o in objects if o.type == "MESH" and o.name.startswith("Sphere"))
    if glass is None:
        bpy.data.objects.remove(sphere, do_unlink=True)
    elif not glass:
        sphere.data.materials[0] = white
    for name in ("warm", "cool")[point_lights:]:
        bpy.data.objects.remove(objects[name], do_unlink=True)
    # More lights: a ring of dim coloured point lights under the ceiling.
    for i in range(extra_lights):
        a = 2 * np.pi * i / max(extra_lights, 1)
        kit.point_light(f"extra{i}", (0.8 * np.cos(a), 0.8 * np.sin(a) - 0.1, 1.75), 60.0 / extra_lights,
                        color=(0.5 + 0.5 * np.cos(a), 0.5 + 0.5 * np.sin(a), 0.7))
    # Instances: small cubes sharing one mesh, in a grid on the floor in front of the sphere.
    if instances:
        n = int(round(instances ** 0.5))
        proto = kit.box("pebble", 0.06, (0, 0, -10), white)
        proto.hide_render = True  # only its instances are in the picture
        for k in range(instances):
            obj = kit.link(bpy.data.objects.new(f"pebble{k}", proto.data))
            obj.location = (-0.85 + 1.7 * (k % n) / max(n - 1, 1), -0.85 + 0.6 * (k // n) / max(n - 1, 1), 0.03)
            obj.rotation_euler = (0, 0, 0.7 * k)
    if world == "constant":
        kit.world((0.2, 0.22, 0.25))
    elif world == "map":
        from hdri import sky
        kit.environment_world(sky(), 0.2)
    if sun:
        kit.sun_light("sun", 2.0, (0.3, 0.8, -0.5), angle=0.02)  # in through the open side
    if emitter:
        panel = kit.plane("glow", 0.3, kit.emission("glow", (1.0, 0.8, 0.6), 15.0), (0.5, 0.98, 1.4))
        panel.rotation_euler = (-np.pi / 2, 0.0, 0.0)  # on the back wall, facing the camera
    return scene


if __name__ == "__main__":
    kit.main(build)
