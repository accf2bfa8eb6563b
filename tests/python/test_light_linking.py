"""Light linking (Blender 4.0+, as Cycles): which objects a lamp lights (receiver sets) and which
objects shadow it (blocker sets). The core's part against closed forms and unlinked renders, and
the add-on's set computation (light_linking.py, plain data, no bpy) against Cycles' rules."""
import math
import sys
from pathlib import Path

import numpy as np
import toyrt
from test_render import camera_above

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "addon"))
from render_toyrt.light_linking import ALL, Emitter, link_sets  # noqa: E402  (plain data: no bpy)

FLOOR = np.float32([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]])


def floor(s, **sets):
    s.add_material("diffuse", color=(0.8, 0.8, 0.8))
    mid = s.add_mesh(FLOOR, [[0, 1, 2], [0, 2, 3]], material_ids=0, instance=False)
    s.add_instance(mid, np.eye(4), **sets)


def linked_lamp_alone(radius, commit=True):
    """The floor in receiver set 1 under the one lamp the tests link to it: 100 W at (0, 0, 2)."""
    s = toyrt.Scene()
    floor(s, receiver_set=1)
    s.add_light("POINT", position=(0, 0, 2), power=100.0, radius=radius)
    if commit:
        s.commit()
    return s


def test_a_plane_linked_to_one_of_two_lights_renders_as_under_that_light_alone():
    """Two point lights (radius 0) over a floor in receiver set 1; the second lamp's receiver
    sets exclude set 1: the image is the first lamp's alone, sample for sample, and its centre
    pixel the closed form albedo / pi x P / (4 pi d^2)."""
    cam = camera_above(size=0.02, resolution=1)
    alone = linked_lamp_alone(0.0)
    linked = linked_lamp_alone(0.0, commit=False)
    linked.add_light("POINT", position=(0.5, 0, 1), power=300.0, radius=0.0, receiver_sets=ALL & ~(1 << 1))
    linked.commit()
    want = alone.render(cam, samples=4)
    np.testing.assert_array_equal(linked.render(cam, samples=4), want)
    np.testing.assert_allclose(want[0, 0, :3], 0.8 / math.pi * 100.0 / (4 * math.pi * 4.0), rtol=1e-3)
    # One lamp chosen per point: the unlinked lamp is left out of the selection (as Cycles' light
    # tree leaves it out), so the linked one is picked with probability 1: the same image, sample
    # for sample, not only the same mean.
    one = linked.render(camera_above(size=1.0, resolution=8), samples=16, light_sampling="one")
    ref = alone.render(camera_above(size=1.0, resolution=8), samples=16, light_sampling="one")
    np.testing.assert_array_equal(one, ref)
    # Unlinked (set 0), the floor gets both.
    both = toyrt.Scene()
    floor(both, receiver_set=0)
    both.add_light("POINT", position=(0, 0, 2), power=100.0, radius=0.0)
    both.add_light("POINT", position=(0.5, 0, 1), power=300.0, radius=0.0, receiver_sets=ALL & ~(1 << 1))
    both.commit()
    assert both.render(cam, samples=4)[0, 0, 0] > 2 * want[0, 0, 0]


def test_through_the_light_tree_the_lamps_not_linked_to_a_floor_are_never_picked():
    """1,000 lamps (radius 0: the camera cannot see them) that do not light the floor's set and one
    that does: above kLightTreeFrom the
    scene selects through its light tree, which never enters a cluster of unlinked lamps, so the
    one lamp is picked with probability 1 and the image is that lamp's alone, sample for sample."""
    cam = camera_above(size=1.0, resolution=8)
    alone = linked_lamp_alone(0.1)
    many = toyrt.Scene()
    floor(many, receiver_set=1)
    rng = np.random.default_rng(3)
    for x, y, z in rng.uniform((-3, -3, 0.5), (3, 3, 3), size=(1000, 3)):
        many.add_light("POINT", position=(x, y, z), power=50.0, radius=0.0, receiver_sets=ALL & ~(1 << 1))
    many.add_light("POINT", position=(0, 0, 2), power=100.0, radius=0.1)
    many.commit()
    assert many.last_commit["light_tree_nodes"] > 0
    want = alone.render(cam, samples=8, light_sampling="one")
    np.testing.assert_array_equal(many.render(cam, samples=8, light_sampling="one"), want)


def occluded_scene(blocker_sets):
    """A floor, a 0.4 m square occluder (blocker set 1) at height 1 under a point lamp at (2, 0, 2)
    whose shadow falls around the origin, out of the occluder's own footprint."""
    s = toyrt.Scene()
    floor(s)
    occluder = np.float32([[0.8, -0.2, 1], [1.2, -0.2, 1], [1.2, 0.2, 1], [0.8, 0.2, 1]])
    mid = s.add_mesh(occluder, [[0, 1, 2], [0, 2, 3]], material_ids=0, instance=False)
    s.add_instance(mid, np.eye(4), blocker_set=1)
    s.add_light("POINT", position=(2, 0, 2), power=200.0, radius=0.0, blocker_sets=blocker_sets)
    s.commit()
    return s


