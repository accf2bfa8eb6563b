"""The Principled material through the module: closed-form pixels at normal incidence under a
point light straight above an orthographic one-pixel camera, where the GGX lobe's value is
D(n) G2 F / 4 = F0 / (4 pi alpha^2) (G2 = 1 there, F = F0 on the normal), and bad input refused
by name."""
import math

import numpy as np
import pytest
import toyrt


def floor(**material):
    s = toyrt.Scene()
    s.add_material("principled", **material)
    s.add_mesh(np.float32([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]), [[0, 1, 2], [0, 2, 3]], material_ids=0)
    s.background = (0.0, 0.0, 0.0)
    s.add_point_light((0.0, 0.0, 2.0), 100.0)
    s.commit()
    m = np.eye(4)
    m[2, 3] = 5.0
    return s.render(dict(type="ORTHO", ortho_scale=1e-3, resolution_x=1, resolution_y=1, matrix_world=m),
                    samples=16)[0, 0, :3]


IRRADIANCE = 100.0 / (4 * math.pi) / 4.0   # a 100 W point 2 m above: W / (4 pi r^2)


def test_unlayered_rough_principled_is_lambert_plus_f0_over_4_pi():
    # Blender 3.x's sum: the whole base plus the lobe; roughness 1: alpha 1, D(n) = 1 / pi.
    color = np.array([0.6, 0.3, 0.1])
    got = floor(color=tuple(color), roughness=1.0, ior=1.5, layered=False, multiscatter=False,
                shadowing="separable")
    np.testing.assert_allclose(got, (color / math.pi + 0.04 / (4 * math.pi)) * IRRADIANCE, rtol=1e-4)


def lit_from(x, **material):
    """The floor's pixel straight below the camera, lit by a 100 W point lamp at (x, 0, 2)."""
    s = toyrt.Scene()
    s.add_material("principled", **material)
    s.add_mesh(np.float32([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]), [[0, 1, 2], [0, 2, 3]], material_ids=0)
    s.background = (0.0, 0.0, 0.0)
    s.add_point_light((x, 0.0, 2.0), 100.0)
    s.commit()
    m = np.eye(4)
    m[2, 3] = 5.0
    return s.render(dict(type="ORTHO", ortho_scale=1e-3, resolution_x=1, resolution_y=1, matrix_world=m),
                    samples=16)[0, 0, :3]


@pytest.mark.parametrize("roughness", [0.0, 0.5, 1.0])
def test_burley_base_has_its_closed_form_under_an_oblique_lamp(roughness):
    # Blender 3.x's Burley diffuse seen head-on (FV = 0) and lit at cos_i: albedo / pi times
    # (1 - FL / 2) + R FL, FL = (1 - cos_i)^5, R = roughness (1 + cos_i); no layer at IOR 1.
    color = np.array([0.6, 0.3, 0.1])
    x = 3.0
    d2 = x * x + 4.0
    cos_i = 2.0 / math.sqrt(d2)
    fl = (1.0 - cos_i) ** 5
    factor = 1.0 - 0.5 * fl + roughness * (1.0 + cos_i) * fl
    got = lit_from(x, color=tuple(color), roughness=roughness, ior=1.0, layered=False, burley=True)
    lambert = lit_from(x, color=tuple(color), roughness=roughness, ior=1.0, layered=False)
    np.testing.assert_allclose(got, color / math.pi * factor * 100.0 / (4 * math.pi * d2) * cos_i, rtol=1e-4)
    np.testing.assert_allclose(got, lambert * factor, rtol=1e-5)


def test_specular_tint_and_level_scale_f0():
    got = floor(color=(0.0, 0.0, 0.0), roughness=1.0, ior=1.5, specular_ior_level=1.0,
                specular_tint=(1.0, 0.5, 0.0), layered=False, multiscatter=False)
    np.testing.assert_allclose(got, np.array([0.08, 0.04, 0.0]) / (4 * math.pi) * IRRADIANCE, rtol=1e-4, atol=1e-9)


def test_layering_takes_from_the_base_what_the_layer_reflects():
    color = (0.6, 0.3, 0.1)
    layered = floor(color=color, roughness=1.0, ior=1.5, multiscatter=False)
    whole = floor(color=color, roughness=1.0, ior=1.5, multiscatter=False, layered=False)
    # Same lobe; the base is scaled by one factor in (1 - 1, 1 - F0]: the layer's albedo at wo.
    lobe = 0.04 / (4 * math.pi) * IRRADIANCE
    factor = (layered - lobe) / (whole - lobe)
    assert np.allclose(factor, factor[0], rtol=2e-3) and 0.5 < factor[0] <= 0.96 + 1e-6


