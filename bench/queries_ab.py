"""CPU-time A/B of the multi-hit queries between builds of the toyrt module (docs/queries.md).

Each module runs in its own child process, the modules' children alternating; a child builds the
icosphere, warms up, then times `count_intersections` (or `list_intersections`,
`compute_occupancy`, or `compute_closest_points` of the rays' origins) on one thread a few times
by the process's CPU time and prints the median.
The report gives, per size, each module's median over the repeats and the median of the
per-repeat ratios against the first module (a busy spell of the machine hits both modules of one
repeat alike). CPU time, not wall time: two other builds on two cores move wall time by 40 %.

    .venv/bin/python bench/queries_ab.py --module before=DIR --module after=build/python [--levels 6 8]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def child(path, level, kind, n, runs, threads):
    sys.path.insert(0, path)
    sys.path.insert(0, os.path.join(HERE, "..", "tests", "python"))
    import time

    import numpy as np
    import toyrt
    from query_meshes import icosphere

    rng = np.random.default_rng(0)
    o = rng.uniform(-1.5, 1.5, (n, 3)).astype(np.float32)
    d = rng.uniform(-1, 1, (n, 3)).astype(np.float32)
    s = toyrt.Scene()
    s.add_mesh(*icosphere(level))
    s.commit()
    call = {"count": lambda: s.count_intersections(o, d, threads=threads),
            "list": lambda: s.list_intersections(o, d, threads=threads),
            "occupancy": lambda: s.compute_occupancy(o, threads=threads),
            "closest": lambda: s.compute_closest_points(o, threads=threads)}[kind]
    call()
    times = []
    for _ in range(runs):
        t0 = time.process_time()
        call()
        times.append(time.process_time() - t0)
    print(json.dumps({"mqps": n / statistics.median(times) / 1e6}))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--module", action="append", required=True, help="NAME=DIR of a built toyrt module")
    ap.add_argument("--levels", type=int, nargs="*", default=[6, 8], help="icosphere levels (6: 82K, 8: 1.3M)")
    ap.add_argument("--kind", default="count", choices=("count", "list", "occupancy", "closest"))
    ap.add_argument("--rays", type=int, default=200_000)
    ap.add_argument("--runs", type=int, default=3, help="timed calls per child (median)")
    ap.add_argument("--repeats", type=int, default=4, help="children per module (alternating)")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args.child[0], int(args.child[1]), args.kind, args.rays, args.runs, args.threads)
        return
    modules = [m.split("=", 1) for m in args.module]
    print(f"load average {os.getloadavg()}; {args.kind}, {args.rays} rays, {args.threads} thread(s)")
    for level in args.levels:
        runs = {name: [] for name, _ in modules}
        for _ in range(args.repeats):
            for name, path in modules:
                out = subprocess.run([sys.executable, __file__, "--module", "x=x", "--child", os.path.abspath(path),
                                      str(level), "--kind", args.kind, "--rays", str(args.rays), "--runs",
                                      str(args.runs), "--threads", str(args.threads)],
                                     check=True, capture_output=True, text=True).stdout
                runs[name].append(json.loads(out.strip().splitlines()[-1])["mqps"])
        base = runs[modules[0][0]]
        cells = []
        for name, _ in modules:
            ratio = statistics.median(a / b for a, b in zip(runs[name], base))
            cells.append(f"{name} {statistics.median(runs[name]):.3f} Mq/s (x{ratio:.3f})")
        print(f"level {level} ({20 * 4 ** level:,} triangles): " + ", ".join(cells), flush=True)
    print(f"load average {os.getloadavg()}")


if __name__ == "__main__":
    main()
