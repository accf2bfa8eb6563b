# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_cancel_cycles.py
# (`make test` runs it, also under the bpy module: tests/blender/run_with_bpy.py).
#
# 50 start/cancel cycles in one Blender process (issue 7, "Cancellation and long sessions"),
# cancelled in turn during the export, during the BVH build and while rendering.
#
# Esc cannot be pressed in batch mode, and a Python subclass cannot answer the engine's
# test_break() (Blender's RNA method wins over a Python override: measured), so:
#   - while rendering: F12 (bpy.ops.render.render) runs the engine as users do, with the native
#     module seen through a proxy whose Scene.render() adds "Esc after 50 ms" to the engine's own
#     should_cancel (its test_break); tiles, begin_result/end_result and all are the engine's;
#   - during the export, which the engine interrupts between objects and between the stages of a
#     mesh's export, the cycle runs the exporter (sync.export_scene, which does not poll) and
#     stops after it: the time printed is what a cancel would wait without polling; that Esc stops
#     the engine's export before any mesh is read is checked once;
#   - during the BVH build, the cycle runs Scene.commit with the engine's kind of should_cancel,
#     answering "Esc" 5 ms into the build: the build stops and the latency is checked.
# Checked: a render cancelled while rendering returns within 0.2 s of Esc (the median of 17); no
# Python thread is left; the OS thread count stays flat (within 2) from cycle 10 on; resident
# memory stays flat from cycle 10 to 50 (within 32 MB: a leaked scene is about 15 MB a cycle).
import os
import sys
import threading
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, run_script  # noqa: E402

CYCLES = int(os.environ.get("TOYRT_CANCEL_CYCLES", "50"))
LATENCY_LIMIT = 0.2      # seconds, the figure, for cancels while rendering
PHASES = ("export", "bvh", "render")


def os_threads():
    return len(os.listdir("/proc/self/task"))


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


class Control:
    """When the test's Esc comes, and when the engine saw it."""
    render_delay = 0.05      # seconds into Scene.render() before "Esc"
    first_yes = None


def install_proxy():
    """render_toyrt.native() returns the module behind a proxy whose Scene adds the test's Esc
    to render()'s should_cancel; everything else is the native module itself."""
    import render_toyrt

    toyrt = render_toyrt.native()

    class CancelledScene(toyrt.Scene):
        def render(self, camera, **kwargs):
            engine_cancel = kwargs.get("should_cancel")
            start = time.perf_counter()

            def should_cancel():
                now = time.perf_counter()
                if now - start >= Control.render_delay:
                    if Control.first_yes is None:
                        Control.first_yes = now
                    return True
                return bool(engine_cancel()) if engine_cancel is not None else False

            kwargs["should_cancel"] = should_cancel
            return super().render(camera, **kwargs)

    class Proxy:
        Scene = CancelledScene

        def __getattr__(self, name):
            return getattr(toyrt, name)

    proxy = Proxy()
    render_toyrt.native = lambda: proxy
    return toyrt


