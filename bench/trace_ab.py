"""A/B of two builds of bench/trace_only on one ray set: the two binaries run in turn, the order
swapped every round (old-new, then new-old), so a slow spell of this shared machine falls on both
alike; the report is the median of the per-round speed ratios with its interquartile range, which
says more than two medians taken apart. The machine's noise changes by the hour: an A/A run (one
binary named twice) just before says how wide the range is at the moment (0.998-1.004 in a quiet
spell, 5-15 % wide in a busy one; docs/trace-speed.md, thirty-eighth session). Both binaries must
find the same hits (count and checksum; exit status 1 otherwise): a change meant to be faster must
not change an answer.

    cp build/bench/trace_only /tmp/trace_old     # before the change; rebuild, then:
    python3 bench/trace_ab.py /tmp/trace_old build/bench/trace_only --rounds 16 -- diffuse 71 30

The arguments after `--` are trace_only's (set, rings, repeats, [room|soup]). docs/trace-speed.md
records what each measured change bought.
"""

import argparse
import re
import statistics
import subprocess
import sys

LINE = re.compile(r"(\d+) found, checksum ([^,]+), ([0-9.]+) Mrays/s")


def run(binary, args):
    out = subprocess.run([binary, *args], capture_output=True, text=True, check=True).stdout
    match = LINE.search(out)
    if not match:
        sys.exit(f"{binary}: no result line in {out!r}")
    return int(match.group(1)), match.group(2), float(match.group(3))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--rounds", type=int, default=16)
    parser.add_argument("trace_args", nargs="+", help="trace_only's arguments, after --")
    a = parser.parse_args()
    binaries = (a.old, a.new)
    speeds = ([], [])  # by position: an A/A run may name one binary twice
    answers = set()
    for r in range(a.rounds):
        for k in (0, 1) if r % 2 == 0 else (1, 0):
            found, checksum, speed = run(binaries[k], a.trace_args)
            answers.add((found, checksum))
            speeds[k].append(speed)
    if len(answers) != 1:
        print(f"the binaries disagree on the hits (found, checksum): {sorted(answers)}", file=sys.stderr)
    ratios = sorted(n / o for o, n in zip(*speeds))
    q = len(ratios) // 4
    print(
        f"{' '.join(a.trace_args)}: old {statistics.median(speeds[0]):.3f}, "
        f"new {statistics.median(speeds[1]):.3f} Mrays/s (medians of {a.rounds}); "
        f"new/old per round: median {statistics.median(ratios):.3f}, "
        f"interquartile {ratios[q]:.3f}-{ratios[-q - 1]:.3f}"
    )
    return 1 if len(answers) != 1 else 0


if __name__ == "__main__":
    sys.exit(main())
