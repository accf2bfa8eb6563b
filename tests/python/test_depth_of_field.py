"""Depth of field against the thin lens's closed form: a black half-plane's edge against a white
background, seen through the lens, spreads over the aperture's image on the sensor (the circle of
confusion), whose size the lens, f-stop and distances fix. Each pixel's value is the share of the
aperture that sees past the edge, so the edge's profile across the columns is the aperture's
projection: its variance is the aperture's second moment, in pixels."""
import numpy as np
import pytest
import toyrt

WIDTH, HEIGHT, LENS, SENSOR = 64, 16, 50.0, 36.0
ORTHO_SCALE = 2.0


def edge_scene(depth):
    """A black (albedo 0) half-plane x >= 0 at depth `depth` in front of a camera at the origin that
    looks down -z; the background is white, so a pixel's value is the share of its rays that miss."""
    s = toyrt.Scene()
    v = np.array([[0, -50, -depth], [50, -50, -depth], [50, 50, -depth], [0, 50, -depth]], np.float32)
    s.add_material("diffuse", color=(0.0, 0.0, 0.0))
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=0)
    s.background = (1.0, 1.0, 1.0)
    s.commit()
    return s


def camera(kind="PERSP", **dof):
    return dict(type=kind, lens=LENS, sensor_width=SENSOR, ortho_scale=ORTHO_SCALE, resolution_x=WIDTH,
                resolution_y=HEIGHT, matrix_world=np.eye(4), clip_start=0.1, clip_end=100.0, **dof)


def blur_radius_px(kind, fstop, depth, focus):
    """The aperture's radius as the edge at `depth` sees it, in pixels. The lens ray from aperture
    point a through the focus point F crosses depth d at a (1 - d / f) + F d / f: the aperture
    scaled by |d - f| / f around the pinhole ray's point. Perspective: radius lens / (2 fstop), seen
    from distance d, projected at lens / sensor * width pixels per unit tangent, so
    c = A |d - f| / (d f) * lens * width / sensor with A = lens / (2 fstop): the thin-lens circle of
    confusion A |d - f| / d * F / (f - F) with f - F ~ f (Cycles' lens has no thickness between
    the pinhole and the plane of focus). Orthographic: radius 1 m / (2 fstop) (Cycles' rule), at
    width / ortho_scale pixels per metre."""
    if kind == "PERSP":
        radius = LENS * 1e-3 / (2 * fstop)
        return radius * abs(depth - focus) / (depth * focus) * LENS / SENSOR * WIDTH
    return 1.0 / (2 * fstop) * abs(depth - focus) / focus * WIDTH / ORTHO_SCALE


def aperture_variance(blades):
    """Var(x) of a point uniform on the unit aperture: the disk's 1/4, a regular n-gon inscribed in
    the unit circle (1 + 2 cos^2(pi / n)) / 12 (half its E[|p|^2], by symmetry)."""
    return 0.25 if blades == 0 else (1 + 2 * np.cos(np.pi / blades) ** 2) / 12


def edge_spread(img):
    """Per row, the line spread's (the edge profile's derivative across columns) mean and variance
    in pixels. Differencing box-filtered pixels samples the spread convolved with two unit boxes,
    which adds 2 / 12 to its variance."""
    e = img[..., 0]
    lsf = -np.diff(e, axis=1)
    m = np.arange(1, WIDTH, dtype=np.float64)
    total = lsf.sum(axis=1, keepdims=True)
    mean = (lsf * m).sum(axis=1, keepdims=True) / total
    var = (lsf * (m - mean) ** 2).sum(axis=1) / total[:, 0] - 2.0 / 12.0
    return total[:, 0], var


CASES = [
    # kind, depth, focus, fstop, blades, rotation, ratio
    ("PERSP", 4.0, 2.0, 0.1, 0, 0.0, 1.0),  # behind the plane of focus
    ("PERSP", 4.0, 8.0, 0.05, 0, 0.0, 1.0),  # in front of it
    ("PERSP", 4.0, 2.0, 0.1, 6, 0.3, 1.0),  # hexagonal aperture
    ("PERSP", 4.0, 2.0, 0.1, 0, 0.0, 2.0),  # anamorphic: x squeezed by 1 / 2
    ("ORTHO", 4.0, 2.0, 3.0, 0, 0.0, 1.0),
]


@pytest.mark.parametrize("kind,depth,focus,fstop,blades,rotation,ratio", CASES)
def test_an_out_of_focus_edge_spreads_as_the_thin_lens_predicts(kind, depth, focus, fstop, blades, rotation, ratio):
    s = edge_scene(depth)
    cam = camera(kind, use_dof=True, focus_distance=focus, aperture_fstop=fstop, aperture_blades=blades,
                 aperture_rotation=rotation, aperture_ratio=ratio)
    total, var = edge_spread(s.render(cam, samples=256))
    np.testing.assert_allclose(total, 1.0, atol=1e-6)  # the whole spread is inside the image
    expected = blur_radius_px(kind, fstop, depth, focus) ** 2 * aperture_variance(blades) / ratio**2
    # The rows are independent estimates (each pixel scrambles its own samples): the mean of 16
    # within four of their standard errors, plus 1 % for sampling the spread at whole pixels.
    se = var.std(ddof=1) / np.sqrt(len(var))
    assert abs(var.mean() - expected) < 4 * se + 0.01 * expected, (var.mean(), expected, se)


@pytest.mark.parametrize("kind", ["PERSP", "ORTHO"])
def test_an_edge_on_the_plane_of_focus_stays_sharp(kind):
    s = edge_scene(4.0)
    fstop = 0.1 if kind == "PERSP" else 3.0
    img = s.render(camera(kind, use_dof=True, focus_distance=4.0, aperture_fstop=fstop), samples=64)
    e = img[..., 0]
    # The edge lies on the boundary between columns 31 and 32: every other column is all in or out.
    np.testing.assert_allclose(e[:, :31], 1.0, atol=1e-6)
    np.testing.assert_allclose(e[:, 33:], 0.0, atol=1e-6)


def test_without_depth_of_field_the_image_is_the_pinholes_exactly():
    s = edge_scene(4.0)
    pinhole = s.render(camera(), samples=16, seed=5)
    off = s.render(camera(use_dof=False, focus_distance=1.0, aperture_fstop=0.1, aperture_blades=6), samples=16,
                   seed=5)
    assert np.array_equal(pinhole, off)


@pytest.mark.parametrize("setting,value", [("focus_distance", -1.0), ("aperture_fstop", float("nan")),
                                           ("aperture_ratio", 0.0), ("aperture_rotation", float("inf"))])
def test_bad_depth_of_field_settings_are_refused_by_name(setting, value):
    s = edge_scene(4.0)
    with pytest.raises(ValueError, match=setting):
        s.render(camera(use_dof=True, **{setting: value}), samples=1)
