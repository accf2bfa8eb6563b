"""Rough Glass (the 'glass' material with roughness > 0) rendered against a quadrature of its lobe.

A rough glass plane at z = 0 seen straight down by an orthographic camera: each pixel is the
lobe's reflection or transmission at normal incidence integrated against what lights it. Three
lightings, three strategies of the integrator, one independent numpy quadrature of Walter et
al.'s BSDF (GGX, separable masking, the Fresnel term on the microfacet):
  - a constant world: found by the continuation ray alone, on both sides: the lobe's albedo A (GGX
    and Beckmann; Glass 4.0+, 3.x's Fresnel-weighted pair, Refraction);
  - a square lamp above, the world black: NEE and the reflected ray under MIS, R over the lamp;
  - the same lamp below, facing up: NEE and the transmitted ray through the plane, T over it;
  - the lamp's square as an emissive mesh, sampled or not, and a uniform environment map: the
    emitter and map samples on either side under MIS (render/glossy_lighting.h, LobeVertex)."""
import numpy as np
import pytest
import toyrt
from test_render import camera_above

ETA, ROUGHNESS = 1.5, 0.4
LAMP_HEIGHT, LAMP_SIZE, LAMP_POWER = 3.0, 6.0, 400.0


def fresnel(c, eta):
    s2t = (1 - c * c) / (eta * eta)
    ct = np.sqrt(np.clip(1 - s2t, 0, None))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return np.where(s2t >= 1, 1.0, 0.5 * (rs * rs + rp * rp))


def lobe_times_cos(wi, alpha=ROUGHNESS ** 2, eta=ETA, kind="glass", distribution="ggx", unchecked=False):
    """f |cos_i| for wo = +z, wi (..., 3) unit on either side. kind: 'glass' (Fresnel per
    microfacet, 4.0+), 'macro' (3.x: F at the normal weighting Fresnel-less lobes), 'refraction'
    (transmission only, no Fresnel). unchecked: also the pairs no microfacet refracts, which
    Cycles (and TOYRT's light samples) evaluate with |wo.h| and |wi.h| (materials/dielectric_lobe.h);
    the lobe's own sampler never makes them."""
    def d(h):
        c2 = np.maximum(h[..., 2], 1e-12) ** 2
        s2 = h[..., 0] ** 2 + h[..., 1] ** 2
        if distribution == "beckmann":
            val = np.exp(-s2 / (c2 * alpha * alpha)) / (np.pi * alpha * alpha * c2 * c2)
        else:
            t = s2 + alpha * alpha * c2
            val = alpha * alpha / (np.pi * t * t)
        return np.where(h[..., 2] > 0, val, 0.0)

    def g1(w):
        c = np.abs(w[..., 2])
        if distribution == "beckmann":   # Walter et al. 2007's rational fit, as Cycles
            with np.errstate(divide="ignore"):
                a = c / (alpha * np.sqrt(np.maximum(1 - c * c, 0.0)))
            fit = (3.535 * a + 2.181 * a * a) / (1 + 2.276 * a + 2.577 * a * a)
            return np.where(a < 1.6, np.nan_to_num(fit), 1.0)
        return 2 * c / (c + np.sqrt(c * c + alpha * alpha * (1 - c * c)))

    def weights(cos_oh):
        if kind == "refraction":
            return 0.0 * cos_oh, 1.0 + 0.0 * cos_oh
        f = fresnel(cos_oh, eta) if kind == "glass" else fresnel(np.ones_like(cos_oh), eta)
        return f, 1 - f

    ci = wi[..., 2]
    up = ci > 0
    # Reflection: h = (wo + wi) / |wo + wi|.
    hr = wi + np.array([0, 0, 1.0])
    hr /= np.linalg.norm(hr, axis=-1, keepdims=True)
    fr = weights(hr[..., 2])[0] * d(hr) * g1(wi) / 4.0  # G1(wo) = 1 at normal incidence
    # Transmission: h along wo + eta wi, turned up.
    ht = np.array([0, 0, 1.0]) + eta * wi
    ht /= np.linalg.norm(ht, axis=-1, keepdims=True)
    ht *= np.where(ht[..., 2] < 0, -1.0, 1.0)[..., None]
    coh, cih = ht[..., 2], np.sum(wi * ht, axis=-1)
    ok = (coh > 0) & (cih < 0)
    if unchecked:
        ok = np.ones_like(ok)
        coh, cih = np.abs(coh), -np.abs(cih)
    denom2 = np.sum((np.array([0, 0, 1.0]) + eta * wi) ** 2, axis=-1)  # (wo.h + eta wi.h)^2
    ft = weights(coh)[1] * d(ht) * g1(wi) * eta * eta * np.abs(cih) * coh / denom2
    return np.where(up, fr, np.where(ok, ft, 0.0))


