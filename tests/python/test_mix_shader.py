"""Mix and Add Shaders of any two materials (the core's 'mix' kind, materials/material_mix.h):
one of the two drawn per hit by its weight, so the mean is the mixed closure's. Known answers:
diffuse floors under a point light (Lambert of the mixed colour) and under a white background
(the mixed albedo, exactly, for a cosine-sampled background), a texture factor, the Fresnel and
Layer Weight factors against their closed forms, and bad input refused by name."""
import math

import numpy as np
import pytest
import toyrt


def floor(s, material, uvs=True):
    v = np.float32([[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]])
    uv = np.float32([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]])
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], uvs=uv if uvs else None, material_ids=material)


def render(s, samples=1024, x=0.0, tilt=0.0):
    """The radiance of one pixel seen by an orthographic camera at (x, 0) tilted by `tilt` radians
    about the x axis from looking straight down."""
    s.commit()
    c, si = math.cos(tilt), math.sin(tilt)
    m = np.eye(4)
    m[:3, :3] = [[1, 0, 0], [0, c, -si], [0, si, c]]
    m[:3, 3] = [x, -5 * si, 5 * c]
    return s.render(dict(type="ORTHO", ortho_scale=1e-3, resolution_x=1, resolution_y=1, matrix_world=m),
                    samples=samples)[0, 0, :3]


A, B, C = np.array([0.9, 0.2, 0.1]), np.array([0.1, 0.5, 0.8]), np.array([0.3, 0.3, 0.3])


def mix_scene(background=(0.0, 0.0, 0.0), **mix):
    s = toyrt.Scene()
    a = s.add_material("diffuse", color=tuple(A))
    b = s.add_material("diffuse", color=tuple(B))
    floor(s, s.add_material("mix", first=a, second=b, **mix))
    s.background = background
    return s


def test_mix_of_two_diffuse_under_a_point_light_is_lambert_of_the_mixed_colour():
    s = mix_scene(fac=0.3)
    power = 100.0
    s.add_point_light((0.0, 0.0, 2.0), power)
    irradiance = power / (4 * math.pi) / 4.0
    expected = (0.7 * A + 0.3 * B) / math.pi * irradiance
    np.testing.assert_allclose(render(s), expected, rtol=2e-3)


def test_add_of_two_diffuse_is_the_sum_of_their_albedos():
    # A white background seen from a diffuse floor: the cosine-sampled estimate is albedo x 1.
    np.testing.assert_allclose(render(mix_scene(background=(1, 1, 1), add=True)), A + B, rtol=2e-3)


def test_factor_outside_the_unit_interval_is_clamped_as_cycles_clamps_it():
    np.testing.assert_allclose(render(mix_scene(background=(1, 1, 1), fac=1.7)), B, rtol=1e-4)
    np.testing.assert_allclose(render(mix_scene(background=(1, 1, 1), fac=-2.0)), A, rtol=1e-4)


def test_nested_mix_weights_multiply():
    s = toyrt.Scene()
    a, b, c = (s.add_material("diffuse", color=tuple(x)) for x in (A, B, C))
    inner = s.add_material("mix", first=a, second=b, fac=0.5)
    floor(s, s.add_material("mix", first=inner, second=c, fac=0.25))
    s.background = (1.0, 1.0, 1.0)
    np.testing.assert_allclose(render(s), 0.75 * (0.5 * A + 0.5 * B) + 0.25 * C, rtol=3e-3, atol=1.5e-3)


def test_an_unlinked_input_is_black():
    s = toyrt.Scene()
    a = s.add_material("diffuse", color=tuple(A))
    floor(s, s.add_material("mix", first=a, second=-1, fac=0.4))
    s.background = (1.0, 1.0, 1.0)
    np.testing.assert_allclose(render(s), 0.6 * A, rtol=1e-4)


