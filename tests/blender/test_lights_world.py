# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_lights_world.py
# (`make test` runs it, also under the bpy module: tests/blender/run_with_bpy.py).
#
# Blender's lights and worlds through F12, against closed forms and for bad input (issue 13):
#   a sun over a floor             the pixel is albedo / pi x strength x cos (no noise: a delta sun)
#   a portal area light            exported as nothing (it emits nothing in Cycles)
#   a light with shadows off       its occluder casts no shadow (3.x cycles.cast_shadow, 4.x+ use_shadow)
#   an Environment Texture world   a missing image: the render finishes, one note names it, the sky
#                                  is the magenta placeholder; inf and NaN texels: a note, a finite
#                                  image; a 1 x 1 image: a uniform world (the floor's albedo x L)
#   a Principled BSDF's emission   seen by the camera as colour x strength (3.x and 4.x socket names)
#   light linking (4.0+)           a lamp whose receiver collection excludes the floor adds nothing
#                                  to it; an emissive mesh's linking is noted
import math
import os
import sys
import tempfile

import bpy
import mathutils
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]
import kit  # noqa: E402
from harness import check, counted_edit, live_sync, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-lights-world-")


def scene_with_floor(albedo=0.8):
    scene = kit.clear_scene()
    kit.output(scene, 16, 16)
    kit.float_exr(scene)
    kit.toyrt(scene, samples=4, seed=0)
    kit.plane("floor", 40.0, kit.diffuse("floor", (albedo,) * 3))
    kit.camera((0, 0, 10), ortho_scale=4.0, clip=(0.1, 100.0))
    kit.world((0, 0, 0))
    return scene


def render(name):
    path = os.path.join(TMP, name + ".exr")
    result, log = render_still(path)
    return result, kit.read_image(path) if os.path.exists(path) else None, log


def notes_of_export():
    """What the scene sync approximated or fell back on (the notes F12 reports), from a one-shot sync."""
    import render_toyrt
    from render_toyrt import sync
    notes = []
    _, _, stats = sync.export_scene(bpy.context.evaluated_depsgraph_get(), render_toyrt.native(),
                                    report=lambda kind, msg: notes.append(msg))
    return stats, " ".join(notes) + " " + " ".join(stats["approximated"])


def test_sun_over_a_floor_gives_strength_cos_over_pi():
    scene_with_floor(0.8)
    tilt = 0.5
    kit.sun_light("sun", 3.0, (math.sin(tilt), 0.0, -math.cos(tilt)), angle=0.0)
    result, px, _ = render("sun")
    expected = 0.8 / math.pi * 3.0 * math.cos(tilt)
    got = float(px[..., 0].mean()) if px is not None else float("nan")
    check(result == {"FINISHED"} and abs(got - expected) <= 1e-4 * expected,
          f"a sun of 3 W/m^2 at {tilt} rad: pixel {got:.5f}, closed form {expected:.5f}")


def sun_over_floor(name, tilt, **light_settings):
    """The floor (albedo 0.8) under a hard sun `tilt` radians from the zenith, with the light's
    `light_settings`: (F12's result, pixels, the sun's cosine on the floor as Blender placed it)."""
    scene_with_floor(0.8)
    sun = kit.sun_light("sun", 3.0, (math.sin(tilt), 0.0, -math.cos(tilt)), angle=0.0)
    for key, value in light_settings.items():
        setattr(sun.data, key, value)
    bpy.context.view_layer.update()
    towards = sun.matrix_world.to_3x3() @ mathutils.Vector((0.0, 0.0, -1.0))
    cos = -towards.normalized().z
    result, px, _ = render(name)
    return result, px, cos


def test_a_grazing_sun_gives_strength_cos_over_pi_on_every_pixel():
    # Down to 0.01 degrees above the horizon: no pixel shadowed by the floor it leaves (the
    # shadow ray runs almost along it), none lit too much, none NaN.
    for degrees in (80.0, 89.0, 89.9, 89.99):
        result, px, cos = sun_over_floor("grazing_sun", math.radians(degrees))
        expected = 0.8 / math.pi * 3.0 * cos
        got = px[..., 0] if px is not None else np.full(1, np.nan)
        check(result == {"FINISHED"} and np.isfinite(px).all()
              and np.abs(got / expected - 1.0).max() <= 1e-3,
              f"a sun {degrees} degrees from the zenith: pixels {got.min():.4g}-{got.max():.4g}, "
              f"closed form {expected:.4g}")