def sphere_grid(n_theta=3000, n_phi=240):
    """Midpoint directions over the whole sphere with their solid angles."""
    th = (np.arange(n_theta) + 0.5) * np.pi / n_theta
    ph = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    t, p = np.meshgrid(th, ph, indexing="ij")
    w = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    return w, np.sin(t) * (np.pi / n_theta) * (2 * np.pi / n_phi)


def sees_lamp(w, below):
    """Directions from the origin that reach the square lamp at z = +-LAMP_HEIGHT."""
    z = -w[..., 2] if below else w[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        x, y = LAMP_HEIGHT * w[..., 0] / z, LAMP_HEIGHT * w[..., 1] / z
    return (z > 0) & (np.abs(x) < LAMP_SIZE / 2) & (np.abs(y) < LAMP_SIZE / 2)


def plane(world=(0.0, 0.0, 0.0), lamp=None, kind="glass", distribution="ggx", **lamp_visibility):
    s = toyrt.Scene()
    s.background = world
    if kind == "refraction":
        s.add_material("refraction", ior=ETA, roughness=ROUGHNESS, distribution=distribution)
    else:
        s.add_material("glass", ior=ETA, roughness=ROUGHNESS, distribution=distribution,
                       fresnel="macro" if kind == "macro" else "microfacet")
    h = 50.0
    v = np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]], np.float32)
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=0)
    if lamp is not None:
        m = np.eye(4)
        if lamp == "below":   # turned over: facing up
            m[1, 1] = m[2, 2] = -1.0
        m[2, 3] = -LAMP_HEIGHT if lamp == "below" else LAMP_HEIGHT
        s.add_area_light(m, shape="SQUARE", size=LAMP_SIZE, power=LAMP_POWER, visible_camera=False,
                         **lamp_visibility)
    s.commit()
    return s


def render_mean(s):
    img = s.render(camera_above(size=0.02, resolution=16), samples=256, max_specular_depth=4)
    assert np.isfinite(img).all()
    return float(img[..., 0].mean())


def test_quadrature_of_the_lobe_is_a_white_furnace_minus_masking():
    w, dw = sphere_grid()
    albedo = float(np.sum(lobe_times_cos(w) * dw))
    assert 0.97 < albedo < 1.0   # roughness 0.4: single-scatter GGX loses a little to masking


@pytest.mark.parametrize("distribution", ["ggx", "beckmann"])
@pytest.mark.parametrize("kind", ["glass", "macro", "refraction"])
def test_constant_world_through_and_in_rough_glass_is_the_lobes_albedo(kind, distribution):
    w, dw = sphere_grid()
    albedo = float(np.sum(lobe_times_cos(w, kind=kind, distribution=distribution) * dw))
    got = render_mean(plane(world=(1.0, 1.0, 1.0), kind=kind, distribution=distribution))
    assert 0.9 < albedo < 1.003   # Beckmann: 1 up to the quadrature (its fitted masking is 1 near the normal)
    assert got == pytest.approx(albedo, rel=2e-3)


@pytest.mark.parametrize("side", ["above", "below"])
def test_a_lamp_seen_in_or_through_rough_glass_matches_the_quadrature(side):
    w, dw = sphere_grid()
    radiance = LAMP_POWER / (4 * LAMP_SIZE * LAMP_SIZE)   # Cycles' area light units (test_render)
    want = radiance * float(np.sum(np.where(sees_lamp(w, side == "below"), lobe_times_cos(w), 0.0) * dw))
    got = render_mean(plane(lamp=side))
    assert want > 0.02 * radiance   # the lamp lights the pixel through this side of the lobe (R ~ 4 %)
    assert got == pytest.approx(want, rel=3e-3)