def test_no_layer_at_ior_1_or_level_0_is_the_diffuse_material():
    for kw in (dict(ior=1.0), dict(specular_ior_level=0.0)):
        got = floor(color=(0.6, 0.3, 0.1), **kw)
        np.testing.assert_allclose(got, np.array([0.6, 0.3, 0.1]) / math.pi * IRRADIANCE, rtol=1e-4)


@pytest.mark.parametrize("bad", [dict(ior=0.0), dict(roughness=math.nan), dict(specular_ior_level=-0.5),
                                 dict(specular_tint=(1.0, math.nan, 1.0)), dict(shadowing="smith")])
def test_bad_parameters_are_refused_by_name(bad):
    s = toyrt.Scene()
    with pytest.raises(ValueError, match=next(iter(bad))):
        s.add_material("principled", **bad)


def sphere_scene(kind, **material):
    """A sphere of the material over a lit checker-free floor, seen in perspective: the pixels a
    rough glass's reflection, transmission and the floor through it make."""
    s = toyrt.Scene()
    s.add_material(kind, **material)
    s.add_material("diffuse", color=(0.6, 0.6, 0.6))
    n_lat, n_lon = 24, 48
    theta = np.linspace(0, np.pi, n_lat + 1)
    phi = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    verts = np.float32([[np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), 1.0 + np.cos(t)] for t in theta for p in phi])
    tris = []
    for i in range(n_lat):
        for j in range(n_lon):
            a, b = i * n_lon + j, i * n_lon + (j + 1) % n_lon
            c, d = a + n_lon, b + n_lon
            tris += [[a, c, b], [b, c, d]]
    s.add_mesh(verts, tris, material_ids=0)
    s.add_mesh(np.float32([[-9, -9, 0], [9, -9, 0], [9, 9, 0], [-9, 9, 0]]), [[0, 1, 2], [0, 2, 3]], material_ids=1)
    s.background = (0.2, 0.2, 0.25)
    s.add_point_light((2.0, -2.0, 4.0), 400.0)
    s.commit()
    m = np.eye(4)
    m[:3, 3] = (0.0, 0.0, 7.0)
    return s.render(dict(type="PERSP", resolution_x=32, resolution_y=24, matrix_world=m), samples=16, seed=3,
                    max_specular_depth=8)


@pytest.mark.parametrize("version", ["4.0+", "3.x"])
def test_principled_transmission_one_renders_the_glass_bsdf(version):
    # Transmission 1, Metallic 0, a white base: every hit draws the glass, which is the Glass BSDF's
    # lobe of the same roughness and conventions: the same image, bit for bit (the same sample
    # numbers). (A coloured base tints the glass: test_glass_color.py.)
    new = version == "4.0+"
    glass = sphere_scene("glass", ior=1.45, roughness=0.3, shadowing="correlated" if new else "separable",
                         fresnel="microfacet" if new else "macro", multiscatter=new)
    principled = sphere_scene("principled", color=(1.0, 1.0, 1.0), ior=1.8 if not new else 1.45, transmission=1.0,
                              transmission_ior=1.45, roughness=0.3, layered=new, burley=not new, multiscatter=new,
                              shadowing="correlated" if new else "separable")
    assert glass.mean() > 0.0
    np.testing.assert_array_equal(principled, glass)


def test_3x_refraction_roughness_roughens_the_refraction_alone():
    # 3.x's glass is a reflection closure of the Roughness and a refraction closure of its own
    # (Transmission Roughness, combined by the add-on). Equal to the roughness: the same image, bit
    # for bit; rougher: another image; with 4.0+'s one glass closure (layered True): refused.
    args = dict(color=(1.0, 1.0, 1.0), ior=1.8, transmission=1.0, transmission_ior=1.45, roughness=0.3,
                layered=False, burley=True, multiscatter=False, shadowing="separable")
    plain = sphere_scene("principled", **args)
    same = sphere_scene("principled", refraction_roughness=0.3, **args)
    rougher = sphere_scene("principled", refraction_roughness=0.8, **args)
    np.testing.assert_array_equal(same, plain)
    assert np.abs(rougher - plain).max() > 0.05
    assert np.isfinite(sphere_scene("principled", **{**args, "roughness": 0.0}, refraction_roughness=0.5)).all()
    with pytest.raises(ValueError, match="refraction_roughness needs layered False"):
        toyrt.Scene().add_material("principled", refraction_roughness=0.5)


