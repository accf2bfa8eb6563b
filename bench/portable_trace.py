"""Trace speed of the shipped wheel against the native build, through the Python module users call.

bench/portable_speed.py compares bench_trace binaries, and its --quick rows trace milliseconds of
rays, too little to resolve a few per cent on a shared machine. This one traces about a million
rays per set through `Scene.intersect` / `Scene.occluded` on one thread, in a child process per
module, the modules' children interleaved; each child times every set three times and keeps its
fastest, and the report gives the medians over the repeats and the median of the per-repeat
ratios (a busy spell of the machine hits both modules of one repeat alike).

    .venv/bin/python bench/portable_trace.py --module native=build/python --module wheel=DIR [--repeats 9]

DIR: a wheel unpacked by `pip install --target DIR dist/toyrt-*-cp311-*.whl`; `TOYRT_CPU` in the
environment forces a CPU level of the wheel, as for users.
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

RINGS = 708  # 2 * 708 * 707 = 1.0M triangles, the size of bench_trace's middle row
SETS = ("primary", "diffuse", "shadow")


def bumpy_sphere(np, rings):
    """A UV sphere with a bumpy radius: triangles of varied size and orientation, as bench_trace's."""
    theta = np.linspace(0.0, np.pi, rings)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, rings, endpoint=False)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    r = 1.0 + 0.15 * np.sin(7.0 * th) * np.cos(5.0 * ph)
    ring = np.stack([r * np.sin(th) * np.cos(ph), r * np.sin(th) * np.sin(ph), r * np.cos(th)], -1).reshape(-1, 3)
    verts = np.concatenate([ring, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]]).astype(np.float32)
    n_rows, n = len(theta), rings
    i, j = np.meshgrid(np.arange(n_rows - 1), np.arange(n), indexing="ij")
    a, b = i * n + j, i * n + (j + 1) % n
    c, d = a + n, b + n
    quads = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3), np.stack([b, c, d], -1).reshape(-1, 3)])
    top, bottom, last = len(ring), len(ring) + 1, (n_rows - 1) * n
    caps = [np.stack([np.full(n, top), np.arange(n), (np.arange(n) + 1) % n], -1),
            np.stack([np.full(n, bottom), last + (np.arange(n) + 1) % n, last + np.arange(n)], -1)]
    return verts, np.concatenate([quads, *caps]).astype(np.uint32)


def cpu_s():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def child():
    """Runs in the subprocess: one module's scene, its three ray sets, the fastest of three each."""
    import numpy as np
    import toyrt

    verts, tris = bumpy_sphere(np, RINGS)
    scene = toyrt.Scene()
    scene.add_mesh(verts, tris)
    scene.commit(builder="sah", threads=1)
    rng = np.random.default_rng(7)
    # Primary rays from a frame in front of the sphere, kept where they hit (computed by this
    # module; both modules find the same hits, since every CPU level gives identical bits).
    ys, zs = np.meshgrid(np.linspace(-1.1, 1.1, 1024), np.linspace(-1.1, 1.1, 1024))
    org = np.stack([np.full(ys.size, -4.0), ys.ravel(), zs.ravel()], -1).astype(np.float32)
    dirs = np.tile(np.float32([1.0, 0.0, 0.0]), (len(org), 1))
    hit = scene.intersect(org, dirs, threads=1)
    keep = np.isfinite(hit["t"])
    org, dirs, t = org[keep], dirs[keep], hit["t"][keep]
    points = org + t[:, None] * dirs
    # Diffuse bounces: uniform directions turned into the hemisphere facing back to the camera,
    # from points nudged off the surface; shadow rays to a point light beside the sphere.
    d = rng.normal(size=points.shape).astype(np.float32)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d[d[:, 0] > 0, 0] *= -1.0
    start = points - 1e-4 * dirs
    light = np.float32([-2.0, -2.5, 3.0])
    to_light = light - start
    sets = {"primary": (org, dirs, np.inf), "diffuse": (start, d, np.inf), "shadow": (start, to_light, 1.0)}
    out = {}
    for name in SETS:
        o, v, tfar = sets[name]
        best_wall, best_cpu = np.inf, np.inf
        for _ in range(3):
            c0, w0 = cpu_s(), time.perf_counter()
            if name == "shadow":
                scene.occluded(o, v, tfar=tfar, threads=1)
            else:
                scene.intersect(o, v, tfar=tfar, threads=1)
            best_wall = min(best_wall, time.perf_counter() - w0)
            best_cpu = min(best_cpu, cpu_s() - c0)
        out[name] = dict(rays=len(o), mrays_wall=len(o) / best_wall / 1e6, mrays_cpu=len(o) / best_cpu / 1e6)
    print(json.dumps(out))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--module", action="append", default=[], help="NAME=DIR of a toyrt module (first: the reference)")
    p.add_argument("--repeats", type=int, default=9)
    p.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.child:
        child()
        return
    modules = [m.split("=", 1) for m in args.module]
    if len(modules) != 2:
        sys.exit("give two modules: --module native=DIR --module wheel=DIR")
    runs = {name: [] for name, _ in modules}
    for r in range(args.repeats):
        order = modules if r % 2 == 0 else modules[::-1]  # alternate who goes first
        for name, path in order:
            env = dict(os.environ, PYTHONPATH=os.path.abspath(path))
            done = subprocess.run([sys.executable, __file__, "--child"], env=env, capture_output=True, text=True)
            if done.returncode != 0:
                sys.exit(f"{name}: {done.stderr[-2000:]}")
            runs[name].append(json.loads(done.stdout.strip().splitlines()[-1]))
        print(f"repeat {r + 1}/{args.repeats}", file=sys.stderr, flush=True)
    (ref, _), (other, _) = modules
    print(f"| rays | count | {ref} Mrays/s | {other} Mrays/s | {other} / {ref} (wall) | {other} / {ref} (CPU time) |")
    print("|---|---|---|---|---|---|")
    for name in SETS:
        rates = {m: [x[name]["mrays_wall"] for x in runs[m]] for m in runs}
        cpu = {m: [x[name]["mrays_cpu"] for x in runs[m]] for m in runs}
        wall_ratio = statistics.median(b / a for a, b in zip(rates[ref], rates[other]))
        cpu_ratio = statistics.median(b / a for a, b in zip(cpu[ref], cpu[other]))
        print(f"| {name} | {runs[ref][0][name]['rays']} | {statistics.median(rates[ref]):.2f} | "
              f"{statistics.median(rates[other]):.2f} | {wall_ratio:.3f} | {cpu_ratio:.3f} |")
    print(f"\n{args.repeats} interleaved repeats, each the fastest of 3 in its process; 1.0M-triangle bumpy sphere,"
          " 1 thread; ratios: median of the per-repeat ratios")


if __name__ == "__main__":
    main()
