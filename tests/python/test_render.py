"""The renderer through the Python API, against known answers: Blender's light units in closed
form, invariants of the image loop (determinism, cancel, finite pixels), and refraction."""
import numpy as np
import pytest
import toyrt


def camera_above(height=5.0, size=2.0, resolution=32, **extra):
    """An orthographic camera looking straight down at the origin, `size` metres across."""
    m = np.eye(4)
    m[2, 3] = height
    cam = dict(type="ORTHO", ortho_scale=size, resolution_x=resolution, resolution_y=resolution,
               matrix_world=m, clip_start=0.1, clip_end=100.0)
    cam.update(extra)
    return cam


def floor_scene(albedo=1.0, half=5.0):
    s = toyrt.Scene()
    v = np.array([[-half, -half, 0], [half, -half, 0], [half, half, 0], [-half, half, 0]], np.float32)
    s.add_material("diffuse", color=(albedo,) * 3)
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=0)
    return s


def add_uv_sphere(s, rings, segs, material_id, radius=0.8, centre=(0, 0, 1)):
    """A coarse UV sphere with smooth normals: each cell of its rings x segs latitude/longitude grid
    as two triangles (degenerate at the poles)."""
    th, ph = np.meshgrid(np.linspace(0, np.pi, rings + 1), np.linspace(0, 2 * np.pi, segs, endpoint=False),
                         indexing="ij")
    p = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1).reshape(-1, 3) * radius + centre
    idx = lambda i, j: i * segs + j % segs  # noqa: E731
    tris = [(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)) for i in range(rings) for j in range(segs)]
    tris += [(idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)) for i in range(rings) for j in range(segs)]
    return s.add_mesh(p.astype(np.float32), tris, normals=((p - centre) / radius).astype(np.float32),
                      material_ids=material_id)


def pixel_centres(cam):
    """World (x, y) of every pixel's area, sampled on a fine grid (for averaging closed forms)."""
    n, size = cam["resolution_x"], cam["ortho_scale"]
    sub = 8
    c = (np.arange(n * sub) + 0.5) / (n * sub) * size - size / 2
    x, y = np.meshgrid(c, -c)  # rows from the top: y decreases downwards
    return x, y, sub


def box_average(values, n, sub):
    return values.reshape(n, sub, n, sub).mean(axis=(1, 3))


def test_point_light_over_a_plane_gives_I_cos_over_r2_in_blender_units():
    power, height, albedo = 100.0, 1.0, 0.7
    s = floor_scene(albedo)
    s.add_point_light((0.3, -0.2, height), power)
    s.commit()
    cam = camera_above(size=3.0, resolution=24)
    img = s.render(cam, samples=64)
    x, y, sub = pixel_centres(cam)
    r2 = (x - 0.3) ** 2 + (y + 0.2) ** 2 + height**2
    intensity = power / (4 * np.pi)                          # W/sr, as Cycles (docs: BLENDER_UNITS.md)
    radiance = albedo / np.pi * intensity * (height / np.sqrt(r2)) / r2
    expected = box_average(radiance, 24, sub)
    np.testing.assert_allclose(img[..., 0], expected, rtol=2e-3)
    assert (img[..., 3] == 1).all()


def test_many_point_lights_are_selected_through_a_light_tree_to_the_closed_form():
    # 1,200 point lights (above the tree's threshold of 1,000) over the floor: commit builds the
    # tree, and one light per hit through it converges to the sum of the lights' I cos / r^2.
    rng = np.random.default_rng(3)
    n, albedo = 1200, 0.8
    pos = np.column_stack([rng.uniform(-6, 6, n), rng.uniform(-6, 6, n), rng.uniform(0.5, 3.0, n)])
    power = rng.uniform(1.0, 50.0, n)
    s = floor_scene(albedo)
    s.commit()
    assert s.last_commit["light_tree_nodes"] == 0
    for p, w in zip(pos, power):
        s.add_point_light(tuple(p), float(w))
    s.commit()
    assert s.last_commit["light_tree_nodes"] > 0
    img = s.render(camera_above(size=1e-3, resolution=1), samples=8192, light_sampling="one")
    r2 = (pos**2).sum(axis=1)
    exact = albedo / np.pi * (power / (4 * np.pi) * (pos[:, 2] / np.sqrt(r2)) / r2).sum()
    assert img[0, 0, 0] == pytest.approx(exact, rel=0.03)


