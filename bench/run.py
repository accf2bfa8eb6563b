# `make bench`: every measurement of docs/results.md, then the report. Each stage writes JSON or
# CSV into the work folder (out/bench by default, outside git); bench/report.py turns them into
# docs/results.md and the charts in docs/results/. The Cycles references are cached in
# out/bench-cache, keyed on the scene's scripts, the Cycles settings and Blender's version.
#
#     .venv/bin/python bench/run.py --build build [--quick] [--only STAGE,...]
# Stages: render (Blender: Cycles and TOYRT sweeps), mitsuba, economy, accel, stability,
# refraction, report.
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

# name, scene script, build options, max specular depth (0: direct light only), Mitsuba can render it
# (its `direct` integrator at depth 0; above, its `path` integrator, for scenes with no diffuse surface)
SCENES = [
    ("cornell", "cornell", {}, 8, False),  # the seed's final scene: glass needs specular chains
    ("cornell_diffuse", "cornell", {"glass": False}, 0, True),
    ("mesh_1m", "mesh_1m", {}, 0, True),
    ("instances", "instances", {}, 0, True),
    ("many_lights", "many_lights", {}, 0, True),
    # Issue 13's lights (Mitsuba: the sun's disc and the spot's edge approximated, listed in its JSON).
    ("sun_spot", "sun_spot", {}, 0, True),
    ("emitter_room", "emitter_room", {}, 0, True),
    ("hdri", "hdri", {}, 0, True),
    # Issue 14's glossy reflections (Principled, metal, Glossy BSDF): paths through the lobes. Mitsuba
    # has no integrator restricted to this transport, nor Cycles' Principled model.
    ("glossy", "glossy", {}, 8, False),
    # The map and an emissive panel seen in the glossy balls: sampled at each glossy vertex.
    ("glossy_hdri", "glossy_hdri", {}, 8, False),
    # Glossy BSDF balls on a Glossy floor, nothing diffuse: TOYRT's transport is then path tracing to
    # depth 8, which Mitsuba's `path` integrator renders too (max_depth 10; bench/mitsuba_bench.py).
    ("glossy_metal", "glossy_metal", {}, 8, True),
]
METHODS = [["solid_angle", "all"], ["solid_angle", "one"], ["area", "all"], ["area", "one"]]
# Features switched on one at a time on the seed's Cornell box (scenes/bench/cornell.py).
ECONOMY = [
    ("bare box, one area light", dict(texture=False, glass=None, point_lights=0)),
    ("+ texture", dict(texture=True, glass=None, point_lights=0)),
    ("+ refraction (glass sphere)", dict(texture=True, glass=True, point_lights=0)),
    ("+ 2 point lights (the seed's scene)", dict(texture=True, glass=True, point_lights=2)),
    ("+ 16 more point lights", dict(texture=True, glass=True, point_lights=2, extra_lights=16)),
    ("+ 400 instances", dict(texture=True, glass=True, point_lights=2, extra_lights=16, instances=400)),
    # The lights issue's additions: each step pays for its own sampling, nothing before it changes.
    ("+ a constant grey world", dict(texture=True, glass=True, point_lights=2, extra_lights=16, instances=400,
                                     world="constant")),
    ("+ an HDRI map for the world instead", dict(texture=True, glass=True, point_lights=2, extra_lights=16,
                                                 instances=400, world="map")),
    ("+ a sun", dict(texture=True, glass=True, point_lights=2, extra_lights=16, instances=400, world="map",
                     sun=True)),
    ("+ an emissive panel", dict(texture=True, glass=True, point_lights=2, extra_lights=16, instances=400,
                                 world="map", sun=True, emitter=True)),
]


def settings(quick):
    if quick:
        return dict(width=64, height=64, ref_spp=1024, spp=[1, 4, 16], repeats=1, economy_spp=16)
    # The economy renders take about a second each at 128 spp: long enough to rise above the
    # timing noise of a shared machine (at 16 spp they took tens of milliseconds and reordered).
    return dict(width=128, height=128, ref_spp=4096, spp=[1, 2, 4, 8, 16, 32, 64, 128], repeats=2, economy_spp=128)


