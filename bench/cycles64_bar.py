# The lights and materials issues' bar, from one run's sweeps: the time at which each renderer's
# error reaches Cycles' error at 64 samples per pixel (interpolated in log-log between the two sample
# counts of its sweep that bracket it), for RMSE and relative MSE, and the speed-ups of TOYRT's
# methods by the report's fits (bench/report.py: speedup). Reads what bench/run.py (render and
# mitsuba stages) wrote into its work folder; prints markdown rows for docs/results.md.
#     .venv/bin/python bench/cycles64_bar.py out/bench glossy_metal [--spp 64]
import argparse
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report import fmt, speedup, worst_share  # noqa: E402


def time_to(runs, method, metric, target):
    """Seconds at which `method`'s sweep (in order of samples per pixel) reaches `target`, log-log
    between the bracketing sample counts; (seconds, spp) or None when the sweep does not reach it."""
    pts = sorted((r["spp"], r["seconds"], r[metric]) for r in runs if r["method"] == method)
    if pts and pts[0][2] <= target:
        return pts[0][1], float(pts[0][0])
    for (s0, t0, e0), (s1, t1, e1) in zip(pts, pts[1:]):
        if e0 >= target >= e1 and e0 > e1:
            f = (math.log(e0) - math.log(target)) / (math.log(e0) - math.log(e1))
            return math.exp(math.log(t0) + f * math.log(t1 / t0)), math.exp(math.log(s0) + f * math.log(s1 / s0))
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("work", type=Path)
    ap.add_argument("scene")
    ap.add_argument("--spp", type=int, default=64, help="Cycles' sample count that sets the bar")
    args = ap.parse_args()
    data = json.loads((args.work / f"render-{args.scene}.json").read_text())
    runs = list(data["runs"])
    mitsuba = args.work / f"mitsuba-{args.scene}.json"
    if mitsuba.exists():
        runs += json.loads(mitsuba.read_text())["runs"]
    methods = list(dict.fromkeys(r["method"] for r in runs))
    peers = [m for m in methods if not m.startswith("TOYRT")]
    bar = {metric: next(r for r in runs if r["method"] == "Cycles" and r["spp"] == args.spp)
           for metric in ("rmse", "relmse")}
    print(f"Cycles at {args.spp} spp: RMSE {fmt(bar['rmse']['rmse'])}, relMSE {fmt(bar['relmse']['relmse'])}, "
          f"{fmt(bar['rmse']['seconds'])} s; worst 1 % of pixels' share of TOYRT's squared error "
          f"{worst_share(args.work, args.scene)}\n")
    print("| method | reaches Cycles' RMSE in s (spp) | reaches Cycles' relMSE in s (spp) | "
          + " | ".join(f"vs {p}, RMSE (n) | vs {p}, relMSE (n)" for p in peers) + " |")
    print("|---|---|---|" + "---|---|" * len(peers))
    for m in methods:
        cells = []
        for metric in ("rmse", "relmse"):
            t = time_to(runs, m, metric, bar[metric][metric])
            cells.append("not reached" if t is None else f"{fmt(t[0])} ({t[1]:.0f})")
        for p in peers:
            for metric in ("rmse", "relmse"):
                s, n = speedup(runs, m, p, metric) if m != p else (None, 0)
                cells.append(f"{'>= ' if s[1] else ''}{fmt(s[0])} ({n})" if s else "-")
        print(f"| {m} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
