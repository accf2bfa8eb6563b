# What a viewport-sized Scene.render costs on a 1M-triangle mesh with per-corner normals and UVs,
# four materials and a point light: wall time of render() at 200x150 and 800x600 (1 sample,
# threads=2) and the peak RSS growth during a second render of the same size (a render that
# copied the scene's shading showed it here, tens of MB). Each module runs in its own subprocess;
# the modules' runs are interleaved so that they share the machine's state, and the medians of
# the repeats are reported.
#     .venv/bin/python bench/render_overhead.py [--module NAME=DIR ...] [--repeats 7]
# DIR holds a built toyrt module (build/python by default).
import argparse
import ctypes
import json
import os
import resource
import statistics
import time

from interleaved import modules_from, run_interleaved

SIZES = [(200, 150), (800, 600)]
# Quads per side: 2 * 708^2 = 1,002,528 triangles.
GRID = 708


def child(sizes):
    """Runs in the subprocess: build, commit, warm up, then time each size once."""
    import numpy as np
    import toyrt

    n = GRID + 1
    xs = np.linspace(-4.0, 4.0, n, dtype=np.float32)
    gx, gy = np.meshgrid(xs, xs)
    gz = 0.15 * np.sin(2.0 * gx) * np.cos(3.0 * gy)  # gently curved, so normals vary
    verts = np.stack([gx, gy, gz], axis=-1).reshape(-1, 3).astype(np.float32)
    i = np.arange(GRID)
    a = (i[:, None] * n + i[None, :]).ravel()
    tris = np.concatenate([np.stack([a, a + 1, a + n + 1], 1), np.stack([a, a + n + 1, a + n], 1)]).astype(np.uint32)
    m = len(tris)
    normals = np.zeros((m, 3, 3), np.float32)
    normals[..., 2] = 1.0
    normals[..., 0] = 0.1 * np.sin(np.arange(m, dtype=np.float32))[:, None]
    uvs = (verts[tris][..., :2] / 8.0 + 0.5).astype(np.float32)
    mats = (np.arange(m) % 4).astype(np.int32)

    s = toyrt.Scene()
    colors = [(0.8, 0.2, 0.2), (0.2, 0.8, 0.2), (0.2, 0.2, 0.8), (0.7, 0.7, 0.7)]
    for c in colors:
        s.add_material("diffuse", color=c)
    s.add_mesh(verts, tris, normals=normals, uvs=uvs, material_ids=mats)
    s.add_point_light((0.5, -0.5, 3.0), 500.0)
    s.background = (0.05, 0.05, 0.05)
    s.commit(builder="sah", threads=2)
    del verts, tris, normals, uvs, mats

    def camera(w, h):
        mw = [[1, 0, 0, 0], [0, 0.6, -0.8, -6.0], [0, 0.8, 0.6, 5.0], [0, 0, 0, 1]]
        return dict(type="PERSP", lens=35.0, resolution_x=w, resolution_y=h, matrix_world=np.array(mw))

    def rss_kb(field):
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1])
        return 0

    def cpu_s():  # user + system time of every thread of the process: less sensitive to a busy machine
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime

    s.render(camera(32, 24), samples=1, threads=2)  # warm-up: thread pool, page faults of the tree
    libc = ctypes.CDLL("libc.so.6")
    out = {}
    for w, h in sizes:
        cpu0, start = cpu_s(), time.perf_counter()
        s.render(camera(w, h), samples=1, threads=2)
        ms, cpu_ms = 1000.0 * (time.perf_counter() - start), 1000.0 * (cpu_s() - cpu0)
        # Memory, by a second render: first give freed heap pages back to the system (otherwise a
        # copy reuses pages already counted in RSS and shows no growth), then reset the peak
        # (Linux: clear_refs 5), so the peak after the render is the render's own.
        libc.malloc_trim(0)
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        before = rss_kb("VmRSS")
        s.render(camera(w, h), samples=1, threads=2)
        out[f"{w}x{h}"] = dict(ms=ms, cpu_ms=cpu_ms, peak_growth_mb=(rss_kb("VmHWM") - before) / 1024.0)
    print(json.dumps(out))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--module", action="append", default=[], help="NAME=DIR of a built toyrt module")
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.child:
        child(SIZES)
        return
    modules = modules_from(args.module, os.path.dirname(os.path.abspath(__file__)))
    runs = run_interleaved(__file__, modules, args.repeats)
    print(f"median of {args.repeats}: render() wall time (its minimum, and the process's CPU time, on a shared"
          " machine); peak RSS growth during a render. 1 sample, threads=2")
    for name, _ in modules:
        for w, h in SIZES:
            key = f"{w}x{h}"
            times = [x[key]["ms"] for x in runs[name]]
            cpu = statistics.median(x[key]["cpu_ms"] for x in runs[name])
            mb = statistics.median(x[key]["peak_growth_mb"] for x in runs[name])
            print(f"  {name:>8} {key:>8}: {statistics.median(times):8.1f} ms (min {min(times):6.1f}, CPU {cpu:7.1f})"
                  f"   {mb:7.1f} MB")


if __name__ == "__main__":
    main()
