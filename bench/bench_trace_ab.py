"""A/B of two builds of bench/bench_trace through its own yardstick: each run times TOYRT against
Embree on the same rays in one process, so the TOYRT / Embree ratio of a row already cancels most of
what a shared machine does to both; this runs the two binaries in turn, the order swapped every
round (old-new, then new-old), and reports each row's median ratio under either build. Where a
change acts through memory (a 1M- or 4M-triangle mesh, beyond the caches), single trace_only runs
(bench/trace_ab.py) moved with the machine's memory traffic more than the change moved them; the
ratio to Embree moved much less (docs/trace-speed.md, thirty-ninth session).

    cp build/bench/bench_trace /tmp/bench_trace_old     # before the change; rebuild, then:
    python3 bench/bench_trace_ab.py /tmp/bench_trace_old build/bench/bench_trace --only "1.0M triangles"

A round takes one bench_trace run per binary: about 15 s for the 1M mesh, 45 s for the 4M one.
"""

import argparse
import collections
import os
import statistics
import subprocess
import sys
import tempfile


def ratios(binary, only, out):
    """TOYRT / Embree by (mesh, rays, threads) from one bench_trace run's tracing table."""
    subprocess.run([binary, "--only", only, "--out", out], check=True, capture_output=True)
    rows = {}
    with open(out) as f:
        for line in f:
            cells = [c.strip() for c in line.split("|")]
            # | mesh | rays | threads | count | TOYRT | Embree | **ratio** | ...
            if len(cells) > 8 and cells[7].startswith("**"):
                rows[(cells[1], cells[2], cells[3])] = float(cells[7].strip("*"))
    if not rows:
        sys.exit(f"{binary}: no tracing rows for --only {only!r}")
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--only", required=True, help="bench_trace's --only (a mesh name's part)")
    parser.add_argument("--rounds", type=int, default=4)
    a = parser.parse_args()
    seen = {a.old: collections.defaultdict(list), a.new: collections.defaultdict(list)}
    with tempfile.TemporaryDirectory() as scratch:
        out = os.path.join(scratch, "bench-trace.md")
        for r in range(a.rounds):
            for binary in (a.old, a.new) if r % 2 == 0 else (a.new, a.old):
                for row, ratio in ratios(binary, a.only, out).items():
                    seen[binary][row].append(ratio)
    print(f"TOYRT / Embree, medians of {a.rounds} runs of each build, the builds alternating")
    for row, old in seen[a.old].items():
        new = seen[a.new][row]
        o, n = statistics.median(old), statistics.median(new)
        print(f"{row[0]}, {row[1]}, {row[2]} thread(s): old {o:.3f}, new {n:.3f}, new/old {n / o:.3f}"
              f"  (old {min(old):.2f}-{max(old):.2f}, new {min(new):.2f}-{max(new):.2f})")


if __name__ == "__main__":
    main()
