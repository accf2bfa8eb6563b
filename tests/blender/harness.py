"""What the Blender test scripts share: checks that are counted instead of raising (one failed
check must not hide the next), parts timed and isolated, Blender's C-level output captured, and
the summary line + exit status that `make test-blender` and run_with_bpy.py read.

The scripts run as `blender -b --python tests/blender/test_x.py`, which does not put the script's
folder on sys.path; each adds it before `from harness import ...`. Not a test itself (no test_
prefix), so `make test-blender` does not run it."""
import os
import sys
import tempfile
import time
import traceback
from contextlib import contextmanager

RESULTS = []  # one bool per check, in order


def check(cond, what):
    RESULTS.append(bool(cond))
    print(("  ok: " if cond else "  FAIL: ") + what, flush=True)


def run_part(fn):
    """Runs one part of a script; an exception counts as a failed check and the next part runs."""
    print(f"{fn.__name__}:", flush=True)
    start = time.perf_counter()
    try:
        fn()
    except Exception:
        traceback.print_exc()
        check(False, f"{fn.__name__} raised")
    print(f"  ({time.perf_counter() - start:.1f} s)", flush=True)


@contextmanager
def captured_output():
    """Everything written to file descriptors 1 and 2 (Blender's C code prints its reports there),
    as the one string in the yielded list once the block ends."""
    sys.stdout.flush()
    sys.stderr.flush()
    buf = tempfile.TemporaryFile()
    saved = os.dup(1), os.dup(2)
    os.dup2(buf.fileno(), 1)
    os.dup2(buf.fileno(), 2)
    text = []
    try:
        yield text
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(saved[0])
        os.close(saved[1])
        buf.seek(0)
        text.append(buf.read().decode(errors="replace"))
        buf.close()


def finish(label):
    """Prints '<label>: N passed, M failed' and exits with 1 if any check failed (or none ran)."""
    failed = RESULTS.count(False)
    print(f"{label}: {len(RESULTS) - failed} passed, {failed} failed", flush=True)
    sys.exit(1 if failed or not RESULTS else 0)