def test_light_exposure_scales_by_two_to_its_power():
    # Blender 4.0+: every light's power times 2^exposure, as Cycles.
    scene_with_floor()
    if not hasattr(bpy.data.lights.new("probe", "SUN"), "exposure"):
        print("  skipped: this Blender's lights have no exposure (4.0+)")
        return
    result, px, cos = sun_over_floor("exposed_sun", 0.5, exposure=1.5)
    expected = 0.8 / math.pi * 3.0 * cos * 2.0 ** 1.5
    got = float(px[..., 0].mean()) if px is not None else float("nan")
    check(result == {"FINISHED"} and abs(got / expected - 1.0) <= 1e-4,
          f"a sun of exposure 1.5: pixel {got:.5f}, closed form {expected:.5f}")


def test_light_temperature_renders_as_in_cycles():
    # Blender 4.5+: the light's colour times its blackbody colour. Cycles is the oracle: a hard
    # sun on a flat floor, direct light only, is exact at any sample count in both engines.
    scene_with_floor()
    if not hasattr(bpy.data.lights.new("probe", "SUN"), "use_temperature"):
        print("  skipped: this Blender's lights have no temperature (4.5+)")
        return
    settings = dict(use_temperature=True, temperature=3200.0, color=(0.9, 1.0, 0.8))
    result, px, _ = sun_over_floor("warm_sun", 0.5, **settings)
    kit.cycles(bpy.context.scene, samples=4, specular_depth=0)
    cycles_result, reference, _ = render("warm_sun_cycles")
    got = px[..., :3].reshape(-1, 3).mean(0) if px is not None else np.full(3, np.nan)
    want = reference[..., :3].reshape(-1, 3).mean(0) if reference is not None else np.full(3, np.nan)
    check(result == cycles_result == {"FINISHED"} and np.allclose(got, want, rtol=1e-3)
          and not np.allclose(want, want[0], rtol=0.05),
          f"a 3200 K sun: TOYRT {np.round(got, 5)}, Cycles {np.round(want, 5)}")


def test_a_principled_emitter_lights_the_floor_as_its_closed_form():
    # A 1 m Principled square glowing L = colour x strength, 1 m over the floor and facing it: the
    # floor's pixel under its centre is albedo / pi x L x (the square's E / L, four corner
    # rectangles), found by sampling the emissive triangles.
    scene_with_floor(0.8)
    kit.toyrt(bpy.context.scene, samples=64, seed=0)
    mat = kit.principled("glowing_panel", (0.0, 0.0, 0.0))
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    kit.input_of(bsdf, "Emission Color", "Emission").default_value = (1.0, 0.5, 0.25, 1.0)   # 4.0+ / 3.x
    bsdf.inputs["Emission Strength"].default_value = 4.0
    panel = kit.plane("panel", 1.0, mat, (0.0, 0.0, 1.0))
    panel.rotation_euler = (math.pi, 0.0, 0.0)   # facing down
    kit.camera((0.0, 0.0, 0.5), ortho_scale=0.01, clip=(0.01, 10.0))   # under the panel
    x = 0.5   # half the side over the height
    corner = x / math.sqrt(1 + x * x) * math.atan(x / math.sqrt(1 + x * x))
    irradiance_over_radiance = 4 * corner
    expected = 0.8 / math.pi * 4.0 * np.array([1.0, 0.5, 0.25]) * irradiance_over_radiance
    result, px, _ = render("principled_panel")
    got = px[..., :3].reshape(-1, 3).mean(0) if px is not None else np.full(3, np.nan)
    check(result == {"FINISHED"} and np.allclose(got, expected, rtol=0.01),
          f"under a glowing Principled square: {np.round(got, 4)}, closed form {np.round(expected, 4)}")


