# Denoising and adaptive sampling against Cycles (issue 15), under the bpy module (Blender 5.0,
# whose Cycles has Open Image Denoise; Debian's 3.4 has none):
#
#   .venv/bin/python tests/blender/run_with_bpy.py bench/denoise_bench.py --build build -- [--quick]
#
# One bench scene (scenes/bench/, Cycles restricted to TOYRT's transport: scenes/cycles_like_toyrt.py)
# against Cycles' converged reference (bench/blender_bench.py's, cached in out/bench-cache/). Sample
# sweeps, each point the best of two warm runs, wall time from the Blender scene to the image:
#   Cycles and Cycles + OIDN (scene.cycles.use_denoising with its albedo and normal), the denoiser's
#   time included; TOYRT and TOYRT + OIDN (pyoidn with the Diffuse Color and Normal passes, as the
#   add-on's Denoise does: addon/render_toyrt/denoise.py), the denoiser's time included; TOYRT with
#   adaptive sampling (Cycles' rule, threshold 0.01, the sweep's count as Max Samples).
# RMSE and relative MSE over the pixels that do not see a light (blender_bench.error_mask). From the
# sweeps: each method's time to Cycles' 64-sample error (log-log interpolation between the two
# bracketing points), and TOYRT + OIDN against Cycles + OIDN at equal time. Writes
# docs/denoise-bench.md.
import importlib.util
import json
import sys
import time
from pathlib import Path

import bpy
import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scenes"))
import kit  # noqa: E402

_spec = importlib.util.spec_from_file_location("blender_bench", REPO / "bench" / "blender_bench.py")
bb = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(bb)

QUICK = "--quick" in sys.argv
SCENE = "cornell_diffuse"  # the seed's box without its glass: a Lambert scene lit by an area light
WIDTH, HEIGHT = (96, 96) if QUICK else (256, 256)
SPP = [1, 4, 16] if QUICK else [1, 2, 4, 8, 16, 32, 64, 128]
REF_SPP = 1024 if QUICK else 4096
REPEATS = 1 if QUICK else 2
OUT = REPO / "docs" / "denoise-bench.md"


def cycles_run(scene, spp, denoise, tmp):
    kit.cycles(scene, spp, 0)
    scene.cycles.use_denoising = denoise
    if denoise:
        scene.cycles.denoiser = "OPENIMAGEDENOISE"
        scene.cycles.denoising_input_passes = "RGB_ALBEDO_NORMAL"
        scene.cycles.denoising_prefilter = "ACCURATE"
    return min((bb.render_cycles(scene, tmp) for _ in range(REPEATS)), key=lambda r: r[1])


def toyrt_run(sync, toyrt, denoise_module, spp, denoise, adaptive=False):
    best = None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        scene_t, cam, _stats = sync.export_scene(bpy.context.evaluated_depsgraph_get(), toyrt)
        scene_t.commit()
        img = scene_t.render(cam, samples=spp, max_specular_depth=0, area_light_sampling="solid_angle",
                             light_sampling="auto", passes=list(denoise_module.AUXILIARIES) if denoise else None,
                             use_adaptive_sampling=adaptive, adaptive_threshold=0.01)
        if denoise:
            img = denoise_module.denoise(img, scene_t.last_passes)
        seconds = time.perf_counter() - t0
        mean = scene_t.last_render.get("mean_samples", spp)
        if best is None or seconds < best[1]:
            best = (img[..., :3].astype(np.float64), seconds, mean)
    return best


def time_to(points, target):
    """Seconds at which the (seconds, rmse) sweep reaches `target`, interpolated in log-log between
    the two points that bracket it; None when the sweep never reaches it."""
    points = sorted(points)
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e0 >= target >= e1 and e0 > e1:
            f = (np.log(e0) - np.log(target)) / (np.log(e0) - np.log(e1))
            return float(np.exp(np.log(t0) + f * (np.log(t1) - np.log(t0))))
    if points and points[0][1] <= target:
        return points[0][0]
    return None


def error_at(points, seconds):
    """RMSE of the sweep at `seconds`, log-log interpolated; None outside the sweep's times."""
    points = sorted(points)
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if t0 <= seconds <= t1:
            f = (np.log(seconds) - np.log(t0)) / (np.log(t1) - np.log(t0)) if t1 > t0 else 0.0
            return float(np.exp(np.log(e0) + f * (np.log(e1) - np.log(e0))))
    return None


