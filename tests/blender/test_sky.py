# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_sky.py
# (`make test` runs it, also under the bpy module: tests/blender/run_with_bpy.py).
#
# A world's Sky Texture through F12 (issue 13, docs/lights.md):
#   Preetham          the camera looking up sees the model's value x the Background
#                     strength; a floor under it gets albedo / pi x the model's irradiance (the
#                     model integrated over the hemisphere here, independently of the baked map)
#   Hosek-Wilkie      drawn as Preetham with the same sun and turbidity (x a measured brightness
#                     factor), with one note
#   an edit           the viewport's sync sends the new map into the world's one texture
#   the atmosphere    Nishita (3.4-4.x), Single / Multiple Scattering (5.0): a blue sky, a sunlit
#   types             floor brighter than the sky alone lights it, finite pixels, one note
import math
import os
import sys
import tempfile

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]
import kit  # noqa: E402
from harness import check, live_sync, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-sky-")
SUN = (0.35, -0.55, 0.76)          # about 50 degrees up
PREETHAM = dict(sun_direction=SUN, turbidity=3.0)
TILT = 0.3
UP = np.array([0.0, math.sin(TILT), math.cos(TILT)])


def scene(albedo=0.8, samples=64):
    s = kit.clear_scene()
    kit.output(s, 16, 16)
    kit.float_exr(s)
    kit.toyrt(s, samples=samples, seed=0)
    if albedo is not None:
        kit.plane("floor", 40.0, kit.diffuse("floor", (albedo,) * 3))
        kit.camera((0, 0, 10), ortho_scale=4.0, clip=(0.1, 100.0))
    else:
        # Orthographic, so every pixel looks along one direction: up, tilted towards +Y by TILT
        # (not at the zenith itself, where the map's lookup holds its top row: docs/lights.md).
        kit.camera((0, 0, 0), rotation=(math.pi - TILT, 0, 0), ortho_scale=1.0)
    return s


def render(name):
    path = os.path.join(TMP, name + ".exr")
    result, _ = render_still(path)
    px = kit.read_image(path) if os.path.exists(path) else np.full((1, 1, 4), np.nan, np.float32)
    return result, px[..., :3].reshape(-1, 3)


def notes_of_export():
    import render_toyrt
    from render_toyrt import sync
    notes = []
    _, _, stats = sync.export_scene(bpy.context.evaluated_depsgraph_get(), render_toyrt.native(),
                                    report=lambda kind, msg: notes.append(msg))
    return " ".join(notes) + " " + " ".join(stats["approximated"])


def model():
    from render_toyrt import sky
    return sky.Preetham.make(SUN, PREETHAM["turbidity"])


def hemisphere_irradiance(radiance, n_theta=300, n_phi=600):
    theta = (np.arange(n_theta) + 0.5) / n_theta * (np.pi / 2)
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2 * np.pi
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    weight = (np.cos(th) * np.sin(th))[..., None] * (np.pi / 2 / n_theta) * (2 * np.pi / n_phi)
    return (radiance(d) * weight).sum((0, 1))


def test_the_camera_sees_the_preetham_sky_times_the_strength():
    scene(albedo=None, samples=4)
    kit.sky_world("PREETHAM", strength=2.0, **PREETHAM)
    result, px = render("zenith")
    expected = 2.0 * model().radiance(UP)
    got = px.mean(0)
    check(result == {"FINISHED"} and np.allclose(got, expected, rtol=1e-3),
          f"looking up at a Preetham sky of strength 2: {np.round(got, 4)} ({np.round(expected, 4)})")


def test_a_floor_under_a_preetham_sky_gets_the_models_irradiance():
    scene(0.8)
    kit.sky_world("PREETHAM", **PREETHAM)
    notes = notes_of_export()
    result, px = render("floor")
    expected = 0.8 / math.pi * hemisphere_irradiance(model().radiance)
    got = px.mean(0)
    check(result == {"FINISHED"} and np.allclose(got, expected, rtol=0.02) and "Sky" not in notes,
          f"a floor of albedo 0.8: {np.round(got, 4)} ({np.round(expected, 4)}), no note ({notes.strip()!r})")


