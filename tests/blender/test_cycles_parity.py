# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_cycles_parity.py
# (`make test` runs it). No --factory-startup: the native module comes from the installed add-on
# (render_toyrt.native()); the scene sync is loaded from this repository (addon/render_toyrt/sync.py).
#
# TOYRT against Cycles on scenes built here with bpy: one point light with a hard shadow, three
# coloured point lights, a rectangular area light with soft shadows, a glass sphere over a textured
# floor (8-bit checker image), and the same with a float checker image. Cycles is restricted to
# TOYRT's light transport (max bounces 0; for the glass scene only transmission/specular chains),
# Box filter of width 1, no denoising, no adaptive sampling, Standard view transform, float EXR
# output read back linear. The scenes are built with the scene kit (scenes/kit.py).
#
# Metrics per scene (Blender's own render tests use the second): mean |TOYRT - Cycles| over the
# mean of Cycles (<= 0.5 %), and the fraction of pixels where a channel differs by more than 0.016
# after clamping both to [0, 1] (<= 1 %). The converged Cycles references are keyed by a hash of
# the scene parameters, what builds scenes here (the text above the Cycles section, and
# render_cycles), the scene kit, the Cycles settings and the Blender version. They are committed
# in tests/blender/parity_refs/<version>/ (`make parity-refs` writes them after a change: a fresh
# clone's `make test` then renders no reference, about 12 minutes of Cycles saved), and a
# reference that is missing there or stale is rendered and cached under build/parity-cache/.
# Results go to docs/parity.md; images of the last run to build/parity-cache/last-run/.
import ast
import hashlib
import importlib.util
import inspect
import json
import os
import sys
import textwrap
import time
import traceback
from pathlib import Path

import bpy
import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "scenes"))  # the scene kit
import kit  # noqa: E402

# The build folder of this run (`make test-blender BUILD=...` and run_with_bpy.py set it).
CACHE = Path(os.environ.get("TOYRT_BUILD_DIR", REPO / "build")) / "parity-cache"
# The committed references of this Blender version, and whether this run writes them (make parity-refs).
REFS = REPO / "tests" / "blender" / "parity_refs" / ".".join(map(str, bpy.app.version))
SAVE_REFS = os.environ.get("TOYRT_PARITY_SAVE_REFS", "") == "1"
# Debian's Blender 3.4 writes docs/parity.md; a current Blender through the bpy module
# (tests/blender/run_with_bpy.py) writes its own report beside it.
DOC = REPO / "docs" / ("parity.md" if bpy.app.version < (4, 0, 0) else
                       f"parity-blender-{bpy.app.version[0]}.{bpy.app.version[1]}.md")

WIDTH, HEIGHT = 80, 60
CYCLES_SAMPLES = int(os.environ.get("TOYRT_PARITY_CYCLES_SAMPLES", "1024"))
TOYRT_SAMPLES = int(os.environ.get("TOYRT_PARITY_TOYRT_SAMPLES", "1024"))
MEAN_LIMIT = 0.005       # mean |difference| / mean(reference): both issues' limit
PIXEL_FAIL = 0.016       # Blender's render tests: a pixel fails above this difference ...
PIXEL_LIMIT = 0.01       # ... and the image fails when more than 1 % of pixels fail
SCENES = os.environ.get("TOYRT_PARITY_SCENES", "")  # comma-separated subset, for development


def load_sync():
    """This repository's scene sync (addon/render_toyrt/sync.py and the converters beside it),
    loaded as a package of its own name: what is tested is this tree, whatever is installed."""
    package, root = "toyrt_addon_under_test", REPO / "addon" / "render_toyrt"
    spec = importlib.util.spec_from_file_location(package, root / "__init__.py", submodule_search_locations=[str(root)])
    module = importlib.util.module_from_spec(spec)
    sys.modules[package] = module
    spec.loader.exec_module(module)
    return importlib.import_module(f"{package}.sync")


# ---- scene building: the kit (scenes/kit.py) --------------------------------------------------

def checker(name, n, c0, c1, float_buffer=False):
    """A diffuse material with an n x n checker image (packed, sRGB-encoded values), 8-bit or float."""
    ij = np.add.outer(np.arange(n), np.arange(n)) % 2
    px = np.where(ij[..., None] == 0, np.float32(c0), np.float32(c1))
    rgba = np.concatenate([np.broadcast_to(px, (n, n, 1)).repeat(3, axis=2), np.ones((n, n, 1), np.float32)], axis=2)
    return kit.diffuse(name, image=kit.image(name, rgba, float_buffer=float_buffer, colorspace="sRGB"))


def camera(location, target):
    return kit.camera(location, target, lens=35.0, clip=(0.1, 100.0))


# The scenes: each a function of its parameters (the parameters also key the Cycles cache).

def scene_point(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (1.0, 1.0, 1.0)))
    kit.box("occluder", 0.6, (0.0, 0.0, 0.5), kit.diffuse("grey", (0.5, 0.5, 0.5)))
    kit.point_light("lamp", p["light"], p["power"], radius=p["radius"])
    camera(p["camera"], (0, 0, 0))
    kit.world((0, 0, 0))


def scene_rgb(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (0.9, 0.9, 0.9)))
    kit.box("occluder", 0.7, (0.0, 0.2, 0.35), kit.diffuse("grey", (0.6, 0.6, 0.6)))
    for i, (loc, power, color) in enumerate(p["lights"]):
        kit.point_light(f"lamp{i}", loc, power, color=color)
    camera(p["camera"], (0, 0, 0))
    kit.world((0, 0, 0))


