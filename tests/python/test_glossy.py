"""The glossy material through the module: a closed-form pixel, and bad input with a defined
result (roughness clamped to [0, 1] as Cycles does, NaN and unknown names refused by name)."""
import math

import numpy as np
import pytest
import toyrt


def glossy_floor(**material):
    s = toyrt.Scene()
    s.add_material("glossy", **material)
    s.add_mesh(np.float32([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]), [[0, 1, 2], [0, 2, 3]], material_ids=0)
    s.background = (0.0, 0.0, 0.0)
    return s


def render(s, samples=16):
    s.commit()
    m = np.eye(4)
    m[2, 3] = 5.0
    return s.render(dict(type="ORTHO", ortho_scale=1e-3, resolution_x=1, resolution_y=1, matrix_world=m),
                    samples=samples)


def test_rough_glossy_floor_under_a_point_light_is_colour_over_4_pi_times_irradiance():
    # Roughness 1 (alpha 1), normal incidence: D = 1 / pi, G2 = 1, f = D G2 / 4 = 1 / (4 pi).
    s = glossy_floor(color=(0.9, 0.6, 0.3), roughness=1.0)
    power = 100.0
    s.add_point_light((0.0, 0.0, 2.0), power)
    got = render(s)[0, 0, :3]
    irradiance = power / (4 * math.pi) / 4.0
    np.testing.assert_allclose(got, np.array([0.9, 0.6, 0.3]) / (4 * math.pi) * irradiance, rtol=1e-4)


def test_roughness_outside_the_unit_interval_renders_as_the_nearest_bound():
    def image(roughness):
        s = glossy_floor(roughness=roughness)
        s.add_point_light((0.5, 0.0, 2.0), 100.0, radius=0.2)
        return render(s)
    np.testing.assert_array_equal(image(3.0), image(1.0))
    np.testing.assert_array_equal(image(-1.0), image(0.0))
    assert np.isfinite(image(0.0)).all()


def test_bad_glossy_parameters_are_refused_by_name():
    with pytest.raises(ValueError, match="roughness"):
        toyrt.Scene().add_material("glossy", roughness=float("nan"))
    with pytest.raises(ValueError, match="shadowing must be 'separable' or 'correlated'"):
        toyrt.Scene().add_material("glossy", shadowing="smith")
    with pytest.raises(ValueError, match="color"):
        toyrt.Scene().add_material("glossy", color=(float("nan"), 0.0, 0.0))
    with pytest.raises(TypeError, match="unknown argument 'ior_level' for a glossy material"):
        toyrt.Scene().add_material("glossy", ior_level=0.5)
