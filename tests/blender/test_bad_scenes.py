# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_bad_scenes.py
# (`make test` runs it, also under the bpy module: tests/blender/run_with_bpy.py).
#
# The Blender part of the bad-input catalogue (issue 7; docs/robustness.md, "Blender"): one check
# per case, each with the outcome a user should get. F12's operator (bpy.ops.render.render) runs
# the engine as a user's render does; its outcome is a result, a warning report (the render still
# finishes), or an error report (the operator raises RuntimeError; in batch mode `blender -b`
# exits non-zero and writes no image, checked on the command line where a blender executable of
# this version exists).
#
#   case                              outcome
#   empty scene (a camera, nothing)   result: an image of the world colour (black), no error
#   no camera                         error report naming the camera; blender -b exits non-zero
#   meshes with only edges / points   result: nothing to hit, the image of an empty scene
#   object scaled to zero             result: the object is not there (the image without it)
#   NaN vertex coordinates            result: triangles using them are dropped, the rest renders
#   a million units from the origin   result: the image of the same scene at the origin
#   missing image file                warning naming the image; magenta placeholder
#   unsupported shader nodes          warning naming the nodes; the image is lit
#   library-linked object             result: the image of the same object made locally
#   100,000 objects                   result; export time and memory printed (not timed)
import os
import resource
import subprocess
import sys
import tempfile
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-bad-scenes-")
HAS_BINARY = bool(bpy.app.binary_path) and not os.environ.get("TOYRT_NO_BLENDER_BINARY")


# ---- scene building: the kit (scenes/kit.py) --------------------------------------------------

def clear_scene():
    """An empty scene (kit.clear_scene) rendered by TOYRT at 4 samples, seed 0, to 32 x 32 float EXR stills."""
    scene = kit.clear_scene()
    kit.output(scene, 32, 32)
    kit.float_exr(scene)
    kit.toyrt(scene, samples=4, seed=0)
    return scene


def camera(location=(0, 0, 10), scale=6.0):
    """Orthographic, looking down -Z."""
    return kit.camera(location, ortho_scale=scale, clip=(0.1, 100.0))


def basic_scene(offset=(0.0, 0.0, 0.0)):
    """A floor, a cube and a point light under an ortho camera, all moved by `offset`."""
    scene = clear_scene()
    ox, oy, oz = offset
    kit.plane("floor", 20.0, kit.diffuse("grey"), (ox, oy, oz))
    kit.box("box", 1.5, (ox + 0.5, oy + 0.3, oz + 0.75), kit.diffuse("red", (0.8, 0.1, 0.1)))
    kit.point_light("lamp", (ox + 2.0, oy - 1.5, oz + 4.0), 300.0)
    camera((ox, oy, oz + 10.0))
    return scene


def render(name="image"):
    """F12 with the still written to a file: (operator result or the error, pixels or None, output)."""
    path = os.path.join(TMP, name + ".exr")
    if os.path.exists(path):
        os.remove(path)
    result, log = render_still(path)
    return result, kit.read_image(path) if os.path.exists(path) else None, log


def warnings_in(log):
    # In background mode a note is printed as 'TOYRT note: ...', never as Blender's 'Warning:'
    # (render_toyrt/report.py: farm managers fail a task on that word).
    return [line for line in log.splitlines() if line.startswith("TOYRT note: ")]


def errors_in(log):
    return [line for line in log.splitlines() if line.startswith("Error") and "TOYRT" in line]


def export_stats():
    import render_toyrt
    from render_toyrt import sync
    _, _, stats = sync.export_scene(bpy.context.evaluated_depsgraph_get(), render_toyrt.native())
    return stats


# ---- the cases ------------------------------------------------------------------------------------

def test_empty_scene():
    clear_scene()
    camera()
    result, px, log = render("empty")
    check(result == {"FINISHED"} and px is not None and px.shape == (32, 32, 4) and not errors_in(log),
          f"an empty scene renders ({result}) without an error report")
    check(px is not None and not px[..., :3].any(), "and the image is black (no world, nothing to see)")