def test_square_area_light_above_a_point_matches_the_closed_form_with_both_estimators():
    power, h, a = 40.0, 0.5, 1.0
    s = floor_scene(1.0)
    m = np.eye(4)
    m[2, 3] = h
    s.add_area_light(m, shape="SQUARE", size=a, power=power)
    s.commit()
    L = power / (4 * a * a)  # Cycles' area-light radiance
    # Irradiance under the centre of a parallel square: four corner rectangles of a/2 x a/2 each,
    # each giving E = pi L F with the form factor F = 1/(2 pi) (X/sqrt(1+X^2) atan(Y/sqrt(1+X^2))
    # + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))), X = Y = (a/2)/h.
    X = Y = a / 2 / h
    corner = (X / np.sqrt(1 + X * X) * np.arctan(Y / np.sqrt(1 + X * X))
              + Y / np.sqrt(1 + Y * Y) * np.arctan(X / np.sqrt(1 + Y * Y)))
    E = 4 * np.pi * L * corner / (2 * np.pi)
    cam = camera_above(size=0.01, resolution=4)
    for estimator in ("solid_angle", "area"):
        img = s.render(cam, samples=1024, area_light_sampling=estimator)
        assert img[..., 0].mean() == pytest.approx(E / np.pi, rel=1e-2), estimator


def test_results_do_not_depend_on_threads_or_tiles():
    s = floor_scene(0.5)
    s.add_point_light((0, 0, 1), 50.0, radius=0.2)
    m = np.eye(4)
    m[:3, 3] = [1, 1, 1.5]
    s.add_area_light(m, shape="RECTANGLE", size=0.5, size_y=0.3, power=30.0)
    s.add_mesh(np.array([[-0.3, -0.3, 0.4], [0.3, -0.3, 0.4], [0, 0.3, 0.4]], np.float32), [[0, 1, 2]], material_ids=0)
    s.commit()
    cam = camera_above(resolution=40)
    a = s.render(cam, samples=8, threads=1, tile_size=7, seed=3)
    b = s.render(cam, samples=8, threads=2, tile_size=32, seed=3)
    assert np.array_equal(a, b)
    c = s.render(cam, samples=8, seed=4)
    assert not np.array_equal(a, c)  # the seed does matter


def test_tiles_arrive_as_they_finish_and_cover_the_image():
    s = floor_scene()
    s.add_point_light((0, 0, 1), 100.0)
    s.commit()
    cam = camera_above(resolution=50)
    seen = np.zeros((50, 50), int)
    tiles = []

    def on_tile(x, y, w, h, pixels):
        tiles.append((x, y, w, h))
        seen[y:y + h, x:x + w] += 1
        assert pixels.shape == (h, w, 4)

    s.render(cam, samples=2, tile_size=16, on_tile=on_tile)
    assert (seen == 1).all() and len(tiles) == 16 and s.last_render["tiles_done"] == 16


def test_cancel_stops_the_render_early():
    s = floor_scene()
    s.add_point_light((0, 0, 1), 100.0)
    s.commit()
    cam = camera_above(resolution=400)
    calls = []

    def should_cancel():
        calls.append(1)
        return len(calls) > 1  # cancel at the second poll

    s.render(cam, samples=64, tile_size=16, should_cancel=should_cancel)
    info = s.last_render
    assert info["cancelled"]
    assert info["tiles_done"] < info["tiles_total"]
    assert 0 <= info["cancel_latency_ms"] < info["render_ms"]
    print(f"cancelled: workers stopped {info['cancel_latency_ms']:.2f} ms after the request; "
          f"{info['tiles_done']} of {info['tiles_total']} tiles")


def test_a_failing_tile_callback_raises_after_the_workers_stop():
    s = floor_scene()
    s.add_point_light((0, 0, 1), 100.0)
    s.commit()

    def boom(*args):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):
        s.render(camera_above(resolution=64), samples=4, tile_size=8, on_tile=boom)
    # The scene is still usable.
    assert s.render(camera_above(resolution=8), samples=1).shape == (8, 8, 4)


