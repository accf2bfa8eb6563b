"""The README's Python example runs as written and gives the answers its comments state."""
import pathlib
import re

import numpy as np

README = pathlib.Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_example_runs_and_matches_its_comments():
    text = README.read_text()
    section = text[text.index("## Python ray API"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    env = {}
    exec(compile(code, str(README), "exec"), env)
    hits = env["hits"]
    np.testing.assert_array_equal(hits["t"], np.float32([1, 1, np.inf]))
    np.testing.assert_array_equal(hits["prim"], [1, 1, -1])
    np.testing.assert_array_equal(hits["instance"], [0, 1, -1])
    assert not env["blocked"].any()
    assert env["m"] == 0
    starts = env["starts"]
    assert starts.shape == (2, 3) and (starts[:, 2] > 0).all() and (starts[:, 2] < 1e-3).all()
