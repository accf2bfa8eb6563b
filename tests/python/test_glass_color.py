"""The colours of glass: Blender's Glass and Refraction BSDF Color, and the Principled BSDF's glass
tinted per Blender version (4.0+: Specular Tint on the reflection, the square root of the base
colour on each transmission; 3.x: the base colour on the refraction, the reflection white).

The scene makes the answer a closed form: the camera looks down through one glass plane that
fills its view, at a lit floor beneath; every camera path meets the glass exactly once (a
reflection leaves to the sky, a refraction ends on the diffuse floor, whose shadow rays to the
low lamp pass beside the glass), and the colours change no sampling decision. So each image is
linear in the tints, pixel by pixel and sample by sample:

    glass of colour c                  = c * (white glass)
    Principled, base b, Specular Tint k = k * R + t(b) * T,   R + T = the white Principled glass

with R the reflected light (the image of a black base, whose transmission is black) and t(b) =
sqrt(b) (4.0+) or b (3.x, where k is not used: R white).

Multiscatter GGX glass (4.0+) is the exception, as in Cycles: its energy compensation keeps, per
channel c of the transmission colour, the share E + F_ms (1 - E) of 1 / E, F_ms = c E_avg / (1 - c
(1 - E_avg)) (materials/dielectric_albedo.h), which is not linear in c: a white channel is the
white glass's, a darker one lies between c E and c times the white glass."""
import numpy as np
import pytest
import toyrt

COLOR = np.array([0.9, 0.5, 0.2])


def plane_scene(kind, **material):
    s = toyrt.Scene()
    s.add_material(kind, **material)
    s.add_material("diffuse", color=(0.6, 0.6, 0.6))
    s.add_mesh(np.float32([[-2, -2, 1.5], [2, -2, 1.5], [2, 2, 1.5], [-2, 2, 1.5]]), [[0, 1, 2], [0, 2, 3]],
               material_ids=0)
    s.add_mesh(np.float32([[-9, -9, 0], [9, -9, 0], [9, 9, 0], [-9, 9, 0]]), [[0, 1, 2], [0, 2, 3]], material_ids=1)
    s.background = (0.2, 0.2, 0.25)
    s.add_point_light((3.0, 0.5, 0.8), 300.0)
    s.commit()
    m = np.eye(4)
    m[:3, 3] = (0.1, -0.2, 3.0)
    return s.render(dict(type="PERSP", resolution_x=24, resolution_y=18, matrix_world=m), samples=8, seed=5,
                    max_specular_depth=8)[..., :3].astype(np.float64)


def close(a, b):
    np.testing.assert_allclose(a, b, rtol=2e-5, atol=1e-6)


GLASSES = [
    ("glass", dict(ior=1.5)),                                                    # sharp, split
    ("glass", dict(ior=1.5, roughness=0.3, fresnel="macro")),                    # 3.x's rough pair
    ("glass", dict(ior=1.5, roughness=0.4, shadowing="correlated")),             # 4.0+ (GGX)
    ("refraction", dict(ior=1.33)),
    ("refraction", dict(ior=1.33, roughness=0.25, distribution="beckmann")),
]


@pytest.mark.parametrize("kind,params", GLASSES)
def test_glass_color_scales_every_path_through_it(kind, params):
    white = plane_scene(kind, **params)
    assert white.mean() > 0.05  # light reaches the camera through the glass
    close(plane_scene(kind, color=tuple(COLOR), **params), COLOR * white)
    close(plane_scene(kind, color=(1.0, 1.0, 1.0), **params), white)  # white is the default
    assert plane_scene(kind, color=(0.0, 0.0, 0.0), **params).max() == 0.0


@pytest.mark.parametrize("version", ["4.0+", "3.x"])
@pytest.mark.parametrize("roughness", [0.0, 0.3])
def test_principled_glass_takes_cycles_tints(version, roughness):
    new = version == "4.0+"
    common = dict(ior=1.45, transmission=1.0, transmission_ior=1.45, roughness=roughness, layered=new,
                  burley=not new, multiscatter=False, shadowing="correlated" if new else "separable")

    def render(base, tint=(1.0, 1.0, 1.0)):
        return plane_scene("principled", color=base, specular_tint=tint, **common)

    white = render((1.0, 1.0, 1.0))
    reflected = render((0.0, 0.0, 0.0))       # a black base: its transmission is black
    transmitted = white - reflected
    assert reflected.mean() > 1e-3 and transmitted.mean() > 0.05
    tint = np.array([0.3, 0.8, 1.0])
    if new:
        close(render(tuple(COLOR), tuple(tint)), tint * reflected + np.sqrt(COLOR) * transmitted)
    else:  # 3.x: Specular Tint does not reach the glass's reflection (the add-on notes it)
        close(render(tuple(COLOR), tuple(tint)), reflected + COLOR * transmitted)


def test_bad_glass_colors_are_refused_by_name():
    for bad in [(float("nan"), 0.0, 0.0), (-0.1, 0.5, 0.5)]:
        with pytest.raises(ValueError, match="color"):
            toyrt.Scene().add_material("glass", color=bad)


@pytest.mark.parametrize("kind", ["glass", "principled"])
def test_multiscatter_glass_darkens_a_tinted_channel_as_cycles(kind):
    params = dict(ior=1.5, roughness=0.4, shadowing="correlated", multiscatter=True)
    c = np.array([1.0, 0.5, 0.2])
    if kind == "principled":
        # Its transmission colour is the square root of the base colour; a Specular Tint of the
        # same colour makes the whole glass that colour, as the Glass BSDF's.
        params.update(transmission=1.0, transmission_ior=1.5, layered=True)
        white = plane_scene(kind, color=(1.0, 1.0, 1.0), **params)
        tinted = plane_scene(kind, color=tuple(c ** 2), specular_tint=tuple(c), **params)
    else:
        white = plane_scene(kind, color=(1.0, 1.0, 1.0), **params)
        tinted = plane_scene(kind, color=tuple(c), **params)
    close(tinted[..., 0], white[..., 0])  # a white channel keeps 1 / E exactly
    for ch in (1, 2):
        linear = c[ch] * white[..., ch]
        assert np.all(tinted[..., ch] <= linear * (1.0 + 1e-5) + 1e-7)
        assert np.all(tinted[..., ch] >= 0.9 * linear)  # E > 0.9 at roughness 0.4 away from grazing
        assert tinted[..., ch].mean() < linear.mean() * (1.0 - 1e-4)  # and darker than linear
