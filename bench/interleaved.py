# Runs a benchmark's child once per built toyrt module and repeat, each in its own process (a
# module's types register once per process), interleaved so every module sees the same moments of
# a shared machine. The child prints one JSON line last; the runs come back per module name.
import json
import os
import subprocess
import sys


def modules_from(specs, here):
    """--module NAME=DIR arguments as [name, dir] pairs; build/python as "build" when none is given."""
    return [m.split("=", 1) for m in specs] or [["build", os.path.join(here, "..", "build", "python")]]


def run_interleaved(script, modules, repeats, child_args=()):
    runs = {name: [] for name, _ in modules}
    for r in range(repeats):
        for name, path in modules:
            env = dict(os.environ, PYTHONPATH=path)
            done = subprocess.run([sys.executable, script, "--child", *child_args], env=env, capture_output=True,
                                  text=True)
            if done.returncode != 0:
                sys.exit(f"{name}: {done.stderr[-2000:]}")
            runs[name].append(json.loads(done.stdout.strip().splitlines()[-1]))
            print(f"repeat {r + 1}/{repeats} {name}: {runs[name][-1]}", file=sys.stderr, flush=True)
    return runs
