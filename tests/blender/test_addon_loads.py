# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_addon_loads.py
# (`make test` runs it). No --factory-startup: it checks the add-on as `make setup` installed and
# enabled it in the user's preferences.
#
# Checks: the add-on render_toyrt is enabled; its native module imports; a one-triangle scene,
# built from a Blender mesh through the toyrt Python API, gives the closed-form hit distance for a
# ray shot straight at it, a miss for a ray beside it, and the right hit for a second, translated
# instance placed with a Blender object's matrix_world. Exits 1 on any failure.
import sys
import traceback

ADDON = "render_toyrt"


def check(cond, what):
    if not cond:
        raise AssertionError(what)
    print(f"  ok: {what}")


def main():
    import bpy
    import numpy as np

    check(ADDON in bpy.context.preferences.addons, f"{ADDON} is enabled in the user preferences")
    import render_toyrt

    toyrt = render_toyrt.native()  # raises ImportError with a hint if the module is missing
    check(render_toyrt.toyrt is toyrt, f"native module imported from {render_toyrt.__path__[0]}")

    # A triangle in the plane z = Z, made as a Blender mesh and read back as numpy arrays.
    Z = 2.0
    me = bpy.data.meshes.new("toyrt_triangle")
    me.from_pydata([(-1.0, -1.0, Z), (1.0, -1.0, Z), (0.0, 1.0, Z)], [], [(0, 1, 2)])
    me.update()
    me.calc_loop_triangles()
    vertices = np.empty(len(me.vertices) * 3, dtype=np.float32)
    me.vertices.foreach_get("co", vertices)
    triangles = np.empty(len(me.loop_triangles) * 3, dtype=np.int32)
    me.loop_triangles.foreach_get("vertices", triangles)
    vertices = vertices.reshape(-1, 3)
    triangles = triangles.astype(np.uint32).reshape(-1, 3)

    # A second copy moved by +5 in x, placed the way the engine will place objects: matrix_world.
    obj = bpy.data.objects.new("toyrt_triangle", me)
    obj.location = (5.0, 0.0, 0.0)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.update()
    world = np.array(obj.matrix_world, dtype=np.float32)  # (4,4), row-major, translation in column 3

    scene = toyrt.Scene()
    mesh = scene.add_mesh(vertices, triangles, transform=None)  # instance 0: identity
    scene.add_instance(mesh, world)                             # instance 1: moved by +5 in x
    scene.commit(builder="sah", threads=0)

    # Rays straight up (+z) from z = OZ: hit at t = Z - OZ, closed form for a unit direction.
    OZ = -3.0
    origins = np.array([[0.1, -0.2, OZ],    # under instance 0
                        [5.1, -0.2, OZ],    # under instance 1
                        [3.0, 0.0, OZ]],    # between the two: miss
                       dtype=np.float32)
    directions = np.tile(np.array([0.0, 0.0, 1.0], dtype=np.float32), (len(origins), 1))
    hits = scene.intersect(origins, directions, tnear=0.0, tfar=np.inf, threads=0)
    t, prim, inst = np.asarray(hits["t"]), np.asarray(hits["prim"]), np.asarray(hits["instance"])
    print(f"  hits: t={t.tolist()} prim={prim.tolist()} instance={inst.tolist()}")

    expected_t = Z - OZ
    check(abs(float(t[0]) - expected_t) <= 1e-5 * expected_t, f"ray 0 hits at t = {expected_t}")
    check(int(prim[0]) == 0 and int(inst[0]) == 0, "ray 0 hits triangle 0 of instance 0")
    check(abs(float(t[1]) - expected_t) <= 1e-5 * expected_t, f"ray 1 hits at t = {expected_t}")
    check(int(prim[1]) == 0 and int(inst[1]) == 1, "ray 1 hits triangle 0 of instance 1")
    check(np.isinf(t[2]) and int(prim[2]) == -1, "ray 2 misses (t = inf, prim = -1)")

    blocked = np.asarray(scene.occluded(origins, directions, tnear=0.0, tfar=np.inf, threads=0))
    check(blocked.tolist() == [True, True, False], "occluded agrees with intersect")
    short = np.asarray(scene.occluded(origins, directions, tnear=0.0, tfar=expected_t * 0.5, threads=0))
    check(not short.any(), "occluded is false when tfar stops short of the triangle")


if __name__ == "__main__":
    try:
        main()
    except BaseException:  # also SystemExit / KeyboardInterrupt: any way out but success is a failure
        traceback.print_exc()
        print("FAIL: tests/blender/test_addon_loads.py", flush=True)
        sys.exit(1)
    print("PASS: tests/blender/test_addon_loads.py (render_toyrt add-on and native module)", flush=True)