@pytest.mark.parametrize("side", ["above", "below"])
def test_a_lamp_hidden_from_one_kind_of_ray_lights_only_the_other_side_of_rough_glass(side):
    # The camera sees a lamp above the plane only by reflection (a glossy ray, Cycles' path
    # flags) and one below only by refraction (a transmission ray). Hidden from that kind of ray,
    # the lamp adds nothing, neither as the lobe's sample nor as what the lobe's ray finds (as
    # Cycles excludes a light from the closures it is hidden from); hidden from the other kind,
    # the image is the same as with the lamp seen by all.
    kind = "visible_glossy" if side == "above" else "visible_transmission"
    other = "visible_transmission" if side == "above" else "visible_glossy"
    seen = render_mean(plane(lamp=side))
    assert seen > 0.0
    assert render_mean(plane(lamp=side, **{kind: False})) == 0.0
    assert render_mean(plane(lamp=side, **{other: False})) == seen


def plane_under_emitter(side, sampling, kind="glass"):
    """The plane with the lamp's square as an Emission surface of the lamp's radiance instead."""
    s = toyrt.Scene()
    s.background = (0.0, 0.0, 0.0)
    s.add_material("glass", ior=ETA, roughness=ROUGHNESS, distribution="ggx", fresnel="microfacet")
    L = LAMP_POWER / (4 * LAMP_SIZE * LAMP_SIZE)
    s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(L, L, L), emission_sampling=sampling)
    h = 50.0
    s.add_mesh(np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]], np.float32), [[0, 1, 2], [0, 2, 3]],
               material_ids=0)
    a, z = LAMP_SIZE / 2, -LAMP_HEIGHT if side == "below" else LAMP_HEIGHT
    s.add_mesh(np.array([[-a, -a, z], [a, -a, z], [a, a, z], [-a, a, z]], np.float32), [[0, 1, 2], [0, 2, 3]],
               material_ids=1)
    s.commit()
    return s


@pytest.mark.parametrize("side", ["above", "below"])
def test_an_emitter_seen_in_or_through_rough_glass_matches_the_quadrature_sampled_or_not(side):
    # The rough dielectric vertex samples an emissive triangle on either side beside its lobe
    # (render/glossy_lighting.h, LobeVertex); not sampled (None), the lobe's ray alone finds it.
    # The camera sits below the square (which emits on both sides), looking down at the plane.
    w, dw = sphere_grid()
    want = LAMP_POWER / (4 * LAMP_SIZE * LAMP_SIZE) * float(
        np.sum(np.where(sees_lamp(w, side == "below"), lobe_times_cos(w), 0.0) * dw))
    cam = camera_above(height=2.0, size=0.02, resolution=16)
    sampled = plane_under_emitter(side, "AUTO").render(cam, samples=256, max_specular_depth=4)[..., 0]
    alone = plane_under_emitter(side, "NONE").render(cam, samples=256, max_specular_depth=4)[..., 0]
    assert sampled.mean() == pytest.approx(want, rel=3e-3)
    assert alone.mean() == pytest.approx(want, rel=0.02)


def test_a_uniform_map_through_and_in_rough_glass_is_the_lobes_albedo_and_the_unrefracted_pairs():
    # The map is sampled on both sides of the dielectric vertex and shares with the lobe by MIS.
    # Its samples also find the pairs no microfacet refracts, which Cycles evaluates: from straight
    # above, every wi in the band between the critical cone and the horizon (0.7 % here). The lobe's
    # pdf there is tiny, so the map's samples keep nearly all of it under MIS.
    w, dw = sphere_grid()
    albedo = float(np.sum(lobe_times_cos(w) * dw))
    unrefracted = float(np.sum((lobe_times_cos(w, unchecked=True) - lobe_times_cos(w)) * dw))
    assert 0.005 < unrefracted < 0.01
    s = plane()
    s.set_environment(s.add_texture(np.full((16, 32, 3), 1.0, np.float32), srgb=False))
    s.commit()
    assert render_mean(s) == pytest.approx(albedo + unrefracted, rel=1e-3)
