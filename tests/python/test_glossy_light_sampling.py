"""A glossy vertex samples emissive triangles and the environment map as it samples lamps, by
multiple importance sampling with its lobe (render/glossy_lighting.h): a small bright emitter or
sun over a rough glossy floor converges to the closed form at few samples, and whether a light is
sampled changes the noise, never the mean.

The closed form: roughness 1 (GGX alpha 1, D = 1 / pi everywhere) seen straight down (cos_o = 1,
so G2 = G1(wi) = 2 cos_i / (1 + cos_i) in both of Blender's masking forms), and f cos_i =
colour G2 / (4 pi)."""
import numpy as np
import pytest
import toyrt
from test_environment import texel_directions
from test_render import camera_above

COLOR = 0.8


def f_cos(cos_i):
    """The glossy floor's BRDF x cos_i for light from cos_i, the camera straight above."""
    return COLOR / (4 * np.pi) * 2 * cos_i / (1 + cos_i)


def glossy_floor():
    s = toyrt.Scene()
    s.add_material("glossy", color=(COLOR, COLOR, COLOR), roughness=1.0)  # 0
    v = np.float32([[-1e3, -1e3, 0], [1e3, -1e3, 0], [1e3, 1e3, 0], [-1e3, 1e3, 0]])
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=0)
    s.background = (0.0, 0.0, 0.0)
    return s


def emitter_over_floor(sampling, L=40.0, a=0.2, h=1.0, **visibility):
    """A rough glossy floor under an a x a emissive square at height h, centred over the origin."""
    s = glossy_floor()
    s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(L, L, L), emission_sampling=sampling)  # 1
    v = np.float32([[-a / 2, -a / 2, h], [a / 2, -a / 2, h], [a / 2, a / 2, h], [-a / 2, a / 2, h]])
    mesh = s.add_mesh(v, [[0, 2, 1], [0, 3, 2]], material_ids=1, instance=False)  # facing down
    s.add_instance(mesh, np.eye(4), **visibility)
    s.commit()
    return s


def square_over_glossy_point(L=40.0, a=0.2, h=1.0, n=400):
    """The pixel at the origin under the square: the integral of f cos_i L cos_e / d^2 over it."""
    c = (np.arange(n) + 0.5) / n * a - a / 2
    x, y = np.meshgrid(c, c)
    d2 = x * x + y * y + h * h
    cos = h / np.sqrt(d2)  # cos_i at the floor and cos_e at the square alike
    return float((f_cos(cos) * L * cos / d2).sum() * (a / n) ** 2)


def test_a_small_emitter_over_a_rough_glossy_floor_is_found_at_few_samples():
    img = emitter_over_floor("AUTO").render(camera_above(height=0.5, size=0.002, resolution=16), samples=16)[..., 0]
    expected = square_over_glossy_point()
    assert img.mean() == pytest.approx(expected, rel=0.02)
    # The typical pixel at 16 samples is within 10 %: the lobe alone hits the square with about
    # one sample in 130 (its share of the lobe's directions), so most pixels would be black.
    assert np.median(img) == pytest.approx(expected, rel=0.10)


def test_sampling_an_emitter_at_a_glossy_vertex_changes_the_noise_not_the_light():
    # Emission sampling None: the continuation ray alone finds the square, with weight 1; sampled,
    # both strategies share it by the power heuristic. The same mean, far less noise.
    # (The lobe alone hits the square about 8,000 times in 256 x 4,096 samples: 1.1 % noise.)
    cam = camera_above(height=0.5, size=0.002, resolution=16)
    sampled = emitter_over_floor("AUTO").render(cam, samples=4096)[..., 0]
    alone = emitter_over_floor("NONE").render(cam, samples=4096)[..., 0]
    assert alone.mean() == pytest.approx(sampled.mean(), rel=0.04)
    assert sampled.mean() == pytest.approx(square_over_glossy_point(), rel=0.005)
    assert sampled.std() < alone.std() / 4


def test_an_emitter_hidden_from_glossy_rays_is_not_sampled_at_a_glossy_vertex():
    # It stays among the sampled emitters (diffuse rays see it), but the lobe's ray passes it, so
    # the glossy vertex's emitter sample must skip it too: the floor stays black.
    s = emitter_over_floor("AUTO", visible_glossy=False)
    assert s.last_commit["emissive_triangles"] == 2
    assert s.render(camera_above(height=0.5, size=0.002, resolution=4), samples=64)[..., :3].max() == 0.0


def test_a_small_bright_sun_in_the_map_is_found_at_few_samples_by_a_rough_glossy_floor():
    w, h = 64, 32
    sky = np.full((h, w, 3), 0.05, np.float32)
    sky[25, 40] = 2000.0  # one texel, 2.8 degrees across, about 51 degrees from the zenith
    d, omega = texel_directions(w, h)
    cos = np.clip(d[..., 2], 0, None)
    expected = float((sky[..., 0] * f_cos(cos) * omega)[cos > 0].sum())
    s = glossy_floor()
    s.set_environment(s.add_texture(sky, srgb=False))
    s.commit()
    img = s.render(camera_above(size=2.0, resolution=16), samples=16)[..., 0]
    assert img.mean() == pytest.approx(expected, rel=0.03)
    assert np.median(img) == pytest.approx(expected, rel=0.10)


def test_a_uniform_map_seen_by_a_glossy_floor_is_the_constant_background():
    # The map is sampled at the glossy vertex and shares with the lobe; the constant background
    # is found by the lobe alone: the same expectation, the lobe's albedo x L.
    def pixel(environment):
        s = glossy_floor()
        if environment:
            s.set_environment(s.add_texture(np.full((16, 32, 3), 0.7, np.float32), srgb=False))
        else:
            s.background = (0.7, 0.7, 0.7)
        s.commit()
        return s.render(camera_above(size=2.0, resolution=8), samples=256)[..., 0].mean()
    assert pixel(True) == pytest.approx(pixel(False), rel=0.01)


@pytest.mark.parametrize("material", ["glossy", "glass"])
def test_one_lamp_picked_at_a_lobe_vertex_changes_the_noise_not_the_light(material):
    # With many lamps (light_sampling "one", auto's choice above 4) a glossy or rough glass vertex
    # samples one lamp chosen by the selector, and a lamp its lobe's ray finds weighs its pdf by
    # that choice's probability (render/visible_lights.h, LampChoice): the mean of every lamp
    # sampled. Round lamps above and below the plane (glass sees both sides).
    s = toyrt.Scene()
    if material == "glossy":
        s.add_material("glossy", color=(0.8, 0.8, 0.8), roughness=0.5)
    else:
        s.add_material("glass", ior=1.5, roughness=0.4)
    v = np.float32([[-20, -20, 0], [20, -20, 0], [20, 20, 0], [-20, 20, 0]])
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=0)
    rng = np.random.default_rng(1)
    for x, y, z in rng.uniform([-3, -3, 0.5], [3, 3, 3.0], (20, 3)):
        s.add_point_light((x, y, z if rng.random() < 0.7 else -z), 50.0, radius=0.3)
    s.commit()
    cam = camera_above(height=6.0, size=4.0, resolution=16)  # 2,048 samples: 0.15 % noise in the mean
    every = s.render(cam, samples=2048, light_sampling="all")[..., 0]
    one = s.render(cam, samples=2048, light_sampling="one")[..., 0]
    assert one.mean() == pytest.approx(every.mean(), rel=0.005)
