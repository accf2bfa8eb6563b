# Runs inside Blender, between loading a .blend and rendering it (bench/blender/bench_blender.py):
#     blender -b scene.blend --python bench/blender/configure.py -o OUT -F OPEN_EXR -f 1 -- ENGINE SAMPLES PERCENT
# Sets the engine and its samples, and for Cycles the light transport TOYRT has, as
# tests/blender/test_cycles_parity.py does for its glass scenes: no diffuse bounces, glass
# (transmission and its reflection) up to 8, box filter one pixel wide, no denoising, no adaptive
# sampling, no light threshold, no clamping. Float EXR output, Standard view transform.
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
engine, samples, percent = argv[0], int(argv[1]), int(argv[2])
scene = bpy.context.scene
r = scene.render
r.resolution_percentage = percent
r.use_border = False
r.image_settings.file_format = "OPEN_EXR"
r.image_settings.color_depth = "32"
r.image_settings.color_mode = "RGBA"
r.threads_mode = "AUTO"
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
if engine == "CYCLES":
    r.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    c.use_denoising = False
    c.use_adaptive_sampling = False
    c.seed = 0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.light_sampling_threshold = 0.0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.max_bounces = 8
    c.diffuse_bounces = 0
    c.glossy_bounces = c.transmission_bounces = c.transparent_max_bounces = 8
    c.volume_bounces = 0
else:
    r.engine = "TOYRT"
    scene.toyrt.samples = samples
    scene.toyrt.max_specular_depth = 8
    scene.toyrt.seed = 0
    # Other TOYRT settings to compare, e.g. TOYRT_BENCH_SET="light_sampling=one".
    for item in filter(None, os.environ.get("TOYRT_BENCH_SET", "").split(",")):
        name, value = item.split("=", 1)
        setattr(scene.toyrt, name, type(getattr(scene.toyrt, name))(value))