def test_glass_slab_passes_the_background_through_unchanged():
    """Perfect refraction through a parallel slab: the ray leaves parallel to itself, with all its
    energy (no Fresnel in Blender's Refraction BSDF), so the background shows as it is."""
    s = toyrt.Scene()
    s.background = (0.2, 0.4, 0.8)
    s.add_material("refraction", ior=1.5)
    # A closed box slab 4 x 4 x 0.5 under the camera, tilted so the rays meet it obliquely.
    box_v = np.array([[x, y, z] for x in (-2, 2) for y in (-2, 2) for z in (0.0, 0.5)], np.float32)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    tilt = np.eye(4)
    tilt[:3, :3] = [[1, 0, 0], [0, np.cos(0.4), -np.sin(0.4)], [0, np.sin(0.4), np.cos(0.4)]]
    s.add_mesh(box_v, tris, transform=tilt, material_ids=0)
    s.commit()
    img = s.render(camera_above(size=1.0, resolution=16), samples=4, max_specular_depth=8)
    np.testing.assert_allclose(img[..., :3], np.broadcast_to([0.2, 0.4, 0.8], img[..., :3].shape), rtol=1e-6)
    # With no specular depth left the path is cut at the slab: black.
    img0 = s.render(camera_above(size=1.0, resolution=16), samples=1, max_specular_depth=0)
    assert (img0[..., :3] == 0).all()


def test_glass_sphere_with_textures_and_lights_has_only_finite_non_negative_pixels():
    s = toyrt.Scene()
    tex = s.add_texture(np.random.default_rng(1).integers(0, 256, (8, 8, 3), dtype=np.uint8))
    s.add_material("diffuse", texture=tex)
    s.add_material("glass", ior=1.45)
    v = np.array([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], np.float32)
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], uvs=np.array([[0, 0], [2, 0], [2, 2], [0, 2]], np.float32), material_ids=0)
    add_uv_sphere(s, 12, 24, material_id=1)
    s.add_point_light((1, 1, 3), 200.0, color=(1, 0.5, 0.2), radius=0.1)
    m = np.eye(4)
    m[:3, 3] = [-1, 0, 3]
    s.add_area_light(m, shape="DISK", size=1.0, power=100.0)
    s.commit()
    cam = dict(type="PERSP", lens=35, resolution_x=48, resolution_y=32,
               matrix_world=np.array([[1, 0, 0, 0], [0, 0, -1, -6], [0, 1, 0, 1.2], [0, 0, 0, 1.0]]))
    img = s.render(cam, samples=8)
    assert np.isfinite(img).all() and (img >= 0).all()
    assert img[..., :3].max() > 0.05  # something is lit


def test_render_input_errors_are_clear():
    s = floor_scene()
    with pytest.raises(RuntimeError, match="commit"):
        s.render(camera_above())
    s.commit()
    with pytest.raises(ValueError, match="unknown setting 'focal'"):
        s.render(dict(focal=50))
    with pytest.raises(ValueError, match="resolution"):
        s.render(camera_above(resolution=0))
    with pytest.raises(ValueError, match="samples"):
        s.render(camera_above(), samples=0)
    with pytest.raises(ValueError, match="area_light_sampling"):
        s.render(camera_above(), area_light_sampling="fast")
    with pytest.raises(ValueError, match="power"):
        s.add_point_light((0, 0, 1), -1.0)
    with pytest.raises(ValueError, match="material kind"):
        s.add_material("metal")
    with pytest.raises(ValueError, match="unknown texture id 3"):
        s.add_material("diffuse", texture=3)
    with pytest.raises(ValueError, match="3 or 4"):
        s.add_texture(np.zeros((4, 4, 2), np.float32))
    s.add_mesh(np.zeros((3, 3), np.float32) + [[0, 0, 1], [1, 0, 1], [0, 1, 1]], [[0, 1, 2]], material_ids=7)
    s.commit()
    with pytest.raises(ValueError, match="material id 7"):
        s.render(camera_above())


