"""Render passes (native/render/aovs.h) through the Python API, against closed forms: a plane at a
known distance, its normal and albedo, pass indices looked up per instance and per material, and
the invariant that asking for passes leaves the image unchanged."""
import numpy as np
import pytest
import toyrt

ALL = ["depth", "mist", "position", "normal", "diffuse_color", "glossy_color", "emission", "environment",
       "object_index", "material_index"]


def camera_down(kind="ORTHO", height=5.0, resolution=16):
    m = np.eye(4)
    m[2, 3] = height
    return dict(type=kind, ortho_scale=2.0, lens=50.0, resolution_x=resolution, resolution_y=resolution,
                matrix_world=m, clip_start=0.1, clip_end=100.0)


def two_tiles(albedos=((0.7, 0.5, 0.3), (0.2, 0.4, 0.6))):
    """Two squares side by side at z = 0 (x < 0: material 0, x > 0: material 1), each its own
    instance, under a point light."""
    s = toyrt.Scene()
    for a in albedos:
        s.add_material("diffuse", color=a)
    for k, x0 in enumerate((-5.0, 0.0)):
        v = np.array([[x0, -5, 0], [x0 + 5, -5, 0], [x0 + 5, 5, 0], [x0, 5, 0]], np.float32)
        s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=k)
    s.add_light("POINT", position=(0, 0, 3), power=100.0)
    s.commit()
    return s


def test_depth_is_the_planar_distance_and_normal_albedo_indices_are_the_planes():
    s = two_tiles()
    for kind in ("ORTHO", "PERSP"):
        s.render(camera_down(kind), samples=4, passes=ALL, object_index=np.array([3.0, 7.0]),
                 material_index=np.array([11.0, 13.0]))
        p = s.last_passes
        assert sorted(p) == sorted(ALL)
        assert p["depth"].shape == (16, 16, 1) and p["normal"].shape == (16, 16, 3)
        # Planar camera z, the same 5 m for every pixel of a plane facing the camera (perspective too).
        assert np.allclose(p["depth"], 5.0, atol=1e-4)
        assert np.allclose(p["normal"], [0, 0, 1], atol=1e-5)
        assert np.allclose(p["position"][..., 2], 0.0, atol=1e-5)
        left, right = (slice(None), slice(0, 7)), (slice(None), slice(9, 16))  # away from the seam at x = 0
        assert np.allclose(p["diffuse_color"][left], (0.7, 0.5, 0.3), atol=1e-6)
        assert np.allclose(p["diffuse_color"][right], (0.2, 0.4, 0.6), atol=1e-6)
        assert np.all(p["object_index"][left] == 3.0) and np.all(p["object_index"][right] == 7.0)
        assert np.all(p["material_index"][left] == 11.0) and np.all(p["material_index"][right] == 13.0)
        assert np.all(p["emission"] == 0.0)


def test_mist_is_cycles_ramp_of_the_camera_distance():
    s = two_tiles()
    # Orthographic: the distance along the view axis, 5 m: linear over [1, 9] gives 0.5, quadratic 0.25.
    for falloff, expected in ((1.0, 0.5), (2.0, 0.25), (0.5, 0.5 ** 0.5)):
        s.render(camera_down(), samples=2, passes=["mist"], mist=(1.0, 8.0, falloff))
        assert np.allclose(s.last_passes["mist"], expected, atol=1e-5)


def test_a_miss_reads_depth_1e10_mist_1_and_zero_elsewhere():
    s = two_tiles()
    up = camera_down()
    up["matrix_world"] = np.diag([1.0, -1.0, -1.0, 1.0])  # looking up, away from the planes
    up["matrix_world"][2, 3] = 1.0
    s.render(up, samples=2, passes=ALL, object_index=np.array([3.0, 7.0]))
    p = s.last_passes
    assert np.all(p["depth"] == 1e10) and np.all(p["mist"] == 1.0)
    for name in ("normal", "diffuse_color", "object_index", "material_index", "position"):
        assert np.all(p[name] == 0.0), name


def test_asking_for_passes_leaves_the_image_unchanged():
    s = two_tiles()
    plain = s.render(camera_down("PERSP"), samples=8)
    assert s.last_passes == {}
    with_passes = s.render(camera_down("PERSP"), samples=8, passes=ALL)
    assert np.array_equal(plain, with_passes)


def test_normal_is_averaged_over_samples_on_a_pixel_across_an_edge():
    # One plane covering half the view: pixels on its edge average the normal with misses (0).
    s = toyrt.Scene()
    s.add_material("diffuse")
    s.add_mesh(np.array([[-5, -5, 0], [0.0625, -5, 0], [0.0625, 5, 0], [-5, 5, 0]], np.float32),
               [[0, 1, 2], [0, 2, 3]], material_ids=0)
    s.commit()
    s.render(camera_down(), samples=64, passes=["normal", "depth"])
    n = s.last_passes["normal"][..., 2]
    assert np.allclose(n[:, :8], 1.0) and np.all(n[:, 9:] == 0.0)
    assert np.all((n[:, 8] > 0.3) & (n[:, 8] < 0.7))  # the pixel half covered: about half the samples hit
    d = s.last_passes["depth"][:, 8, 0]
    assert np.all((d == 5.0) | (d == 1e10))  # depth is one sample's, never a mean


def test_an_unknown_pass_is_a_value_error_naming_the_known_ones():
    s = two_tiles()
    with pytest.raises(ValueError, match="unknown pass 'vector'.*depth"):
        s.render(camera_down(), samples=1, passes=["vector"])


