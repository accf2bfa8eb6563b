"""Adaptive sampling and the time limit (Cycles' use_adaptive_sampling, adaptive_threshold,
adaptive_min_samples, time_limit): a time-limited render is rendered in passes and must equal one
render of the samples it took; adaptive sampling stops pixels whose noise estimate is below the
threshold, and a pixel it stops early keeps the value of its own samples."""
import numpy as np
import pytest
import toyrt
from test_progressive import camera, lit_box_scene


def test_a_time_limit_that_is_not_reached_gives_the_one_pass_render():
    s, cam = lit_box_scene(), camera()
    full = s.render(cam, samples=24, seed=5)
    passes = s.render(cam, samples=24, seed=5, time_limit=1e6)  # 1, 1, 2, 4, 8, 8 samples
    info = s.last_render
    assert info["samples_done"] == 24 and not info["time_limit_reached"]
    np.testing.assert_allclose(passes, full, rtol=1e-5, atol=1e-6)


def test_the_passes_add_up_every_render_pass_as_one_render_does():
    s, cam = lit_box_scene(), camera()
    ids = {"object": np.float32([1.5, 2.5])}
    kw = dict(samples=24, seed=5, passes=["depth", "normal", "diffuse_color", "object_index", "mist"],
              object_index=np.float32([3, 7]), cryptomatte=ids, cryptomatte_depth=4)
    s.render(cam, **kw)
    one = {k: v.copy() for k, v in s.last_passes.items()}
    s.render(cam, time_limit=1e6, **kw)
    many = s.last_passes
    # From the first sample: identical. Averaged: the same up to float rounding.
    for name in ("depth", "object_index"):
        np.testing.assert_array_equal(many[name], one[name])
    for name in ("normal", "diffuse_color", "mist"):
        np.testing.assert_allclose(many[name], one[name], rtol=1e-5, atol=1e-6)
    # Two objects, depth 4: every id is kept, so the merged ranking is the one render's.
    a, b = many["cryptomatte_object"], one["cryptomatte_object"]
    np.testing.assert_array_equal(a[..., 0::2], b[..., 0::2])
    np.testing.assert_allclose(a[..., 1::2], b[..., 1::2], atol=1e-6)


def test_a_reached_time_limit_stops_between_passes_with_a_complete_render_of_its_samples():
    s, cam = lit_box_scene(), camera(64)
    image = s.render(cam, samples=1 << 20, seed=2, time_limit=0.3)
    info = s.last_render
    assert info["time_limit_reached"] and 1 <= info["samples_done"] < 1 << 20
    # Exactly the samples taken, normalised by their count: the same as asking for that many.
    same = s.render(cam, samples=info["samples_done"], seed=2)
    np.testing.assert_allclose(image, same, rtol=1e-5, atol=1e-6)
    assert np.all(image[..., 3] == 1.0)


def test_adaptive_sampling_stops_flat_pixels_and_keeps_their_value():
    s, cam = lit_box_scene(), camera()
    cam["lens"] = 12  # wide: the background shows around the floor
    plain = s.render(cam, samples=256, seed=1)
    adaptive = s.render(cam, samples=256, seed=1, use_adaptive_sampling=True, adaptive_threshold=0.01)
    info = s.last_render
    # Automatic minimum for 0.01: ceil(16 / 0.01^0.3) = 64; the first test after sample 79. The
    # background (0.05 everywhere, no noise) stops there; the lit, noisy pixels go on.
    assert 80 <= info["mean_samples"] < 256
    background = np.all(np.abs(plain[..., :3] - 0.05) < 1e-6, axis=-1)
    assert background.sum() > 100
    np.testing.assert_allclose(adaptive[background], plain[background], rtol=1e-5)  # float rounding only
    # Elsewhere each pixel is the mean of its first k samples: close to the full render's.
    err = np.abs(adaptive - plain)[..., :3].mean() / plain[..., :3].mean()
    assert err < 0.02


def test_adaptive_sampling_in_passes_stops_each_pixel_at_the_same_sample():
    s, cam = lit_box_scene(), camera()
    kw = dict(samples=200, seed=4, use_adaptive_sampling=True, adaptive_threshold=0.02)
    one = s.render(cam, **kw)
    mean_one = s.last_render["mean_samples"]
    many = s.render(cam, time_limit=1e6, **kw)
    assert s.last_render["mean_samples"] == pytest.approx(mean_one)
    np.testing.assert_allclose(many, one, rtol=1e-5, atol=1e-6)


def test_no_threshold_and_min_samples_mean_automatic_and_bad_values_are_refused():
    s, cam = lit_box_scene(), camera(16)
    s.render(cam, samples=64, use_adaptive_sampling=True, adaptive_threshold=0.0, adaptive_min_samples=0)
    assert s.last_render["mean_samples"] <= 64
    for bad in (dict(adaptive_threshold=-1.0), dict(adaptive_threshold=float("nan")),
                dict(adaptive_min_samples=-1), dict(time_limit=-1.0), dict(time_limit=float("inf"))):
        with pytest.raises(ValueError, match=next(iter(bad))):
            s.render(cam, samples=4, use_adaptive_sampling=True, **bad)


def test_progress_counts_samples_over_the_whole_image():
    s, cam = lit_box_scene(), camera()
    seen = []
    s.render(cam, samples=16, tile_size=16, on_progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == pytest.approx(16.0) and len(seen) == 9
    seen.clear()
    s.render(cam, samples=16, tile_size=16, time_limit=1e6, on_progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == pytest.approx(16.0) and len(seen) == 9 * 5  # passes 1 1 2 4 8
    assert toyrt.defaults["time_limit"] == 0.0 and toyrt.defaults["use_adaptive_sampling"] is False