def test_a_uniform_background_lights_an_open_plane_with_albedo_times_its_radiance():
    """Under a constant sky of radiance L, an unoccluded Lambert plane reflects albedo * L (the
    cosine-weighted hemisphere integrates to pi, and f = albedo / pi)."""
    s = floor_scene(albedo=0.6, half=50.0)
    s.background = (0.5, 1.0, 2.0)
    s.commit()
    img = s.render(camera_above(size=0.5, resolution=4), samples=256)
    np.testing.assert_allclose(img[..., :3].mean(axis=(0, 1)), [0.3, 0.6, 1.2], rtol=2e-3)
    s.background_lighting = False
    assert (s.render(camera_above(size=0.5, resolution=4), samples=4)[..., :3] == 0).all()


def test_a_world_hidden_from_the_camera_is_black_behind_objects_but_still_lights_and_shows_through_glass():
    """background_visible_camera=False (Blender's world camera ray visibility): camera rays that
    leave the scene see opaque black; the floor's world lighting (albedo * L) and the world seen
    through a refracting slab (exactly L, as above) are unchanged."""
    s = floor_scene(albedo=0.6, half=1.0)  # a 2 m floor: the 4 m view sees past its edges
    s.background = (0.5, 1.0, 2.0)
    s.add_material("refraction", ior=1.5)
    v = np.array([[x, y, z] for x in (1.2, 1.8) for y in (-0.3, 0.3) for z in (0.1, 0.4)], np.float32)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    s.add_mesh(v, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], material_ids=1)
    s.commit()
    cam = camera_above(size=4.0, resolution=40)
    shown = s.render(cam, samples=64)
    assert s.background_visible_camera
    s.background_visible_camera = False
    hidden = s.render(cam, samples=64)
    c = (np.arange(40) + 0.5) / 40 * 4.0 - 2.0  # pixel centres, 0.1 m apart
    x, y = np.meshgrid(c, -c)  # rows from the top
    on_floor = (abs(x) < 0.9) & (abs(y) < 0.9)
    off_floor = (np.maximum(abs(x), abs(y)) > 1.1) & ~((abs(x - 1.5) < 0.4) & (abs(y) < 0.4))
    through_glass = (abs(x - 1.5) < 0.2) & (abs(y) < 0.2)
    np.testing.assert_allclose(shown[off_floor][:, :3], np.broadcast_to([0.5, 1.0, 2.0], (off_floor.sum(), 3)))
    assert (hidden[off_floor][:, :3] == 0).all() and (hidden[off_floor][:, 3] == 1).all()
    np.testing.assert_array_equal(hidden[on_floor], shown[on_floor])  # the same lighting, sample for sample
    np.testing.assert_allclose(hidden[through_glass][:, :3], np.broadcast_to([0.5, 1.0, 2.0], (through_glass.sum(), 3)),
                               rtol=1e-6)


def test_a_world_hidden_from_glossy_rays_is_black_in_reflections_and_from_transmission_rays_black_through_glass():
    """background_visible_glossy / _transmission (world.cycles_visibility.glossy / .transmission),
    as Cycles' path flags: a ray reflected by a mirror or a glossy lobe is a glossy ray, one
    refracted through glass a transmission ray. Under a constant world L, a mirror (Glossy BSDF,
    roughness 0) of colour c shows c L, exactly; hidden from glossy rays it shows black, and so does
    a rough glossy floor (no other light). The world through a refracting slab is exactly L (as
    above), black when hidden from transmission rays; each flag leaves the other kind alone."""
    L = np.array([0.5, 1.0, 2.0])
    cam = camera_above(size=1.0, resolution=4)
    for roughness in (0.0, 0.4):
        s = toyrt.Scene()
        s.add_material("glossy", color=(0.9, 0.6, 0.3), roughness=roughness)
        s.add_mesh(np.float32([[-50, -50, 0], [50, -50, 0], [50, 50, 0], [-50, 50, 0]]), [[0, 1, 2], [0, 2, 3]],
                   material_ids=0)
        s.background = tuple(L)
        s.commit()
        shown = s.render(cam, samples=16)[..., :3]
        if roughness == 0.0:
            np.testing.assert_allclose(shown, np.broadcast_to([0.45, 0.6, 0.6], shown.shape), rtol=1e-6)
        assert (shown > 0.1).all()
        s.background_visible_transmission = False
        np.testing.assert_array_equal(s.render(cam, samples=16)[..., :3], shown)
        assert s.background_visible_glossy
        s.background_visible_glossy = False
        assert (s.render(cam, samples=16)[..., :3] == 0).all()

    s = toyrt.Scene()
    s.add_material("refraction", ior=1.5)
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (0.1, 0.4)], np.float32)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    s.add_mesh(v, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], material_ids=0)
    s.background = tuple(L)
    s.commit()
    through = s.render(cam, samples=16)[..., :3]
    np.testing.assert_allclose(through, np.broadcast_to(L, through.shape), rtol=1e-6)
    s.background_visible_glossy = False
    np.testing.assert_array_equal(s.render(cam, samples=16)[..., :3], through)
    s.background_visible_glossy = True
    s.background_visible_transmission = False
    assert (s.render(cam, samples=16)[..., :3] == 0).all()


