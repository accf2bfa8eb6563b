# Adaptive sampling where noise is uneven (issue 15): time to equal error with and without it, the
# method of bench/denoise_bench.py (sample sweeps, best of `REPEATS` runs each, log-log
# interpolation of the time at which a sweep reaches the target error) on the toyrt module alone:
#
#   PYTHONPATH=build/python .venv/bin/python bench/adaptive_bench.py [--quick]
#
# The scene: a floor split by a wall along x = 0 (the camera looks straight down on it, the wall's
# top edge is a pixel wide). The left half is lit by a point light only (Lambert under a point
# light: direct lighting with no noise); the right half by a large area light close above it with
# a cube between, casting soft shadows (noisy). Adaptive sampling (Cycles' rule, threshold 0.01,
# Max Samples the fixed sweep's largest count, thresholds from Cycles' default 0.01 down) should
# stop the left half at its minimum and spend the rest on the right. For each threshold: its time
# and error, and the time fixed sampling takes to the same error (log-log between its brackets).
# Error: RMSE and relative MSE against a fixed-sampling reference of REF_SPP samples.
# Prints a Markdown table (docs/denoise-bench.md keeps one run's).
import sys
import time

import numpy as np
import toyrt

QUICK = "--quick" in sys.argv
SIZE = 64 if QUICK else 128
SPP = [4, 8, 16, 32, 64] if QUICK else [4, 8, 16, 32, 64, 128, 256, 512, 1024]  # fixed sampling
THRESHOLDS = [0.01, 0.005] if QUICK else [0.01, 0.005, 0.0025, 0.00125]  # adaptive, Max Samples = SPP[-1]
REF_SPP = 1024 if QUICK else 8192
REPEATS = 1 if QUICK else 2


def quad(s, corners, material):
    s.add_mesh(np.array(corners, np.float32), [[0, 1, 2], [0, 2, 3]], material_ids=material)


def box(s, lo, hi, material):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = np.array([[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)], np.float32)
    f = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7], [2, 7, 3], [0, 4, 6],
         [0, 6, 2], [1, 3, 7], [1, 7, 5]]
    s.add_mesh(v, f, material_ids=material)


def scene():
    s = toyrt.Scene()
    s.add_material("diffuse", color=(0.7, 0.7, 0.7))
    quad(s, [[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], 0)
    quad(s, [[0, -3, 0], [0, 3, 0], [0, 3, 3], [0, -3, 3]], 0)  # the wall between the halves
    box(s, (0.7, -0.3, 0.3), (1.3, 0.3, 0.9), 0)  # the cube over the right half
    s.add_light("POINT", position=(-1.0, 0.0, 2.0), power=200.0)
    lamp = np.eye(4)
    lamp[:3, 3] = (1.0, 0.0, 1.5)  # emits along -Z, onto the cube and the floor around it
    s.add_light("AREA", matrix=lamp, size=1.6, power=100.0)
    s.commit()
    return s


def camera():
    m = np.eye(4)
    m[:3, 3] = (0.0, 0.0, 4.0)
    return dict(type="ORTHO", ortho_scale=4.0, resolution_x=SIZE, resolution_y=SIZE, matrix_world=m,
                clip_start=0.1, clip_end=100.0)


def run(s, spp, adaptive, threshold=0.01):
    best = None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        img = s.render(camera(), samples=spp, use_adaptive_sampling=adaptive, adaptive_threshold=threshold)
        seconds = time.perf_counter() - t0
        if best is None or seconds < best[1]:
            best = (np.asarray(img)[..., :3].astype(np.float64), seconds, s.last_render.get("mean_samples", spp))
    return best


def time_to(points, target):
    """Seconds at which the (seconds, rmse) sweep reaches `target` (log-log between its brackets)."""
    points = sorted(points)
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e0 >= target >= e1 and e0 > e1:
            f = (np.log(e0) - np.log(target)) / (np.log(e0) - np.log(e1))
            return float(np.exp(np.log(t0) + f * (np.log(t1) - np.log(t0))))
    return None


def main():
    s = scene()
    t0 = time.perf_counter()
    ref = np.asarray(s.render(camera(), samples=REF_SPP))[..., :3].astype(np.float64)
    print(f"reference: {REF_SPP} samples, {time.perf_counter() - t0:.1f} s", flush=True)
    half = SIZE // 2
    rows, fixed = [], []

    def measure(kind, spp, adaptive, threshold=0.01):
        img, seconds, mean = run(s, spp, adaptive, threshold)
        err = (img - ref) ** 2
        rmse, rel = float(np.sqrt(err.mean())), float((err / (ref ** 2 + 1e-2)).mean())
        left, right = float(np.sqrt(err[:, : half - 1].mean())), float(np.sqrt(err[:, half + 1:].mean()))
        rows.append((kind, spp, seconds, mean, rmse, rel, left, right))
        print(f"{kind:16s} {spp:5d} spp {seconds:7.3f} s mean {mean:7.1f} RMSE {rmse:.5f} relMSE {rel:.2e} "
              f"(left {left:.5f}, right {right:.5f})", flush=True)
        return seconds, rmse

    for spp in SPP:
        fixed.append(measure("fixed", spp, False))
    adaptive = [(t, *measure(f"adaptive {t:g}", SPP[-1], True, t)) for t in THRESHOLDS]
    print("\n| sampling | Max Samples | seconds | mean samples / pixel | RMSE | relative MSE | RMSE left / right |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for kind, spp, seconds, mean, rmse, rel, left, right in rows:
        print(f"| {kind} | {spp} | {seconds:.3f} | {mean:.1f} | {rmse:.5f} | {rel:.2e} | {left:.5f} / {right:.5f} |")
    # Samples are the load-free measure (a shared machine's times drift between sweeps): fixed
    # sampling's samples to the same RMSE, log-log between its brackets, as time_to does for seconds.
    fixed_spp = [(float(spp), rmse) for (_, rmse), spp in zip(fixed, SPP)]
    means = {kind: mean for kind, _spp, _s, mean, *_ in rows}
    print("\n| threshold | adaptive: seconds, mean samples, RMSE | fixed sampling to that RMSE: seconds, samples "
          "| speed-up in time, in samples |")
    print("| --- | --- | --- | --- |")
    for threshold, seconds, rmse in adaptive:
        tf, sf = time_to(fixed, rmse), time_to(fixed_spp, rmse)
        mean = means[f"adaptive {threshold:g}"]
        if tf and sf:
            print(f"| {threshold:g} | {seconds:.3f} s, {mean:.1f}, {rmse:.5f} | {tf:.3f} s, {sf:.1f} "
                  f"| {tf / seconds:.2f}x, {sf / mean:.2f}x |")
        else:
            print(f"| {threshold:g} | {seconds:.3f} s, {mean:.1f}, {rmse:.5f} | not bracketed by the sweep | - |")


if __name__ == "__main__":
    main()
