"""Lights and materials by type name (Scene.add_light, Scene.add_material with keyword
parameters): the generic path is the one add_point_light and add_area_light take, so their
images are bitwise the same; unknown types and keywords are refused by name."""
import numpy as np
import pytest
import toyrt


def floor_scene():
    s = toyrt.Scene()
    s.add_mesh(np.float32([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]), [[0, 1, 2], [0, 2, 3]])
    s.background = (0.0, 0.0, 0.0)
    return s


def render(s):
    s.commit()
    m = np.eye(4)
    m[2, 3] = 5.0
    return s.render(dict(type="ORTHO", ortho_scale=4.0, resolution_x=16, resolution_y=16, matrix_world=m), samples=4)


def test_add_light_point_renders_the_same_image_as_add_point_light():
    a, b = floor_scene(), floor_scene()
    a.add_point_light((0.3, -0.2, 1.5), 80.0, color=(1.0, 0.5, 0.25), radius=0.2)
    b.add_light("POINT", position=(0.3, -0.2, 1.5), power=80.0, color=(1.0, 0.5, 0.25), radius=0.2)
    np.testing.assert_array_equal(render(a), render(b))


def test_add_light_area_renders_the_same_image_as_add_area_light():
    m = np.eye(4)
    m[:3, 3] = (0.2, 0.1, 1.0)
    a, b = floor_scene(), floor_scene()
    a.add_area_light(m, shape="RECTANGLE", size=0.8, size_y=0.4, power=60.0, visible_camera=False)
    b.add_light("AREA", matrix=m, shape="RECTANGLE", size=0.8, size_y=0.4, power=60.0, visible_camera=False)
    np.testing.assert_array_equal(render(a), render(b))


def test_unknown_light_type_lists_the_known_ones():
    with pytest.raises(ValueError, match="unknown light type 'HEMI': expected 'POINT', 'AREA', 'SPOT' or 'SUN'"):
        toyrt.Scene().add_light("HEMI", angle=0.1)


def test_unknown_keyword_is_named():
    with pytest.raises(TypeError, match="unknown argument 'powr' for a POINT light"):
        toyrt.Scene().add_light("POINT", position=(0, 0, 1), powr=10.0)
    with pytest.raises(TypeError, match="unknown argument 'metallic' for a glass material"):
        toyrt.Scene().add_material("glass", roughness=0.1, metallic=1.0)


def test_unknown_material_kind_lists_the_known_ones():
    known = "'diffuse', 'refraction', 'glass', 'glossy', 'diffuse_glossy' or 'principled'"
    with pytest.raises(ValueError, match=f"expected {known}"):
        toyrt.Scene().add_material("metal")


def test_keyword_of_the_wrong_type_is_a_type_error_naming_it():
    with pytest.raises(TypeError, match="position"):
        toyrt.Scene().add_light("POINT", position=object())
    with pytest.raises(ValueError, match="POINT light: power must be a number"):
        toyrt.Scene().add_light("POINT", power="a lot")


def test_the_documented_material_keywords_work_for_every_kind():
    s = toyrt.Scene()
    assert s.add_material("glass", color=(1, 0, 0), texture=-1, ior=1.5) == 0
    assert s.add_material("diffuse", ior=1.5) == 1
    s.set_material(1, "refraction", ior=1.3)


def test_docstrings_list_the_types_and_their_parameters():
    for name in ("'POINT'", "'AREA'", "radius", "size_y"):
        assert name in toyrt.Scene.add_light.__doc__
    for name in ("'diffuse'", "'refraction'", "'glass'", "texture"):
        assert name in toyrt.Scene.add_material.__doc__
