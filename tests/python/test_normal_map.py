"""The Normal Map through the Python API (add_material's normal_* keywords, add_mesh's tangents),
against closed forms: a Lambert floor under a sun, lit as albedo / pi x E x max(0, N'.L) with N'
the normal a constant texel encodes (tangent frame T = x, B = sign y, N = z); a flat texel, a
mesh without tangents and strength 0 render as no normal map; DirectX negates green; 3.x's and
4.x+'s strength rules; a normal bent below the surface never gives NaN; Cycles' bump shadowing
terms of 3.x (Chiang et al.) and 4.x+ (Conty Estevez et al.) as factors on that law."""
import numpy as np
import pytest
import toyrt
from test_render import camera_above
from test_sun_spot import aimed

ALBEDO, SUN = 0.8, 3.0


def normal_texture(s, n):
    """A 2 x 2 float texture of the constant texel encoding unit vector n."""
    n = np.asarray(n, np.float32) / np.linalg.norm(n)
    return s.add_texture(np.tile((0.5 * (n + 1.0)).astype(np.float32), (2, 2, 1)), srgb=False)


def floor(s, material, tangents=True, sign=1.0, half=2.0):
    v = np.array([[-half, -half, 0], [half, -half, 0], [half, half, 0], [-half, half, 0]], np.float32)
    uvs = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]], np.float32)
    t = np.tile(np.array([1.0, 0.0, 0.0, sign], np.float32), (2, 3, 1)) if tangents else None
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], uvs=uvs, material_ids=material, tangents=t)


def render(light_dir, n=None, tangents=True, sign=1.0, **normal):
    """The floor's radiance (one value: every pixel must agree) under a sun shining towards
    -light_dir, its material bent by the texel of n (None: no normal map)."""
    s = toyrt.Scene()
    args = {}
    if n is not None:
        args = dict(normal_map=normal_texture(s, n), normal_shadowing="none")
        args.update(normal)
    s.add_material("diffuse", color=(ALBEDO,) * 3, **args)
    floor(s, 0, tangents, sign)
    s.add_light("SUN", matrix=aimed(-np.asarray(light_dir, float)), strength=SUN, angle=0.0)
    s.commit()
    img = s.render(camera_above(size=2.0, resolution=8), samples=2)[..., :3]
    assert np.isfinite(img).all()
    np.testing.assert_allclose(img, img[0, 0, 0], rtol=1e-5, atol=1e-7)
    return float(img[0, 0, 0])


def lambert(normal, light_dir):
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    light_dir = np.asarray(light_dir, float) / np.linalg.norm(light_dir)
    return ALBEDO / np.pi * SUN * max(0.0, float(normal @ light_dir))


LIGHT = (np.sin(0.7), 0.0, np.cos(0.7))


def test_flat_texel_renders_as_no_normal_map():
    assert render(LIGHT, (0, 0, 1)) == render(LIGHT)


def test_tilted_texel_lights_the_floor_as_its_normal():
    n = (np.sin(0.5), 0.0, np.cos(0.5))
    assert render(LIGHT, n) == pytest.approx(lambert(n, LIGHT), rel=1e-5)
    # Tilted away from the light: darker, by the same law.
    away = (-np.sin(0.5), 0.0, np.cos(0.5))
    assert render(LIGHT, away) == pytest.approx(lambert(away, LIGHT), rel=1e-5)


def test_bitangent_sign_and_directx_negate_green():
    n = (0.0, np.sin(0.5), np.cos(0.5))
    light = (0.0, np.sin(0.6), np.cos(0.6))
    mirrored = (0.0, -np.sin(0.5), np.cos(0.5))
    assert render(light, n) == pytest.approx(lambert(n, light), rel=1e-5)
    assert render(light, n, sign=-1.0) == pytest.approx(lambert(mirrored, light), rel=1e-5)
    assert render(light, n, normal_convention="DIRECTX") == pytest.approx(lambert(mirrored, light), rel=1e-5)


def test_strength_rules_of_blender_3_and_4():
    n = np.array([np.sin(0.5), 0.0, np.cos(0.5)])
    # 4.x+ (tangent): n.x * s, n.z = 1 + (n.z - 1) min(s, 1).
    scaled = (0.5 * n[0], 0.0, 1.0 + (n[2] - 1.0) * 0.5)
    assert render(LIGHT, n, normal_strength=0.5) == pytest.approx(lambert(scaled, LIGHT), rel=1e-5)
    # 3.x (blend): normalize(z + 0.5 (n - z)).
    blended = np.array([0.0, 0.0, 1.0]) + 0.5 * (n - np.array([0.0, 0.0, 1.0]))
    assert render(LIGHT, n, normal_strength=0.5, normal_strength_mode="blend") == pytest.approx(
        lambert(blended, LIGHT), rel=1e-5)
    assert render(LIGHT, n, normal_strength=0.0) == render(LIGHT)


def test_mesh_without_tangents_keeps_the_surface_normal():
    assert render(LIGHT, (np.sin(0.5), 0.0, np.cos(0.5)), tangents=False) == render(LIGHT)


def test_object_and_world_space_read_the_texel_as_the_normal():
    n = (np.sin(0.4), 0.0, np.cos(0.4))
    for space in ("OBJECT", "WORLD"):
        assert render(LIGHT, n, tangents=False, normal_space=space) == pytest.approx(lambert(n, LIGHT), rel=1e-5)