def test_diffuse_color_reads_the_texture_and_emission_the_radiance_and_glass_has_no_albedo():
    s = toyrt.Scene()
    tex = s.add_texture(np.full((4, 4, 3), (0.25, 0.5, 0.75), np.float32), srgb=False)
    s.add_material("diffuse", texture=tex)  # x < 0: a constant texture, linear
    s.add_material("diffuse", color=(0, 0, 0), emission=(2.0, 1.0, 0.5))  # 0 < x < 0.5: an emitter
    s.add_material("glass", ior=1.5)  # x > 0.5: glass
    for k, (x0, x1) in enumerate(((-5.0, 0.0), (0.0, 0.5), (0.5, 5.0))):
        v = np.array([[x0, -5, 0], [x1, -5, 0], [x1, 5, 0], [x0, 5, 0]], np.float32)
        s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], uvs=np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32),
                   material_ids=k)
    s.commit()
    s.render(camera_down(), samples=4, passes=["diffuse_color", "emission", "normal"])
    p = s.last_passes
    tex_px, glow_px, glass_px = (slice(None), slice(0, 7)), (slice(None), slice(9, 11)), (slice(None), slice(13, 16))
    assert np.allclose(p["diffuse_color"][tex_px], (0.25, 0.5, 0.75), atol=1e-6)
    assert np.allclose(p["emission"][glow_px], (2.0, 1.0, 0.5)) and np.all(p["emission"][tex_px] == 0)
    assert np.all(p["diffuse_color"][glow_px] == 0)  # black Diffuse under its emission
    assert np.all(p["diffuse_color"][glass_px] == 0) and np.allclose(p["normal"][glass_px], (0, 0, 1))


def test_glossy_color_is_the_glossy_bsdfs_colour_and_a_lambert_surface_has_none():
    s = two_tiles()
    s.set_material(1, "glossy", color=(0.9, 0.6, 0.3), roughness=0.3)  # x > 0: a Glossy BSDF
    s.commit()
    s.render(camera_down(), samples=4, passes=["glossy_color", "diffuse_color"])
    p = s.last_passes
    left, right = (slice(None), slice(0, 7)), (slice(None), slice(9, 16))
    assert np.all(p["glossy_color"][left] == 0)
    assert np.allclose(p["glossy_color"][right], (0.9, 0.6, 0.3), atol=1e-6)
    assert np.all(p["diffuse_color"][right] == 0)


def test_a_metal_at_normal_incidence_has_its_colour_as_glossy_color():
    # Blender 4.0+'s Principled metal, smooth and seen head-on by an orthographic camera: Cycles'
    # albedo estimate mix(F0, 1, s) with s = 0 there, so exactly the base colour F0 (to the table's
    # interpolation).
    s = two_tiles()
    s.set_material(1, "principled", color=(0.95, 0.64, 0.54), metallic=1.0, roughness=0.0, multiscatter=False)
    s.commit()
    s.render(camera_down(), samples=2, passes=["glossy_color"])
    assert np.allclose(s.last_passes["glossy_color"][:, 9:16], (0.95, 0.64, 0.54), atol=1e-3)


def test_the_world_seen_directly_is_the_environment_and_lamps_seen_directly_are_emission():
    # A constant world of colour c beside a floor, and an area lamp facing the camera: Environment
    # is c where the camera sees the world, Emission the lamp's radiance in Cycles' units, P / (4 A)
    # (native/lights/area_light.h), where it sees the lamp; Combined is their sum with the rest of
    # the light, exactly, where nothing else is seen.
    s = toyrt.Scene()
    s.add_material("diffuse", color=(0.5, 0.5, 0.5))
    v = np.array([[-5, -5, 0], [0, -5, 0], [0, 5, 0], [-5, 5, 0]], np.float32)  # x < 0 only
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=0)
    lamp = np.diag([1.0, -1.0, -1.0, 1.0])  # emitting up, towards the camera
    lamp[:3, 3] = (0.5, 0.5, 1.0)
    s.add_light("AREA", matrix=lamp, size=0.5, power=20.0, color=(1.0, 0.5, 0.25))
    s.background = (0.2, 0.3, 0.4)
    s.commit()
    image = np.asarray(s.render(camera_down(resolution=32), samples=8, passes=["environment", "emission"]))
    p = s.last_passes
    env, emit = p["environment"], p["emission"]
    # 1/16 m per pixel over x, y in [-1, 1], rows from the top (+y first).
    world_px = (slice(18, 32), slice(18, 32))  # x > 0, y < 0: below the lamp's square
    lamp_px = (slice(7, 9), slice(23, 25))     # the lamp's centre, (0.5, 0.5)
    floor_px = (slice(None), slice(0, 14))
    assert np.allclose(env[world_px], (0.2, 0.3, 0.4), atol=1e-6) and np.all(emit[world_px] == 0)
    assert np.all(env[floor_px] == 0) and np.all(emit[floor_px] == 0)
    radiance = 20.0 / (4.0 * 0.25) * np.array([1.0, 0.5, 0.25])
    assert np.allclose(emit[lamp_px], radiance, rtol=1e-5)
    assert np.allclose(env[lamp_px], (0.2, 0.3, 0.4), atol=1e-6)  # the world behind the lamp
    # Combined = Emission + Environment + (nothing else seen there), exactly.
    for px in (world_px, lamp_px):
        assert np.allclose(image[px][..., :3], emit[px] + env[px], rtol=1e-6, atol=1e-6)
