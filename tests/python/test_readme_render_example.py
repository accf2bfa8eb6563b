"""The README's render example runs as written."""
import pathlib
import re

import numpy as np

README = pathlib.Path(__file__).resolve().parents[2] / "README.md"


def test_readme_render_example_runs():
    text = README.read_text()
    section = text[text.index("## Python render API"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    env = {}
    exec(compile(code.replace("samples=16", "samples=2"), str(README), "exec"), env)
    image = env["image"]
    assert image.shape == (240, 320, 4) and image.dtype == np.float32
    assert np.isfinite(image).all() and (image >= 0).all()
    assert image[..., :3].mean() > 0.01
