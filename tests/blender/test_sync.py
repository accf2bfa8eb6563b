# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_sync.py
# (`make test` runs it). No --factory-startup: the add-on as `make setup` installed it.
#
# One door in (addon/render_toyrt/sync.py): F12, the viewport and the one-shot export_scene the
# tests and benchmarks use are one scene sync, so they give the same native scene. On a scene
# with an object scaled to zero along one axis (the core cannot invert its matrix: it is baked,
# flattened, as Cycles renders it), a collection instanced twice, a point and an area light:
#   1. SameSceneOnEveryPath: the one-shot export_scene, a SceneSync's first sync and F12 (the
#      engine's final-render sync, written to a float EXR) give the same triangle and instance
#      counts, the same lights and the same image; the flattened object is in it (the image
#      differs from the scene without it where it lies).
#   2. IncrementalEqualsOneShot: a SceneSync fed with Blender's depsgraph.updates (as the viewport
#      is) after a light edit, a material edit, moving the flattened object, flattening another
#      object and giving the first its volume back, adding a Normal Map to a material and removing
#      it (its meshes are sent again with and without tangents), each time gives what a fresh
#      export_scene of the same depsgraph gives: counts, lights and the image (bit for bit).
#   3. DefaultsMatchTheCore: properties.py's defaults (literal, so the add-on registers without
#      the native module) equal the core's toyrt.defaults, where the module has them.
import os
import sys
import tempfile

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, counted_edit, live_sync, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-sync-")
SAMPLES = 4


def addon():
    import render_toyrt
    from render_toyrt import sync
    return sync, render_toyrt.native()


# ---- the scene: the kit (scenes/kit.py) ---------------------------------------------------------

def build():
    """Floor, a red cube flattened to a square (scale z = 0), a collection (a small sphere and a
    small cube) instanced twice by empties, a blue sphere, a point light and an area light, seen
    from above at an angle."""
    scene = kit.clear_scene()
    scene.frame_start = scene.frame_end = 1
    scene.frame_set(1)
    kit.output(scene, 48, 36)
    kit.toyrt(scene, samples=SAMPLES, seed=0)
    kit.world((0.05, 0.05, 0.05))
    kit.plane("floor", 12.0, kit.diffuse("floor"))
    flat = kit.box("flat", 2.0, (-2.0, 0.0, 0.5), kit.diffuse("red", (0.8, 0.1, 0.1)))
    flat.scale = (1.0, 1.0, 0.0)            # a square at z = 0.5: Cycles renders it, so must TOYRT
    kit.uv_sphere("ball", 0.7, (2.0, -1.0, 0.7), kit.diffuse("blue", (0.1, 0.2, 0.8)), segments=24, rings=12)

    parts = bpy.data.collections.new("parts")
    scene.collection.children.link(parts)
    for obj in (kit.uv_sphere("pebble", 0.4, (0.0, 0.0, 0.4), None, segments=16, rings=8),
                kit.box("brick", 0.4, (0.6, 0.0, 0.2))):
        scene.collection.objects.unlink(obj)
        parts.objects.link(obj)
    bpy.context.view_layer.layer_collection.children["parts"].exclude = True  # shown through the instances only
    for i, location in enumerate(((0.0, 2.0, 0.0), (1.0, 3.0, 0.0))):
        empty = kit.link(bpy.data.objects.new(f"instancer{i}", None))
        empty.instance_type, empty.instance_collection = "COLLECTION", parts
        empty.location = location

    kit.point_light("lamp", (1.0, -2.0, 4.0), 400.0, radius=0.1)
    kit.area_light("panel", (-2.0, 1.0, 3.0), 200.0, 2.0, target=(-2.0, 1.0, 0.0), visible_camera=True)
    kit.camera((0.0, -9.0, 9.0), rotation=(0.785, 0.0, 0.0))
    bpy.context.view_layer.update()
    return scene


def blender_counts(depsgraph):
    """An independent count of what Blender shows: renderable instances and their triangles."""
    n, tris = 0, 0
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type != "MESH" or not (inst.is_instance or inst.show_self):
            continue
        mesh = obj.to_mesh()
        mesh.calc_loop_triangles()
        n, tris = n + 1, tris + len(mesh.loop_triangles)
        obj.to_mesh_clear()
    return n, tris


