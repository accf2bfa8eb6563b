# The seed report's final scene, built with bpy: a Cornell box (red and green walls), a glass
# sphere on a checker-textured floor, a rectangular area light under the ceiling and two coloured
# point lights. Run by `make demo`:
#   blender -b --python scenes/cornell_demo.py -- OUTPUT.blend
# It saves the .blend; the Makefile then renders it with `blender -b OUTPUT.blend -E TOYRT -f 1`.
# scenes/bench/cornell.py builds the benchmark's Cornell box from it.
import math
import sys
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))  # the scene kit
import kit  # noqa: E402


def checker_image(size=64, cells=8):
    y, x = np.mgrid[:size, :size] * cells // size
    on = ((x + y) % 2 == 1)[..., None]
    return kit.image("checker", np.where(on, [0.9, 0.9, 0.9, 1.0], [0.15, 0.15, 0.2, 1.0]))


def wall(name, location, rotation, material, uv_repeat=1.0):
    obj = kit.plane(name, 2.0, material, location, uv_repeat=uv_repeat)
    obj.rotation_euler = rotation
    return obj


def build():
    scene = kit.clear_scene()
    white = kit.diffuse("white", (0.8, 0.8, 0.8))
    floor = kit.diffuse("floor", (1, 1, 1), checker_image())
    red = kit.diffuse("red", (0.8, 0.1, 0.1))
    green = kit.diffuse("green", (0.1, 0.7, 0.1))
    # A 2 m box: floor at z = 0, open towards -Y where the camera stands.
    wall("floor", (0, 0, 0), (0, 0, 0), floor, uv_repeat=2.0)
    wall("ceiling", (0, 0, 2), (math.pi, 0, 0), white)
    wall("back", (0, 1, 1), (math.pi / 2, 0, 0), white)
    wall("left", (-1, 0, 1), (0, math.pi / 2, 0), red)
    wall("right", (1, 0, 1), (0, -math.pi / 2, 0), green)
    # Blender's own UV sphere and cube, "Sphere" and "Cube": scenes/bench/cornell.py and the
    # viewport test find them by name.
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, location=(0.25, 0.2, 0.45), segments=64, ring_count=32)
    sphere = bpy.context.object
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(kit.glass("glass"))
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(-0.45, 0.35, 0.25), rotation=(0, 0, 0.4))
    bpy.context.object.data.materials.append(white)

    kit.area_light("area", (0, 0, 1.98), 60.0, 0.6, 0.4)  # emits down (-Z)
    kit.point_light("warm", (-0.6, -0.5, 1.5), 15.0, color=(1.0, 0.6, 0.3))
    kit.point_light("cool", (0.6, -0.6, 1.2), 15.0, color=(0.3, 0.5, 1.0))
    kit.camera((0, -3.6, 1.0), rotation=(math.pi / 2, 0, 0), lens=32.0)
    kit.toyrt(scene, samples=64)
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 640, 480, 100
    scene.view_settings.view_transform = "Standard"
    return scene


if __name__ == "__main__":
    kit.main(build)
