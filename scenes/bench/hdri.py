# An HDRI-lit scene: a floor, a red box and a grey sphere under an equirectangular sky with a
# small bright sun (generated, float), turned by a Mapping node; the world seen above the horizon.
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the scene kit
import kit  # noqa: E402


def sky(width=256, height=128, sun=(0.5, 0.9), sun_radiance=300.0):
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    el, az = np.meshgrid((v - 0.5) * np.pi, (0.5 - u) * 2 * np.pi, indexing="ij")
    up = np.clip(np.sin(el), 0, 1)[..., None]
    img = np.where(el[..., None] > 0, (0.3 + 0.6 * up) * np.array([0.45, 0.6, 1.0]), np.array([0.1, 0.08, 0.05]))
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], -1)
    s = np.array([np.cos(sun[0]) * np.cos(sun[1]), np.cos(sun[0]) * np.sin(sun[1]), np.sin(sun[0])])
    angle = np.arccos(np.clip(d @ s, -1, 1))
    img = img + sun_radiance * np.exp(-0.5 * (angle / np.radians(1.0)) ** 2)[..., None] * np.array([1, 0.9, 0.75])
    rgba = np.concatenate([img, np.ones((height, width, 1))], axis=2).astype(np.float32)
    return kit.image("sky", rgba, float_buffer=True)


def build():
    scene = kit.clear_scene()
    kit.plane("floor", 10.0, kit.diffuse("white", (0.8, 0.8, 0.8)))
    kit.box("box", 0.9, (-0.7, 0.3, 0.45), kit.diffuse("red", (0.7, 0.2, 0.1)))
    kit.uv_sphere("ball", 0.5, (0.8, -0.3, 0.5), kit.diffuse("grey", (0.5, 0.5, 0.5)))
    kit.environment_world(sky(), 1.0, (0.0, 0.0, 0.4))
    kit.camera((0.0, -6.0, 2.0), (0, 0, 0.4), lens=35)
    return scene


if __name__ == "__main__":
    kit.main(build)