def render(t_scene, camera):
    s = bpy.context.scene
    return t_scene.render(camera, samples=SAMPLES, seed=s.toyrt.seed + s.frame_current,
                          max_specular_depth=s.toyrt.max_specular_depth,
                          area_light_sampling=s.toyrt.area_light_sampling, light_sampling=s.toyrt.light_sampling)


def f12_image(name):
    """F12 (the engine's final-render sync) written as a 32-bit float EXR, read back linear:
    (height, width, 4), rows from the top."""
    kit.float_exr(bpy.context.scene)
    path = os.path.join(TMP, f"{name}.exr")
    result, log = render_still(path)
    check(result == {"FINISHED"}, f"F12 finished ({result!r:.120})")
    return kit.read_image(path)[::-1]


# ---- 1. one scene, every path ---------------------------------------------------------------------

def test_same_scene_on_every_path():
    sync, toyrt = addon()
    build()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    one, camera, stats = sync.export_scene(depsgraph, toyrt)
    one.commit()
    engine = sync.SceneSync(toyrt)
    engine.sync(depsgraph)
    engine.commit()
    n_inst, n_tris = blender_counts(depsgraph)
    print(f"  one-shot stats: { {k: v for k, v in stats.items() if k != 'approximated'} }")
    check(stats["instances"] == n_inst == one.instance_count == engine.scene.instance_count
          and stats["triangles_instanced"] == n_tris == engine.stats["triangles_instanced"],
          f"instances: one-shot {stats['instances']} (scene {one.instance_count}), SceneSync "
          f"{engine.scene.instance_count}, Blender {n_inst}; instanced triangles {stats['triangles_instanced']}, "
          f"{engine.stats['triangles_instanced']}, Blender {n_tris}")
    check(one.triangle_count == engine.scene.triangle_count == stats["triangles_stored"]
          and stats["meshes"] == engine.stats["meshes"],
          f"stored triangles: one-shot {one.triangle_count}, SceneSync {engine.scene.triangle_count}; "
          f"meshes {stats['meshes']}, {engine.stats['meshes']}")
    check(stats["lights"] == engine.stats["lights"] == 2 and len(engine.lights) == 2,
          f"lights: one-shot {stats['lights']}, SceneSync {engine.stats['lights']} (2 in the scene)")
    a, b = render(one, camera), render(engine.scene, camera)
    check(np.array_equal(a, b),
          f"one-shot and SceneSync render the same image (max difference {np.abs(a - b).max():.3g})")

    f12 = f12_image("f12")
    check(f12.shape == a.shape and float(np.abs(f12 - a).max()) <= 1e-6,
          f"F12 renders the one-shot's image ({f12.shape}, max difference "
          f"{float(np.abs(f12 - a).max()) if f12.shape == a.shape else float('nan'):.3g})")

    # Where is the flattened cube? Rays straight down onto its square hit it at z = 0.5.
    hits = one.intersect(np.float32([[-2.0, 0.0, 5.0], [-2.5, 0.5, 5.0]]), np.float32([[0, 0, -1]] * 2))
    check(np.allclose(hits["t"], 4.5, atol=1e-4),
          f"the cube scaled to zero along z is there, flattened at z = 0.5 (hit distances {hits['t']})")
    bpy.data.objects.remove(bpy.data.objects["flat"])
    without, _, _ = sync.export_scene(bpy.context.evaluated_depsgraph_get(), toyrt)
    without.commit()
    check(not np.array_equal(render(without, camera), a),
          "and the image without it differs (it is rendered, not left out)")


# ---- 2. incremental updates -------------------------------------------------------------------------