def test_no_camera():
    scene = basic_scene()
    scene.camera = None
    result, px, log = render("nocam")
    check(isinstance(result, str) and "camera" in result.lower() and px is None,
          f"no camera: an error report ({result!r:.90}) and no image")
    if not HAS_BINARY:
        print("  skipped: blender -b exit status (bpy module: no blender executable of this version)", flush=True)
        return
    blend = os.path.join(TMP, "nocam.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend, copy=True)
    out = os.path.join(TMP, "nocam_")
    run = subprocess.run([bpy.app.binary_path, "-b", blend, "-E", "TOYRT", "-o", out, "-F", "PNG", "-f", "1"],
                         capture_output=True, text=True, timeout=300)
    said = (run.stdout + run.stderr).lower()
    check(run.returncode != 0 and not os.path.exists(out + "0001.png") and "camera" in said,
          f"no camera in batch mode: blender -b exits {run.returncode}, writes no image, says why")


def test_edges_and_points_only():
    clear_scene()
    kit.mesh_object("edges", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], edges=[(0, 1), (1, 2), (2, 3), (3, 0)])
    kit.mesh_object("points", [(x * 0.3, 0.5, 0.2) for x in range(10)])
    kit.point_light("lamp", (0, 0, 3), 300.0)
    camera()
    stats = export_stats()
    check(stats["meshes"] == 0 and stats["instances"] == 0 and stats["triangles"] == 0,
          f"meshes with only edges or only points export nothing ({stats['meshes']} meshes, "
          f"{stats['instances']} instances)")
    result, px, log = render("edges")
    check(result == {"FINISHED"} and px is not None and not px[..., :3].any() and not errors_in(log),
          "and render as an empty scene (black, no error)")


def test_zero_scale():
    basic_scene()
    _, reference, _ = render("without_box")
    bpy.data.objects.remove(bpy.data.objects["box"])
    _, without, _ = render("without")
    basic_scene()
    bpy.data.objects["box"].scale = (0.0, 0.0, 0.0)
    result, px, log = render("zero_scale")
    check(result == {"FINISHED"} and not errors_in(log), f"an object scaled to zero renders ({result!r:.120})")
    same = px is not None and without is not None and float(np.abs(px - without).max()) <= 1e-6
    check(same and not np.array_equal(reference, without),
          "and the image is that of the scene without the object (it is nowhere)")


def test_nan_vertices():
    scene = clear_scene()
    kit.plane("floor", 20.0, material=kit.diffuse("grey"))
    # Two triangles: the first has a NaN vertex, the second is fine and covers the camera's centre.
    nan = float("nan")
    kit.mesh_object("broken", [(-1, -1, 1), (1, -1, 1), (nan, 0, 1), (-1, -1, 1), (1, -1, 1), (0, 2, 1)],
                    faces=[(0, 1, 2), (3, 4, 5)], material=kit.diffuse("red", (0.8, 0.1, 0.1)))
    kit.point_light("lamp", (0, 0, 4), 300.0)
    camera(scale=6.0)
    scene.render.resolution_x = scene.render.resolution_y = 32
    result, px, log = render("nan")
    check(result == {"FINISHED"} and px is not None and np.isfinite(px).all() and not errors_in(log),
          f"a mesh with a NaN vertex renders ({result!r:.120}), every pixel finite")
    if px is not None:
        centre = px[16, 16, :3]
        check(centre[0] > 4 * max(centre[1], 1e-6), f"the triangle without NaN is there (red at the centre: {centre})")