def scene_area(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    kit.box("occluder", 0.6, (0.2, -0.1, 0.6), kit.diffuse("red", (0.7, 0.2, 0.1)))
    kit.area_light("panel", p["light"], p["power"], p["size"], p["size_y"], target=p["light_target"])
    camera(p["camera"], (0, 0, 0))
    kit.world((0, 0, 0))


def scene_glass(p):
    floor = checker("checker", 8, p["checker"][0], p["checker"][1], float_buffer=p["float_texture"])
    kit.plane("floor", 6.0, floor, uv_repeat=p["uv_repeat"])
    glass = kit.glass("glass", p["ior"])
    if "glass_color" in p:  # the Glass BSDF's Color: every ray through or mirrored by it takes it
        next(n for n in glass.node_tree.nodes if n.type == "BSDF_GLASS").inputs["Color"].default_value = \
            (*p["glass_color"], 1.0)
    kit.uv_sphere("ball", 0.7, (0.0, 0.0, 0.75), glass)
    lamp = kit.area_light("panel", p["light"], p["power"], 1.5, 1.0, target=(0, 0, 0))
    if p["hide_light_from_specular"]:
        # The light hidden from camera and specular rays (the exporter passes the flags on).
        lamp.visible_glossy = lamp.visible_transmission = lamp.visible_camera = False
    camera(p["camera"], (0, 0, 0.4))
    kit.world(p["world"], lights_diffuse=p["world_lights_diffuse"])


def scene_rough_glass(p):
    """A rough GGX glass sphere over the checker floor, the lamp hidden from the camera only: seen
    in and through the sphere by light sampling at both of its surfaces and by the lobe's rays."""
    floor = checker("checker", 8, p["checker"][0], p["checker"][1])
    kit.plane("floor", 6.0, floor, uv_repeat=p["uv_repeat"])
    mat = kit.glass("rough_glass", p["ior"])
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_GLASS")
    bsdf.distribution = "GGX"    # 3.x defaults to Beckmann, 4.0+ to Multiscatter GGX
    bsdf.inputs["Roughness"].default_value = p["roughness"]
    kit.uv_sphere("ball", 0.7, (0.0, 0.0, 0.75), mat)
    kit.area_light("panel", p["light"], p["power"], *p["size"], target=(0, 0, 0))
    camera(p["camera"], (0, 0, 0.4))
    kit.world(p["world"])


def scene_depth_of_field(p):
    """Three boxes at 3, 6 and 9 m on a checker floor, the camera focused on the middle one (its
    focus object) through a bladed, turned aperture: the near and far boxes and the floor blur."""
    floor = checker("checker", 8, 0.15, 0.85)
    kit.plane("floor", 30.0, floor, uv_repeat=p["uv_repeat"])
    grey = kit.diffuse("grey", (0.7, 0.7, 0.7))
    boxes = [kit.box(f"box{i}", 0.6, (x, y, 0.3), grey) for i, (x, y) in enumerate(p["boxes"])]
    kit.point_light("lamp", (1.0, -2.0, 4.0), 600.0, radius=0.2)
    cam = camera(p["camera"], (0.0, 0.0, 0.3))
    dof = cam.data.dof
    dof.use_dof, dof.focus_object = True, boxes[1]
    dof.aperture_fstop, dof.aperture_blades, dof.aperture_rotation = p["fstop"], p["blades"], p["rotation"]
    kit.world((0.05, 0.05, 0.05))


def scene_sun(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    kit.box("occluder", 0.6, (0.0, 0.0, 0.6), kit.diffuse("grey", (0.5, 0.5, 0.5)))
    kit.sun_light("sun", p["strength"], p["direction"], angle=p["angle"])
    camera(p["camera"], (0, 0, 0))
    kit.world((0, 0, 0))


def scene_spot(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    kit.box("occluder", 0.5, (0.3, 0.2, 0.25), kit.diffuse("grey", (0.5, 0.5, 0.5)))
    kit.spot_light("spot", p["light"], p["power"], p["spot_size"], p["spot_blend"], radius=p["radius"],
                   scale=p["scale"])
    camera(p["camera"], (0, 0, 0))
    kit.world((0, 0, 0))


def scene_near_point(p):
    # A 1 m light just above a floor and a box: where Cycles' soft falloff (a disk facing the
    # shading point) and a sphere differ most (docs/render.md).
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    kit.box("occluder", 0.6, (0.9, 0.0, 0.3), kit.diffuse("grey", (0.5, 0.5, 0.5)))
    kit.point_light("lamp", p["light"], p["power"], radius=p["radius"], soft_falloff=p["soft_falloff"])
    camera(p["camera"], (0, 0, 0))
    kit.world((0, 0, 0))


def scene_emitters(p):
    # An Emission panel above a floor, a box in its light, a glowing sphere (2,208 emissive
    # triangles), and (with transmission) a glass sphere the panel is seen through.
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    kit.box("occluder", 0.5, (0.6, 0.3, 0.25), kit.diffuse("grey", (0.5, 0.5, 0.5)))
    image = stripes("stripes", 16) if p.get("image") else None
    panel = kit.plane("panel", 1.2, kit.emission("glow", (1.0, 0.85, 0.6), p["strength"], p["sampling"], image),
                      (-0.4, 0.6, 1.6))
    panel.rotation_euler = (0.5, 0.3, 0.0)
    kit.uv_sphere("glowing_ball", 0.3, (-1.2, -0.6, 0.3), kit.emission("ball_glow", (0.2, 0.5, 1.0), 2.0))
    if p["glass"]:
        kit.uv_sphere("ball", 0.5, (0.0, -0.8, 0.5), kit.glass("glass", 1.45))
    camera(p["camera"], (0, 0, 0.3))
    kit.world((0, 0, 0))


def stripes(name, n):
    """An 8-bit sRGB n x n image: warm, cool and dark vertical stripes, a brighter band across."""
    u = (np.arange(n) + 0.5) / n
    colors = np.array([(1.0, 0.7, 0.3), (0.3, 0.6, 1.0), (0.05, 0.05, 0.05)])
    rgb = np.broadcast_to(colors[(np.arange(n) * 3) // n][None, :, :], (n, n, 3)).copy()
    rgb[(u > 0.6) & (u < 0.8)] = np.minimum(rgb[(u > 0.6) & (u < 0.8)] * 1.6, 1.0)
    return kit.image(name, np.concatenate([rgb, np.ones((n, n, 1))], axis=2))


def sky_image(width, height, sun_elevation, sun_azimuth, sun_radiance):
    """An equirectangular float sky (rows from the bottom): a bluish gradient above the horizon, a
    dim brown ground below, and a small bright sun (a Gaussian a few texels wide)."""
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    elevation = (v - 0.5) * np.pi
    azimuth = (0.5 - u) * 2 * np.pi
    el, az = np.meshgrid(elevation, azimuth, indexing="ij")
    up = np.clip(np.sin(el), 0, 1)[..., None]
    sky = np.where(el[..., None] > 0, (0.25 + 0.5 * up) * np.array([0.45, 0.6, 1.0]), np.array([0.12, 0.09, 0.06]))
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], -1)
    s = np.array([np.cos(sun_elevation) * np.cos(sun_azimuth), np.cos(sun_elevation) * np.sin(sun_azimuth),
                  np.sin(sun_elevation)])
    angle = np.arccos(np.clip(d @ s, -1, 1))
    sky = sky + sun_radiance * np.exp(-0.5 * (angle / np.radians(2.0)) ** 2)[..., None] * np.array([1.0, 0.9, 0.75])
    rgba = np.concatenate([sky, np.ones((height, width, 1))], axis=2).astype(np.float32)
    return kit.image("sky", rgba, float_buffer=True)


def scene_hdri(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    kit.box("occluder", 0.8, (0.0, 0.0, 0.4), kit.diffuse("red", (0.7, 0.2, 0.1)))
    kit.environment_world(sky_image(128, 64, *p["sun"]), p["strength"], p["rotation"])
    camera(p["camera"], (0, 0, 0.3))


def glossy_row(roughness, color, distribution="GGX"):
    """A row of Glossy BSDF balls (GGX, or `distribution`) at the given roughness values, centred on the origin."""
    for i, rough in enumerate(roughness):
        x = (i - (len(roughness) - 1) / 2) * 0.9
        kit.uv_sphere(f"ball{i}", 0.4, (x, 0.0, 0.4), kit.glossy(f"glossy{i}", color, rough, distribution))


def scene_emitters_glossy(p):
    # Glossy balls lit by emissive meshes alone: a panel over the row and a small glowing ball
    # beside it. Each glossy vertex samples an emissive triangle beside its lobe's ray (MIS), as
    # Cycles samples mesh lights at every vertex.
    kit.plane("floor", 8.0, kit.diffuse("floor", (0.6, 0.6, 0.6)))
    panel = kit.plane("panel", 1.0, kit.emission("glow", (1.0, 0.85, 0.6), p["strength"]), (-0.6, 0.9, 1.8))
    panel.rotation_euler = (2.6, 0.3, 0.0)  # facing the row, down and forwards
    kit.uv_sphere("glowing_ball", 0.2, (1.3, -0.9, 0.2), kit.emission("ball_glow", (0.2, 0.5, 1.0), 3.0))
    glossy_row(p["roughness"], p["color"])
    camera((0.0, -4.5, 1.6), (0, 0, 0.35))
    kit.world((0, 0, 0))


def scene_hdri_glossy(p):
    # Glossy balls in the HDRI world with its small bright sun: each glossy vertex samples the map
    # beside its lobe's ray (MIS).
    kit.plane("floor", 8.0, kit.diffuse("floor", (0.6, 0.6, 0.6)))
    kit.environment_world(sky_image(128, 64, *p["sun"]), p["strength"], p["rotation"])
    glossy_row(p["roughness"], p["color"])
    camera((0.0, -4.5, 1.6), (0, 0, 0.35))


def ball_row_stage(lamp="point"):
    """The material-ball scenes' shared stage: the grey floor, a round point lamp or a rectangular
    area lamp, the camera looking along the row, no world."""
    kit.plane("floor", 8.0, kit.diffuse("floor", (0.6, 0.6, 0.6)))
    if lamp == "point":
        kit.point_light("lamp", (0.8, -1.5, 2.5), 150.0, radius=0.25)
    else:
        kit.area_light("panel", (-0.8, -1.2, 2.2), 120.0, 1.2, 0.6, target=(0.0, 0.0, 0.3))
    camera((0.0, -4.5, 1.6), (0, 0, 0.35))
    kit.world((0, 0, 0))


def scene_glossy_sweep(p):
    # Material balls: a row of Glossy BSDF (GGX) spheres, roughness 0.05 to 1, over a diffuse floor
    # (the spheres reflect it and each other: glossy chains ending on the floor's direct light),
    # under one lamp the sharp balls show as a highlight.
    ball_row_stage(p["lamp"])
    glossy_row(p["roughness"], p["color"], p.get("distribution", "GGX"))


def scene_metal_sweep(p):
    # Principled BSDF, Metallic 1, at the sweep's roughness values (Blender's defaults otherwise: 3.x
    # GGX, 4.0+ Multiscatter GGX and a white Specular Tint).
    ball_row_stage()
    for i, rough in enumerate(p["roughness"]):
        x = (i - (len(p["roughness"]) - 1) / 2) * 0.9
        kit.uv_sphere(f"ball{i}", 0.4, (x, 0.0, 0.4), kit.metal(f"metal{i}", p["color"], rough))


def scene_principled(p):
    # Principled BSDF dielectrics (Metallic 0): a row of balls over a diffuse floor, each its own
    # (roughness, Specular, tint); the version's default distribution (3.x GGX, 4.0+ Multiscatter
    # GGX). A tint is a scalar on 3.x and a colour on 4.0+: each ball gets the version's kind.
    ball_row_stage(p["lamp"])
    new = bpy.app.version >= (4, 0, 0)
    for i, (rough, specular, tint) in enumerate(p["balls"]):
        x = (i - (len(p["balls"]) - 1) / 2) * 0.9
        t = None if tint is None else (tint[1] if new else tint[0])
        kit.uv_sphere(f"ball{i}", 0.4, (x, 0.0, 0.4),
                      kit.principled_dielectric(f"principled{i}", p["color"], rough, specular, t))


def scene_diffuse_and_glossy(p):
    # Mix and Add shaders of a Diffuse and a Glossy BSDF: balls at three mix factors and one sum.
    ball_row_stage()
    for i, (fac, rough) in enumerate(p["balls"]):
        x = (i - (len(p["balls"]) - 1) / 2) * 1.0
        mat = kit.diffuse_and_glossy(f"mixed{i}", (0.7, 0.25, 0.15), (0.9, 0.9, 0.9), rough, fac)
        kit.uv_sphere(f"ball{i}", 0.42, (x, 0.0, 0.42), mat)


# A real file: five 1 m point lights of 100 W a metre above a torus, from Debian's assimp-testmodels
# (Blender 2.50; the Makefile installs it). Its own camera, lights and grey world.
TORUS_FILE = Path("/usr/share/assimp/models/BLEND/TorusLightsCams_250_compressed.blend")


def scene_torus_file(p):
    with bpy.data.libraries.load(str(TORUS_FILE)) as (src, dst):
        dst.objects = list(src.objects)
    for obj in dst.objects:
        kit.link(obj)
    bpy.context.scene.camera = bpy.data.objects["Camera"]
    kit.world((0.05087609,) * 3)


SCENES_SPEC = [
    ("point", scene_point, dict(light=(1.0, 1.2, 2.5), power=150.0, radius=0.0, camera=(0.0, -6.0, 4.5)), 0),
    ("three_rgb_points", scene_rgb, dict(lights=[((-1.5, -1.0, 2.0), 60.0, (1.0, 0.1, 0.1)),
                                                 ((1.5, -1.0, 2.0), 60.0, (0.1, 1.0, 0.1)),
                                                 ((0.0, 1.2, 2.0), 60.0, (0.1, 0.1, 1.0))],
                                         camera=(0.0, -6.0, 4.5)), 0),
    ("area_soft_shadow", scene_area, dict(light=(-0.5, 0.5, 2.2), light_target=(0.0, 0.0, 0.0), power=80.0,
                                          size=1.6, size_y=0.8, camera=(0.0, -6.0, 4.5)), 0),
    ("glass_sphere", scene_glass, dict(light=(1.0, -1.0, 3.0), power=120.0, ior=1.45, uv_repeat=4.0,
                                       checker=(0.15, 0.85), world=(0.05, 0.05, 0.05),
                                       hide_light_from_specular=True, world_lights_diffuse=False, float_texture=False,
                                       camera=(0.0, -5.0, 2.5)), 8),
    # The same with a float image holding the same sRGB-encoded values: Cycles decodes float images
    # when it loads them, and 8-bit sRGB images only after filtering (see docs/parity.md).
    ("glass_sphere_float_texture", scene_glass, dict(light=(1.0, -1.0, 3.0), power=120.0, ior=1.45, uv_repeat=4.0,
                                                     checker=(0.15, 0.85), world=(0.05, 0.05, 0.05),
                                                     hide_light_from_specular=True, world_lights_diffuse=False,
                                                     float_texture=True,
                                                     camera=(0.0, -5.0, 2.5)), 8),
    # A tinted Glass BSDF (issue 14): the colour on each reflection and refraction, as Cycles.
    ("glass_tinted", scene_glass, dict(light=(1.0, -1.0, 3.0), power=120.0, ior=1.45, uv_repeat=4.0,
                                       checker=(0.15, 0.85), world=(0.05, 0.05, 0.05), glass_color=(0.95, 0.6, 0.3),
                                       hide_light_from_specular=True, world_lights_diffuse=False, float_texture=False,
                                       camera=(0.0, -5.0, 2.5)), 8),
    ("sun_hard_shadow", scene_sun, dict(strength=3.0, direction=(-0.4, 0.5, -1.0), angle=0.0,
                                        camera=(0.0, -6.0, 4.5)), 0),
    ("sun_soft_shadow", scene_sun, dict(strength=3.0, direction=(-0.4, 0.5, -1.0), angle=0.35,
                                        camera=(0.0, -6.0, 4.5)), 0),
    ("spot", scene_spot, dict(light=(1.0, -1.0, 3.0), power=400.0, spot_size=0.9, spot_blend=0.3, radius=0.0,
                              scale=(1.0, 1.0, 1.0), camera=(0.0, -6.0, 4.5)), 0),
    # A round spot scaled along one axis: Cycles 4.x widens its cone there, 3.x does not.
    ("spot_soft_scaled", scene_spot, dict(light=(-1.0, -1.0, 2.5), power=400.0, spot_size=0.8, spot_blend=0.15,
                                          radius=0.3, scale=(1.8, 1.0, 1.0), camera=(0.0, -6.0, 4.5),
                                          sample_factor=2), 0),
    ("point_near_soft_falloff", scene_near_point, dict(light=(0.0, 0.0, 1.2), power=150.0, radius=1.0,
                                                       soft_falloff=True, camera=(0.0, -6.0, 4.5)), 0),
    ("point_near_sphere", scene_near_point, dict(light=(0.0, 0.0, 1.2), power=150.0, radius=1.0,
                                                 soft_falloff=False, camera=(0.0, -6.0, 4.5)), 0),
    # Emissive meshes: sampled as lights, seen directly and (second scene) through glass; and an
    # emitter Cycles does not sample (emission sampling None), which lights nothing.
    ("emitters", scene_emitters, dict(strength=6.0, sampling=None, glass=False, camera=(0.5, -5.5, 3.0)), 0),
    # An Emission panel whose colour is an image (8-bit sRGB stripes): seen directly, and lighting
    # the floor and the box by its pixels where shadow rays land on it.
    ("emitters_textured", scene_emitters, dict(strength=6.0, sampling=None, glass=False, image=True,
                                               camera=(0.5, -5.5, 3.0)), 0),
    ("emitters_through_glass", scene_emitters, dict(strength=6.0, sampling=None, glass=True,
                                                    camera=(0.5, -5.5, 3.0)), 8),
    # Not sampled as a light, Cycles' emitter still lights the floor through the BSDF-sampled ray
    # of the last bounce (emission is collected before the path ends); so does TOYRT's cosine ray
    # (combined with emitter sampling by MIS where both apply). Noisier: 8x the samples.
    ("emitter_not_sampled", scene_emitters, dict(strength=6.0, sampling="NONE", glass=False,
                                                 camera=(0.5, -5.5, 3.0), sample_factor=16), 0),
    # Glossy balls (GGX, roughness 0.05 to 1) lit by emissive meshes alone, and by the HDRI world:
    # glossy vertices sample emitters and the map as they sample lamps (docs/lights.md).
    ("emitters_glossy", scene_emitters_glossy, dict(roughness=[0.05, 0.2, 0.5, 1.0], color=(0.9, 0.75, 0.5),
                                                    strength=8.0, sample_factor=4), 8),
    ("hdri_glossy", scene_hdri_glossy, dict(roughness=[0.05, 0.2, 0.5, 1.0], color=(0.9, 0.75, 0.5),
                                            sun=(0.6, 0.8, 60.0), strength=1.5, rotation=(0.0, 0.0, 0.7),
                                            sample_factor=2), 8),
    # An HDRI world with a small bright sun, turned by a Mapping node; seen by the camera above the
    # horizon and lighting the floor and the box.
    ("hdri_sky", scene_hdri, dict(sun=(0.6, 0.8, 60.0), strength=1.5, rotation=(0.0, 0.0, 0.7),
                                  camera=(0.0, -6.0, 2.0)), 0),
    # The torus has no material: Cycles' default surface, a Diffuse BSDF on 3.4 and a default
    # Principled BSDF on 5.0 (materials.DEFAULT_SURFACE_PRINCIPLED_FROM; docs/parity-blender-5.0.md).
    ("torus_file", scene_torus_file, dict(file=TORUS_FILE.name, sample_factor=4), 0),
    # Glossy roughness sweeps (GGX; the mean limit 0.5 %, the materials issue's), under a spherical
    # point lamp and a rectangular area lamp; glossy bounces 8, diffuse bounces 0.
    ("glossy_sweep_point", scene_glossy_sweep, dict(roughness=[0.05, 0.2, 0.4, 0.7, 1.0], color=(0.9, 0.75, 0.5),
                                                    lamp="point", sample_factor=2), 8),
    ("glossy_sweep_area", scene_glossy_sweep, dict(roughness=[0.05, 0.2, 0.4, 0.7, 1.0], color=(0.9, 0.75, 0.5),
                                                   lamp="area", sample_factor=4), 8),
    # The Glossy BSDF's Beckmann distribution (3.x separable masking, 4.0+ height-correlated).
    ("glossy_sweep_beckmann", scene_glossy_sweep, dict(roughness=[0.05, 0.2, 0.4, 0.7, 1.0],
                                                       color=(0.9, 0.75, 0.5), lamp="point", distribution="BECKMANN",
                                                       sample_factor=2), 8),
    ("mix_diffuse_glossy", scene_diffuse_and_glossy, dict(balls=[(0.2, 0.3), (0.5, 0.3), (0.8, 0.3), (None, 0.1)],
                                                          sample_factor=4), 8),
    # Principled dielectrics: a roughness sweep under a point lamp, and Specular levels and tints
    # under an area lamp (3.x: a Burley diffuse base, 4.0+: a Lambert base layered under the layer).
    ("principled_sweep_point", scene_principled, dict(balls=[(r, 0.5, None) for r in (0.05, 0.2, 0.4, 0.7, 1.0)],
                                                      color=(0.7, 0.25, 0.15), lamp="point", sample_factor=2), 8),
    ("principled_specular_area", scene_principled, dict(balls=[(0.3, 0.0, None), (0.3, 1.0, None),
                                                               (0.3, 0.5, (1.0, (1.0, 0.5, 0.2))),
                                                               (0.15, 2.0, None), (0.6, 0.25, None)],
                                                        color=(0.2, 0.45, 0.7), lamp="area", sample_factor=4), 8),
    # Principled metals (Metallic 1): 3.x's Fresnel blend from the base colour, 4.0+'s F82-tint
    # with Multiscatter GGX.
    ("metal_sweep", scene_metal_sweep, dict(roughness=[0.05, 0.2, 0.4, 0.7, 1.0], color=(0.9, 0.75, 0.5),
                                            sample_factor=2), 8),
    # Depth of field: a hexagonal aperture focused on a focus object (docs/render.md).
    ("depth_of_field", scene_depth_of_field, dict(boxes=[(-1.0, -3.0), (0.0, 0.0), (1.2, 3.0)], uv_repeat=12.0,
                                                  fstop=0.1, blades=6, rotation=0.3, camera=(0.0, -6.0, 1.0),
                                                  sample_factor=4), 0),
    # Cycles' defaults: the light is seen through and in the glass (camera, glossy and transmission
    # rays see it), and the world lights the floor, as in TOYRT.
    ("glass_sphere_visible_light", scene_glass, dict(light=(1.0, -1.0, 3.0), power=120.0, ior=1.45, uv_repeat=4.0,
                                                     checker=(0.15, 0.85), world=(0.05, 0.05, 0.05),
                                                     hide_light_from_specular=False, world_lights_diffuse=True,
                                                     float_texture=False, camera=(0.0, -5.0, 2.5), sample_factor=4), 8),
    # Rough glass (GGX, roughness 0.3): 3.x's separable masking and Fresnel-weighted lobe pair,
    # 4.0+'s height-correlated masking and Fresnel term per microfacet (docs/render.md).
    # A large lamp: seen through both surfaces, it is found by the lobe's rays alone (the sphere
    # shadows the inner vertex's light samples), in both renderers; a small one is all fireflies.
    ("rough_glass", scene_rough_glass, dict(light=(1.0, -1.0, 3.0), power=200.0, size=(4.0, 3.0), ior=1.45,
                                            roughness=0.3, uv_repeat=4.0, checker=(0.15, 0.85),
                                            world=(0.05, 0.05, 0.05), camera=(0.0, -5.0, 2.5), sample_factor=8), 8),
]



# A Preetham Sky Texture world (issue 13: the add-on bakes the model into an environment map) lights
# a diffuse floor and ball; the camera sees the sky above the floor's far edge. Preetham exists in
# Blender 3.4 to 5.0, so it is asserted on each (the mean limit 0.5 %).
def scene_sky_preetham(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    kit.uv_sphere("ball", 0.5, (0.0, 0.0, 0.5), kit.diffuse("orange", (0.7, 0.45, 0.25)))
    kit.sky_world("PREETHAM", strength=p["strength"], sun_direction=p["sun"], turbidity=p["turbidity"])
    camera(p["camera"], (0.0, 0.0, 0.6))


SCENES_SPEC.append(("sky_preetham", scene_sky_preetham, dict(sun=(0.5, -0.4, 0.77), turbidity=2.5, strength=1.0,
                                                             camera=(0.0, -6.0, 1.2), sample_factor=2), 0))


# An area light's spread (issue 13): a soft box whose slats narrow its beam to 30 degrees, so it
# lights a pool on the floor with a soft rim and the box beside it from one side only. Cycles 3.x
# and 4.0+ write the same function of the angle (lights/area_spread.h), asserted on each.
def scene_area_spread(p):
    scene_area(p)
    bpy.data.objects["panel"].data.spread = p["spread"]


SCENES_SPEC.append(("area_spread", scene_area_spread,
                    dict(light=(-0.5, 0.5, 2.2), light_target=(0.3, 0.0, 0.0), power=150.0, size=2.0, size_y=1.2,
                         spread=0.5236, camera=(0.0, -6.0, 4.5), sample_factor=8), 0))


# Principled Transmission (a warm base colour, which tints the glass as each version's Cycles does:
# 4.0+ by its square root per interface, 3.x by itself on each refraction): a ball
# of Transmission 1 (the Glass BSDF's lobe) beside one of 0.5 (the glass drawn beside the opaque
# parts: 3.x's Burley base and layer, 4.0+'s layered base), roughness 0.3, IOR 1.45, the rough
# glass scene's lamp and floor. 16x the samples: the partial ball draws glass or opaque parts per
# hit in TOYRT (one of them, unweighted), a noisier estimator than Cycles' (NEE over all closures).
def scene_principled_glass(p):
    floor = checker("checker", 8, 0.15, 0.85)
    kit.plane("floor", 6.0, floor, uv_repeat=4.0)
    for i, (weight, x) in enumerate(((1.0, -0.8), (0.5, 0.8))):
        mat = kit.principled_dielectric(f"principled_glass{i}", p["base"], p["roughness"])
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        kit.input_of(bsdf, "Transmission Weight", "Transmission").default_value = weight
        bsdf.inputs["IOR"].default_value = 1.45
        kit.uv_sphere(f"ball{i}", 0.6, (x, 0.0, 0.65), mat)
    kit.area_light("panel", (1.0, -1.0, 3.0), 200.0, 4.0, 3.0, target=(0, 0, 0))
    camera((0.0, -5.0, 2.5), (0, 0, 0.4))
    kit.world((0.05, 0.05, 0.05))


SCENES_SPEC.append(("principled_glass", scene_principled_glass, dict(roughness=0.3, base=(0.95, 0.8, 0.6),
                                                                     sample_factor=16), 8))

# 4.0+'s default Glass BSDF (issue 14): Multiscatter GGX, the single-scatter lobe scaled by 1 / E
# from Cycles' precomputed glass tables (which TOYRT recomputes on the same grid and reads the same
# way), darkened for a tinted glass by the multi-bounce Fresnel factor of its colour
# (materials/dielectric_albedo.h). A white ball and a tinted one, rougher than rough_glass's.
def scene_rough_glass_multiscatter(p):
    kit.plane("floor", 6.0, checker("checker", 8, 0.15, 0.85), uv_repeat=4.0)
    for i, (rough, color, x) in enumerate(((p["roughness"][0], (1.0, 1.0, 1.0), -0.8),
                                           (p["roughness"][1], p["tint"], 0.8))):
        mat = kit.glass(f"multiscatter_glass{i}", 1.45)
        bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_GLASS")
        bsdf.distribution = "MULTI_GGX"
        bsdf.inputs["Roughness"].default_value = rough
        bsdf.inputs["Color"].default_value = (*color, 1.0)
        kit.uv_sphere(f"ball{i}", 0.6, (x, 0.0, 0.65), mat)
    kit.area_light("panel", (1.0, -1.0, 3.0), 200.0, 4.0, 3.0, target=(0, 0, 0))
    camera((0.0, -5.0, 2.5), (0, 0, 0.4))
    kit.world((0.05, 0.05, 0.05))


SCENES_SPEC.append(("rough_glass_multiscatter", scene_rough_glass_multiscatter,
                    dict(roughness=(0.6, 0.35), tint=(0.9, 0.6, 0.35), from_version=(4, 0, 0), sample_factor=16), 8))

# 3.x's Transmission Roughness (issue 14): Cycles 3.x's Principled glass is a reflection closure of
# the Roughness and a refraction closure of 1 - (1 - Roughness)(1 - Transmission Roughness) (GGX;
# Multiscatter GGX ignores it). A sharp reflection over a rough refraction (Roughness 0,
# Transmission Roughness 0.5) and a rough pair (0.2, 0.6), Transmission 1, in principled_glass's
# set. 3.x only: 4.0 removed the socket.
def scene_principled_transmission_roughness(p):
    kit.plane("floor", 6.0, checker("checker", 8, 0.15, 0.85), uv_repeat=4.0)
    for i, (rough, extra, x) in enumerate(((0.0, 0.5, -0.8), (0.2, 0.6, 0.8))):
        mat = kit.principled_dielectric(f"transmission_rough{i}", p["base"], rough)
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Transmission"].default_value = 1.0
        bsdf.inputs["Transmission Roughness"].default_value = extra
        bsdf.inputs["IOR"].default_value = 1.45
        kit.uv_sphere(f"ball{i}", 0.6, (x, 0.0, 0.65), mat)
    kit.area_light("panel", (1.0, -1.0, 3.0), 200.0, 4.0, 3.0, target=(0, 0, 0))
    camera((0.0, -5.0, 2.5), (0, 0, 0.4))
    kit.world((0.05, 0.05, 0.05))


SCENES_SPEC.append(("principled_transmission_roughness", scene_principled_transmission_roughness,
                    dict(base=(0.95, 0.8, 0.6), before_version=(4, 0, 0), sample_factor=8), 8))


# 4.0+'s Coat (issue 14): balls of a red Principled base under a sharp coat, a rough one and a
# tinted one, and a coated gold metal, on the checker floor under an area lamp. Coat exists from
# 4.0 (3.x's Clearcoat is another model, noted): not run on 3.4.
def scene_coat(p):
    kit.plane("floor", 6.0, checker("checker", 8, 0.15, 0.85), uv_repeat=4.0)
    for i, (coat_rough, tint, metal) in enumerate(((0.05, None, False), (0.3, None, False),
                                                   (0.1, (0.3, 0.6, 1.0), False), (0.1, None, True))):
        mat = (kit.metal(f"coated{i}", (0.95, 0.7, 0.3), 0.4) if metal
               else kit.principled_dielectric(f"coated{i}", (0.7, 0.08, 0.05), 0.5))
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Coat Weight"].default_value = 1.0
        bsdf.inputs["Coat Roughness"].default_value = coat_rough
        if tint:
            bsdf.inputs["Coat Tint"].default_value = (*tint, 1.0)
        kit.uv_sphere(f"ball{i}", 0.45, (-1.5 + 1.0 * i, 0.0, 0.45), mat)
    kit.area_light("panel", (1.0, -2.0, 3.0), 250.0, 2.0, 1.0, target=(0, 0, 0))
    camera((0.0, -5.0, 2.5), (0, 0, 0.4))
    kit.world((0.05, 0.05, 0.05))


# Asserted since the layers under the coat are scaled as Cycles scales them (materials/coat.h: by
# Cycles' estimate of the coat's albedo, energy share included, not its Fresnel term at wo): mean
# 0.288 %, 0.92 % of pixels beyond 0.016 (before: 0.307 %, 1.31 %, the rough-coated ball's rim
# 1.6 % darker than Cycles', now 0.6 %). A thin margin: with the tinted ball untinted, 1.67 % of
# pixels; with Coat Weight 0 the same balls leave 1.21 %, the same red-too-dark, green-and-blue-
# too-bright split: not the BSDF's but Cycles' closure pick under diffuse bounces 0, which carries the
# floor's light along glossy picks only (principled_layers below, docs/render.md).
SCENES_SPEC.append(("coat", scene_coat, dict(from_version=(4, 0, 0), sample_factor=4), 8))


# 3.x's Clearcoat (issue 14): the coat scene's balls with Blender 3.x's Principled Clearcoat
# instead (materials/clearcoat.h: Cycles 3.x's GTR1 lobe, fixed masking, GGX sampling with its
# pdf, added beside the rest): Clearcoat 1 at Clearcoat Roughness 0.03 and 0.3, 0.5 at 0.1, and a
# clearcoated gold metal. 3.x only: 4.0 replaced it by the Coat (the coat scene above).
def scene_clearcoat(p):
    kit.plane("floor", 6.0, checker("checker", 8, 0.15, 0.85), uv_repeat=4.0)
    for i, (weight, coat_rough, metal) in enumerate(((1.0, 0.03, False), (1.0, 0.3, False), (0.5, 0.1, False),
                                                     (1.0, 0.1, True))):
        mat = (kit.metal(f"clearcoated{i}", (0.95, 0.7, 0.3), 0.4) if metal
               else kit.principled_dielectric(f"clearcoated{i}", (0.7, 0.08, 0.05), 0.5))
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Clearcoat"].default_value = weight
        bsdf.inputs["Clearcoat Roughness"].default_value = coat_rough
        kit.uv_sphere(f"ball{i}", 0.45, (-1.5 + 1.0 * i, 0.0, 0.45), mat)
    kit.area_light("panel", (1.0, -2.0, 3.0), 250.0, 2.0, 1.0, target=(0, 0, 0))
    camera((0.0, -5.0, 2.5), (0, 0, 0.4))
    kit.world((0.05, 0.05, 0.05))


# Asserted on 3.4 since 2026-12-04 (4 x 1024 samples): mean 0.294 %, 0.23 % of pixels beyond 0.016.
# Cycles evaluates the diffuse, specular and clearcoat closures together along every direction and
# weighs MIS by their pdfs mixed by sample weight, where the clearcoat's reported pdf is not the
# density it samples; TOYRT copies that estimator (materials/closure_mixture.h). Drawing one lobe
# instead gave 0.41 % and 2.0 % of pixels off (the clearcoated metal 1.1 % dark on a black floor).
# The lobe itself is checked in tests/native/clearcoat_test.cpp.
SCENES_SPEC.append(("clearcoat", scene_clearcoat, dict(before_version=(4, 0, 0), sample_factor=4), 8))


# The uncoated 4.0+ Principled's layers one by one (the coat scene's red base, roughness 0.5): a
# base alone (Specular IOR Level 0), a specular layer alone (black base) and both, over a black
# floor, under the coat scene's lamp and world. Each part matches Cycles per channel within 0.1 %;
# over the checker floor the full ball did not (base -0.9 %, reflections +1.8 / +2.8 %): Cycles
# picks one closure per vertex to continue with, and under diffuse bounces 0 only a glossy pick
# carries the floor's light, weighted by the whole BSDF over the closures' mixed pdf (TOYRT copies
# that since: principled_closure_pick, render/closure_pick.h, docs/render.md). The black floor
# leaves nothing for that to act on, so this scene checks the layers themselves.
def scene_principled_layers(p):
    kit.plane("floor", 6.0, kit.diffuse("black", (0.0, 0.0, 0.0)))
    for i, (color, level) in enumerate((((0.7, 0.08, 0.05), 0.0), ((0.0, 0.0, 0.0), 0.5), ((0.7, 0.08, 0.05), 0.5))):
        mat = kit.principled_dielectric(f"layers{i}", color, 0.5, specular=level)
        kit.uv_sphere(f"ball{i}", 0.45, (-1.0 + 1.0 * i, 0.0, 0.45), mat)
    kit.area_light("panel", (1.0, -2.0, 3.0), 250.0, 2.0, 1.0, target=(0, 0, 0))
    camera((0.0, -5.0, 2.5), (0, 0, 0.4))
    kit.world((0.05, 0.05, 0.05))


SCENES_SPEC.append(("principled_layers", scene_principled_layers, dict(from_version=(4, 0, 0), sample_factor=2), 8))


# The same uncoated red Principled (four balls, the coat scene's places) over the lit checker
# floor, where Cycles' closure pick decides how the floor's light reaches base and layer: TOYRT
# copies it (render/closure_pick.h). Before: base -0.9 %, reflections +1.8 / +2.8 % per channel.
def scene_principled_closure_pick(p):
    kit.plane("floor", 6.0, checker("checker", 8, 0.15, 0.85), uv_repeat=4.0)
    for i in range(4):
        mat = kit.principled_dielectric(f"picked{i}", (0.7, 0.08, 0.05), 0.5)
        kit.uv_sphere(f"ball{i}", 0.45, (-1.5 + 1.0 * i, 0.0, 0.45), mat)
    kit.area_light("panel", (1.0, -2.0, 3.0), 250.0, 2.0, 1.0, target=(0, 0, 0))
    camera((0.0, -5.0, 2.5), (0, 0, 0.4))
    kit.world((0.05, 0.05, 0.05))


SCENES_SPEC.append(("principled_closure_pick", scene_principled_closure_pick, dict(sample_factor=2), 8))

# General Mix and Add Shaders (issue 14: the core's 'mix' kind, one input drawn per hit by its
# weight): left, a Mix of a Principled BSDF (a warm base, roughness 0.3) and a smooth Glass BSDF
# with a constant Fac; middle, the same two mixed by an image's stripes (the Image Texture's Color
# as Fac); right, an Add of a Diffuse BSDF and a metal Principled BSDF inside a Mix with a Glossy
# BSDF by a Layer Weight's Facing output. The checker floor and area lamp of principled_glass.
# 16x the samples: each hit shades one input (TOYRT), a noisier estimator than Cycles' sum. (An
# Add of a Diffuse and a sharp Glass there left 1.3 % of pixels, under the ball where light goes
# through the glass, beyond 0.016 at 16384 samples with both signs: noise, mean 0.43 % / 0.38 %.)
def scene_mix_principled_glass(p):
    kit.plane("floor", 6.0, checker("checker", 8, 0.15, 0.85), uv_repeat=4.0)
    n = 16
    stripes = np.where((np.arange(n) // 4) % 2 == 0, 0.15, 0.85).astype(np.float32)
    rgba = np.ones((n, n, 4), np.float32)
    rgba[..., :3] = stripes[None, :, None]
    image = kit.image("mix_stripes", rgba, float_buffer=True, colorspace="Non-Color")

    def mixed(name, first, second):
        mat, mix = kit.surface(name, "ShaderNodeMixShader")
        links = mat.node_tree.links
        links.new(first(mat).outputs[0], mix.inputs[1])
        links.new(second(mat).outputs[0], mix.inputs[2])
        return mat, mix

    def principled(mat):
        node = mat.node_tree.nodes.new("ShaderNodeBsdfPrincipled")
        node.inputs["Base Color"].default_value = (*p["base"], 1.0)
        node.inputs["Roughness"].default_value = 0.3
        return node

    def glass(mat):
        node = mat.node_tree.nodes.new("ShaderNodeBsdfGlass")
        if "SHARP" in node.bl_rna.properties["distribution"].enum_items.keys():
            node.distribution = "SHARP"
        node.inputs["Roughness"].default_value = 0.0
        node.inputs["IOR"].default_value = 1.45
        return node

    def glossy(mat):
        node = mat.node_tree.nodes.new("ShaderNodeBsdfGlossy")
        node.distribution = "GGX"
        node.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
        node.inputs["Roughness"].default_value = 0.2
        return node

    def diffuse_plus_metal(mat):
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        add = nodes.new("ShaderNodeAddShader")
        d = nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Color"].default_value = (0.1, 0.2, 0.4, 1.0)
        links.new(d.outputs[0], add.inputs[0])
        metal = nodes.new("ShaderNodeBsdfPrincipled")
        metal.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1.0)
        metal.inputs["Metallic"].default_value = 1.0
        metal.inputs["Roughness"].default_value = 0.4
        links.new(metal.outputs[0], add.inputs[1])
        return add

    constant, mix = mixed("mix_constant", principled, glass)
    mix.inputs[0].default_value = p["fac"]
    textured, mix = mixed("mix_texture", principled, glass)
    tex = textured.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation, tex.extension = "Linear", "REPEAT"
    textured.node_tree.links.new(tex.outputs["Color"], mix.inputs[0])
    layered, mix = mixed("mix_layer_weight", diffuse_plus_metal, glossy)
    weight = layered.node_tree.nodes.new("ShaderNodeLayerWeight")
    weight.inputs["Blend"].default_value = 0.4
    layered.node_tree.links.new(weight.outputs["Facing"], mix.inputs[0])
    for i, (mat, x) in enumerate(((constant, -1.3), (textured, 0.0), (layered, 1.3))):
        kit.uv_sphere(f"ball{i}", 0.55, (x, 0.0, 0.6), mat)
    kit.area_light("panel", (1.0, -1.0, 3.0), 200.0, 4.0, 3.0, target=(0, 0, 0))
    camera((0.0, -5.0, 2.5), (0, 0, 0.4))
    kit.world((0.05, 0.05, 0.05))


SCENES_SPEC.append(("mix_principled_glass", scene_mix_principled_glass,
                    dict(fac=0.4, base=(0.95, 0.8, 0.6), sample_factor=16), 8))

def scene_cut_out(p):
    # Alpha cut-outs (the materials issue): two planes masked by one generated 8-bit image's alpha
    # (a checker of holes, alpha 0, 0.5 and 1), over a floor, lit by a sun and the world: the camera
    # sees the floor through the holes and half through the 0.5 cells, and the sun's shadow is
    # patterned likewise. Left, a Mix Shader of a Transparent and a Diffuse BSDF (the leaf
    # material); right, a Principled BSDF's Alpha; behind, a pane of a Transparent BSDF alone (its
    # colour tints what is seen through it and its shadow).
    n = 6
    ij = np.add.outer(np.arange(n), np.arange(n))
    alpha = np.where(ij % 2 == 0, 1.0, np.where(ij % 3 == 0, 0.5, 0.0)).astype(np.float32)
    rgba = np.concatenate([np.ones((n, n, 3), np.float32), alpha[..., None]], axis=2)
    mask = kit.image("leaf_mask", rgba, alpha=True)
    kit.plane("floor", 8.0, kit.diffuse("floor", (0.8, 0.8, 0.8)))
    for i, (kind, color, x) in enumerate((("mix", (0.2, 0.6, 0.15), -0.75), ("principled", (0.7, 0.3, 0.1), 0.75))):
        kit.plane(f"leaf{i}", 1.3, kit.cut_out(f"leaf_{kind}", color, mask, kind), location=(x, 0.0, 0.7))
    pane, node = kit.surface("tinted_pane", "ShaderNodeBsdfTransparent")  # a Transparent BSDF alone
    node.inputs["Color"].default_value = (*p["pane"], 1.0)
    kit.plane("pane", 1.0, pane, location=(0.0, 1.3, 0.5))
    kit.sun_light("sun", 3.0, p["direction"])
    camera((0.0, -3.5, 3.2), (0, 0, 0.2))
    kit.world((0.3, 0.35, 0.4))


SCENES_SPEC.append(("cut_out", scene_cut_out, dict(direction=(0.35, 0.25, -1.0), pane=(0.9, 0.55, 0.3)), 0))

def raked_ball_stage(ball, direction):
    """The normal-map and bump scenes' stage beside their floor: a smooth UV sphere (Blender's
    primitive, so it has UVs) of material `ball`, a low sun from `direction`, the camera, a dim
    world."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=0.6, location=(0.4, 0.3, 0.6))
    sphere = bpy.context.active_object
    sphere.data.polygons.foreach_set("use_smooth", np.ones(len(sphere.data.polygons), bool))
    sphere.data.materials.append(ball)
    kit.sun_light("sun", 3.0, direction)
    camera((0.0, -3.6, 2.6), (0, 0.2, 0.3))
    kit.world((0.1, 0.12, 0.15))


def scene_normal_map(p):
    # Normal maps (the materials issue): one generated tangent-space map of sine bumps (float,
    # Non-Color) on a diffuse floor turned 30 degrees about Z (its tangents turn with it), and on a
    # smooth UV sphere of a Principled BSDF (roughness 0.4, Strength 0.6: the version's strength
    # rule), whose MikkTSpace tangents curve with the sphere; a low sun rakes the bumps.
    bumps = kit.bump_normal_image("bumps", size=64, cycles=3, slope=p["slope"])
    floor = kit.diffuse("bumpy_floor", (0.7, 0.7, 0.7))
    kit.normal_map(floor, bumps)
    kit.plane("floor", 4.0, floor).rotation_euler = (0.0, 0.0, np.radians(30.0))
    ball = kit.principled_dielectric("bumpy_ball", (0.6, 0.25, 0.1), 0.4)
    kit.normal_map(ball, bumps, strength=0.6)
    raked_ball_stage(ball, p["direction"])


SCENES_SPEC.append(("normal_map", scene_normal_map, dict(direction=(-0.8, 0.3, -0.6), slope=0.6), 0))


# The Bump node (the materials issue): one float height image of sine bumps (256 texels) on a
# diffuse floor turned 30 degrees, and on a smooth Principled UV sphere (Strength 0.6, inverted),
# raked by a low sun. 4.4+'s Filter Width (0.1 pixel) makes Cycles' differences the slope at the
# point, as TOYRT's default; 3.4 differences the height over the ray's footprint, which TOYRT then
# copies (bump_footprint; docs/render.md). Asserted on both (3.4: 0.064 %; the slope at the point
# gave 3.0 %, 19.9 % of pixels off).
def scene_bump(p):
    heights = kit.height_image("heights", size=256, cycles=3)
    floor = kit.diffuse("bumped_floor", (0.7, 0.7, 0.7))
    kit.bump(floor, heights, distance=p["distance"])
    kit.plane("floor", 4.0, floor).rotation_euler = (0.0, 0.0, np.radians(30.0))
    ball = kit.principled_dielectric("bumped_ball", (0.6, 0.25, 0.1), 0.4)
    kit.bump(ball, heights, strength=0.6, distance=0.1, invert=True)
    raked_ball_stage(ball, p["direction"])


SCENES_SPEC.append(("bump", scene_bump, dict(direction=(-0.8, 0.3, -0.6), distance=0.25), 0))


# The world's ray visibility for glossy and transmission rays (issue 13): a mirror-like glossy ball
# and a glass ball in a blue world, one of the two kinds of ray hidden from the world (in Cycles a
# world hidden from glossy rays is black in reflections, one hidden from transmission rays black
# through glass; camera and diffuse rays still see it).
# Object ray visibility (the lights issue): an Emission panel hidden from the camera lights the
# floor, a box and a glossy ball (Blender users' "invisible light plane"); a grey ball hidden from
# diffuse rays lets the world's and the panel's diffuse light through to the floor (its lamp-free
# shadow gone) while the camera sees it; a red box hidden from glossy rays is missing from the
# glossy ball's reflection.
def scene_ray_visibility(p):
    kit.plane("floor", 6.0, kit.diffuse("floor", (0.7, 0.7, 0.7)))
    panel = kit.plane("panel", 1.4, kit.emission("panel_glow", (1.0, 0.9, 0.75), p["strength"]), (0.0, 0.3, 2.0))
    panel.rotation_euler = (np.pi, 0.0, 0.0)   # facing down
    panel.visible_camera = False
    kit.uv_sphere("shiny_ball", 0.45, (-0.6, 0.0, 0.45), kit.glossy("shiny", (0.9, 0.9, 0.9), 0.1))
    kit.uv_sphere("ghost_ball", 0.4, (0.7, -0.2, 0.4), kit.diffuse("ghost", (0.5, 0.5, 0.5))).visible_diffuse = False
    kit.box("unreflected", 0.5, (-1.4, -0.6, 0.25), kit.diffuse("red", (0.7, 0.15, 0.1))).visible_glossy = False
    camera((0.0, -4.0, 1.8), (0, 0, 0.4))
    kit.world((0.15, 0.2, 0.3))


SCENES_SPEC.append(("ray_visibility", scene_ray_visibility, dict(strength=8.0), 8))


def scene_world_visibility(p):
    kit.plane("floor", 6.0, checker("checker", 8, 0.15, 0.85), uv_repeat=4.0)
    kit.uv_sphere("mirror", 0.5, (-0.7, 0.0, 0.5), kit.glossy("shiny", (0.9, 0.9, 0.9), 0.15))
    kit.uv_sphere("ball", 0.5, (0.7, 0.0, 0.5), kit.glass("glass", 1.45))
    lamp = kit.point_light("lamp", (1.0, -2.0, 3.0), 300.0, radius=0.2)
    # Hidden from glossy and glass rays as in glass_sphere: the scene tests the world, not the
    # lamp's image in the balls (seen there, it put the mean difference at 0.73 % on 5.0, all of
    # it in the glass ball where the lamp's image is, with either world flag).
    lamp.visible_glossy = p.get("lamp_glossy", False)
    lamp.visible_transmission = p.get("lamp_transmission", False)
    camera((0.0, -4.0, 1.6), (0, 0, 0.4))
    kit.world((0.2, 0.35, 0.7))
    visibility = bpy.context.scene.world.cycles_visibility
    visibility.glossy, visibility.transmission = p["glossy"], p["transmission"]


SCENES_SPEC.append(("world_hidden_from_glossy", scene_world_visibility,
                    dict(glossy=False, transmission=True), 8))
SCENES_SPEC.append(("world_hidden_from_transmission", scene_world_visibility,
                    dict(glossy=True, transmission=False), 8))
# A lamp's own glossy and transmission visibility (the lights issue): hidden from one kind of ray,
# it is missing from that kind's reflections or refractions, as an image and as the light of the
# lobes of that kind (Cycles excludes it from those closures), and still seen by the other.
SCENES_SPEC.append(("lamp_hidden_from_glossy", scene_world_visibility,
                    dict(glossy=True, transmission=True, lamp_glossy=False, lamp_transmission=True,
                         sample_factor=4), 8))
SCENES_SPEC.append(("lamp_hidden_from_transmission", scene_world_visibility,
                    dict(glossy=True, transmission=True, lamp_glossy=True, lamp_transmission=False,
                         sample_factor=4), 8))


# Light linking (Blender 4.0+; 3.x has none): a key lamp excluded from one box's lighting (its
# receiver collection EXCLUDEs it) and not shadowed by the other (its blocker collection EXCLUDEs
# that one), and a fill lamp that lights only the first box (an INCLUDE entry: the floor and the
# other box are left unlit by it).
def linking(name, obj, state):
    """A new collection holding `obj` with link state `state` (INCLUDE / EXCLUDE): a light-linking
    receiver or blocker collection."""
    coll = bpy.data.collections.new(name)
    coll.objects.link(obj)
    coll.collection_objects[0].light_linking.link_state = state
    return coll


def scene_light_linking(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    unlit = kit.box("unlit_by_key", 0.6, (-0.8, 0.2, 0.3), kit.diffuse("red", (0.7, 0.2, 0.1)))
    no_shadow = kit.box("no_key_shadow", 0.6, (0.8, 0.0, 0.3), kit.diffuse("grey", (0.5, 0.5, 0.5)))
    key = kit.point_light("key", (1.5, -1.5, 2.5), 500.0, radius=0.1)
    fill = kit.point_light("fill", (-2.0, -1.0, 1.5), 200.0, color=(0.4, 0.6, 1.0), radius=0.1)

    key.light_linking.receiver_collection = linking("key_receivers", unlit, "EXCLUDE")
    key.light_linking.blocker_collection = linking("key_blockers", no_shadow, "EXCLUDE")
    fill.light_linking.receiver_collection = linking("fill_receivers", unlit, "INCLUDE")
    camera((0.0, -5.5, 3.5), (0, 0, 0.2))
    kit.world((0, 0, 0))


SCENES_SPEC.append(("light_linking", scene_light_linking, dict(from_version=(4, 0, 0)), 0))


# Light linking of an emissive object (4.0+): a warm Emission panel whose receiver collection
# excludes a red box (lit by the cool panel alone), and a cool panel whose collection includes
# only the box; the camera (receiver set 0) sees neither panel's emission where its collection
# leaves set 0 out: the cool one.
def scene_emitter_linking(p):
    kit.plane("floor", 8.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    red = kit.box("red_box", 0.6, (-0.6, 0.2, 0.3), kit.diffuse("red", (0.7, 0.2, 0.1)))
    kit.box("grey_box", 0.6, (0.8, 0.0, 0.3), kit.diffuse("grey", (0.5, 0.5, 0.5)))
    warm = kit.plane("warm_panel", 1.0, kit.emission("warm", (1.0, 0.8, 0.6), 12.0), (0.8, -0.8, 1.8))
    warm.rotation_euler = (np.radians(150), 0.0, 0.0)
    cool = kit.plane("cool_panel", 0.8, kit.emission("cool", (0.4, 0.6, 1.0), 12.0), (-1.6, -0.4, 1.2))
    cool.rotation_euler = (np.radians(140), np.radians(-30), 0.0)

    warm.light_linking.receiver_collection = linking("warm_receivers", red, "EXCLUDE")
    cool.light_linking.receiver_collection = linking("cool_receivers", red, "INCLUDE")
    camera((0.0, -5.5, 3.5), (0, 0, 0.2))
    kit.world((0.02, 0.02, 0.02))


SCENES_SPEC.append(("emitter_linking", scene_emitter_linking, dict(from_version=(4, 0, 0)), 0))


# ---- Cycles ------------------------------------------------------------------------------------

def render_cycles(scene, path):
    """Render with Cycles to an EXR; (rows from the top, (h, w, 4) float32, seconds)."""
    scene.render.filepath = str(path)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - t0
    return kit.read_image(path)[::-1].copy(), seconds


def applies(params):
    """Whether a scene exists in this Blender (from_version: the version its nodes appeared in;
    before_version: the version that replaced them)."""
    version = tuple(bpy.app.version)
    return tuple(params.get("from_version", (0, 0, 0))) <= version < tuple(params.get("before_version", (99, 0, 0)))


# Parameters that only decide how a scene is judged, not how it is rendered.
JUDGEMENT_PARAMS = ("asserted_from", "mean_limit")


def code_of(text):
    """Python source without comments and layout (its syntax tree written back), so that editing a
    comment or a line break leaves the references valid."""
    return ast.unparse(ast.parse(text))


def shared_scene_source():
    """What every scene is built with in this file: the text above the Cycles section without the
    scene_* functions and the SCENES_SPEC table (each scene's own function is keyed by itself)."""
    text = Path(__file__).read_text()
    tree = ast.parse(text[:text.index("# ---- Cycles ---")])
    tree.body = [node for node in tree.body
                 if not (isinstance(node, ast.FunctionDef) and node.name.startswith("scene_"))
                 and "SCENES_SPEC" not in ast.unparse(node)]
    return ast.unparse(tree)


def scene_code(build):
    """A scene function's code, and that of the scene functions it calls."""
    code = code_of(textwrap.dedent(inspect.getsource(build)))
    called = sorted({node.id for node in ast.walk(ast.parse(code))
                     if isinstance(node, ast.Name) and node.id.startswith("scene_") and node.id != build.__name__})
    return "\n".join([code] + [scene_code(globals()[name]) for name in called])


def scene_source(build):
    """What a Cycles reference depends on in this file: the shared scene code, the scene's own
    function and render_cycles. The comparison, the report and the other scenes do not count."""
    return "\n".join((shared_scene_source(), scene_code(build), code_of(inspect.getsource(render_cycles))))


def cache_key(name, build, params, transmission, samples):
    # What builds the scene, the kit and the Cycles settings are part of the key: any change to
    # how the scene is built or how Cycles is set up renders its reference again.
    kit_files = (REPO / "scenes" / "kit.py", REPO / "scenes" / "cycles_like_toyrt.py")
    source = hashlib.sha256(scene_source(build).encode() + b"".join(f.read_bytes() for f in kit_files)).hexdigest()
    rendered = {k: v for k, v in params.items() if k not in JUDGEMENT_PARAMS}
    blob = json.dumps(dict(name=name, params=rendered, transmission=transmission, samples=samples,
                           size=(WIDTH, HEIGHT), blender=bpy.app.version_string, source=source), sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def committed_reference(name, key):
    """The committed reference of this scene, or None where there is none or it is stale."""
    path = REFS / f"{name}.npz"
    if not path.exists():
        return None
    with np.load(path) as ref:
        return (ref["image"], float(ref["seconds"])) if str(ref["key"]) == key else None


def save_reference(name, key, img, seconds):
    """Writes the committed reference (make parity-refs), where it is missing or stale."""
    if committed_reference(name, key) is None:
        REFS.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(REFS / f"{name}.npz", image=img.astype(np.float32), key=np.array(key),
                            seconds=np.array(seconds))


def cycles_reference(name, key, transmission, samples):
    """(image, Cycles seconds, where it came from: 'committed', 'cached' or 'rendered')."""
    CACHE.mkdir(parents=True, exist_ok=True)
    committed = committed_reference(name, key)
    if committed is not None:
        return committed[0], committed[1], "committed"
    npy, meta = CACHE / f"{name}-{key}.npy", CACHE / f"{name}-{key}.json"
    if npy.exists() and meta.exists():
        return np.load(npy), json.loads(meta.read_text())["seconds"], "cached"
    kit.cycles(bpy.context.scene, samples, transmission)
    img, seconds = render_cycles(bpy.context.scene, CACHE / f"{name}-{key}.exr")
    for stale in list(CACHE.glob(f"{name}-*.npy")) + list(CACHE.glob(f"{name}-*.json")):
        stale.unlink()  # references of older versions of this scene
    np.save(npy, img)
    meta.write_text(json.dumps(dict(seconds=seconds, samples=samples, blender=bpy.app.version_string)))
    (CACHE / f"{name}-{key}.exr").unlink(missing_ok=True)
    return img, seconds, "rendered"


# ---- comparison ----------------------------------------------------------------------------------

def compare(toyrt_img, ref):
    a, b = toyrt_img[..., :3].astype(np.float64), ref[..., :3].astype(np.float64)
    mean_rel = float(np.abs(a - b).mean() / max(b.mean(), 1e-12))
    d = np.abs(np.clip(a, 0, 1) - np.clip(b, 0, 1)).max(axis=2)
    frac = float((d > PIXEL_FAIL).mean())
    bias = float((a - b).mean() / max(b.mean(), 1e-12))  # signed: TOYRT brighter when > 0
    return mean_rel, frac, bias


def save_png(path, img):
    """An sRGB PNG of a linear image (for looking at failures), rows from the top."""
    h, w = img.shape[:2]
    image = bpy.data.images.new(path.stem, w, h, alpha=True)
    try:
        rgba = np.ones((h, w, 4), np.float32)
        rgba[..., :3] = np.clip(img[..., :3], 0, 1)
        image.pixels.foreach_set(rgba[::-1].ravel())  # linear float -> byte with sRGB on save
        image.filepath_raw = str(path)
        image.file_format = "PNG"
        image.save()
    finally:
        bpy.data.images.remove(image)


def main():
    import render_toyrt

    toyrt = render_toyrt.native()
    sync = load_sync()
    wanted = {s for s in SCENES.split(",") if s}
    results, failures, sources = [], [], {}
    out_dir = CACHE / "last-run"
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, build, params, transmission in SCENES_SPEC:
        if (wanted and name not in wanted) or not applies(params):
            continue
        print(f"parity: {name}", flush=True)
        kit.clear_scene()
        build(params)
        kit.output(bpy.context.scene, WIDTH, HEIGHT)  # read by both engines
        bpy.context.view_layer.update()
        # Scenes where a bright light is seen through glass need more samples on both sides for the
        # noise to fall below the mean-difference threshold (a light's edge pixel has a standard
        # deviation of about L / (2 sqrt(spp))).
        factor = params.get("sample_factor", 1)
        cycles_spp, toyrt_spp = CYCLES_SAMPLES * factor, TOYRT_SAMPLES * factor
        key = cache_key(name, build, params, transmission, cycles_spp)
        ref, cycles_s, source = cycles_reference(name, key, transmission, cycles_spp)
        sources[source] = sources.get(source, 0) + 1
        if SAVE_REFS:
            save_reference(name, key, ref, cycles_s)

        warnings = []
        depsgraph = bpy.context.evaluated_depsgraph_get()
        t0 = time.perf_counter()
        scene_t, cam, stats = sync.export_scene(depsgraph, toyrt, report=lambda kind, msg: warnings.append(msg))
        scene_t.commit()
        t1 = time.perf_counter()
        img = scene_t.render(cam, samples=toyrt_spp, seed=0, max_specular_depth=max(transmission, 0))
        toyrt_s = time.perf_counter() - t1
        assert img.shape == ref.shape, f"{name}: TOYRT {img.shape} vs Cycles {ref.shape}"
        mean_rel, frac, bias = compare(img, ref)
        ok = mean_rel <= params.get("mean_limit", MEAN_LIMIT) and frac <= PIXEL_LIMIT
        asserted = (tuple(params.get("asserted_from", (0, 0, 0))) <= tuple(bpy.app.version)
                    < tuple(params.get("asserted_before", (99, 0, 0))))
        save_png(out_dir / f"{name}-toyrt.png", img)
        save_png(out_dir / f"{name}-cycles.png", ref)
        np.save(out_dir / f"{name}-toyrt.npy", img)
        np.save(out_dir / f"{name}-cycles.npy", ref)
        verdict = "ok" if ok else "FAIL" if asserted else "gap (reported)"
        print(f"  mean |diff| / mean = {mean_rel * 100:.3f} % (signed {bias * 100:+.3f} %), "
              f"pixels > {PIXEL_FAIL}: {frac * 100:.3f} %  -> {verdict}", flush=True)
        print(f"  TOYRT {toyrt_spp} spp: {toyrt_s:.2f} s render (+{t1 - t0:.3f} s export+commit); "
              f"Cycles {cycles_spp} spp: {cycles_s:.2f} s{'' if source == 'rendered' else f' ({source})'}; "
              f"export: {stats['meshes']} meshes, {stats['instances']} instances, {stats['lights']} lights, "
              f"approximated: {stats['approximated'] or 'nothing'}", flush=True)
        if warnings:
            print(f"  warning: {warnings}", flush=True)
        results.append(dict(name=name, mean_rel=mean_rel, frac=frac, bias=bias, ok=ok, toyrt_s=toyrt_s,
                            export_s=t1 - t0, cycles_s=cycles_s, mean_ref=float(ref[..., :3].mean()),
                            toyrt_spp=toyrt_spp, cycles_spp=cycles_spp, asserted=asserted))
        if not ok and asserted:
            failures.append(name)
    print(f"parity: Cycles references {sources}" + (
        "" if not sources.get("rendered") or SAVE_REFS else
        " (`make parity-refs` commits the rendered ones: tests/blender/parity_refs/)"), flush=True)
    if SAVE_REFS and not wanted:  # a whole run: references of scenes no longer here go
        names = {n for n, _, p, _ in SCENES_SPEC if applies(p)}
        for old in REFS.glob("*.npz"):
            if old.stem not in names:
                old.unlink()
    write_doc(results)
    return results, failures


def write_doc(results):
    if not results or len(results) != sum(applies(p) for _, _, p, _ in SCENES_SPEC):
        return  # a partial run (TOYRT_PARITY_SCENES) does not rewrite the report
    cpu = os.cpu_count()
    lines = [
        "# Parity with Cycles",
        "",
        "Generated by `tests/blender/test_cycles_parity.py` (run by `make test`), on Blender "
        f"{bpy.app.version_string}, {WIDTH}x{HEIGHT} pixels, {cpu} cores.",
        "",
        "Each scene is built with bpy, rendered by Cycles restricted to TOYRT's light transport (max bounces 0; "
        "for the glass scene transmission and glossy bounces 8 with diffuse bounces 0, so only specular chains "
        "through the glass; Box filter of width 1, no denoising, no adaptive sampling, light threshold 0, Standard "
        f"view transform, float EXR) at {CYCLES_SAMPLES} samples per pixel (the table gives each scene's count), "
        "and by TOYRT through the add-on's "
        f"scene sync (`addon/render_toyrt/sync.py`) at as many.",
        "",
        f"Pass: mean |TOYRT - Cycles| / mean(Cycles) <= {MEAN_LIMIT * 100:g} %, and at most {PIXEL_LIMIT * 100:g} % "
        f"of pixels with a channel differing by more than {PIXEL_FAIL} after clamping to [0, 1] (the rule of "
        "Blender's own render tests). Signed: mean (TOYRT - Cycles) / mean(Cycles).",
        "",
        "| scene | mean \\|diff\\| / mean | signed | pixels > 0.016 | result | TOYRT render | Cycles render |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in results:
        lines.append(f"| {r['name']} | {r['mean_rel'] * 100:.3f} % | {r['bias'] * 100:+.3f} % | "
                     f"{r['frac'] * 100:.3f} % | "
                     f"{'pass' if r['ok'] else 'FAIL' if r['asserted'] else 'gap (reported)'} | "
                     f"{r['toyrt_s']:.2f} s ({r['toyrt_spp']} spp) | "
                     f"{r['cycles_s']:.2f} s ({r['cycles_spp']} spp) |")
    lines += [
        "",
        "Times are wall-clock seconds of the render call alone (Cycles: `bpy.ops.render.render`, including its "
        "scene sync; a cached or committed reference (tests/blender/parity_refs/, `make parity-refs`) keeps the "
        "time of the run that made it).",
        "",
        "Notes:",
        ("- Point and spot lights of radius R: Cycles 3.4 renders them as a disk facing the shading point "
         "(Blender 4.0's soft falloff, on by default), and so does TOYRT (docs/render.md); point_near_sphere "
         "asks for a sphere, which 3.4 cannot make, so both render the disk. The sun is 3.4's tangent-disk "
         "disc, the spot 3.4's cosine-times-smoothstep edge, which ignores the object's scale "
         "(spot_soft_scaled). torus_file is TorusLightsCams_250_compressed.blend from Debian's "
         "assimp-testmodels: five 1 m lights of 100 W a metre above a torus; it rendered 24 % brighter "
         "when TOYRT made every round light a sphere."
         if bpy.app.version < (4, 0, 0) else
         "- Area lights: Cycles 4.x and later give an area light of power P the radiance P / (pi A), 3.4 "
         "P / (4 A); the exporter scales the power by 4 / pi on 4.x (docs/blender.md). Point and spot lights of "
         "radius R follow use_soft_falloff: a disk facing the shading point (on, the default) or a sphere "
         "(point_near_sphere). Sun discs have uniform radiance over their cone; spot edges are a smoothstep "
         "in the object's scaled frame (spot_soft_scaled widens along its scaled axis).\n"
         "- torus_file (TorusLightsCams_250_compressed.blend, Debian's assimp-testmodels): the gap is found and "
         "closed (2026-12-03). The torus has no material, so Cycles renders it with its default surface: a "
         "Diffuse BSDF of 0.8 grey on 3.4, but a Principled BSDF with its defaults on 5.0 (a 5.0 render of the "
         "torus without a material equals, bit for bit, one with an explicit default Principled, and is 0.9 % "
         "darker than one with a Diffuse 0.8; the Principled default is also in a 4.5-era Cycles source). TOYRT "
         "gave it the Diffuse on both: +0.901 % signed, 1.482 % mean |diff|, reported. With the add-on's default "
         "surface per version (`materials.DEFAULT_SURFACE_PRINCIPLED_FROM`, 4.5; 4.0-4.4 not verified): the "
         "table's figure (at 4x the samples since 2026-12-04; at 1024 spp the scene's noise put 3.4 at 0.6 %). "
         "Asserted at the 0.5 % limit on both versions. The earlier reading of \"2.6 % darker\" compared "
         "different settings."),
        "- Lights are seen by camera rays and through glass (Blender's per-object ray visibility, which the "
        "exporter passes on): glass_sphere_visible_light keeps Cycles' defaults and passes at 4x the samples "
        "(the light's image through the sphere is the noisiest part of both renders); glass_sphere and "
        "glass_sphere_float_texture hide the light from camera, glossy and transmission rays in both.",
        "- The world lights diffuse surfaces in both (TOYRT samples the constant background over the "
        "hemisphere) unless the world's diffuse ray visibility is off, which the exporter passes on: "
        "glass_sphere_visible_light keeps it on; the other glass scenes turn it off in both.",
        "- Glass: TOYRT's Fresnel dielectric reflects as well as refracts, so Cycles runs with glossy bounces "
        "equal to the transmission bounces (8; diffuse bounces 0). With glossy bounces 0 Cycles drops the "
        "reflections: TOYRT +0.6 % (1.25 % of pixels over 0.016).",
        "- Rough glass (docs/render.md, 'Rough Glass and Refraction'): rough_glass is a GGX glass ball of "
        "roughness 0.3, each version's model against its own Cycles. Light samples through a rough interface "
        "count the light-to-view pairs no microfacet refracts, as Cycles evaluates them (on one interface at "
        "roughness 0.7 they are 4-5 % of the light through it).",
        *(["- Multiscatter GGX glass (4.0+'s default): rough_glass_multiscatter has a white ball of roughness 0.6 "
           "and a tinted one of 0.35; TOYRT scales the lobe by 1 / E with E as Cycles' precomputed glass tables "
           "give it (recomputed on their grid) and darkens the tinted one by Cycles' multi-bounce Fresnel factor "
           "of its colour. Asserted at the 0.5 % limit (16x the samples: rough glass under an area lamp is noisy "
           "in both)."]
          if bpy.app.version >= (4, 0, 0) else []),
        "- 8-bit sRGB textures: Cycles filters an 8-bit sRGB image in its sRGB values and decodes to linear "
        "after the bilinear lookup; TOYRT does the same (Texture.EightBitSrgbIsFilteredBeforeDecodingAsCycles). "
        "Before that fix, decoding every texel at load made glass_sphere's magnified 8x8 checker +42 % too "
        "bright. Float images are kept linear by Blender and filtered linear by both (glass_sphere_float_texture).",
        "- Glossy (GGX) roughness sweeps and Mix/Add of Diffuse and Glossy: balls at roughness 0.05-1 over a "
        "diffuse floor, Cycles with glossy bounces 8 and diffuse bounces 0; these scenes pass at a mean "
        "difference of 0.5 % (the materials issue's limit), at 2x (point lamp) and 4x (area lamp, mix) the "
        "samples: the sharp balls' highlights are the noisiest pixels of both renders. The Glossy node is set to "
        "GGX (4.x/5.x default to Multiscatter GGX, which TOYRT renders as Cycles compensates it; 3.x's is a "
        "random walk, rendered as single-scatter GGX and noted).",
        "- Glossy balls lit by emissive meshes alone (emitters_glossy: a panel and a small glowing ball, 4x the "
        "samples) and by the HDRI world with its small sun (hdri_glossy, 2x): each glossy vertex samples an "
        "emissive triangle and a direction of the map beside its lobe, under MIS, as Cycles samples mesh lights "
        "and the background at every vertex (docs/lights.md, 'Emitters and the map at glossy and rough glass "
        "vertices'). Asserted on both at the 0.5 % limit.",
        "- Principled BSDF (docs/render.md, 'Principled BSDF and Multiscatter GGX'): principled_sweep_point and "
        "principled_specular_area (Metallic 0) are asserted on both: 4.0+'s Lambert base energy-layered under "
        "a GGX layer (Multiscatter GGX), 3.x's Burley diffuse (darker towards grazing, with a "
        "roughness-dependent retro-reflection) with the layer added. metal_sweep (Metallic 1, Blender's "
        "defaults otherwise: 3.x GGX with its Fresnel blend from the base colour, 4.0+ Multiscatter GGX with "
        "F82-tint) is asserted on both.",
        "- Alpha cut-outs (docs/render.md, 'Alpha cut-outs and the Transparent BSDF'): cut_out masks two planes "
        "with one generated 8-bit image's alpha (0, 0.5 and 1 cells) over a floor under a sun and the world: "
        "left a Mix Shader of a Transparent and a Diffuse BSDF (Fac the image's Alpha), right a Principled "
        "BSDF's Alpha; behind them a pane of a Transparent BSDF alone, tinted. Camera rays pass the holes "
        "(and half the 0.5 cells), shadow rays are attenuated by them "
        "(Cycles' transparent shadows, transparent_max_bounces 8 in both); asserted on both at the 0.5 % limit.",
        "- The world's ray visibility (docs/lights.md, 'The world's ray visibility'): world_hidden_from_glossy "
        "and world_hidden_from_transmission put a glossy ball (GGX, roughness 0.15) and a glass ball (IOR 1.45) "
        "on the checker floor in a blue world, hidden from glossy rays (black in reflections) or from "
        "transmission rays (black through glass); the lamp is hidden from glossy and glass rays, as in "
        "glass_sphere. Asserted on both at the 0.5 % limit.",
        "- Bump node (docs/render.md, 'Bump node'): bump puts one height image of sine bumps on a diffuse floor "
        "and on a Principled ball (inverted, Strength 0.6) under a low sun. 4.4+ (Filter Width) takes the "
        "height's slope at the point, as TOYRT by default; before 4.4 Cycles differences the height over the "
        "ray's footprint (the camera's pixel spread times the path length, kept across bounces) along its own "
        "two tangents, which the add-on asks TOYRT to copy (bump_footprint): on 3.4 the slope at the point left "
        "3.0 % (19.9 % of pixels off). Asserted on both.",
        *(["- Light linking (docs/lights.md, 'Light linking'; 4.0+ only): light_linking has a key lamp whose "
           "receiver collection EXCLUDEs the red box and whose blocker collection EXCLUDEs the grey box (it casts "
           "no key shadow), and a blue fill lamp whose receiver collection INCLUDEs the red box alone (floor and "
           "grey box unlit by it). Asserted at the 0.5 % limit."]
          if bpy.app.version >= (4, 0, 0) else []),
        "",
    ]
    DOC.write_text("\n".join(lines))
    print(f"parity: wrote {DOC}", flush=True)


if __name__ == "__main__":
    try:
        results, failures = main()
    except BaseException:  # any way out but success is a failure
        traceback.print_exc()
        print("parity: 0 passed, 1 failed (error)", flush=True)
        sys.exit(1)
    gaps = [r["name"] for r in results if not r["ok"] and not r["asserted"]]
    print(f"parity: {sum(r['ok'] for r in results)} passed, {len(failures)} failed"
          + (f" ({', '.join(failures)})" if failures else "")
          + (f"; reported, not asserted: {', '.join(gaps)}" if gaps else ""), flush=True)
    sys.exit(1 if failures else 0)
