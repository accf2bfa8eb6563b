# Is a renderer's converged image the Cycles reference's? Before a time-to-error comparison means
# anything, each renderer's error floor (its bias against the reference) must sit well below the
# errors compared. Runs inside Blender on a scene where bench/run.py's render stage (and, for
# Mitsuba, its dump) ran: renders a second Cycles reference with another seed, and TOYRT and
# Mitsuba (imported from .venv) at SPP samples with two seeds each, then separates noise from bias:
#     noise of one image = RMSE(seed 1 - seed 0) / sqrt(2)
#     bias RMSE^2 = RMSE(mean of X's two - mean of Cycles' two)^2 - (noise_X^2 + noise_Cycles^2) / 2
# also the relative difference of the mean over the counted pixels, and the same on 4 x 4 pixel
# blocks (noise down 4x, a smooth bias kept). Prints one JSON object and a summary.
#     blender -b --python-exit-code 1 --python bench/converged_bias.py -- WORK SCENE [--spp 4096]
import argparse
import json
import math
import sys
import time
from pathlib import Path

import bpy
import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "bench"))
import blender_bench as bb  # noqa: E402
import kit  # noqa: E402
from interleaved_sweep import job_scene, mitsuba_module  # noqa: E402


def rms(x, mask):
    return float(np.sqrt(np.mean(x[mask] ** 2)))


def blocks(img, k=4):
    h, w = img.shape[0] // k * k, img.shape[1] // k * k
    return img[:h, :w].reshape(h // k, k, w // k, k, -1).mean(axis=(1, 3))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("work", type=Path)
    ap.add_argument("scene")
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--save", type=Path, default=None, help="folder for the images (npy)")
    args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:])
    job, ref0, mask = job_scene(args.work, args.scene)

    import render_toyrt
    from render_toyrt import sync

    toyrt = render_toyrt.native()
    scene = bpy.context.scene
    depth = job["specular_depth"]
    images, seconds = {}, {}

    kit.cycles(scene, job["ref_spp"], depth)
    scene.cycles.seed = 1
    images["Cycles"] = [ref0, None]
    images["Cycles"][1], seconds["Cycles"] = bb.render_cycles(scene, args.work / f"{args.scene}.bias.exr")
    print(f"bench: Cycles {job['ref_spp']} spp, seed 1: {seconds['Cycles']:.1f} s", flush=True)
    images["TOYRT"] = []
    for seed in (0, 1):
        img, s = bb.toyrt_render(sync, toyrt, args.spp, "solid_angle", "all", depth, seed=seed)[:2]
        images["TOYRT"].append(img)
        print(f"bench: TOYRT {args.spp} spp, seed {seed}: {s:.1f} s", flush=True)
    mitsuba_dir = Path(job["mitsuba_dir"]) if job.get("mitsuba_dir") else None
    if mitsuba_dir is not None:
        import mitsuba_bench as mb

        old = args.work / f"mitsuba-{args.scene}.json"
        mi = mitsuba_module(json.loads(old.read_text())["variant"] if old.exists() else "scalar_rgb")
        desc = json.loads((mitsuba_dir / "scene.json").read_text())
        images["Mitsuba"] = []
        for seed in (0, 1):
            t0 = time.perf_counter()
            s = mi.load_dict(mb.build_dict(mi, mitsuba_dir, desc))
            images["Mitsuba"].append(np.array(mi.render(s, spp=args.spp, seed=seed), np.float64)[..., :3])
            print(f"bench: Mitsuba {args.spp} spp, seed {seed}: {time.perf_counter() - t0:.1f} s", flush=True)
    if args.save:
        args.save.mkdir(parents=True, exist_ok=True)
        for name, pair in images.items():
            for seed, img in enumerate(pair):
                np.save(args.save / f"{args.scene}-{name}-{seed}.npy", img.astype(np.float32))

    c0, c1 = images["Cycles"]
    cmean = (c0 + c1) / 2
    noise_c = rms(c1 - c0, mask) / math.sqrt(2)
    bmask = blocks(mask[..., None].astype(float))[..., 0] > 0.999
    noise_cb = rms(blocks(c1) - blocks(c0), bmask) / math.sqrt(2)
    out = dict(scene=args.scene, spp=args.spp, ref_spp=job["ref_spp"], cycles_noise=noise_c,
               cycles_noise_4x4=noise_cb, cycles_mean=float(c0[mask].mean()), renderers={})
    for name in ("TOYRT", "Mitsuba"):
        if name not in images:
            continue
        x0, x1 = images[name]
        xmean = (x0 + x1) / 2
        noise = rms(x1 - x0, mask) / math.sqrt(2)
        diff = rms(xmean - cmean, mask)
        bias2 = diff ** 2 - (noise ** 2 + noise_c ** 2) / 2
        noise_b = rms(blocks(x1) - blocks(x0), bmask) / math.sqrt(2)
        diff_b = rms(blocks(xmean) - blocks(cmean), bmask)
        bias2_b = diff_b ** 2 - (noise_b ** 2 + noise_cb ** 2) / 2
        out["renderers"][name] = dict(
            noise=noise, rmse_vs_both_refs=diff, bias_rmse=math.sqrt(max(bias2, 0.0)), bias2=bias2,
            noise_4x4=noise_b, rmse_4x4=diff_b, bias_rmse_4x4=math.sqrt(max(bias2_b, 0.0)), bias2_4x4=bias2_b,
            rmse_vs_reference=rms(xmean - ref0, mask),
            mean_abs_vs_reference=float(np.mean(np.abs(xmean - ref0)[mask])),
            relative_mean_difference=float(xmean[mask].mean() / cmean[mask].mean() - 1.0))
    print("bench: bias " + json.dumps(out), flush=True)


if __name__ == "__main__":
    try:
        main()
    except Exception:
        import traceback
        traceback.print_exc()
        sys.exit(1)
