"""What the Blender test scripts share: checks that are counted instead of raising (one failed
check must not hide the next), parts timed and isolated, Blender's C-level output captured, F12
to a file, and the summary line + exit status that `make test-blender` and run_with_bpy.py read.
Their scenes come from the scene kit, scenes/kit.py, which the benchmarks and the demo use too.

The scripts run as `blender -b --python tests/blender/test_x.py`, which does not put the script's
folder on sys.path; each adds it and scenes/ before `from harness import ...` and `import kit`:

    HERE = os.path.dirname(os.path.abspath(__file__))
    sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit

Not a test itself (no test_ prefix), so `make test-blender` does not run it."""
import os
import shutil
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


def render_still(path):
    """F12's operator, writing the still to `path` in the scene's file format: (the operator's
    result, or the text of the error it raised; everything Blender printed meanwhile)."""
    import bpy

    bpy.context.scene.render.filepath = str(path)
    with captured_output() as out:
        try:
            result = bpy.ops.render.render(write_still=True)
        except RuntimeError as err:
            result = str(err)
    return result, out[0]


def run_script(parts, label, tmp=None):
    """A script's last line: runs its parts in turn (run_part: an exception fails one check and the
    next part still runs), removes the folder `tmp` they wrote to, then finish(label)."""
    for part in parts:
        run_part(part)
    if tmp is not None:
        shutil.rmtree(tmp, ignore_errors=True)
    finish(label)


def finish(label):
    """Prints '<label>: N passed, M failed' and exits with 1 if any check failed (or none ran)."""
    failed = RESULTS.count(False)
    print(f"{label}: {len(RESULTS) - failed} passed, {failed} failed", flush=True)
    sys.exit(1 if failed or not RESULTS else 0)
