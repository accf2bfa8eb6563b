"""Cancelling a BVH build: Scene.commit(should_cancel=...) stops a large build early, leaves the
scene uncommitted (queries refuse it), and the next commit gives the same answers as a scene that
was never cancelled. No time limits: "early" is measured against the same build run to the end."""
import time

import numpy as np
import pytest
import toyrt


def soup(n, seed=3):
    rng = np.random.default_rng(seed)
    centres = rng.random((n, 1, 3), dtype=np.float32) * 100
    v = (centres + rng.random((n, 3, 3), dtype=np.float32)).reshape(-1, 3)
    return v, np.arange(3 * n, dtype=np.uint32).reshape(-1, 3)


def rays(n=2000, seed=5):
    rng = np.random.default_rng(seed)
    o = rng.random((n, 3), dtype=np.float32) * 100
    d = rng.normal(size=(n, 3)).astype(np.float32)
    return o, d


def test_a_cancelled_commit_stops_early_and_leaves_the_scene_uncommitted():
    v, t = soup(400_000)
    full = toyrt.Scene()
    full.add_mesh(v, t)
    start = time.perf_counter()
    assert full.commit(builder="sah", should_cancel=lambda: False) is True
    full_s = time.perf_counter() - start

    s = toyrt.Scene()
    s.add_mesh(v, t)
    polls = []

    def cancel_at_once():
        polls.append(time.perf_counter())
        return True

    start = time.perf_counter()
    assert s.commit(builder="sah", should_cancel=cancel_at_once) is False
    cancelled_s = time.perf_counter() - start
    assert polls, "should_cancel was polled"
    # The build stopped at its first poll (10 ms) instead of running to the end.
    assert cancelled_s < full_s / 2, (cancelled_s, full_s)
    with pytest.raises(RuntimeError, match="commit"):
        s.intersect(*rays())

    # Committing again builds everything and agrees with the scene that was never cancelled.
    assert s.commit(builder="sah") is True
    o, d = rays()
    a, b = s.intersect(o, d), full.intersect(o, d)
    np.testing.assert_array_equal(a["prim"], b["prim"])
    np.testing.assert_array_equal(a["t"], b["t"])


def test_an_exception_in_should_cancel_stops_the_build_and_reaches_the_caller():
    v, t = soup(200_000)
    s = toyrt.Scene()
    s.add_mesh(v, t)

    def broken():
        raise KeyError("from should_cancel")

    with pytest.raises(KeyError, match="from should_cancel"):
        s.commit(builder="sah", should_cancel=broken)
    assert s.commit(builder="sah") is True  # usable afterwards


def test_commit_without_should_cancel_returns_true():
    v, t = soup(10)
    s = toyrt.Scene()
    s.add_mesh(v, t)
    assert s.commit() is True