def two_colour_image():
    """64 x 64: the left half gray 0.2 with alpha 0.9, the right half gray 0.8 with alpha 0.1."""
    img = np.zeros((64, 64, 4), np.float32)
    img[:, :32] = (0.2, 0.2, 0.2, 0.9)
    img[:, 32:] = (0.8, 0.8, 0.8, 0.1)
    return img


@pytest.mark.parametrize("source,left,right", [("gray", 0.2, 0.8), ("alpha", 0.9, 0.1)])
def test_texture_factor_reads_the_image_at_the_hit(source, left, right):
    s = toyrt.Scene()
    t = s.add_texture(two_colour_image(), srgb=False)
    a = s.add_material("diffuse", color=tuple(A))
    b = s.add_material("diffuse", color=tuple(B))
    floor(s, s.add_material("mix", first=a, second=b, fac_source=source, fac_texture=t))
    s.background = (1.0, 1.0, 1.0)
    for x, f in ((-1.0, left), (1.0, right)):   # u = 0.25 and 0.75, far from the edge
        np.testing.assert_allclose(render(s, x=x), (1 - f) * A + f * B, rtol=3e-3, atol=1.5e-3)


def fresnel_dielectric_cos(c, eta):
    """Cycles' closed form (kernel/closure/bsdf_util.h)."""
    c = abs(c)
    g = eta * eta - 1 + c * c
    if g <= 0:
        return 1.0
    g = math.sqrt(g)
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1) / (c * (g - c) + 1)
    return 0.5 * a * a * (1 + b * b)


@pytest.mark.parametrize("tilt", [0.0, 0.9, 1.3])
def test_fresnel_factor_follows_the_dielectric_fresnel_of_the_view_cosine(tilt):
    f = fresnel_dielectric_cos(math.cos(tilt), 1.45)
    got = render(mix_scene(background=(1, 1, 1), fac_source="fresnel", fac_param=1.45), tilt=tilt)
    np.testing.assert_allclose(got, (1 - f) * A + f * B, rtol=3e-3, atol=1.5e-3)


@pytest.mark.parametrize("tilt", [0.4, 1.1])
def test_layer_weight_outputs_follow_their_closed_forms(tilt):
    blend = 0.3
    facing = 1 - math.cos(tilt) ** (2 * blend)
    fresnel = fresnel_dielectric_cos(math.cos(tilt), 1 / (1 - blend))
    for source, f in (("layer_facing", facing), ("layer_fresnel", fresnel)):
        got = render(mix_scene(background=(1, 1, 1), fac_source=source, fac_param=blend), tilt=tilt)
        np.testing.assert_allclose(got, (1 - f) * A + f * B, rtol=3e-3, atol=1.5e-3, err_msg=source)


def test_a_plain_material_set_over_a_mix_is_no_longer_mixed():
    s = mix_scene(background=(1, 1, 1), fac=0.5)
    s.set_material(2, "diffuse", color=tuple(C))
    np.testing.assert_allclose(render(s), C, rtol=1e-4)


def test_bad_mixes_are_refused_by_name():
    s = toyrt.Scene()
    a = s.add_material("diffuse")
    with pytest.raises(ValueError, match="mix input 5 must be -1 or another material id"):
        s.add_material("mix", first=a, second=5)
    with pytest.raises(ValueError, match="fac_source must be"):
        s.add_material("mix", first=a, fac_source="noise")
    with pytest.raises(ValueError, match="needs a fac_texture"):
        s.add_material("mix", first=a, fac_source="alpha")
    with pytest.raises(ValueError, match="unknown fac_texture id 3"):
        s.add_material("mix", first=a, fac_source="gray", fac_texture=3)
    with pytest.raises(TypeError, match="unknown argument"):
        s.add_material("mix", first=a, roughness=0.5)
    with pytest.raises(ValueError, match="must be -1 or another material id"):
        s.set_material(a, "mix", first=a)   # itself
    m1 = s.add_material("mix", first=a)
    m2 = s.add_material("mix", first=m1)
    with pytest.raises(ValueError, match="mix 1 would contain itself"):
        s.set_material(m1, "mix", first=m2)   # a cycle through another mix
