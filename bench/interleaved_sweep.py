# The render and mitsuba stages' sweeps again, interleaved, for a shared machine whose load changes
# over minutes: bench/run.py renders all of Cycles' sample counts, then TOYRT's, then Mitsuba's, so a
# build starting beside it slows one renderer's sweep and not another's. Here each repeat renders
# every sample count with every renderer in turn (the order rotating between repeats) in one Blender
# process, Mitsuba imported from .venv, and each point keeps its best time, as bench/run.py does.
# Reads the scene's job, reference, mask and Mitsuba dump from a work folder where bench/run.py's
# render stage ran; writes render-SCENE.json and mitsuba-SCENE.json in the same form to OUT (with
# the reference and mask beside them), which bench/cycles64_bar.py and bench/report.py read.
#     blender -b --python-exit-code 1 --python bench/interleaved_sweep.py -- WORK SCENE OUT \
#         [--spp 1 2 4 ...] [--repeats 3] [--methods solid_angle/all area/all]
import argparse
import json
import sys
import time
from pathlib import Path

import bpy
import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "bench"))
import blender_bench as bb  # noqa: E402  (puts scenes/ on sys.path)
import kit  # noqa: E402


def mitsuba_module(variant):
    """Mitsuba from .venv (requirements-bench.txt), after Blender's own packages on sys.path."""
    sys.path.extend(str(p) for p in sorted((REPO / ".venv" / "lib").glob("python3*/site-packages")))
    import mitsuba as mi

    mi.set_variant(variant)
    return mi


def job_scene(work, name):
    """The job bench/run.py wrote into `work` for scene `name`, its scene rebuilt in this Blender:
    (job, the Cycles reference as float64, the pixel mask)."""
    job = json.loads((work / f"job-{name}.json").read_text())
    ref = np.load(work / f"render-{name}.ref.npy").astype(np.float64)
    mask = np.load(work / f"render-{name}.mask.npy")
    module, _ = bb.load_scene_module(job["module"])
    module.build(**job.get("options", {}))
    kit.output(bpy.context.scene, job["width"], job["height"])
    bpy.context.view_layer.update()
    return job, ref, mask


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("work", type=Path)
    ap.add_argument("scene")
    ap.add_argument("out", type=Path)
    ap.add_argument("--spp", type=int, nargs="+", default=[1, 2, 4, 8, 16, 32, 64, 128, 256, 512])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--methods", nargs="+", default=["solid_angle/all", "area/all"])
    args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:])
    job, ref, mask = job_scene(args.work, args.scene)
    args.out.mkdir(parents=True, exist_ok=True)
    np.save(args.out / f"render-{args.scene}.ref.npy", ref.astype(np.float32))
    np.save(args.out / f"render-{args.scene}.mask.npy", mask)

    import render_toyrt
    from render_toyrt import mesh, sync  # noqa: F401  (the add-on's exporter)

    toyrt = render_toyrt.native()
    scene = bpy.context.scene
    depth = job["specular_depth"]
    tmp = args.out / f"{args.scene}.cycles.exr"

    mitsuba_dir = Path(job["mitsuba_dir"]) if job.get("mitsuba_dir") else None
    mi = desc = None
    if mitsuba_dir is not None:
        import mitsuba_bench as mb

        old = args.work / f"mitsuba-{args.scene}.json"
        variant = json.loads(old.read_text())["variant"] if old.exists() else "scalar_rgb"
        mi = mitsuba_module(variant)
        desc = json.loads((mitsuba_dir / "scene.json").read_text())
        approximations = []
        integrator = mb.build_dict(mi, mitsuba_dir, desc, approximations)["integrator"]

    def cycles(spp):
        kit.cycles(scene, spp, depth)
        return bb.render_cycles(scene, tmp)

    def toyrt_method(area, lights):
        def render(spp):
            img, seconds = bb.toyrt_render(sync, toyrt, spp, area, lights, depth)[:2]
            return img, seconds
        return render

    def mitsuba(spp):
        t0 = time.perf_counter()
        s = mi.load_dict(mb.build_dict(mi, mitsuba_dir, desc))
        img = np.array(mi.render(s, spp=spp), np.float64)[..., :3]
        return img, time.perf_counter() - t0

    renderers = [("Cycles", "cycles", cycles)]
    for m in args.methods:
        area, lights = m.split("/")
        renderers.append((f"TOYRT {m}", "toyrt", toyrt_method(area, lights)))
    if mi is not None:
        renderers.append((f"Mitsuba 3 {integrator['type']}", "mitsuba", mitsuba))
    for _, _, render in renderers:
        render(1)  # warm-up: kernels, JIT, first-use allocations
    points = {}
    for r in range(args.repeats):
        order = renderers[r % len(renderers):] + renderers[:r % len(renderers)]
        for spp in args.spp:
            for name, kind, render in order:
                img, seconds = render(spp)
                p = points.setdefault((name, spp), dict(renderer=kind, method=name, spp=spp, times=[]))
                p["times"].append(seconds)
                if "rmse" not in p:
                    p["rmse"], p["relmse"] = bb.errors(img, ref, mask)
                    if name == f"TOYRT {args.methods[0]}" and spp == max(args.spp):
                        np.save(args.out / f"render-{args.scene}.toyrt.npy", img.astype(np.float32))
        print(f"bench: {args.scene}: repeat {r + 1}/{args.repeats} done", flush=True)
    runs = []
    for p in points.values():
        p["seconds"] = min(p["times"])
        p["median_seconds"] = float(np.median(p["times"]))
        runs.append(p)
        print(f"bench: {args.scene}: {p['method']} {p['spp']} spp {p['seconds']:.3f} s (median "
              f"{p['median_seconds']:.3f}) rmse {p['rmse']:.4g}", flush=True)
    render_json = json.loads((args.work / f"render-{args.scene}.json").read_text())
    render_json["runs"] = [p for p in runs if p["renderer"] != "mitsuba"]
    render_json["interleaved"] = dict(repeats=args.repeats, spp=args.spp, source=str(args.work))
    (args.out / f"render-{args.scene}.json").write_text(json.dumps(render_json, indent=1))
    if mi is not None:
        (args.out / f"mitsuba-{args.scene}.json").write_text(json.dumps(dict(
            variant=mi.variant(), version=mi.__version__, integrator=integrator, approximations=approximations,
            runs=[p for p in runs if p["renderer"] == "mitsuba"], interleaved=True), indent=1))


if __name__ == "__main__":
    try:
        main()
    except Exception:
        import traceback
        traceback.print_exc()
        sys.exit(1)