def test_portal_is_not_a_light():
    scene_with_floor()
    panel = kit.area_light("portal", (0, 0, 3), 500.0, 2.0)
    panel.data.cycles.is_portal = True
    stats, _ = notes_of_export()
    result, px, _ = render("portal")
    check(stats["lights"] == 0 and px is not None and not px[..., :3].any(),
          f"a portal exports no light ({stats['lights']}) and lights nothing")


def test_shadow_switch_removes_the_shadow():
    scene_with_floor()
    kit.box("blocker", 2.0, (0, 0, 3), kit.diffuse("grey"))
    kit.camera((0, 0, 1.5), ortho_scale=1.0, clip=(0.1, 100.0))  # below the blocker, seeing the floor
    sun = kit.sun_light("sun", 2.0, (0.0, 0.0, -1.0), angle=0.0)
    _, shadowed, _ = render("shadowed")
    if hasattr(sun.data, "use_shadow"):
        sun.data.use_shadow = False   # 4.x+
    else:
        sun.data.cycles.cast_shadow = False
    _, unshadowed, _ = render("unshadowed")
    lit = 0.8 / math.pi * 2.0
    check(shadowed is not None and shadowed[8, 8, 0] == 0.0 and abs(unshadowed[8, 8, 0] - lit) <= 1e-4 * lit,
          f"under the blocker: {shadowed[8, 8, 0]:.4f} with shadows, {unshadowed[8, 8, 0]:.4f} without (lit {lit:.4f})")


def environment(pixels, name):
    rgba = np.concatenate([pixels, np.ones(pixels.shape[:2] + (1,), np.float32)], axis=2)
    return kit.environment_world(kit.image(name, rgba, float_buffer=True))


def test_missing_environment_image_is_magenta_with_one_note():
    scene_with_floor()
    image = bpy.data.images.new("gone_sky", 4, 2, float_buffer=True)
    image.source = "FILE"
    image.filepath = os.path.join(TMP, "no-such-dir", "sky.exr")
    kit.environment_world(image)
    kit.camera((0, 0, 0), rotation=(math.pi, 0, 0), ortho_scale=1.0)   # looking straight up at the sky
    _, notes = notes_of_export()
    result, px, _ = render("missing_sky")
    r, g, b = px[..., :3].reshape(-1, 3).mean(0) if px is not None else (0, 0, 0)
    check(result == {"FINISHED"} and "gone_sky" in notes and "magenta" in notes and g == 0.0 and r > 0.5,
          f"a missing HDRI: the render finishes, the note names it, the sky is magenta ({r:.2f} {g:.2f} {b:.2f})")


def test_unreadable_environment_image_is_magenta_with_one_note():
    # The world's image file exists but holds no image Blender can decode (a .blend that refers to
    # a file overwritten by something else): the world renders as a missing one does.
    scene_with_floor()
    path = os.path.join(TMP, "broken_sky.exr")
    with open(path, "wb") as f:
        f.write(b"this file holds no image\n" * 200)
    image = bpy.data.images.new("broken_sky", 4, 2, float_buffer=True)
    image.source = "FILE"
    image.filepath = path
    kit.environment_world(image)
    kit.camera((0, 0, 0), rotation=(math.pi, 0, 0), ortho_scale=1.0)
    _, notes = notes_of_export()
    result, px, _ = render("broken_sky")
    r, g, b = px[..., :3].reshape(-1, 3).mean(0) if px is not None else (0, 0, 0)
    check(result == {"FINISHED"} and "broken_sky" in notes and "magenta" in notes and g == 0.0 and r > 0.5,
          f"an unreadable HDRI: the render finishes, the note names it, the sky is magenta ({r:.2f} {g:.2f} {b:.2f})")


def test_non_finite_texels_are_noted_and_the_image_stays_finite():
    scene_with_floor()
    sky = np.full((8, 16, 3), 0.5, np.float32)
    sky[6, 3] = np.inf
    sky[2, 9] = np.nan
    environment(sky, "bad_sky")
    _, notes = notes_of_export()
    result, px, _ = render("bad_sky")
    check(result == {"FINISHED"} and "non-finite" in notes and px is not None and np.isfinite(px).all(),
          f"inf and NaN texels: a note ({'non-finite' in notes}) and a finite image")