# ---- 4.0+'s coat ------------------------------------------------------------------------------

def test_coat_head_on_is_its_lobe_plus_the_base_it_leaves():
    # At normal incidence under the point straight above, a coat of weight 1 over a base without a
    # specular layer (Specular IOR Level 0): the coat's lobe D(n) G2 F0 / 4 = F0 / (4 pi alpha^2)
    # (G2 = 1, F = F0 on the normal) times its energy compensation (Cycles always compensates the
    # coat: 1 + F_ms (1 - E) / E, a little above 1, more the rougher), plus the base scaled by
    # 1 - A with A Cycles' estimate of the coat's albedo, E (1 + F_ms (1 - E) / E) mix(F0, 1, s):
    # near F0 head-on, below it as the coat roughens (E < 1; the exact value from the tables is
    # tests/native/principled_test.cpp's). The coat is drawn on half the samples with twice the
    # weight; 16 Sobol samples split exactly in half, so the base's scale is one number for every
    # colour and the black base isolates the lobe.
    color = np.array([0.6, 0.3, 0.1])
    f0 = ((1.5 - 1.0) / (1.5 + 1.0)) ** 2
    compensation = []
    for rough in (0.3, 0.6):
        alpha = rough ** 2
        common = dict(ior=1.5, specular_ior_level=0.0, roughness=0.9, coat_weight=1.0, coat_roughness=rough,
                      coat_ior=1.5)
        lobe = floor(color=(0.0, 0.0, 0.0), **common)
        got = floor(color=tuple(color), **common)
        k = lobe / (IRRADIANCE * f0 / (4.0 * math.pi * alpha ** 2))
        assert np.all(k >= 1.0) and np.all(k < 1.03), k
        compensation.append(k[0])
        kept = (got - lobe) / (IRRADIANCE * color / math.pi)
        np.testing.assert_allclose(kept, kept[0], rtol=1e-5)
        assert 1.0 - f0 - 1e-4 < kept[0] < 1.0 - 0.03, kept
    assert compensation[1] > compensation[0]


def test_coat_tint_tints_what_lies_below_it_only():
    # Head-on the path through a coat of unit thickness is 1: the base under it is tinted by the
    # tint itself (Beer's law), the coat's own reflection is not. A black base isolates the coat.
    common = dict(ior=1.5, specular_ior_level=0.0, roughness=0.5, coat_weight=1.0, coat_roughness=0.3)
    lobe = floor(color=(0.0, 0.0, 0.0), **common)
    white = floor(color=(0.7, 0.7, 0.7), **common)
    tint = np.array([0.9, 0.5, 0.2])
    tinted = floor(color=(0.7, 0.7, 0.7), coat_tint=tuple(tint), **common)
    assert lobe.min() > 0.0 and (white - lobe).min() > 0.0
    np.testing.assert_allclose(tinted, lobe + tint * (white - lobe), rtol=1e-5)
    # Half a coat: half its lobe, and the tint mixed halfway towards white.
    half = floor(color=(0.7, 0.7, 0.7), coat_tint=tuple(tint), **dict(common, coat_weight=0.5))
    assert np.all(np.isfinite(half)) and np.all(half < white + 1e-6)


def test_coated_metal_and_bad_coats():
    coated = floor(color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.3, coat_weight=1.0)
    bare = floor(color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.3)
    assert np.all(np.isfinite(coated)) and coated.sum() != bare.sum()
    with pytest.raises(ValueError, match="coat_weight"):
        floor(coat_weight=float("nan"))



def test_3x_clearcoat_head_on_is_a_quarter_of_its_weight_times_f0_times_gtr1():
    # Blender 3.x's Clearcoat (layered False: coat_weight is it) over a black base with no layer:
    # head-on under a point lamp, f = 0.25 x Clearcoat x F0(1.5) x D G1 G1 / 4, with GTR1's
    # D(n) = 1 / pi at Clearcoat Roughness 1 and the masking 1 at the normal. Drawn in half the
    # samples (probability Clearcoat / 2) at twice its weight: exact over 16 stratified samples.
    common = dict(color=(0.0, 0.0, 0.0), roughness=0.5, ior=1.0, layered=False, burley=True, multiscatter=False,
                  shadowing="separable", coat_roughness=1.0)
    np.testing.assert_allclose(floor(coat_weight=1.0, **common), 0.25 * 0.04 / (4 * math.pi) * IRRADIANCE,
                               rtol=1e-4)
    np.testing.assert_array_equal(floor(coat_weight=0.0, **common), 0.0)