def test_far_from_origin():
    basic_scene()
    _, near, _ = render("origin")
    basic_scene(offset=(1.0e6, -1.0e6, 0.0))
    result, far, log = render("far")
    check(result == {"FINISHED"} and far is not None and not errors_in(log),
          "a scene a million units from the origin renders")
    if far is not None and near is not None:
        a, b = far[..., :3].astype(np.float64), near[..., :3].astype(np.float64)
        mean_rel = float(np.abs(a - b).mean() / b.mean())
        frac = float((np.abs(a - b).max(axis=2) > 0.05 * b.max()).mean())
        # float32 positions there are 1/16 unit apart: edges may move by a pixel, shading by a little.
        check(mean_rel < 0.02 and frac < 0.05,
              f"and looks as the same scene at the origin: mean |diff| {mean_rel * 100:.2f} % of the mean, "
              f"{frac * 100:.1f} % of pixels off by more than 5 % of the peak")


def test_missing_image():
    clear_scene()
    image = bpy.data.images.new("gone", 4, 4)
    image.source = "FILE"
    image.filepath = os.path.join(TMP, "no-such-dir", "gone.png")
    kit.plane("floor", 20.0, kit.diffuse("textured", image=image))
    kit.point_light("lamp", (0, 0, 3), 300.0)
    camera()
    result, px, log = render("missing")
    warned = [w for w in warnings_in(log) if "gone" in w and "magenta" in w]
    check(result == {"FINISHED"} and px is not None and len(warned) == 1,
          f"a missing image file: the render finishes with one warning naming it: {warned[:1]}")
    r, g, b = px[8:24, 8:24, :3].reshape(-1, 3).mean(0)
    check(r > 0.1 and g == 0.0 and abs(r - b) <= 1e-3 * r,
          f"the placeholder is magenta (R {r:.3f} G {g:.3f} B {b:.3f})")


