# The Python ray APIs on the very rays bench_accel wrote (its --dump files): TOYRT's toyrt.Scene
# against Open3D's RaycastingScene (PyPI open3d-cpu, Embree 4 inside), build and trace per ray type,
# whether they agree on hit or miss, and what TOYRT's builder="auto" builds for a preview and for a
# final render's ray count. Runs in .venv with PYTHONPATH=BUILD/python:
#     .venv/bin/python bench/accel_python.py DUMP_DIR OUT.json [--runs N]
import argparse
import json
import sys
import time
import types
from pathlib import Path

import numpy as np

# The workloads of bench_accel (and bench_lbvh): one primary, one shadow and one bounce ray per sample.
PREVIEW_RAYS = 640 * 360 * 3
FINAL_RAYS = 1920 * 1080 * 64 * 3


def import_open3d():
    """Open3D, or (None, why). open3d's package __init__ imports its notebook plotting
    (plotly, dash) at import time; the ray API needs neither, so empty stand-ins keep those large
    web stacks out of requirements-bench.txt."""
    class Absent(types.ModuleType):
        def __getattr__(self, name):
            if name.startswith("__"):
                raise AttributeError(name)
            return None
    for name in ("plotly", "plotly.graph_objects", "dash"):
        sys.modules.setdefault(name, Absent(name))
    try:
        import open3d
        return open3d, ""
    except Exception as e:  # no wheel for this Python, or a missing system library
        return None, f"{type(e).__name__}: {e}"


def best(runs, f):
    times, out = [], None
    for _ in range(runs):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def load_rays(path):
    r = np.fromfile(path, np.float32).reshape(-1, 8)
    org, d, tnear, tfar = r[:, 0:3], r[:, 3:6], r[:, 6], r[:, 7]
    # Open3D's occlusion test takes one tfar for all rays: scale shadow directions so it is 1.
    finite = np.isfinite(tfar)
    if finite.all():
        d = d * tfar[:, None]
        tnear, tfar = tnear / tfar, np.ones_like(tfar)
    return np.ascontiguousarray(org), np.ascontiguousarray(d), tnear, tfar


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dump_dir", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--runs", type=int, default=2)
    args = ap.parse_args()
    import toyrt
    o3d, o3d_error = import_open3d()

    sizes = sorted(int(p.name.split("-")[1].split(".")[0]) for p in args.dump_dir.glob("accel-*.verts.bin"))
    rows = []
    for n in sizes:
        base = args.dump_dir / f"accel-{n}"
        verts = np.fromfile(f"{base}.verts.bin", np.float32).reshape(-1, 3)
        tris = np.fromfile(f"{base}.tris.bin", np.uint32).reshape(-1, 3)
        rays = {kind: load_rays(f"{base}.{kind}.bin") for kind in ("primary", "diffuse", "shadow")}
        row = dict(triangles=n)

        def toyrt_build(builder, expected=None):
            s = toyrt.Scene()
            s.add_mesh(verts, tris)
            t0 = time.perf_counter()
            s.commit(builder=builder, expected_rays=expected)
            return time.perf_counter() - t0, s
        build_s, scene = min((toyrt_build("sah") for _ in range(args.runs)), key=lambda r: r[0])
        row["toyrt_build_ms"] = build_s * 1e3
        toyrt_hits = {}
        for kind, (org, d, tnear, tfar) in rays.items():
            if kind == "shadow":
                sec, res = best(args.runs, lambda: scene.occluded(org, d, tnear=tnear, tfar=tfar))
                toyrt_hits[kind] = np.asarray(res, bool)
            else:
                sec, res = best(args.runs, lambda: scene.intersect(org, d, tnear=tnear, tfar=tfar))
                toyrt_hits[kind] = np.isfinite(res["t"])
            row[f"toyrt_{kind}_mrays"] = len(org) / sec / 1e6
        for label, expected in (("preview", PREVIEW_RAYS), ("final", FINAL_RAYS)):
            _, s = toyrt_build("auto", expected)
            row[f"auto_{label}"] = json.loads(json.dumps(s.last_commit, default=str))

        if o3d is not None:
            def o3d_build():
                s = o3d.t.geometry.RaycastingScene()
                s.add_triangles(o3d.core.Tensor(verts), o3d.core.Tensor(tris))
                # Open3D builds its BVH (Embree's) lazily, on the first query: one ray includes it.
                s.cast_rays(o3d.core.Tensor(np.float32([[0, 0, 10, 0, 0, -1]])))
                return s
            sec, s = best(args.runs, o3d_build)
            row["open3d_build_ms"] = sec * 1e3
            for kind, (org, d, tnear, tfar) in rays.items():
                t = o3d.core.Tensor(np.hstack([org, d]).astype(np.float32))
                if kind == "shadow":
                    sec, res = best(args.runs, lambda: s.test_occlusions(t, tnear=float(tnear.max()), tfar=1.0))
                    hit = res.numpy().astype(bool)
                else:
                    sec, res = best(args.runs, lambda: s.cast_rays(t))
                    hit = np.isfinite(res["t_hit"].numpy())
                row[f"open3d_{kind}_mrays"] = len(org) / sec / 1e6
                row[f"agree_{kind}"] = float((hit == toyrt_hits[kind]).mean())
        rows.append(row)
        print(f"bench: python ray APIs, {n} triangles: " + ", ".join(
            f"{k} {v:.3g}" for k, v in row.items() if isinstance(v, float)), flush=True)
    info = dict(toyrt=getattr(toyrt, "__version__", "?"), open3d=o3d.__version__ if o3d else None,
                open3d_error=o3d_error, rows=rows)
    args.out.write_text(json.dumps(info, indent=1))


if __name__ == "__main__":
    main()
