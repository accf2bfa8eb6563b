"""Chart of bench_lbvh's CSV: build time and trace speed against triangle count, per builder.

    python3 bench/plot_lbvh.py docs/lbvh.csv docs/lbvh.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path, png_path):
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    n = [int(r["triangles"]) for r in rows]
    series = [("SAH (TBB)", "sah", "o-"), ("LBVH 30-bit (PoCL)", "lbvh", "s-"),
              ("LBVH 63-bit (PoCL)", "lbvh63", "^--"), ("LBVH on the host", "host", "v-"), ("Embree 3", "embree", "d:")]
    fig, (build, trace) = plt.subplots(1, 2, figsize=(11, 4.2))
    for label, key, style in series:
        build.plot(n, [float(r[f"{key}_ms"]) for r in rows], style, label=label)
        trace.plot(n, [float(r[f"{key}_mrays"]) for r in rows], style, label=label)
    build.set(xscale="log", yscale="log", xlabel="triangles", ylabel="build time (ms)", title="Build time")
    trace.set(xscale="log", xlabel="triangles", ylabel="Mrays/s (all threads)", title="Trace speed, mixed rays")
    trace.set_ylim(bottom=0)
    for ax in (build, trace):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
