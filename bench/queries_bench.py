"""The exact geometric queries against their peers (docs/queries.md; run by `make bench`).

Correctness: closed meshes (cube, icosphere; at the origin, far from it, tiny) with query sets aligned
with their vertices and edges, whose answers are known in closed form: rays from an interior point
aimed at every vertex and edge point cross a convex mesh exactly once; points on those rays at 0.5x
and 1.5x, and a cube's integer grid points off its faces, are inside or outside; a cube's grid
points are at known distances. Each library's wrong answers are counted on the same sets: TOYRT,
Open3D's RaycastingScene (Embree), trimesh (with embreex when installed), and Embree 3 itself
counting as Open3D does (bench/bench_embree_counts.cpp, which reads the sets from a file).

Speed: Mqueries/s on icospheres of 5K to 5.2M triangles, 1 and 2 threads, TOYRT and Open3D side by
side (interleaved calls, medians), with the machine's load average.

Usage: python bench/queries_bench.py [--build build] [--out docs/queries-bench.md] [--quick]
       [--speed-only] [--kinds count ...] [--clock cpu]   (CPU time: steadier on a loaded machine)
"""
import argparse
import os
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))
sys.path.insert(0, str(ROOT / "bench"))
from query_meshes import aligned_rays, cube, icosphere  # noqa: E402


def correctness_sets():
    """(name, (vertices, triangles), rays (o, d) with 1 crossing each, points, inside, distance or None)."""
    sets = []
    for name, size, offset in (("cube", 4.0, (0, 0, 0)), ("cube at 1e5", 4.0, (1e5, -2e5, 4e5)),
                               ("cube at 2^-59", 2.0**-58, (0, 0, 0))):
        mesh = cube(size, offset)
        centre = np.asarray(offset, np.float64) + size / 2
        o, d = aligned_rays(*mesh, centre)
        k = np.arange(-1, 6)
        g = np.stack(np.meshgrid(k, k, k, indexing="ij"), -1).reshape(-1, 3).astype(np.float64)
        g = g * (size / 4)
        inside = np.all((g > 0) & (g < size), axis=1)
        on = np.all((g >= 0) & (g <= size), axis=1) & ~inside
        g, inside = g[~on], inside[~on]  # on-face points: no peer defines them
        outside_d = np.linalg.norm(np.maximum(np.maximum(-g, g - size), 0), axis=1)
        inside_d = np.min(np.concatenate([g, size - g], axis=1), axis=1)
        dist = np.where(inside, inside_d, outside_d)
        pts = (g + np.asarray(offset)).astype(np.float32)
        sets.append((name, mesh, (o, d), pts, inside, dist))
    for name, radius, offset in (("icosphere", 1.0, (0, 0, 0)), ("icosphere at 1e4", 1.0, (1e4, 1e4, 1e4)),
                                 ("icosphere 1e-6", 1e-6, (0, 0, 0))):
        mesh = icosphere(4, radius, offset)
        o, d = aligned_rays(*mesh, offset)
        pts = np.concatenate([o + np.float32(s) * d for s in (0.5, 1.5)]).astype(np.float32)
        inside = np.repeat([True, False], len(o))
        sets.append((name, mesh, (o, d), pts, inside, None))
    return sets


class Toyrt:
    name = "TOYRT"

    def __init__(self, toyrt, mesh):
        self.s = toyrt.Scene()
        self.s.add_mesh(*mesh)
        self.s.commit()

    def count(self, o, d, threads=0):
        return self.s.count_intersections(o, d, threads=threads)

    def list(self, o, d, threads=0):
        return self.s.list_intersections(o, d, threads=threads)["t"]

    def occupancy(self, p, threads=0):
        return self.s.compute_occupancy(p, threads=threads)

    def distance(self, p, threads=0):
        return self.s.compute_distance(p, threads=threads)


class Open3d:
    name = "Open3D"

    def __init__(self, o3d, mesh):
        self.o3d = o3d
        self.s = o3d.t.geometry.RaycastingScene()
        self.s.add_triangles(o3d.core.Tensor(mesh[0]), o3d.core.Tensor(mesh[1]))

    def count(self, o, d, threads=0):
        rays = self.o3d.core.Tensor(np.concatenate([o, d], axis=1).astype(np.float32))
        return self.s.count_intersections(rays, nthreads=threads).numpy()

    def list(self, o, d, threads=0):
        rays = self.o3d.core.Tensor(np.concatenate([o, d], axis=1).astype(np.float32))
        return self.s.list_intersections(rays, nthreads=threads)["t_hit"].numpy()

    def occupancy(self, p, threads=0):
        return self.s.compute_occupancy(self.o3d.core.Tensor(p), nthreads=threads).numpy() > 0.5

    def distance(self, p, threads=0):
        return self.s.compute_distance(self.o3d.core.Tensor(p), nthreads=threads).numpy()