def test_hosek_wilkie_is_drawn_as_preetham_with_one_note():
    scene(albedo=None, samples=4)
    kit.sky_world("HOSEK_WILKIE", **PREETHAM)
    notes = notes_of_export()
    result, px = render("hosek")
    from render_toyrt.world_sky import HOSEK_AS_PREETHAM
    expected = HOSEK_AS_PREETHAM * model().radiance(UP)
    check(result == {"FINISHED"} and np.allclose(px.mean(0), expected, rtol=1e-3)
          and notes.count("Hosek-Wilkie drawn as Preetham") == 1,
          f"Hosek-Wilkie: Preetham's sky x {HOSEK_AS_PREETHAM} {np.round(px.mean(0), 4)} and one note "
          f"({notes.strip()!r})")


def test_an_edited_sky_is_sent_again_into_its_texture():
    """The viewport's sync: a new turbidity sends the new map into the world's one texture."""
    import render_toyrt
    from render_toyrt import sky, sync
    from render_toyrt.camera import export_camera

    scene(albedo=None, samples=4)
    world = kit.sky_world("PREETHAM", **PREETHAM)
    node = world.node_tree.nodes["Sky Texture"]
    with live_sync(sync, render_toyrt.native()) as live:
        cam = export_camera(bpy.context.evaluated_depsgraph_get())
        before = live.scene.render(cam, samples=1)[..., :3].reshape(-1, 3).mean(0)
        node.turbidity = 6.0
        bpy.context.view_layer.update()
        after = live.scene.render(cam, samples=1)[..., :3].reshape(-1, 3).mean(0)
        textures = len(live.textures)
    expected = sky.Preetham.make(SUN, 6.0).radiance(UP)
    check(np.allclose(before, model().radiance(UP), rtol=1e-3) and np.allclose(after, expected, rtol=1e-3)
          and textures == 1, f"turbidity 3 -> 6 in the viewport: {np.round(after, 4)} ({np.round(expected, 4)}), "
          f"{textures} texture")


def atmosphere_types():
    items = bpy.types.ShaderNodeTexSky.bl_rna.properties["sky_type"].enum_items.keys()
    return [t for t in ("NISHITA", "SINGLE_SCATTERING", "MULTIPLE_SCATTERING") if t in items]


def test_the_atmosphere_types_give_a_blue_sky_a_sunlit_floor_and_a_note():
    for kind in atmosphere_types():
        settings = dict(sun_elevation=math.radians(40.0), sun_rotation=math.radians(30.0))
        scene(albedo=None, samples=4)
        kit.sky_world(kind, **settings)
        notes = notes_of_export()
        _, up = render(f"{kind}_up")
        zenith = up.mean(0)   # (near the zenith)
        scene(0.8)
        kit.sky_world(kind, **settings)
        result, floor = render(f"{kind}_floor")
        scene(0.8)
        kit.sky_world(kind, sun_disc=False, **settings)
        _, no_disc = render(f"{kind}_floor_no_disc")
        lit, sky_only = floor.mean(0), no_disc.mean(0)
        check(result == {"FINISHED"} and np.isfinite(floor).all() and zenith[2] > zenith[0] > 0
              and lit[1] > 2.0 * sky_only[1] > 0 and notes.count("drawn by TOYRT's own") == 1,
              f"{kind}: zenith {np.round(zenith, 3)} (blue), floor {np.round(lit, 3)} with the sun's disc, "
              f"{np.round(sky_only, 3)} without; one note ({notes.strip()!r})")


PARTS = [test_the_camera_sees_the_preetham_sky_times_the_strength,
         test_a_floor_under_a_preetham_sky_gets_the_models_irradiance,
         test_hosek_wilkie_is_drawn_as_preetham_with_one_note, test_an_edited_sky_is_sent_again_into_its_texture,
         test_the_atmosphere_types_give_a_blue_sky_a_sunlit_floor_and_a_note]
run_script(PARTS, "sky", TMP)
