"""The README's Python examples run as written and give the answers their comments state."""
import pathlib
import re

import numpy as np

README = pathlib.Path(__file__).resolve().parents[2] / "README.md"


def run_example(section, replace=()):
    """Executes the first ```python block after the heading `section`; returns its variables."""
    text = README.read_text()
    code = re.search(r"```python\n(.*?)```", text[text.index(section):], re.S).group(1)
    for old, new in replace:
        code = code.replace(old, new)
    env = {}
    exec(compile(code, str(README), "exec"), env)
    return env


def test_ray_api_example_matches_its_comments():
    env = run_example("## Python ray API")
    hits = env["hits"]
    np.testing.assert_array_equal(hits["t"], np.float32([1, 1, np.inf]))
    np.testing.assert_array_equal(hits["prim"], [1, 1, -1])
    np.testing.assert_array_equal(hits["instance"], [0, 1, -1])
    assert not env["blocked"].any()
    assert env["m"] == 0
    starts = env["starts"]
    assert starts.shape == (2, 3) and (starts[:, 2] > 0).all() and (starts[:, 2] < 1e-3).all()


def test_exact_queries_example_matches_its_comments():
    env = run_example("### Exact geometric queries")
    assert env["counts"].tolist() == [2, 0]
    hits = env["hits"]
    assert hits["ray_splits"].tolist() == [0, 2, 2] and hits["t"].tolist() == [1, 2]
    p, cube = env["p"], env["cube"]
    assert cube.compute_occupancy(p).tolist() == [True, True, False]
    assert cube.compute_signed_distance(p).tolist() == [-0.5, 0, 1]
    assert env["near"]["points"].shape == (3, 3)


def test_render_example_runs():
    env = run_example("## Python render API", replace=[("samples=16", "samples=2")])
    image = env["image"]
    assert image.shape == (240, 320, 4) and image.dtype == np.float32
    assert np.isfinite(image).all() and (image >= 0).all()
    assert image[..., :3].mean() > 0.01
