# Runs inside Blender, between loading a .blend and rendering it (bench/blender/bench_blender.py):
#     blender -b scene.blend --python bench/blender/configure.py -o OUT -F OPEN_EXR -f 1 -- ENGINE SAMPLES PERCENT
# Sets the engine and its samples, and for Cycles the light transport TOYRT has, as
# tests/blender/test_cycles_parity.py does for its glass scenes: no diffuse bounces, glass
# (transmission and its reflection) up to 8, box filter one pixel wide, no denoising, no adaptive
# sampling, no light threshold, no clamping. Float EXR output, Standard view transform.
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scenes"))  # the scene kit
import kit  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
engine, samples, percent = argv[0], int(argv[1]), int(argv[2])
scene = bpy.context.scene
r = scene.render
r.resolution_percentage = percent
r.use_border = False
r.threads_mode = "AUTO"
kit.float_exr(scene)
kit.standard_view(scene)
if engine == "CYCLES":
    kit.cycles(scene, samples, 8)
else:
    kit.toyrt(scene, samples=samples, max_specular_depth=8, seed=0)
    # Other TOYRT settings to compare, e.g. TOYRT_BENCH_SET="light_sampling=one".
    for item in filter(None, os.environ.get("TOYRT_BENCH_SET", "").split(",")):
        name, value = item.split("=", 1)
        setattr(scene.toyrt, name, type(getattr(scene.toyrt, name))(value))
