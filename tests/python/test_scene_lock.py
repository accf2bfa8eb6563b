"""Edits from one Python thread while another renders or commits: the edit waits for the scene's
lock with the GIL released, so the render's callbacks (which take the GIL every 10 ms) go on and
the edit lands when the render ends. Holding the GIL while waiting deadlocked both threads (the
binding before issue 12 did). Each case runs in a child process, so that a regression fails here
instead of hanging the test run."""
import os
import subprocess
import sys

import pytest

PRELUDE = '''
import threading, numpy as np, toyrt
s = toyrt.Scene()
s.add_mesh(np.float32([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]), [[0, 1, 2], [0, 2, 3]])
s.add_point_light((0, 0, 1), 100.0)
s.commit()
m = np.eye(4)
m[2, 3] = 5.0
cam = dict(type="ORTHO", ortho_scale=2.0, resolution_x=64, resolution_y=64, matrix_world=m)
started = threading.Event()
def poll():
    started.set()
    return False
'''

EDITS = {
    "add_material": 's.add_material("diffuse")',
    "set_background": "s.background = (0.1, 0.1, 0.1)",
    "add_mesh": "s.add_mesh(np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]], instance=False)",
    "read": "assert s.mesh_count >= 1 and s.background_lighting",
}


@pytest.mark.parametrize("edit", sorted(EDITS))
def test_an_edit_during_a_polling_render_waits_for_it_instead_of_deadlocking(edit):
    script = PRELUDE + f'''
t = threading.Thread(target=lambda: s.render(cam, samples=256, threads=1, should_cancel=poll))
t.start()
started.wait()
for _ in range(3):
    {EDITS[edit]}
t.join()
print("ok", s.last_render["tiles_done"])
'''
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    try:
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{edit} during a render deadlocked")
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["ok", "4"]  # the render finished all its tiles


def test_an_edit_during_a_polling_commit_waits_for_it_instead_of_deadlocking():
    script = PRELUDE + '''
rng = np.random.default_rng(1)
v = (rng.random((300_000, 1, 3), dtype=np.float32) * 100 + rng.random((300_000, 3, 3), dtype=np.float32)).reshape(-1, 3)
s.add_mesh(v, np.arange(len(v), dtype=np.uint32).reshape(-1, 3))
t = threading.Thread(target=lambda: s.commit(builder="sah", should_cancel=poll))
t.start()
started.wait()
s.add_material("diffuse")
t.join()
print("ok", s.committed)
'''
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    try:
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.fail("an edit during a commit deadlocked")
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["ok", "True"]