def run(cmd, log, env=None):
    print("bench: $ " + " ".join(str(c) for c in cmd), flush=True)
    t0 = time.perf_counter()
    with open(log, "a") as f:
        p = subprocess.run([str(c) for c in cmd], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           env=env, cwd=REPO)
        f.write(p.stdout)
    for line in p.stdout.splitlines():
        if line.startswith("bench:") or "Error" in line or "Traceback" in line:
            print("  " + line, flush=True)
    if p.returncode != 0:
        print(p.stdout[-3000:], file=sys.stderr)
        raise SystemExit(f"bench: failed ({p.returncode}): {cmd[0]} ... (log: {log})")
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--blender", default=os.environ.get("BLENDER", "blender"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--work", default="out/bench")
    ap.add_argument("--cache", default="out/bench-cache")
    ap.add_argument("--only", default="", help="comma-separated stages")
    ap.add_argument("--scenes", default="", help="comma-separated scenes of the render and mitsuba stages (all)")
    args = ap.parse_args()
    cfg = settings(args.quick)
    work, cache, build = (REPO / args.work).resolve(), (REPO / args.cache).resolve(), (REPO / args.build).resolve()
    work.mkdir(parents=True, exist_ok=True)
    log = work / "bench.log"
    stages = set(args.only.split(",")) if args.only else {"render", "mitsuba", "economy", "accel", "stability",
                                                          "refraction", "report"}
    env = dict(os.environ, PYTHONPATH=str(build / "python"))
    timings = {}
    t_all = time.perf_counter()

    def blender_job(job):
        path = work / f"job-{job['name']}.json"
        path.write_text(json.dumps(job))
        return run([args.blender, "-b", "--python-exit-code", "1", "--python", REPO / "bench" / "blender_bench.py",
                    "--", path], log)

    wanted = set(args.scenes.split(",")) if args.scenes else {s[0] for s in SCENES}
    for name, module, options, depth, mitsuba in SCENES:
        if name not in wanted:
            continue
        if "render" in stages:
            timings[f"render {name}"] = blender_job(dict(
                name=name, module=module, options=options, width=cfg["width"], height=cfg["height"],
                ref_spp=cfg["ref_spp"], specular_depth=depth, cycles_spp=cfg["spp"], toyrt_spp=cfg["spp"],
                methods=METHODS, repeats=cfg["repeats"], out=str(work / f"render-{name}.json"), cache=str(cache),
                mitsuba_dir=str(work / f"mitsuba-{name}") if mitsuba else ""))
        if "mitsuba" in stages and mitsuba:
            timings[f"mitsuba {name}"] = run([sys.executable, REPO / "bench" / "mitsuba_bench.py",
                                              work / f"mitsuba-{name}", work / f"render-{name}.ref.npy",
                                              work / f"mitsuba-{name}.json",
                                              "--spp", *cfg["spp"], "--repeats", cfg["repeats"]], log)
    if "economy" in stages:
        timings["economy"] = blender_job(dict(name="economy", module="cornell", economy=ECONOMY, width=cfg["width"],
                                              height=cfg["height"], spp=cfg["economy_spp"], specular_depth=8,
                                              repeats=cfg["repeats"] + 1, out=str(work / "economy.json")))
    if "accel" in stages:
        dump = work / "accel-rays"
        dump.mkdir(exist_ok=True)
        timings["accel"] = run([build / "bench" / "bench_accel", "--csv", work / "accel.csv", "--dump", dump,
                                "--runs", cfg["repeats"] + 1, *(["--quick"] if args.quick else [])], log)
        timings["accel python"] = run([sys.executable, REPO / "bench" / "accel_python.py", dump,
                                       work / "accel-python.json", "--runs", cfg["repeats"] + 1], log, env)
        for f in dump.glob("*.bin"):
            f.unlink()  # up to 200 MB of meshes and rays: only needed for the step above
    if "stability" in stages:
        timings["stability"] = run([build / "bench" / "bench_stability", "--out", work / "stability.json",
                                    *(["--quick"] if args.quick else [])], log)
    if "refraction" in stages:
        timings["refraction"] = run([sys.executable, REPO / "bench" / "refraction_bench.py", work / "refraction.json",
                                     *(["--quick"] if args.quick else [])], log, env)
    meta_path = work / "run.json"
    meta = json.loads(meta_path.read_text()) if meta_path.exists() and args.only else {}
    meta.update(dict(quick=args.quick, settings=cfg, methods=METHODS, scenes=[s[0] for s in SCENES],
                     date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), build=str(build)))
    meta.setdefault("timings", {}).update(timings)
    meta["total_seconds"] = meta.get("total_seconds", 0.0) * bool(args.only) + time.perf_counter() - t_all
    meta_path.write_text(json.dumps(meta, indent=1))
    if "report" in stages:
        run([sys.executable, REPO / "bench" / "report.py", work, "--blender", args.blender], log, env)
    print(f"bench: done in {time.perf_counter() - t_all:.0f} s; report: docs/results.md", flush=True)


if __name__ == "__main__":
    main()