def test_incremental_equals_one_shot():
    sync, toyrt = addon()
    build()
    with live_sync(sync, toyrt) as cache:
        def edit(label, fn, expect=None):
            counted_edit(cache, label, fn, expect)
            depsgraph = bpy.context.evaluated_depsgraph_get()
            fresh, camera, stats = sync.export_scene(depsgraph, toyrt)
            fresh.commit()
            same_counts = (fresh.instance_count == cache.scene.instance_count
                           and fresh.triangle_count == cache.scene.triangle_count
                           and stats["triangles_instanced"] == cache.stats["triangles_instanced"]
                           and stats["lights"] == len(cache.lights))
            check(same_counts, f"{label}: the same instances ({cache.scene.instance_count}, "
                               f"fresh {fresh.instance_count}), stored triangles ({cache.scene.triangle_count}, "
                               f"fresh {fresh.triangle_count}), lights ({len(cache.lights)}, fresh {stats['lights']})")
            a, b = render(cache.scene, camera), render(fresh, camera)
            check(np.array_equal(a, b), f"{label}: the updated scene renders what a fresh export renders "
                                        f"(max difference {np.abs(a - b).max():.3g})")

        edit("light edit", lambda: setattr(bpy.data.lights["lamp"], "energy", 150.0),
             dict(light_sends=1, meshes_exported=0))

        def material_edit():
            color = bpy.data.materials["red"].node_tree.nodes["Diffuse BSDF"].inputs["Color"]
            color.default_value = (0.1, 0.8, 0.1, 1.0)
        edit("material edit", material_edit, dict(materials_converted=1, meshes_exported=0, light_sends=0))

        def into_a_mix():    # the general Mix Shader: its inputs are sent as materials of their own
            tree = bpy.data.materials["red"].node_tree
            mix = tree.nodes.new("ShaderNodeMixShader")
            mix.inputs[0].default_value = 0.3
            tree.links.new(tree.nodes["Diffuse BSDF"].outputs[0], mix.inputs[1])
            tree.links.new(tree.nodes.new("ShaderNodeBsdfGlass").outputs[0], mix.inputs[2])
            tree.links.new(mix.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
        edit("material edit into a Mix of a Diffuse and a Glass", into_a_mix, dict(materials_converted=1))
        parts = list(cache.mix_parts["red"])
        edit("the Mix's factor edited (its inputs sent into the same ids)",
             lambda: setattr(bpy.data.materials["red"].node_tree.nodes["Mix Shader"].inputs[0], "default_value",
                             0.7), dict(materials_converted=1))
        check(len(parts) == 2 and cache.mix_parts["red"] == parts,
              f"the Mix's inputs keep their material ids: {parts} -> {cache.mix_parts['red']}")
        flat = bpy.data.objects["flat"]
        edit("move the flattened cube (baked again)", lambda: setattr(flat, "location", (-2.5, 0.5, 0.8)),
             dict(meshes_exported=1, light_sends=0))
        edit("flatten the ball along y", lambda: setattr(bpy.data.objects["ball"], "scale", (1.0, 0.0, 1.0)),
             dict(meshes_exported=1))
        edit("give the cube its volume back", lambda: setattr(flat, "scale", (1.0, 1.0, 0.5)),
             dict(meshes_exported=1))
        edit("then move it (instance matrices only)", lambda: setattr(flat, "location", (-2.0, 0.0, 0.5)),
             dict(meshes_exported=0, walks=0, transforms_set=1))
        edit("move a collection instance", lambda: setattr(bpy.data.objects["instancer1"], "location", (1.5, 3.0, 0.0)))
        # A material edit alone does not tell the viewport that geometry changed, but a normal map
        # needs its meshes' tangents: the floor (a UV-mapped plane) is sent again with them.
        edit("a Normal Map added to the floor's material (its mesh sent again, with tangents)",
             lambda: kit.normal_map(bpy.data.materials["floor"], kit.bump_normal_image("bumps")),
             dict(materials_converted=1, meshes_exported=1))
        edit("and removed again (sent without them)",
             lambda: bpy.data.materials["floor"].node_tree.nodes.remove(
                 bpy.data.materials["floor"].node_tree.nodes["Normal Map"]),
             dict(materials_converted=1, meshes_exported=1))


# ---- 3. defaults ----------------------------------------------------------------------------------------

def test_defaults_match_the_core():
    import render_toyrt

    core = render_toyrt.native().defaults
    settings = bpy.types.Scene.bl_rna.properties["toyrt"].fixed_type.bl_rna.properties
    compared = 0
    names = ("samples", "max_specular_depth", "transparent_max_bounces", "area_light_sampling",
             "light_sampling", "builder", "seed",
             "use_adaptive_sampling", "adaptive_threshold", "adaptive_min_samples", "time_limit")
    for name in names:
        ours = settings[name].default  # an enum's: its identifier
        # A float property's default is a float32: the core's (also float32) printed to fewer digits.
        same = abs(ours - core[name]) <= 1e-7 if isinstance(core[name], float) else ours == core[name]
        check(same, f"properties.py's {name} default {ours!r} is the core's {core[name]!r}")
        compared += 1
    check(compared == len(names), f"{compared} defaults compared")


run_script((test_same_scene_on_every_path, test_incremental_equals_one_shot, test_defaults_match_the_core), "sync",
           tmp=TMP)