def test_one_pixel_environment_is_a_uniform_world():
    scene_with_floor(0.5)
    environment(np.full((1, 1, 3), 0.6, np.float32), "one_pixel")
    kit.toyrt(bpy.context.scene, samples=64, seed=0)
    result, px, _ = render("one_pixel")
    got = float(px[..., 0].mean()) if px is not None else float("nan")
    check(result == {"FINISHED"} and abs(got - 0.3) <= 0.01 * 0.3,
          f"a 1 x 1 environment of 0.6 lights a floor of albedo 0.5 with {got:.4f} (0.3)")


def test_a_world_hidden_from_the_camera_still_lights_the_floor():
    """World > Ray Visibility > Camera off (world.cycles_visibility.camera): the camera sees black
    where it sees the sky, while the world lights the floor with albedo x L as before."""
    scene_with_floor(0.5)
    environment(np.full((1, 1, 3), 0.6, np.float32), "hidden_sky")
    kit.toyrt(bpy.context.scene, samples=64, seed=0)
    bpy.context.scene.world.cycles_visibility.camera = False
    result, floor_px, _ = render("hidden_sky_floor")
    kit.camera((0, 0, 0), rotation=(math.pi, 0, 0), ortho_scale=1.0)   # looking straight up at the sky
    _, sky_px, _ = render("hidden_sky_up")
    floor = float(floor_px[..., 0].mean()) if floor_px is not None else float("nan")
    sky = sky_px[..., :4].reshape(-1, 4) if sky_px is not None else np.ones((1, 4))
    check(result == {"FINISHED"} and abs(floor - 0.3) <= 0.01 * 0.3 and (sky[:, :3] == 0).all()
          and (sky[:, 3] == 1).all(), f"the floor is still lit ({floor:.4f}, 0.3); the sky is opaque black "
          f"(max {sky[:, :3].max():.3g})")


def test_principled_emission_is_seen_as_colour_times_strength():
    scene_with_floor()
    mat = kit.principled("glowing", (0.5, 0.5, 0.5))
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    kit.input_of(bsdf, "Emission Color", "Emission").default_value = (0.2, 0.5, 1.0, 1.0)   # 4.0+ / 3.x
    bsdf.inputs["Emission Strength"].default_value = 3.0
    kit.plane("glowing_plane", 10.0, mat, (0, 0, 0.5))
    result, px, _ = render("principled_emission")
    got = px[..., :3].reshape(-1, 3).mean(0) if px is not None else np.zeros(3)
    check(result == {"FINISHED"} and np.allclose(got, (0.6, 1.5, 3.0), rtol=1e-5),
          f"a Principled BSDF's emission, no lights: the camera sees {np.round(got, 4)} (0.6 1.5 3)")


def test_a_lamp_whose_receiver_collection_excludes_the_floor_does_not_light_it():
    """Light linking (4.0+): a second lamp whose receiver collection EXCLUDEs the floor leaves the
    image as the first lamp's alone (both radius 0: no noise); an emissive plane's receiver
    collection links it as a lamp's (no note), its blocker collection is noted (not followed).
    Blender 3.x has no light linking: nothing to test."""
    if "light_linking" not in bpy.types.Object.bl_rna.properties.keys():
        check(True, "no light linking in this Blender (3.x): nothing is read")
        return
    scene_with_floor(0.5)
    kit.point_light("key", (0.5, 0.0, 3.0), 300.0)
    result_alone, alone, _ = render("linking_alone")
    other = kit.point_light("other", (-1.0, 0.5, 2.0), 500.0)
    receivers = bpy.data.collections.new("other_receivers")
    receivers.objects.link(bpy.data.objects["floor"])
    receivers.collection_objects[0].light_linking.link_state = "EXCLUDE"
    other.light_linking.receiver_collection = receivers
    result, linked, _ = render("linking_linked")
    glow = kit.plane("glow", 0.5, kit.emission("glow", (1.0, 1.0, 1.0), 1.0), (3.0, 3.0, 1.0))
    glow.light_linking.receiver_collection = receivers
    _, receiver_notes = notes_of_export()
    glow.light_linking.blocker_collection = receivers
    _, notes = notes_of_export()
    same = alone is not None and linked is not None and np.allclose(linked, alone, rtol=1e-6, atol=0)
    check(result_alone == result == {"FINISHED"} and same and "glow" not in receiver_notes
          and "glow" in notes and "shadow linking" in notes,
          f"the excluded lamp adds nothing to the floor ({same}); the emissive plane's receivers are followed "
          f"({'glow' not in receiver_notes}), its blockers noted ({'glow' in notes})")