def test_normal_bent_below_the_surface_is_lifted_not_nan():
    # Bent 85 degrees: the view straight down would reflect under the floor; the normal is turned
    # towards the floor's until the reflection is 0.01 above it (cos 2 theta = 0.01), which a
    # light at that normal's angle lights as max(0, N'.L).
    n = (np.sin(1.48), 0.0, np.cos(1.48))
    theta = 0.5 * np.arccos(0.01)
    lifted = (np.sin(theta), 0.0, np.cos(theta))
    assert render(LIGHT, n) == pytest.approx(lambert(lifted, LIGHT), rel=1e-4)


def test_bump_shadowing_terms_of_blender_3_and_4():
    theta = 0.5
    n = np.array([np.sin(theta), 0.0, np.cos(theta)])    # tilted towards the light: g < 1
    z = np.array([0.0, 0.0, 1.0])
    light = np.array(LIGHT)
    plain = lambert(n, light)
    # 3.x: g = (Ns.L) / ((N.L)(Ns.N)), factor -g^3 + g^2 + g below 1.
    g = (z @ light) / ((n @ light) * (z @ n))
    assert 0.0 < g < 1.0
    assert render(LIGHT, n, normal_shadowing="chiang") == pytest.approx(plain * (g + g * g - g ** 3), rel=1e-5)
    # 4.x+: GGX G1 at cos_i = Ns.L with alpha^2 = tan^2(theta) / 8.
    a2, ci = np.tan(theta) ** 2 / 8.0, z @ light
    g1 = 1.0 / (1.0 + 0.5 * (np.sqrt(1.0 + a2 * (1.0 / ci ** 2 - 1.0)) - 1.0))
    assert render(LIGHT, n, normal_shadowing="conty") == pytest.approx(plain * g1, rel=1e-5)
    # Flat texel: the normal is the smooth one, no factor.
    assert render(LIGHT, (0, 0, 1), normal_shadowing="conty") == render(LIGHT)


def test_bad_normal_map_arguments_are_refused_by_name():
    s = toyrt.Scene()
    with pytest.raises(ValueError, match="normal_map"):
        s.add_material("diffuse", normal_map=0)
    t = normal_texture(s, (0, 0, 1))
    with pytest.raises(ValueError, match="normal_space"):
        s.add_material("diffuse", normal_map=t, normal_space="UV")
    with pytest.raises(ValueError, match="normal_convention"):
        s.add_material("diffuse", normal_map=t, normal_convention="D3D")
    with pytest.raises(ValueError, match="normal_shadowing"):
        s.add_material("diffuse", normal_map=t, normal_shadowing="soft")
    v = np.zeros((3, 3), np.float32)
    with pytest.raises(ValueError, match="tangents"):
        s.add_mesh(v, [[0, 1, 2]], tangents=np.zeros((2, 3, 4), np.float32))
    with pytest.raises(ValueError, match="tangents"):
        s.add_mesh(v, [[0, 1, 2]], tangents=np.full((1, 3, 4), np.nan, np.float32))


@pytest.mark.parametrize("kind", ["diffuse", "principled", "glossy", "glass"])
def test_strongly_bent_normals_on_a_sphere_give_no_nan_and_no_black_pixel(kind):
    # A sphere seen whole (grazing rims included) under a uniform world, every texel bending the
    # normal 80 degrees: the lift keeps each view's mirror above the surface, so every pixel of
    # the sphere is finite and lit (a uniform world lights any direction above the surface).
    s = toyrt.Scene()
    s.background = (1.0, 1.0, 1.0)
    extra = dict(roughness=0.3) if kind in ("principled", "glossy") else {}
    s.add_material(kind, color=(0.8, 0.8, 0.8), normal_map=normal_texture(s, (np.sin(1.4), 0.0, np.cos(1.4))),
                   normal_shadowing="conty", **extra)
    rings, segs, centre = 16, 32, np.array([0.0, 0.0, 1.0])
    th, ph = np.meshgrid(np.linspace(0, np.pi, rings + 1), np.linspace(0, 2 * np.pi, segs, endpoint=False),
                         indexing="ij")
    n = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1).reshape(-1, 3)
    east = np.stack([-np.sin(ph), np.cos(ph), np.zeros_like(ph)], -1).reshape(-1, 3)
    idx = lambda i, j: i * segs + j % segs  # noqa: E731
    tris = [(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)) for i in range(rings) for j in range(segs)]
    tris += [(idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)) for i in range(rings) for j in range(segs)]
    uv = np.stack([ph / (2 * np.pi), 1.0 - th / np.pi], -1).reshape(-1, 2)
    tangents = np.concatenate([east, np.ones((len(east), 1))], 1)
    s.add_mesh((0.8 * n + centre).astype(np.float32), tris, normals=n.astype(np.float32), uvs=uv.astype(np.float32),
               tangents=tangents.astype(np.float32), material_ids=0)
    s.commit()
    m = np.eye(4)
    m[:3, 3] = (0.0, 0.0, 6.0)   # looking down -Z at the sphere from above
    img = s.render(dict(type="ORTHO", ortho_scale=2.0, resolution_x=24, resolution_y=24, matrix_world=m,
                        clip_start=0.1, clip_end=100.0), samples=16, max_specular_depth=4)[..., :3]
    assert np.isfinite(img).all()
    y, x = np.mgrid[0:24, 0:24]
    on_sphere = ((x + 0.5 - 12) ** 2 + (y + 0.5 - 12) ** 2) < (0.8 * 12 * 0.97) ** 2
    black = np.count_nonzero(img[on_sphere].max(axis=1) == 0.0)
    assert black == 0, f"{black} black pixels on the sphere"
