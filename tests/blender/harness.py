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


def render_multilayer(engine, samples, path):
    """The current scene rendered by `engine` ("TOYRT", or "CYCLES" restricted to TOYRT's light
    transport: seed 0, depth 8) into the multilayer OpenEXR `path`: render_still's answer. Needs
    the scene kit on sys.path."""
    import bpy
    import kit
    from cycles_like_toyrt import configure_cycles

    scene = bpy.context.scene
    scene.render.engine = engine
    if engine == "CYCLES":
        configure_cycles(scene, samples, 8)
        scene.cycles.seed = 0
    else:
        kit.toyrt(scene, samples=samples)
    kit.multilayer_exr(scene)
    return render_still(path)


@contextmanager
def live_sync(sync, toyrt):
    """A SceneSync (`sync`: the add-on's sync module) of the current scene, synced and committed,
    then kept up to date as the viewport's is: with Blender's own depsgraph.updates, through a
    depsgraph_update_post handler removed when the block ends."""
    import bpy

    live = sync.SceneSync(toyrt)
    live.sync(bpy.context.evaluated_depsgraph_get())
    live.commit()

    def on_update(_scene, depsgraph):
        live.sync(depsgraph, depsgraph.updates)
        live.commit()

    bpy.app.handlers.depsgraph_update_post.append(on_update)
    try:
        yield live
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)


def counted_edit(live, label, fn, expect=None):
    """Makes the edit fn() and lets Blender evaluate it (live_sync's handler syncs it), then checks
    that the SceneSync's counters moved by `expect` ({counter: change}) when given."""
    import bpy

    before = dict(live.counters)
    fn()
    bpy.context.view_layer.update()  # Blender evaluates and calls depsgraph_update_post
    if expect:
        delta = {k: live.counters[k] - before[k] for k in live.counters}
        wrong = {k: (delta[k], v) for k, v in expect.items() if delta[k] != v}
        check(not wrong, f"{label}: {', '.join(f'{k} {v}' for k, v in expect.items())}"
                         + (f" -- got (got, expected) {wrong}" if wrong else ""))


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