def test_light_linking_edits_reach_the_viewport_as_a_fresh_export():
    """Light linking edited while the viewport renders (4.0+): a SceneSync kept up to date with
    Blender's depsgraph.updates, as the viewport's is, renders what a fresh export of the same
    scene renders, bit for bit, after each edit: a receiver collection given to a lamp, the floor
    excluded from it, then included again; and the excluded lamp really drops out."""
    if "light_linking" not in bpy.types.Object.bl_rna.properties.keys():
        check(True, "no light linking in this Blender (3.x): nothing to edit")
        return
    import render_toyrt
    from render_toyrt import sync
    toyrt = render_toyrt.native()
    scene_with_floor(0.5)
    kit.point_light("key", (0.5, 0.0, 3.0), 300.0)
    other = kit.point_light("other", (-1.0, 0.5, 2.0), 500.0)
    receivers = bpy.data.collections.new("live_receivers")
    means = {}
    with live_sync(sync, toyrt) as cache:
        def same_as_fresh(label):
            fresh, camera, _ = sync.export_scene(bpy.context.evaluated_depsgraph_get(), toyrt)
            fresh.commit()
            a, b = cache.scene.render(camera, samples=2, seed=0), fresh.render(camera, samples=2, seed=0)
            means[label] = float(a[..., :3].mean())
            check(np.array_equal(a, b), f"{label}: the live scene renders what a fresh export renders "
                                        f"(max difference {np.abs(a - b).max():.3g})")

        same_as_fresh("before any linking")

        def give_collection():
            receivers.objects.link(bpy.data.objects["floor"])
            other.light_linking.receiver_collection = receivers
        counted_edit(cache, "a receiver collection holding the floor given to a lamp", give_collection)
        same_as_fresh("receiver collection given")
        counted_edit(cache, "the floor excluded", lambda: setattr(
            receivers.collection_objects[0].light_linking, "link_state", "EXCLUDE"))
        same_as_fresh("floor excluded")
        counted_edit(cache, "and included again", lambda: setattr(
            receivers.collection_objects[0].light_linking, "link_state", "INCLUDE"))
        same_as_fresh("floor included again")
    check(means["floor excluded"] < 0.9 * means["before any linking"]
          and abs(means["floor included again"] / means["before any linking"] - 1) < 1e-6,
          f"the excluded lamp drops out and comes back: mean {means}")


PARTS = [test_sun_over_a_floor_gives_strength_cos_over_pi,
         test_a_grazing_sun_gives_strength_cos_over_pi_on_every_pixel, test_light_exposure_scales_by_two_to_its_power,
         test_light_temperature_renders_as_in_cycles, test_a_principled_emitter_lights_the_floor_as_its_closed_form,
         test_portal_is_not_a_light,
         test_shadow_switch_removes_the_shadow, test_missing_environment_image_is_magenta_with_one_note,
         test_unreadable_environment_image_is_magenta_with_one_note,
         test_non_finite_texels_are_noted_and_the_image_stays_finite, test_one_pixel_environment_is_a_uniform_world,
         test_a_world_hidden_from_the_camera_still_lights_the_floor,
         test_principled_emission_is_seen_as_colour_times_strength,
         test_a_lamp_whose_receiver_collection_excludes_the_floor_does_not_light_it,
         test_light_linking_edits_reach_the_viewport_as_a_fresh_export]
run_script(PARTS, "lights and world", TMP)
