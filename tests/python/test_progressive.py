"""The progressive render API the viewport uses: passes of the one Sobol-Owen sequence that
accumulate to the full render, cancel inside a pixel's sample loop, renders refused before they
allocate more memory than the machine has, and the scene edits of incremental export."""
import threading
import time

import numpy as np
import pytest
import toyrt


def lit_box_scene():
    """A floor, a box on it and an area light: soft shadows make every sample count differ."""
    s = toyrt.Scene()
    s.add_material("diffuse", color=(0.8, 0.8, 0.8))
    s.add_material("diffuse", color=(0.8, 0.1, 0.1))
    floor = np.float32([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]])
    s.add_mesh(floor, [[0, 1, 2], [0, 2, 3]], material_ids=0)
    cube = np.float32([[x, y, z] for z in (0, 1) for y in (-.5, .5) for x in (-.5, .5)])
    faces = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
             [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    s.add_mesh(cube, faces, material_ids=1)
    lamp = np.eye(4)
    lamp[:3, 3] = (1, 1, 3)
    s.add_area_light(lamp, shape="SQUARE", size=1.5, power=400.0)
    s.background = (0.05, 0.05, 0.05)
    s.commit()
    return s


def camera(resolution=48):
    m = np.array([[1, 0, 0, 0], [0, 0.6, -0.8, -6], [0, 0.8, 0.6, 5], [0, 0, 0, 1.0]])
    return dict(type="PERSP", lens=35, resolution_x=resolution, resolution_y=resolution, matrix_world=m)


def test_passes_of_4_plus_4_samples_accumulate_to_the_8_sample_render():
    s, cam = lit_box_scene(), camera()
    full = s.render(cam, samples=8, seed=3)
    first = s.render(cam, samples=4, seed=3, first_sample=0)
    second = s.render(cam, samples=4, seed=3, first_sample=4)
    assert s.last_render["first_sample"] == 4
    accumulated = (first * 4 + second * 4) / 8
    # Only float rounding separates them: the sums are over the same samples in another grouping.
    np.testing.assert_allclose(accumulated, full, rtol=1e-5, atol=1e-6)
    # ... and the two passes are different samples (otherwise the test above proves nothing).
    assert np.abs(first - second).max() > 1e-2
    # Passes of unequal size too: 1 + 2 + 5.
    parts = [(0, 1), (1, 2), (3, 5)]
    acc = sum(s.render(cam, samples=n, seed=3, first_sample=f) * n for f, n in parts) / 8
    np.testing.assert_allclose(acc, full, rtol=1e-5, atol=1e-6)


def test_first_sample_must_not_be_negative():
    s = lit_box_scene()
    with pytest.raises(ValueError, match="first_sample"):
        s.render(camera(), samples=1, first_sample=-1)
    with pytest.raises(ValueError, match="first_sample"):
        s.render(camera(), samples=2, first_sample=2**31 - 2)


def test_cancel_stops_inside_a_pixel_even_at_100000_samples():
    # One pixel per worker at 100,000 samples: before the check inside the sample loop, a worker
    # finished its pixel first (about 1 s here).
    s, cam = lit_box_scene(), camera(resolution=2)
    requested = []

    def should_cancel():
        if not requested:
            requested.append(time.perf_counter())
        return True

    s.render(cam, samples=100_000, tile_size=1, threads=2, should_cancel=should_cancel)
    info = s.last_render
    assert info["cancelled"]
    print(f"100,000 spp: cancel latency {info['cancel_latency_ms']:.2f} ms (request to workers stopped), "
          f"render() returned {1000 * (time.perf_counter() - requested[0]):.1f} ms after the first poll")
    # Work, not time: no worker finished its 100,000-sample pixel (each takes far longer than the
    # first 10 ms poll); before the check inside the sample loop both finished theirs first.
    assert info["tiles_done"] == 0


def test_a_render_larger_than_memory_is_refused_before_allocating():
    s = lit_box_scene()
    cam = camera()
    cam.update(resolution_x=1_000_000, resolution_y=1_000_000)
    with pytest.raises(MemoryError, match=r"1000000 x 1000000 image needs 32\.0 TB"):
        s.render(cam, samples=1)
    # The scene is still usable.
    assert s.render(camera(8), samples=1).shape == (8, 8, 4)


def test_render_releases_the_gil_for_other_python_threads():
    s, cam = lit_box_scene(), camera(96)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    s.render(cam, samples=64)
    done.set()
    t.join()
    assert len(ticks) > 5  # the other thread ran during the render


def test_set_instance_transform_moves_only_the_top_level():
    s = lit_box_scene()
    before = s.intersect([[0, 0, 5]], [[0, 0, -1]])["t"][0]
    assert before == pytest.approx(4.0)  # the cube's top at z = 1
    up = np.eye(4)
    up[2, 3] = 1.0
    s.set_instance_transform(1, up)
    with pytest.raises(RuntimeError):
        s.intersect([[0, 0, 5]], [[0, 0, -1]])  # uncommitted
    s.commit()
    assert s.last_commit["meshes_built"] == 0  # only the top level
    assert s.intersect([[0, 0, 5]], [[0, 0, -1]])["t"][0] == pytest.approx(3.0)
    with pytest.raises(ValueError, match="unknown instance"):
        s.set_instance_transform(7, up)


def test_replace_mesh_rebuilds_that_mesh_only_and_keeps_its_instances():
    s = lit_box_scene()
    tall = np.float32([[x, y, z] for z in (0, 2) for y in (-.5, .5) for x in (-.5, .5)])
    faces = [[4, 6, 7], [4, 7, 5]]  # just the top
    s.replace_mesh(1, tall, faces, material_ids=1)
    s.commit()
    assert s.last_commit["meshes_built"] == 1
    assert s.instance_count == 2
    assert s.intersect([[0, 0, 5]], [[0, 0, -1]])["t"][0] == pytest.approx(3.0)
    # An emptied mesh is never hit, and the scene still renders.
    s.replace_mesh(1, np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32))
    s.commit()
    assert s.intersect([[0, 0, 5]], [[0, 0, -1]])["t"][0] == pytest.approx(5.0)
    assert np.isfinite(s.render(camera(8), samples=1)).all()


def test_set_material_and_lights_edit_in_place():
    s, cam = lit_box_scene(), camera(16)
    red = s.render(cam, samples=4)
    s.set_material(1, "diffuse", color=(0.1, 0.1, 0.8))
    blue = s.render(cam, samples=4)
    centre = (slice(6, 10), slice(6, 10))
    assert red[centre][..., 0].mean() > red[centre][..., 2].mean()
    assert blue[centre][..., 2].mean() > blue[centre][..., 0].mean()
    s.clear_lights()
    s.background_lighting = False
    dark = s.render(cam, samples=4)
    assert dark[centre][..., :3].max() == 0.0
    with pytest.raises(ValueError, match="unknown material"):
        s.set_material(9, "diffuse")