class Trimesh:
    name = "trimesh"

    def __init__(self, trimesh, mesh):
        self.m = trimesh.Trimesh(mesh[0], mesh[1], process=False)
        self.trimesh = trimesh

    def count(self, o, d, threads=0):
        _, rays, _ = self.m.ray.intersects_location(o, d, multiple_hits=True)
        return np.bincount(rays, minlength=len(o))

    def occupancy(self, p, threads=0):
        return self.m.contains(p)

    def distance(self, p, threads=0):
        return self.trimesh.proximity.closest_point(self.m, p)[1]


def embree_direct(build, sets):
    """Embree 3 itself counting crossings as Open3D does (bench/bench_embree_counts.cpp) on the same
    sets, with its default and robust scene flags: ({flags: {set name: (count, occupancy, None)}},
    version) or (None, why)."""
    exe = ROOT / build / "bench" / "bench_embree_counts"
    if not exe.exists():
        return None, f"{exe} not built"
    import struct
    import subprocess
    import tempfile

    with tempfile.NamedTemporaryFile(suffix=".bin", delete=False) as f:
        for name, (v, t), (o, d), pts, inside, _ in sets:
            f.write(struct.pack("<I", len(name.encode())) + name.encode())
            for arr, dtype in ((v, np.float32), (t, np.uint32), (o, np.float32)):
                f.write(struct.pack("<I", len(arr)) + np.ascontiguousarray(arr, dtype).tobytes())
                if arr is o:
                    f.write(np.ascontiguousarray(d, np.float32).tobytes())
            f.write(struct.pack("<I", len(pts)) + np.ascontiguousarray(pts, np.float32).tobytes())
            f.write(np.asarray(inside, np.uint8).tobytes())
    try:
        out = subprocess.run([str(exe), f.name], check=True, capture_output=True, text=True).stdout
    finally:
        os.unlink(f.name)
    rows, version = {}, "3"
    for line in out.splitlines():
        cols = line.split("\t")
        if cols[0] == "version":
            n = int(cols[1])
            version = f"{n // 10000}.{n // 100 % 100}.{n % 100}"
            continue
        name, flags, _, wrong_count, _, wrong_occ = cols
        rows.setdefault(flags, {})[name] = (int(wrong_count), int(wrong_occ), None)
    return rows, version


def wrong_counts(lib, sets):
    """Wrong answers per set: {set name: (count, occupancy, distance or None)}, with the set sizes."""
    out = {}
    for name, mesh, (o, d), pts, inside, dist in sets:
        engine = lib(mesh)
        wrong_count = int(np.sum(engine.count(o, d) != 1))
        wrong_occ = int(np.sum(engine.occupancy(pts) != inside))
        wrong_dist = None
        if dist is not None:
            got = np.asarray(engine.distance(pts), np.float64)
            scale = np.max(np.abs(mesh[0]))
            wrong_dist = int(np.sum(np.abs(got - dist) > 1e-6 * dist + 4 * np.spacing(np.float32(scale))))
        out[name] = (wrong_count, wrong_occ, wrong_dist)
    return out