def test_unsupported_nodes():
    clear_scene()
    # A Toon BSDF with a Principled Volume, and a Mix Shader of a Diffuse and a Translucent BSDF
    # (the mix is modelled; the Translucent BSDF inside it is what is approximated).
    mat, toon = kit.surface("odd", "ShaderNodeBsdfToon")
    toon.inputs["Color"].default_value = (0.2, 0.7, 0.3, 1.0)
    volume = mat.node_tree.nodes.new("ShaderNodeVolumePrincipled")
    mat.node_tree.links.new(volume.outputs[0], mat.node_tree.nodes["Material Output"].inputs["Volume"])
    mat2, mix = kit.surface("mixed", "ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.5
    for k, shader in ((1, "ShaderNodeBsdfDiffuse"), (2, "ShaderNodeBsdfTranslucent")):
        mat2.node_tree.links.new(mat2.node_tree.nodes.new(shader).outputs[0], mix.inputs[k])
    kit.plane("floor", 20.0, material=mat)
    kit.box("box", 1.5, (0.5, 0.3, 0.75), material=mat2)
    kit.point_light("lamp", (0, 0, 4), 300.0)
    camera()
    result, px, log = render("unsupported")
    warned = warnings_in(log)
    check(result == {"FINISHED"} and len(warned) == 1 and "ShaderNodeBsdfToon" in warned[0]
          and "ShaderNodeBsdfTranslucent" in warned[0],
          f"unsupported shader nodes: the render finishes with one warning naming them: {warned[:1]}")
    check(px is not None and np.isfinite(px).all() and px[..., 1].mean() > 0, "and the image is lit")


def box_stage(box_material, floor_material=None):
    """A box of the material under test on a floor, a point lamp above, a grey world, the camera."""
    kit.plane("floor", 20.0, floor_material or kit.diffuse("grey"))
    kit.box("box", 1.5, (0.5, 0.3, 0.75), material=box_material)
    kit.point_light("lamp", (0, 0, 4), 300.0, radius=0.3)
    kit.world((0.2, 0.2, 0.2))
    camera()


def test_glossy_and_metal():
    clear_scene()
    # A Glossy BSDF in Multiscatter GGX (4.x/5.x's default; 3.x's random walk is approximated by
    # single scattering) and a Principled metal whose base colour is NaN: both render, finite, with
    # one note naming what was approximated.
    metal = kit.metal("nan_metal", (float("nan"), 0.5, 0.5), 0.4)
    box_stage(metal, kit.glossy("shiny", (0.9, 0.8, 0.6), 0.3, distribution="MULTI_GGX"))
    result, px, log = render("glossy")
    warned = warnings_in(log)
    old = bpy.app.version < (4, 0, 0)
    check(result == {"FINISHED"} and len(warned) == 1 and ("Multiscatter GGX" in warned[0]) == old
          and "nan_metal" in warned[0] and "NaN" in warned[0],
          f"a multiscatter glossy and a NaN metal: one note naming {'both' if old else 'the NaN'}: {warned[:1]}")
    check(px is not None and np.isfinite(px).all() and px[..., :3].mean() > 0, "and the image is lit and finite")


def test_bad_glass():
    clear_scene()
    # A rough Beckmann Glass whose roughness is NaN and IOR 0, and a rough Refraction of IOR 1: both
    # render, finite, with one note naming the NaN (roughness 0: sharp), the IOR below Cycles'
    # floor (1e-5: a mirror) and the IOR 1 (nothing bends).
    glass = kit.glass("bad_glass", 0.0)
    node = next(n for n in glass.node_tree.nodes if n.type == "BSDF_GLASS")
    node.distribution = "BECKMANN"
    node.inputs["Roughness"].default_value = float("nan")
    refraction, rnode = kit.surface("odd_refraction", "ShaderNodeBsdfRefraction")
    rnode.distribution = "GGX"
    rnode.inputs["Roughness"].default_value = 0.4
    rnode.inputs["IOR"].default_value = 1.0
    box_stage(glass)
    kit.box("box2", 1.0, (-2.0, -1.0, 1.0), material=refraction)
    result, px, log = render("glass")
    warned = warnings_in(log)
    w = warned[0] if warned else ""
    check(result == {"FINISHED"} and len(warned) == 1 and "bad_glass" in w and "NaN" in w and "IOR 0" in w
          and "odd_refraction" in w and "IOR 1" in w,
          f"a NaN-rough glass of IOR 0 and a refraction of IOR 1: one note naming them: {warned[:1]}")
    check(px is not None and np.isfinite(px).all() and px[..., :3].mean() > 0, "and the image is lit and finite")


def test_principled_ior_zero():
    # A Principled BSDF whose IOR is 0 (Blender's socket allows it; no material has it): clamped to
    # 1e-5 as Cycles clamps its IORs, one note naming the material, the render finite; with half
    # Transmission, so its glass takes the IOR too.
    clear_scene()
    mat = kit.principled_dielectric("zero_ior", (0.8, 0.5, 0.3), 0.3)
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    bsdf.inputs["IOR"].default_value = 0.0
    kit.input_of(bsdf, "Transmission Weight", "Transmission").default_value = 0.5   # 4.0+ / 3.x
    box_stage(mat)
    result, px, log = render("principled_ior_zero")
    warned = warnings_in(log)
    w = warned[0] if warned else ""
    check(result == {"FINISHED"} and len(warned) == 1 and "zero_ior" in w and "IOR" in w and "1e-05" in w,
          f"a Principled of IOR 0: one note naming it and the clamp: {warned[:1]}")
    check(px is not None and np.isfinite(px).all() and px[..., :3].mean() > 0, "and the image is lit and finite")


def test_bad_light_strength():
    # A negative or NaN strength (Blender accepts both; Cycles renders negative light, TOYRT has
    # none) or a NaN colour: F12 fails with an error naming the light, writes no image, and
    # renders again once the light is mended.
    basic_scene()
    lamp = bpy.data.objects["lamp"]
    for setting, value in (("energy", -100.0), ("energy", float("nan")), ("color", (1.0, float("nan"), 1.0))):
        saved = tuple(getattr(lamp.data, setting)) if setting == "color" else getattr(lamp.data, setting)
        setattr(lamp.data, setting, value)
        result, px, _ = render(f"bad_light_{setting}")
        message = str(result)
        check(result != {"FINISHED"} and px is None and "'lamp'" in message
              and ("power" in message if setting == "energy" else "colour" in message),
              f"light {setting} {value}: F12 fails naming the light, no image: {message[:160]}")
        setattr(lamp.data, setting, saved)
    result, px, _ = render("bad_light_mended")
    check(result == {"FINISHED"} and px is not None and px[..., :3].mean() > 0, "mended, the scene renders")


def test_library_linked():
    # A library file holding a cube object with its mesh and material, written by this Blender.
    basic_scene()
    _, local, _ = render("local")
    box = bpy.data.objects["box"]
    lib_path = os.path.join(TMP, "library.blend")
    bpy.data.libraries.write(lib_path, {box}, fake_user=True)
    basic_scene()
    bpy.data.objects.remove(bpy.data.objects["box"])
    with bpy.data.libraries.load(lib_path, link=True) as (data_from, data_to):
        data_to.objects = ["box"]
    linked = data_to.objects[0]
    kit.link(linked)
    check(linked.library is not None and linked.data.library is not None,
          f"the cube is linked from {os.path.basename(linked.library.filepath)} (object and mesh)")
    result, px, log = render("linked")
    same = px is not None and float(np.abs(px - local).max()) <= 1e-6
    check(result == {"FINISHED"} and not errors_in(log) and same,
          "a library-linked object renders as the same object made locally (identical image)")


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def test_100k_objects():
    n = 100_000
    scene = clear_scene()
    coll = bpy.data.collections.new("many")
    scene.collection.children.link(coll)
    me = kit.box("cube", 0.5, (0, 0, 0)).data
    bpy.data.objects.remove(bpy.data.objects["cube"])
    t0 = time.perf_counter()
    # Linked duplicates of one 12-triangle cube on a 400 x 250 grid (one unit apart). Each its own
    # name: Blender makes a repeated name unique by trying suffixes, 2.4x slower here than names
    # that are already unique (20,000 objects in 3.4: 8.5 s against 3.6 s).
    for i in range(n):
        obj = bpy.data.objects.new(f"c{i:06d}", me)
        obj.location = (i % 400 - 200.0, i // 400 - 125.0, 0.0)
        coll.objects.link(obj)
    made = time.perf_counter() - t0
    kit.point_light("lamp", (0, 0, 50), 20000.0)
    camera(location=(0, 0, 20), scale=400.0)
    rss0 = rss_mb()
    t0 = time.perf_counter()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    dg_s = time.perf_counter() - t0
    import render_toyrt
    from render_toyrt import sync
    t_scene, _, stats = sync.export_scene(depsgraph, render_toyrt.native())
    t_scene.commit(threads=0)
    print(f"  {n:,} objects: made in {made:.1f} s, depsgraph {dg_s:.1f} s, export {stats['export_s']:.2f} s, "
          f"BVH {t_scene.last_commit['build_ms']:.0f} ms, native scene {t_scene.memory_bytes / 1e6:.1f} MB, "
          f"process RSS {rss0:.0f} -> {rss_mb():.0f} MB", flush=True)
    check(stats["instances"] == n and stats["meshes"] == 1 and stats["triangles"] == 12 * n,
          f"{n:,} objects export as {stats['instances']:,} instances of {stats['meshes']} mesh")
    del t_scene
    t0 = time.perf_counter()
    result, px, log = render("many")
    f12 = time.perf_counter() - t0
    check(result == {"FINISHED"} and px is not None and not errors_in(log) and px[..., :3].mean() > 0,
          f"and render (F12 {result} in {f12:.1f} s); peak RSS of the process {peak_rss_mb():.0f} MB")
    # Last part: left for the process exit to free (removing 100,000 objects takes Blender 2 minutes).


PARTS = [test_empty_scene, test_no_camera, test_edges_and_points_only, test_zero_scale, test_nan_vertices,
         test_far_from_origin, test_missing_image, test_unsupported_nodes, test_glossy_and_metal, test_bad_glass,
         test_principled_ior_zero, test_bad_light_strength, test_library_linked,
         test_100k_objects]
run_script(PARTS, "bad scenes", TMP)
