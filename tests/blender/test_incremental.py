# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_incremental.py
# (`make test` runs it). The incremental scene sync (addon/render_toyrt/sync.py) fed with
# Blender's own depsgraph.updates (a depsgraph_update_post handler, as view_update gets them):
#   - each edit does only its part, by the cache's counters: a camera move exports and commits
#     nothing; moving an object sets one transform and rebuilds the top level only (no mesh BVH);
#     editing a mesh re-exports and rebuilds that mesh only; editing a material converts that
#     material only; editing a light sends the lights again and nothing else; moving a parent moves
#     its child's instance too, without a walk over the scene; deleting an object frees its mesh;
#   - after every edit, the incrementally updated scene renders exactly the image a fresh export of
#     the same depsgraph renders (same meshes, transforms, materials, lights): the known answer.
import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, counted_edit, live_sync, run_script  # noqa: E402


def build():
    scene = kit.clear_scene()
    kit.toyrt(scene)
    scene.render.resolution_x = scene.render.resolution_y = 24
    scene.render.resolution_percentage = 100
    # The operators: the test edits Blender's own "Cube" and "Icosphere".
    bpy.ops.mesh.primitive_plane_add(size=6)
    bpy.context.object.data.materials.append(kit.principled("floor", (0.8, 0.8, 0.8)))
    bpy.ops.mesh.primitive_cube_add(size=1, location=(-1, 0, 0.5))
    bpy.context.object.data.materials.append(kit.principled("red", (0.8, 0.1, 0.1)))
    bpy.ops.mesh.primitive_ico_sphere_add(radius=0.5, location=(1, 0, 0.5))
    kit.point_light("lamp", (0, -1, 3), 300.0, radius=0.25)    # Blender 3.4's default radius
    kit.camera((0, -6, 4), rotation=(0.9, 0, 0))
    bpy.context.view_layer.update()
    return scene


def main():
    import render_toyrt
    from render_toyrt import sync
    from render_toyrt.camera import export_camera

    toyrt = render_toyrt.native()
    scene = build()
    with live_sync(sync, toyrt) as cache:
        def edit(label, fn, expect):
            counted_edit(cache, label, fn, expect)
            depsgraph = bpy.context.evaluated_depsgraph_get()
            camera = export_camera(depsgraph)
            fresh, _, _ = sync.export_scene(depsgraph, toyrt)
            fresh.commit()
            a = cache.scene.render(camera, samples=4)
            b = fresh.render(camera, samples=4)
            check(np.array_equal(a, b), f"{label}: the updated scene renders what a fresh export renders "
                                        f"(max difference {np.abs(a - b).max():.3g})")

        cube, sphere = bpy.data.objects["Cube"], bpy.data.objects["Icosphere"]
        nothing = dict(meshes_exported=0, commits=0, mesh_bvhs_built=0, light_sends=0, materials_converted=0)
        edit("camera move", lambda: setattr(scene.camera, "location", (0.5, -6, 4)), nothing)
        edit("object move", lambda: setattr(cube, "location", (-1.2, 0.3, 0.5)),
             dict(transforms_set=1, fast_moves=1, walks=0, meshes_exported=0, mesh_bvhs_built=0, top_level_builds=1,
                  instance_resets=0))

        def mesh_edit():
            sphere.data.vertices[0].co.z += 0.3
            sphere.data.update()
        edit("mesh edit", mesh_edit, dict(meshes_exported=1, mesh_bvhs_built=1, transforms_set=0, light_sends=0))

        def material_edit():
            bsdf = bpy.data.materials["red"].node_tree.nodes["Principled BSDF"]
            bsdf.inputs["Base Color"].default_value = (0.1, 0.2, 0.9, 1)
        edit("material edit", material_edit, dict(materials_converted=1, meshes_exported=0, mesh_bvhs_built=0))

        def light_edit():
            bpy.data.lights["lamp"].energy = 150
        edit("light edit", light_edit, dict(light_sends=1, meshes_exported=0, mesh_bvhs_built=0, transforms_set=0))
        edit("parent the sphere to the cube", lambda: setattr(sphere, "parent", cube), dict(meshes_exported=0))
        edit("move the parent: the child follows", lambda: setattr(cube, "location", (-0.8, 0.2, 0.5)),
             dict(transforms_set=2, walks=0, meshes_exported=0, mesh_bvhs_built=0))
        edit("delete an object", lambda: bpy.data.objects.remove(sphere),
             dict(meshes_freed=1, meshes_exported=0, instance_resets=1))
        check(cache.scene.instance_count == 2, f"two instances left ({cache.scene.instance_count})")


run_script([main], "incremental")
