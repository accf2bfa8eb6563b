"""What building without -march=native costs the ray tracer: bench_trace of two builds (a native
one and a portable one, -DTOYRT_NATIVE_ARCH=OFF as the wheels are), run in turn so that both see the
same state of a shared machine, and the medians of TOYRT's Mrays/s per row of its tracing table
(docs/install.md). The render side is bench/render_overhead.py with one --module per build.

    .venv/bin/python bench/portable_speed.py --native build --portable build-portable [--runs 5]
    .venv/bin/python bench/portable_speed.py --native build --portable build-levels/tests/levels/bench_trace_v4
"""
import argparse
import math
import re
import statistics
import subprocess
import tempfile
from pathlib import Path

# | bumpy sphere, 1.0M triangles | primary | 1 | 76800 | 2.86 | 5.42 | **0.53** |
ROW = re.compile(r"^\| (?P<mesh>[^|]+) \| (?P<rays>primary|diffuse|shadow[^|]*) \| (?P<threads>\d+) \| \d+ "
                 r"\| (?P<toyrt>[\d.]+) \|")


def trace_rates(bench: Path) -> dict[tuple[str, str, str], float]:
    """One quick bench_trace run: TOYRT Mrays/s by (mesh, rays, threads)."""
    with tempfile.NamedTemporaryFile(suffix=".md") as out:
        subprocess.run([str(bench), "--quick", "--runs", "1", "--out", out.name], check=True, capture_output=True)
        text = Path(out.name).read_text()
    return {(m["mesh"], m["rays"], m["threads"]): float(m["toyrt"]) for m in map(ROW.match, text.splitlines()) if m}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--native", default="build", help="build folder with -march=native")
    parser.add_argument("--portable", default="build-portable", help="build folder with TOYRT_NATIVE_ARCH=OFF")
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    # A build folder (its bench/bench_trace) or a bench_trace binary itself, e.g. one CPU level of the
    # wheels: build-levels/tests/levels/bench_trace_v4 (make test-levels' folder, target toyrt_level_benches).
    builds = {name: Path(path) if Path(path).is_file() else Path(path) / "bench" / "bench_trace"
              for name, path in (("native", args.native), ("portable", args.portable))}
    rates = {name: [] for name in builds}
    for run in range(args.runs):
        for name, bench in builds.items():  # interleaved: a busy spell of the machine hits both
            rates[name].append(trace_rates(bench))
        print(f"run {run + 1}/{args.runs} done", flush=True)
    print("\n| rays | threads | native Mrays/s | portable Mrays/s | portable / native |\n|---|---|---|---|---|")
    ratios = []
    for key in rates["native"][0]:
        native = statistics.median(r[key] for r in rates["native"])
        portable = statistics.median(r[key] for r in rates["portable"])
        ratios.append(portable / native)
        print(f"| {key[0]}, {key[1]} | {key[2]} | {native:.2f} | {portable:.2f} | {portable / native:.2f} |")
    geomean = math.exp(statistics.fmean(math.log(r) for r in ratios))
    print(f"\nmedians of {args.runs} interleaved runs; geometric mean of portable / native: {geomean:.2f}")


if __name__ == "__main__":
    main()