def test_an_occluder_does_not_shadow_a_light_whose_blocker_sets_leave_it_out():
    cam = camera_above(size=1.0, resolution=10)  # x, y in [-0.5, 0.5]: the shadow, not the occluder
    open_floor = toyrt.Scene()
    floor(open_floor)
    open_floor.add_light("POINT", position=(2, 0, 2), power=200.0, radius=0.0)
    open_floor.commit()
    unshadowed = open_floor.render(cam, samples=4)
    np.testing.assert_array_equal(occluded_scene(ALL & ~(1 << 1)).render(cam, samples=4), unshadowed)
    shadowed = occluded_scene(ALL).render(cam, samples=4)
    assert (shadowed[..., 0] == 0).sum() >= 4 and (shadowed[..., 0] <= unshadowed[..., 0]).all()
    # Blocker sets that include only set 1 keep its shadow (and the floor, set 0, shadows nothing).
    np.testing.assert_array_equal(occluded_scene(1 << 1).render(cam, samples=4), shadowed)


def test_a_receiver_collection_with_an_include_entry_lights_only_what_it_includes():
    links = link_sets([Emitter("key", receivers=(("ball", "INCLUDE"),), receivers_key="C")])
    rset = links.receiver_set["ball"]
    assert rset >= 1 and links.instance_sets("floor") == (0, 0)
    assert links.receiver_sets["key"] == 1 << rset  # not set 0: the floor is not lit
    assert links.blocker_sets == {}


def test_a_receiver_collection_of_exclusions_lights_everything_else():
    links = link_sets([Emitter("key", receivers=(("ball", "EXCLUDE"), ("cube", "EXCLUDE")), receivers_key="C"),
                       Emitter("fill")])
    rset = links.receiver_set["ball"]
    assert links.receiver_set["cube"] == rset  # the same entries: one set
    assert links.receiver_sets == {"key": ALL & ~(1 << rset)}


def test_emitters_sharing_a_collection_share_its_sets_and_objects_differ_by_their_entries():
    c = (("a", "INCLUDE"), ("b", "EXCLUDE"))
    links = link_sets([Emitter("l1", receivers=c, receivers_key="C"), Emitter("l2", receivers=c, receivers_key="C"),
                       Emitter("l3", receivers=(("b", "INCLUDE"),), receivers_key="D")])
    a, b = links.receiver_set["a"], links.receiver_set["b"]
    assert a != b and 0 not in (a, b)
    assert links.receiver_sets["l1"] == links.receiver_sets["l2"] == 1 << a  # includes a; b excluded anyway
    assert links.receiver_sets["l3"] == 1 << b


def test_the_later_entry_for_an_object_wins_and_blockers_are_computed_apart():
    links = link_sets([Emitter("l", receivers=(("a", "INCLUDE"), ("a", "EXCLUDE")), receivers_key="C",
                               blockers=(("wall", "EXCLUDE"),), blockers_key="B")])
    a = links.receiver_set["a"]
    assert links.receiver_sets["l"] == ALL & ~(1 << a)
    w = links.blocker_set["wall"]
    assert links.blocker_sets["l"] == ALL & ~(1 << w) and links.instance_sets("wall") == (0, w)


def test_an_emissive_object_lights_only_the_receiver_sets_it_is_linked_to():
    """Emissive objects link as lamps do (emitter_receiver_sets). A 1 m emissive square 0.5 m over
    the floor's point (set 1), and a brighter one beside it whose sets leave out set 1: the point
    gets the first square's pi L F alone; with the second linked too it gets more. The camera sees
    an emitter whatever its sets (as Cycles' camera rays see mesh lights)."""
    from test_mesh_emitters import grid, square_irradiance_over_radiance

    def scene(second_sets):
        s = toyrt.Scene()
        floor(s, receiver_set=1)
        s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(2.0, 2.0, 2.0))
        s.add_material("diffuse", color=(0.0, 0.0, 0.0), emission=(20.0, 20.0, 20.0))
        for material, x, sets in ((1, 0.0, ALL), (2, 1.5, second_sets)):
            v, t = grid(1, 1.0, 0.5)
            mid = s.add_mesh(v + np.float32([x, 0, 0]), t, material_ids=material, instance=False)
            s.add_instance(mid, np.eye(4), emitter_receiver_sets=sets)
        s.commit()
        return s

    under = camera_above(height=0.25, size=0.002, resolution=2)
    expected = 0.8 * 2.0 * square_irradiance_over_radiance(1.0, 0.5) / math.pi
    got = scene(ALL & ~(1 << 1)).render(under, samples=2048)[..., 0].mean()
    assert abs(got - expected) < 0.01 * expected
    assert scene(ALL).render(under, samples=256)[..., 0].mean() > 1.2 * expected
    over_second = camera_above(height=5.0, size=0.002, resolution=2)
    over_second["matrix_world"][0, 3] = 1.5
    np.testing.assert_allclose(scene(ALL & ~1).render(over_second, samples=4)[..., :3], 20.0, rtol=1e-6)