def speed_side_by_side(engines, o, d, p, q, threads, repeats, clock=time.perf_counter,
                       only=("count", "occupancy", "distance")):
    """Mqueries/s of count, occupancy and distance per engine: the engines run interleaved (one
    call each, in turn, `repeats` times after a warm-up call), so a change in the machine's load
    hits both alike; the median of the repeats. `clock` is wall time, or the process's CPU time
    (all its threads), which other processes on a loaded machine disturb far less.
    {engine name: {kind: Mqueries/s}}."""
    kinds = (("count", lambda e: e.count(o, d, threads), len(o)),
             ("list", lambda e: e.list(o, d, threads), len(o)),
             ("occupancy", lambda e: e.occupancy(p, threads), len(p)),
             ("distance", lambda e: e.distance(q, threads), len(q)))
    res = {name: {} for name in engines}
    for kind, f, n in (k for k in kinds if k[0] in only):
        times = {name: [] for name in engines}
        for r in range(repeats + 1):
            for name, e in engines.items():
                t0 = clock()
                f(e)
                if r:  # the first round warms caches and thread pools
                    times[name].append(clock() - t0)
        for name in engines:
            res[name][kind] = n / float(np.median(times[name])) / 1e6
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default=str(ROOT / "docs" / "queries-bench.md"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--levels", type=int, nargs="*", help="icosphere levels of the speed table (default 4-9)")
    ap.add_argument("--speed-only", action="store_true", help="skip the wrong-answer table")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="time per call: wall, or the process's CPU time (steadier on a loaded machine)")
    ap.add_argument("--kinds", nargs="*", default=("count", "occupancy", "distance"),
                    help="queries to time (count, occupancy, distance, list)")
    args = ap.parse_args()
    sys.path.insert(0, str((ROOT / args.build / "python").resolve()))
    import toyrt

    libs = [("TOYRT", lambda m: Toyrt(toyrt, m))]
    from accel_python import import_open3d

    o3d, why = import_open3d()
    if o3d is not None:
        libs.append(("Open3D " + o3d.__version__, lambda m: Open3d(o3d, m)))
    try:
        import trimesh

        libs.append((f"trimesh {trimesh.__version__} ({'embreex' if trimesh.ray.has_embree else 'no embreex'})",
                     lambda m: Trimesh(trimesh, m)))
    except ImportError as e:
        print("trimesh:", e)

    lines = ["# Exact queries against their peers (bench/queries_bench.py)", "",
             f"Machine: {os.cpu_count()} cores. Generated by `python bench/queries_bench.py` (`make bench`).", "",
             "## Wrong answers on sets aligned with vertices and edges", "",
             "Per set: rays from an interior point at every vertex, edge midpoint and 2 random edge points "
             "(answer: 1 crossing); points (cube: the integer grid off the faces; icosphere: 0.5x and 1.5x "
             "along those rays) inside or outside; the cube grid's distances (closed form, tolerance 1e-6 "
             "relative + 4 float ulps of the coordinates).", ""]
    sets = [] if args.speed_only else correctness_sets()
    header = "| library | " + " | ".join(name for name, *_ in sets) + " |"
    sizes = "| (rays / points) | " + " | ".join(f"{len(r[0])} / {len(p)}" for _, _, r, p, *_ in sets) + " |"
    lines += [header, "| --- " * (len(sets) + 1) + "|", sizes]
    for name, make in libs:
        w = wrong_counts(make, sets)
        cells = [f"{c} / {o}" + (f" / {dd}" if dd is not None else "") for c, o, dd in w.values()]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
        print(lines[-1], flush=True)
    if sets:
        rows, version = embree_direct(args.build, sets)
        if rows is None:
            print("Embree direct:", version)
        for flags, w in (rows or {}).items():
            cells = [f"{c} / {o}" for c, o, _ in w.values()]
            lines.append(f"| Embree {version} direct ({flags}) | " + " | ".join(cells) + " |")
            print(lines[-1], flush=True)
    lines += ["", "Cells: wrong counts / wrong occupancies / wrong distances (cubes only). Embree direct: "
              "bench/bench_embree_counts.cpp, one rtcIntersect1 per ray with a filter that records each hit "
              "offered and rejects it (as Open3D counts), on Embree's default or robust scene; counted "
              "as distinct primitives, or merged (Open3D's rule: a hit with the primitive or the t of the "
              "last one counted is not counted again); occupancy from the parity of one +x ray, TOYRT's "
              "rule; no distances."]
    n = 50_000 if args.quick else 200_000
    repeats = 3 if args.quick else 5
    load_before = os.getloadavg()
    clock = time.process_time if args.clock == "cpu" else time.perf_counter
    lines += ["", f"## Speed (Mqueries/s of {args.clock} time, median of {repeats}, TOYRT and Open3D interleaved): "
              "icospheres, "
              f"{n // 1000}K random rays from [-1.5, 1.5]^3 and points in [-1.2, 1.2]^3 (2K to 20K points for "
              "distance, fewer on the larger meshes)", "",
              "| triangles | threads | count: TOYRT / Open3D | ratio | occupancy: TOYRT / Open3D | ratio | "
              "distance: TOYRT / Open3D | ratio |"
              + (" list: TOYRT / Open3D | ratio |" if "list" in args.kinds else ""),
              "| --- | --- | --- | --- | --- | --- | --- | --- |" + (" --- | --- |" if "list" in args.kinds else "")]
    rng = np.random.default_rng(0)
    levels = args.levels or ((4, 5) if args.quick else (4, 5, 6, 7, 8, 9))
    peers = [lib for lib in libs[:2]]  # trimesh is too slow to time at these sizes
    for level in levels:
        mesh = icosphere(level)
        o = rng.uniform(-1.5, 1.5, (n, 3)).astype(np.float32)
        d = (rng.uniform(-1, 1, (n, 3))).astype(np.float32)
        p = rng.uniform(-1.2, 1.2, (n, 3)).astype(np.float32)
        q = p[: max(2000, n // 10 >> max(0, level - 6))]  # distance: little pruning near the centre
        engines = {name: make(mesh) for name, make in peers}
        for threads in (1, 2):
            r = speed_side_by_side(engines, o, d, p, q, threads, repeats, clock, args.kinds)
            cells = []
            for kind in ("count", "occupancy", "distance") + (("list",) if "list" in args.kinds else ()):
                if kind not in args.kinds:
                    cells += ["-", "-"]
                    continue
                vals = [r[name][kind] for name, _ in peers]
                fmt = "{:.2f}" if kind != "distance" else "{:.3f}"
                cells.append(" / ".join(fmt.format(v) for v in vals))
                cells.append(f"{vals[0] / vals[1]:.2f}" if len(vals) > 1 else "-")
            lines.append(f"| {len(mesh[1]):,} | {threads} | " + " | ".join(cells) + " |")
            print(lines[-1], flush=True)
        del engines
    load_after = os.getloadavg()
    lines += ["", "Ratio: TOYRT / Open3D (above 1: TOYRT faster). Load average (1, 5, 15 min) before: "
              + ", ".join(f"{x:.2f}" for x in load_before) + "; after: "
              + ", ".join(f"{x:.2f}" for x in load_after) + f" ({os.cpu_count()} cores)."]
    pathlib.Path(args.out).write_text("\n".join(lines) + "\n")
    print("wrote", args.out)


if __name__ == "__main__":
    main()
