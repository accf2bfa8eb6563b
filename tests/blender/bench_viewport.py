# A benchmark, not a test (make test does not run it: not named test_*):
#   blender -b --python tests/blender/bench_viewport.py
# The viewport's path after a camera move, timed in background Blender on the Cornell box
# (scenes/cornell_demo.py) at an 800x600 view on 2 threads, then with a 1M-triangle mesh added:
#   sync   the cache applying depsgraph.updates of the camera move (nothing to export)
#   coarse the first pass viewport.py renders: 1 sample at 200x150 (what the user sees first)
#   full   the first full-resolution pass: 1 sample at 800x600
# Printed as a Markdown table for docs/viewport.md. Drawing (the texture upload) is not included:
# there is no GPU in background mode; under Xvfb a 200x150 upload is well under a millisecond.
import os
import statistics
import sys
import time

import bpy
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scenes"))  # the scene kit and the seed's scene
import cornell_demo  # noqa: E402
import kit  # noqa: E402

THREADS = 2
MOVES = 7


def add_big_mesh(triangles_wanted=1_000_000):
    """A UV-sphere topology with about `triangles_wanted` triangles, built with foreach_set."""
    seg, rings = 1000, triangles_wanted // 2000 + 1
    theta = np.linspace(0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0, 2 * np.pi, seg, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    verts = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3) * 0.3
    verts = np.vstack([verts, [[0, 0, 0.3], [0, 0, -0.3]]]).astype(np.float32)
    quads = []
    for r in range(rings - 2):
        a = r * seg + np.arange(seg)
        b = r * seg + (np.arange(seg) + 1) % seg
        quads.append(np.stack([a, b, b + seg, a + seg], -1))
    quads = np.concatenate(quads)
    kit.mesh_object("big", verts, quads, location=(-0.3, -0.4, 0.5))
    return len(quads) * 2


def measure(label, rows):
    import render_toyrt
    from render_toyrt import sync
    from render_toyrt.camera import export_camera

    toyrt = render_toyrt.native()
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 800, 600, 100
    depsgraph = bpy.context.evaluated_depsgraph_get()
    cache = sync.SceneSync(toyrt)
    t0 = time.perf_counter()
    cache.sync(depsgraph)
    export_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    cache.commit(builder="auto", threads=THREADS, expected_rays=800 * 600 * 32 * 5.0)
    build_s = time.perf_counter() - t0

    synced = []

    def on_update(scn, dg):
        t = time.perf_counter()
        cache.sync(dg, dg.updates)
        cache.commit(threads=THREADS)
        synced.append(time.perf_counter() - t)

    bpy.app.handlers.depsgraph_update_post.append(on_update)
    exported_before = cache.counters["meshes_exported"]
    sync_ms, coarse_ms, full_ms = [], [], []
    try:
        for i in range(MOVES):
            scene.camera.location.x += 0.02 * (1 if i % 2 else -1)
            bpy.context.view_layer.update()  # runs depsgraph_update_post with the camera's update
            camera = export_camera(bpy.context.evaluated_depsgraph_get())
            small = dict(camera, resolution_x=200, resolution_y=150)
            t = time.perf_counter()
            cache.scene.render(small, samples=1, threads=THREADS)
            coarse_ms.append((time.perf_counter() - t) * 1000)
            t = time.perf_counter()
            cache.scene.render(camera, samples=1, threads=THREADS)
            full_ms.append((time.perf_counter() - t) * 1000)
        sync_ms = [s * 1000 for s in synced]
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)
    assert cache.counters["meshes_exported"] == exported_before, "a camera move exported something"
    med = statistics.median
    rows.append(f"| {label} | {cache.scene.triangle_count:,} | {export_s * 1000:.0f} ms + BVH {build_s * 1000:.0f} ms "
                f"| {med(sync_ms) if sync_ms else 0:.2f} ms | {med(coarse_ms):.1f} ms | {med(full_ms):.1f} ms "
                f"| {med(sync_ms or [0]) + med(coarse_ms):.1f} ms |")


def main():
    cornell_demo.build()
    rows = ["| scene | triangles | first sync (once) | sync after a camera move | coarse pass 200x150, 1 spp "
            "| full pass 800x600, 1 spp | camera move to first picture |",
            "| --- | --- | --- | --- | --- | --- | --- |"]
    measure("Cornell box", rows)
    n = add_big_mesh()
    measure(f"Cornell box + a {n:,}-triangle mesh", rows)
    print("\n".join(rows), flush=True)


main()