def main():
    import render_toyrt
    from render_toyrt import denoise as denoise_module
    from render_toyrt import sync

    why = denoise_module.available()
    if why is not None:
        sys.exit(f"denoise bench: {why}")
    toyrt = render_toyrt.native()
    module, path = bb.load_scene_module("cornell")
    module.build(glass=False)
    scene = bpy.context.scene
    kit.output(scene, WIDTH, HEIGHT)
    bpy.context.view_layer.update()
    job = dict(name=SCENE, options={"glass": False}, width=WIDTH, height=HEIGHT, ref_spp=REF_SPP, specular_depth=0)
    ref, info = bb.reference(job, path, REPO / "out" / "bench-cache")
    mask = bb.error_mask(ref)
    tmp = REPO / "out" / "denoise-bench.exr"
    tmp.parent.mkdir(parents=True, exist_ok=True)
    cycles_run(scene, 1, False, tmp)  # warm: Cycles' first render in a process loads its kernels
    toyrt_run(sync, toyrt, denoise_module, 1, True)  # warm: OIDN's first device and filter

    rows = []
    for spp in SPP:
        for method, run in (("Cycles", lambda: cycles_run(scene, spp, False, tmp) + (spp,)),
                            ("Cycles + OIDN", lambda: cycles_run(scene, spp, True, tmp) + (spp,)),
                            ("TOYRT", lambda: toyrt_run(sync, toyrt, denoise_module, spp, False)),
                            ("TOYRT + OIDN", lambda: toyrt_run(sync, toyrt, denoise_module, spp, True)),
                            ("TOYRT adaptive", lambda: toyrt_run(sync, toyrt, denoise_module, spp, False, True))):
            img, seconds, mean = run()
            rmse, relmse = bb.errors(img, ref, mask)
            rows.append(dict(method=method, spp=spp, mean_samples=float(mean), seconds=seconds, rmse=rmse,
                             relmse=relmse))
            print(f"bench: {method} {spp} spp {seconds:.3f} s rmse {rmse:.4g}", flush=True)
    write(rows, info)


def write(rows, info):
    methods = list(dict.fromkeys(r["method"] for r in rows))
    sweep = {m: [(r["seconds"], r["rmse"]) for r in rows if r["method"] == m] for m in methods}
    target_spp = 64 if 64 in SPP else SPP[-1]
    target = next(r["rmse"] for r in rows if r["method"] == "Cycles" and r["spp"] == target_spp)
    cycles_time = next(r["seconds"] for r in rows if r["method"] == "Cycles" and r["spp"] == target_spp)
    lines = [
        "# Denoising and adaptive sampling against Cycles",
        "",
        f"Made by `bench/denoise_bench.py` under the bpy module (Blender {bpy.app.version_string}, whose Cycles has "
        f"Open Image Denoise) on {time.strftime('%Y-%m-%d', time.gmtime())}: the seed's Cornell box without its "
        f"glass (Lambert, one area light), {WIDTH} x {HEIGHT}, Cycles restricted to TOYRT's light transport, "
        f"against Cycles' {REF_SPP}-sample reference; every point the best of {REPEATS} warm runs, wall time from "
        "the Blender scene to the image, the denoiser's time included. OIDN runs on the CPU in both engines "
        "(Cycles: albedo and normal, accurate prefilter; TOYRT: pyoidn with the Diffuse Color and Normal "
        "passes, as its Denoise setting). Adaptive: Cycles' rule, threshold 0.01, the count as Max Samples. "
        "RMSE over the pixels that do not see the light. This machine: 2 cores, shared with other work while "
        "it ran, so single points carry noise.",
        "",
        f"## Time to Cycles' {target_spp}-sample error (RMSE {target:.4g}, {cycles_time:.3f} s)",
        "",
        "| method | seconds | against Cycles |",
        "| --- | --- | --- |",
    ]
    for m in methods:
        t = time_to(sweep[m], target)
        lines.append(f"| {m} | not reached in the sweep | |" if t is None else
                     f"| {m} | {t:.3f} | {cycles_time / t:.2f}x Cycles' speed |")
    toyrt_t, toyrt_dn_t = time_to(sweep["TOYRT"], target), time_to(sweep["TOYRT + OIDN"], target)
    if toyrt_t and toyrt_dn_t:
        lines += ["", f"Denoising buys TOYRT {toyrt_t / toyrt_dn_t:.1f}x at that error."]
    ad_t = time_to(sweep["TOYRT adaptive"], target)
    if toyrt_t and ad_t:
        lines += [f"Adaptive sampling: {toyrt_t / ad_t:.2f}x the speed of the plain render at that error."]
    lines += ["", "## TOYRT + OIDN against Cycles + OIDN at equal time", "",
              "| samples (TOYRT) | seconds | TOYRT + OIDN RMSE | Cycles + OIDN RMSE at that time |",
              "| --- | --- | --- | --- |"]
    for r in rows:
        if r["method"] == "TOYRT + OIDN":
            other = error_at(sweep["Cycles + OIDN"], r["seconds"])
            lines.append(f"| {r['spp']} | {r['seconds']:.3f} | {r['rmse']:.4g} | "
                         + (f"{other:.4g} |" if other is not None else "outside Cycles' sweep |"))
    lines += ["", "## Every point", "", "| method | samples | mean samples per pixel | seconds | RMSE | relative MSE |",
              "| --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r['method']} | {r['spp']} | {r['mean_samples']:.1f} | {r['seconds']:.4f} | "
                     f"{r['rmse']:.4g} | {r['relmse']:.4g} |")
    lines += ["", f"Reference: {json.dumps(info)}", ""]
    if not QUICK:
        OUT.write_text("\n".join(lines))
    print("\n".join(lines))


main()