def glass_plane_under_a_light(split_depth_scene_power=40.0, size=20.0):
    """A glass (Fresnel) plane at z = 0 seen straight down by an ortho camera at z = 5, and a large
    area light at z = 3 facing down, which camera rays pass (visible_camera=False) but the
    plane's reflection sees. Below the plane nothing: the refracted ray sees the black world."""
    s = toyrt.Scene()
    s.add_material("glass", ior=1.5)
    h = 50.0
    v = np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]], np.float32)
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=0)
    m = np.eye(4)
    m[2, 3] = 3.0
    s.add_area_light(m, shape="SQUARE", size=size, power=split_depth_scene_power, visible_camera=False)
    s.commit()
    return s, split_depth_scene_power / (4 * size * size)  # the light's radiance (Cycles' units)


def test_split_glass_gives_fresnel_times_the_reflected_light_without_noise():
    """At normal incidence F = ((1 - 1.5) / (1 + 1.5))^2 = 0.04: the pixel is 0.04 L. Splitting
    traces both branches with weights F and 1 - F, so even one sample per pixel is exact; choosing
    one branch with probability F is right only on average (a Bernoulli of mean 0.04)."""
    s, L = glass_plane_under_a_light()
    cam = camera_above(size=1.0, resolution=16)
    F = ((1 - 1.5) / (1 + 1.5)) ** 2
    split = s.render(cam, samples=1, split_depth=2)[..., 0]
    np.testing.assert_allclose(split, F * L, rtol=1e-4)
    chosen = s.render(cam, samples=64, split_depth=0)[..., 0]
    # Unbiased: the mean of 16 x 16 x 64 Bernoulli samples of L with p = F, within 5 sigma.
    n = chosen.size * 64
    sigma = L * np.sqrt(F * (1 - F) / n)
    assert abs(chosen.mean() - F * L) < 5 * sigma
    assert chosen.std() > 100 * split.std()  # the noise splitting removes


def test_split_and_chosen_branches_agree_on_a_glass_sphere():
    """Splitting changes the noise, not the answer: the same glass-sphere scene with and without
    it converges to one image (mean over the image within a few standard errors)."""
    s = floor_scene(albedo=0.8, half=3.0)
    s.add_material("glass", ior=1.45)
    add_uv_sphere(s, 16, 32, material_id=1)
    m = np.eye(4)
    m[:3, 3] = [0.5, 0, 3]
    s.add_area_light(m, shape="SQUARE", size=1.5, power=200.0)
    s.commit()
    cam = camera_above(size=2.0, resolution=16)
    a = s.render(cam, samples=256, split_depth=0)[..., :3].astype(np.float64)
    b = s.render(cam, samples=256, split_depth=3, seed=7)[..., :3].astype(np.float64)
    # Per-pixel sample noise is unknown in closed form: estimate it from a second run of each.
    a2 = s.render(cam, samples=256, split_depth=0, seed=11)[..., :3].astype(np.float64)
    noise = np.std(a - a2) / np.sqrt(2) / np.sqrt(a.size)  # standard error of an image mean
    assert abs(a.mean() - b.mean()) < 6 * noise + 1e-6
    assert np.std(b - s.render(cam, samples=256, split_depth=3, seed=13)[..., :3]) < np.std(a - a2)
