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
#      object and giving the first its volume back, each time gives what a fresh export_scene of
#      the same depsgraph gives: counts, lights and the image (bit for bit).
#   3. DefaultsMatchTheCore: properties.py's defaults (literal, so the add-on registers without
#      the native module) equal the core's toyrt.defaults, where the module has them.
import os
import shutil
import sys
import tempfile

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from harness import check, finish, run_part  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-sync-")
SAMPLES = 4


def addon():
    import render_toyrt
    from render_toyrt import sync
    return sync, render_toyrt.native()


# ---- the scene ----------------------------------------------------------------------------------

def diffuse(name, color):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    return mat


def build():
    """Floor, a red cube flattened to a square (scale z = 0), a collection (ico sphere + small
    cube) instanced twice by empties, a blue sphere, a point light and an area light, seen from
    above at an angle."""
    bpy.data.batch_remove(list(bpy.data.objects) + list(bpy.data.meshes) + list(bpy.data.lights)
                          + list(bpy.data.materials) + list(bpy.data.collections))
    scene = bpy.context.scene
    scene.render.engine = "TOYRT"
    scene.render.resolution_x, scene.render.resolution_y = 48, 36
    scene.render.resolution_percentage = 100
    scene.render.use_border = False
    scene.frame_start = scene.frame_end = 1
    scene.frame_set(1)
    scene.toyrt.samples, scene.toyrt.seed = SAMPLES, 0
    scene.view_settings.view_transform = "Standard"
    if scene.world is not None:
        scene.world.use_nodes = False
        scene.world.color = (0.05, 0.05, 0.05)

    bpy.ops.mesh.primitive_plane_add(size=12)
    bpy.context.object.data.materials.append(diffuse("floor", (0.8, 0.8, 0.8)))
    bpy.ops.mesh.primitive_cube_add(size=2, location=(-2.0, 0.0, 0.5))
    flat = bpy.context.object
    flat.name = "flat"
    flat.scale = (1.0, 1.0, 0.0)            # a square at z = 0.5: Cycles renders it, so must TOYRT
    flat.data.materials.append(diffuse("red", (0.8, 0.1, 0.1)))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, location=(2.0, -1.0, 0.7))
    bpy.context.object.name = "ball"
    bpy.context.object.data.materials.append(diffuse("blue", (0.1, 0.2, 0.8)))

    coll = bpy.data.collections.new("kit")
    scene.collection.children.link(coll)
    bpy.ops.mesh.primitive_ico_sphere_add(radius=0.4, location=(0.0, 0.0, 0.4))
    ico = bpy.context.object
    bpy.ops.mesh.primitive_cube_add(size=0.4, location=(0.6, 0.0, 0.2))
    small = bpy.context.object
    for obj in (ico, small):
        for c in list(obj.users_collection):
            c.objects.unlink(obj)
        coll.objects.link(obj)
    bpy.context.view_layer.layer_collection.children["kit"].exclude = True  # shown through the instances only
    for i, loc in enumerate(((0.0, 2.0, 0.0), (1.0, 3.0, 0.0))):
        empty = bpy.data.objects.new(f"instancer{i}", None)
        empty.instance_type, empty.instance_collection = "COLLECTION", coll
        empty.location = loc
        scene.collection.objects.link(empty)

    point = bpy.data.lights.new("lamp", "POINT")
    point.energy = 400.0
    lo = bpy.data.objects.new("lamp", point)
    lo.location = (1.0, -2.0, 4.0)
    scene.collection.objects.link(lo)
    area = bpy.data.lights.new("panel", "AREA")
    area.energy, area.size = 200.0, 2.0
    ao = bpy.data.objects.new("panel", area)
    ao.location = (-2.0, 1.0, 3.0)
    scene.collection.objects.link(ao)

    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    cam.location = (0.0, -9.0, 9.0)
    cam.rotation_euler = (0.785, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
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
    s = bpy.context.scene
    s.render.image_settings.file_format = "OPEN_EXR"
    s.render.image_settings.color_depth = "32"
    s.render.image_settings.color_mode = "RGBA"
    path = os.path.join(TMP, f"{name}.exr")
    s.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    w, h = img.size
    px = np.empty(w * h * 4, np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return px.reshape(h, w, 4)[::-1]


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
    cache = sync.SceneSync(toyrt)
    cache.sync(bpy.context.evaluated_depsgraph_get())
    cache.commit()

    def on_update(_scene, depsgraph):
        cache.sync(depsgraph, depsgraph.updates)
        cache.commit()

    def edit(label, fn, expect=None):
        before = dict(cache.counters)
        fn()
        bpy.context.view_layer.update()  # Blender evaluates and calls depsgraph_update_post
        delta = {k: cache.counters[k] - before[k] for k in cache.counters}
        if expect:
            wrong = {k: (delta[k], v) for k, v in expect.items() if delta[k] != v}
            check(not wrong, f"{label}: {', '.join(f'{k} {v}' for k, v in expect.items())}"
                             + (f" -- got (got, expected) {wrong}" if wrong else ""))
        depsgraph = bpy.context.evaluated_depsgraph_get()
        fresh, camera, stats = sync.export_scene(depsgraph, toyrt)
        fresh.commit()
        same_counts = (fresh.instance_count == cache.scene.instance_count
                       and fresh.triangle_count == cache.scene.triangle_count
                       and stats["triangles_instanced"] == cache.stats["triangles_instanced"]
                       and stats["lights"] == len(cache.lights))
        check(same_counts, f"{label}: the same instances ({cache.scene.instance_count}, fresh {fresh.instance_count}), "
                           f"stored triangles ({cache.scene.triangle_count}, fresh {fresh.triangle_count}), "
                           f"lights ({len(cache.lights)}, fresh {stats['lights']})")
        a, b = render(cache.scene, camera), render(fresh, camera)
        check(np.array_equal(a, b), f"{label}: the updated scene renders what a fresh export renders "
                                    f"(max difference {np.abs(a - b).max():.3g})")

    bpy.app.handlers.depsgraph_update_post.append(on_update)
    try:
        edit("light edit", lambda: setattr(bpy.data.lights["lamp"], "energy", 150.0),
             dict(light_sends=1, meshes_exported=0))

        def material_edit():
            bpy.data.materials["red"].node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = \
                (0.1, 0.8, 0.1, 1.0)
        edit("material edit", material_edit, dict(materials_converted=1, meshes_exported=0, light_sends=0))
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
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)


# ---- 3. defaults ----------------------------------------------------------------------------------------

def test_defaults_match_the_core():
    import render_toyrt

    core = getattr(render_toyrt.native(), "defaults", None)
    if core is None:
        print("  note: this toyrt module has no `defaults` (it comes with the core's change); not compared")
        return
    settings = bpy.types.Scene.bl_rna.properties["toyrt"].fixed_type.bl_rna.properties
    compared = 0
    for name in ("samples", "max_specular_depth", "area_light_sampling", "light_sampling", "builder", "seed"):
        if name not in core:
            print(f"  note: toyrt.defaults has no '{name}'")
            continue
        ours = settings[name].default  # an enum's: its identifier
        check(ours == core[name], f"properties.py's {name} default {ours!r} is the core's {core[name]!r}")
        compared += 1
    check(compared > 0, f"{compared} defaults compared")


try:
    for part in (test_same_scene_on_every_path, test_incremental_equals_one_shot, test_defaults_match_the_core):
        run_part(part)
finally:
    shutil.rmtree(TMP, ignore_errors=True)
finish("sync")