def build_scene():
    scene = kit.clear_scene()
    # A bumpy 300 x 300 grid (180,000 triangles, built with foreach_set: the primitive operators
    # are slow at this size), so the export and the BVH build each take a measurable time.
    n = 300
    x, y = np.meshgrid(np.linspace(-4, 4, n + 1), np.linspace(-4, 4, n + 1))
    co = np.stack([x, y, 0.3 * np.sin(3 * x) * np.cos(2 * y)], axis=-1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    v0 = (j * (n + 1) + i).ravel()
    quads = np.stack([v0, v0 + 1, v0 + n + 2, v0 + n + 1], axis=1).astype(np.int32)
    kit.mesh_object("bumps", co, quads)
    kit.point_light("lamp", (2.0, -2.0, 4.0), 500.0, radius=0.5)
    kit.camera((0, 0, 10), ortho_scale=6.0)
    kit.output(scene, 160, 120)
    # 100,000 samples per pixel: uncancelled, this render would take hours.
    kit.toyrt(scene, samples=100_000, builder="sah")
    return scene


def main():
    toyrt = install_proxy()
    from render_toyrt import render_cache, sync

    build_scene()
    py_threads = threading.active_count()
    phase_s = {p: [] for p in PHASES}          # how long the cancelled phase ran (export, bvh)
    latencies, f12_s = [], []
    bvh_cancels = []                             # (commit completed?, seconds from Esc to return)
    threads, rss = [], []
    for i in range(CYCLES):
        phase = PHASES[i % 3]
        if phase == "render":
            Control.first_yes = None
            start = time.perf_counter()
            bpy.ops.render.render()
            end = time.perf_counter()
            f12_s.append(end - start)
            latencies.append(end - Control.first_yes if Control.first_yes is not None else float("inf"))
        else:
            depsgraph = bpy.context.evaluated_depsgraph_get()
            t0 = time.perf_counter()
            t_scene, _, _ = sync.export_scene(depsgraph, toyrt)
            t1 = time.perf_counter()
            if phase == "bvh":
                esc = []

                def test_break():
                    if not esc and time.perf_counter() - t1 > 0.005:
                        esc.append(time.perf_counter())
                    return bool(esc)

                completed = t_scene.commit(builder="sah", threads=0, should_cancel=test_break)
            t2 = time.perf_counter()
            if phase == "bvh":
                bvh_cancels.append((completed, t2 - esc[0] if esc else None))
            phase_s[phase].append(t1 - t0 if phase == "export" else t2 - t1)
            del t_scene   # as the engine returns: the scene goes with it
        threads.append(os_threads())
        rss.append(rss_mb())
        if os.environ.get("TOYRT_CANCEL_VERBOSE"):
            print(f"  cycle {i + 1}: {phase}, threads {threads[-1]}, RSS {rss[-1]:.0f} MB", flush=True)

    # The engine's export polls test_break between objects and before each mesh: Esc already
    # down when the export starts stops it before any mesh is read, and the half-done cache is
    # dropped (the engine calls discard_render_cache), so the next render exports afresh.
    depsgraph = bpy.context.evaluated_depsgraph_get()
    cache = sync.SceneSync(toyrt)
    try:
        cache.sync(depsgraph, should_cancel=lambda: True)
        raised = False
    except sync.ExportCancelled:
        raised = True
    check(raised and cache.counters["meshes_exported"] == 0,
          f"Esc before the export: ExportCancelled, no mesh read ({cache.counters['meshes_exported']} exported)")
    render_cache.for_render(depsgraph, toyrt)
    render_cache.discard_render_cache(depsgraph)
    check(render_cache.for_render(depsgraph, toyrt).counters["syncs"] == 0,
          "after discard_render_cache the next render gets a fresh cache")
    render_cache.free_render_caches()

    stopped = [s for done, s in bvh_cancels if not done and s is not None]
    check(len(stopped) == len(bvh_cancels),
          "cancelled during the BVH build: every build stopped before completing "
          f"({len(stopped)} of {len(bvh_cancels)})")
    if stopped:
        check(float(np.median(stopped)) <= LATENCY_LIMIT,
              f"cancel during the BVH build returned within {LATENCY_LIMIT} s of Esc (median "
              f"{np.median(stopped) * 1000:.1f} ms, max {max(stopped) * 1000:.1f} ms)")
    for p in ("export",):
        print(f"  cancel during {p}: honoured when the phase ends, {np.median(phase_s[p]) * 1000:.0f} ms "
              f"(median of {len(phase_s[p])}; max {max(phase_s[p]) * 1000:.0f} ms) for 180,000 triangles", flush=True)
    print(f"  cancel while rendering: F12 returned {np.median(latencies) * 1000:.1f} ms after Esc (median of "
          f"{len(latencies)}; max {max(latencies) * 1000:.1f} ms), {np.median(f12_s):.2f} s after it started",
          flush=True)
    # The median, not the maximum: on a loaded machine one cancel in 17 has taken 0.4 s (the OS did
    # not schedule the process), while the median stays near 1 ms; a cancel that is not polled
    # inside pixels takes the whole 100,000-sample pixel (about 1 s) every time and fails this.
    check(float(np.median(latencies)) <= LATENCY_LIMIT,
          f"cancelled while rendering (100,000 spp): F12 returned within {LATENCY_LIMIT} s of Esc "
          f"(median {np.median(latencies) * 1000:.1f} ms, max {max(latencies) * 1000:.0f} ms)")
    check(threading.active_count() == py_threads,
          f"no Python thread left ({threading.active_count()} now, {py_threads} before)")
    # Thread pools (TBB's, PoCL's) start workers lazily, so one or two may appear after the first
    # renders; a leak adds one per cycle or more, 40 by the end. Flat from cycle 10 on, within 2.
    check(max(threads[9:]) <= threads[9] + 2,
          f"OS threads flat: {threads[0]} after cycle 1, {threads[9]} after cycle 10, "
          f"at most {max(threads[9:])} after")
    # One leaked native scene of this size is about 15 MB, so 40 cycles leaking one each would
    # grow by 600 MB; the bound leaves room for the allocators' steps (+21 MB seen once on 5.0,
    # flat on the rerun), so it catches leaked scenes and images, not every small allocation.
    growth = rss[-1] - rss[9]
    slope = float(np.polyfit(np.arange(10, CYCLES + 1), rss[9:], 1)[0])
    check(growth < 32.0,
          f"resident memory flat: {rss[9]:.0f} MB after cycle 10, {rss[-1]:.0f} MB after cycle {CYCLES} "
          f"({growth:+.1f} MB, trend {slope * 1024:+.0f} KB per cycle; max {max(rss[9:]):.0f} MB)")


run_script([main], "cancel cycles")
