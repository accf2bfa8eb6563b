# The Normal Map node as the add-on converts it (addon/render_toyrt/material_normal.py) and the
# tangents it exports (mesh_tangents.py): Blender's own MikkTSpace over the triangles TOYRT
# renders. Tangents equal Mesh.calc_tangents on a quad mesh (which it accepts) and, on a mesh with
# an n-gon (which it refuses), the closed form of a planar face with an affine UV map; the spec of
# a Normal Map node (space, strength, UV map, 5.x+'s convention where it exists) and of a Bump
# node; bad input (no image, a Bump without a height image, no UV map) keeps the surface normal
# with a note, and F12 renders finite.
# Cycles parity of the rendered result is tests/blender/test_cycles_parity.py's normal_map scene.
#     blender -b --python-exit-code 1 --python tests/blender/test_normal_map.py
import os
import sys
import tempfile

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-normal-map-")


def exported(obj, uv_map=""):
    """The add-on's corner tangents of `obj` (mesh.evaluated_geometry, as sync.py calls it) and the
    loop of each exported corner."""
    from render_toyrt.mesh import evaluated_geometry

    depsgraph = bpy.context.evaluated_depsgraph_get()
    g = evaluated_geometry(obj.evaluated_get(depsgraph), depsgraph, tangents_for=lambda mats: uv_map)
    data = obj.data
    data.calc_loop_triangles()
    loops = np.empty(len(data.loop_triangles) * 3, np.int64)
    data.loop_triangles.foreach_get("loops", loops)
    return g, loops


def wavy_grid(n=8, smooth=True):
    """An n x n quad grid over [-1, 1]^2 displaced by a wave, UVs a skewed, slightly curved map of x
    and y. Skewed so that each quad's diagonal 0-2 is the shorter one in UV space: MikkTSpace
    splits a quad along that one, as Blender's loop triangles do, so calc_tangents over the quads
    and over TOYRT's triangles must agree (elsewhere they legitimately differ, and Cycles' are
    those of the triangles)."""
    x, y = np.meshgrid(np.linspace(-1, 1, n + 1), np.linspace(-1, 1, n + 1))
    # Flat shading of a non-planar quad: Blender's tangents use the quad's normal, Cycles' (and
    # TOYRT's) each triangle's own, so the flat grid is kept planar.
    z = 0.2 * np.sin(2.5 * x) * np.cos(1.7 * y) if smooth else 0.0 * x
    verts = np.stack([x, y, z], -1).reshape(-1, 3)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    quads = np.stack([idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]], -1).reshape(-1, 4)
    uv_of = lambda v: (0.5 * (v[0] - 0.3 * v[1]) + 0.03 * v[1] ** 2, 0.5 * (v[1] - 0.3 * v[0]))  # noqa: E731
    uvs = np.array([uv_of(verts[i]) for i in quads.ravel()], np.float32)
    return kit.mesh_object("wavy", verts, quads, kit.diffuse("wavy"), uvs=uvs, smooth=smooth)


def test_tangents_equal_calc_tangents_on_a_quad_mesh():
    kit.clear_scene()
    for smooth in (True, False):
        obj = wavy_grid(smooth=smooth)
        g, loops = exported(obj)
        obj.data.calc_tangents(uvmap="UVMap")
        t = np.empty(len(obj.data.loops) * 3, np.float32)
        obj.data.loops.foreach_get("tangent", t)
        s = np.empty(len(obj.data.loops), np.float32)
        obj.data.loops.foreach_get("bitangent_sign", s)
        want_t, want_s = t.reshape(-1, 3)[loops], s[loops]
        got = g.tangents.reshape(-1, 4)
        err = float(np.abs(got[:, :3] - want_t).max())
        check(g.tangents.shape == (len(g.triangles), 3, 4) and err < 2e-3 and (got[:, 3] == want_s).all(),
              f"{'smooth' if smooth else 'flat'} quads: the exported tangents are calc_tangents' per loop "
              f"(largest difference {err:.2e}), signs equal")
        bpy.data.objects.remove(obj)


def test_tangents_of_a_mesh_with_an_ngon_are_the_closed_form():
    kit.clear_scene()
    # A planar hexagon and a quad beside it, UV = a rotation of (x, y) by 30 degrees, scaled:
    # the tangent (direction of increasing u on the face) is the rotated x axis, the bitangent
    # sign +1; a mirrored V gives sign -1.
    a = np.radians(30.0)
    ring = [(np.cos(t), np.sin(t), 0.0) for t in np.linspace(0, 2 * np.pi, 6, endpoint=False)]
    verts = ring + [(1.0, 0.0, 0.0), (2.5, 0.0, 0.0), (2.5, 1.0, 0.0), (1.0, 1.0, 0.0)]
    faces = [np.array([[0, 1, 2, 3, 4, 5]]), np.array([[6, 7, 8, 9]])]
    for mirror in (1.0, -1.0):
        order = list(range(6)) + [6, 7, 8, 9]
        uvs = np.array([(0.3 * (np.cos(a) * verts[i][0] + np.sin(a) * verts[i][1]),
                         mirror * 0.3 * (-np.sin(a) * verts[i][0] + np.cos(a) * verts[i][1])) for i in order],
                       np.float32)
        obj = kit.mesh_object("ngon", verts, faces, kit.diffuse("ngon"), uvs=uvs)
        refused = False
        try:
            obj.data.calc_tangents(uvmap="UVMap")
        except RuntimeError:
            refused = True
        g, _ = exported(obj)
        got = g.tangents.reshape(-1, 4)
        err = float(np.abs(got[:, :3] - [np.cos(a), np.sin(a), 0.0]).max())
        check(refused and err < 1e-5 and (got[:, 3] == mirror).all(),
              f"n-gon (calc_tangents refuses it: {refused}), V {'mirrored' if mirror < 0 else 'kept'}: tangents "
              f"the rotated x axis (largest difference {err:.1e}), signs {mirror:+.0f}")
        bpy.data.objects.remove(obj)


def test_normal_map_node_becomes_the_spec():
    from render_toyrt import materials

    kit.clear_scene()
    image = kit.bump_normal_image("bumps")
    mat = kit.principled("bumpy", (0.5, 0.5, 0.5))
    node = kit.normal_map(mat, image, strength=0.7, uv_map="Second")
    converted = materials.material_spec(mat)
    bent = converted.spec.normal_map
    check(bent is not None and bent.space == "TANGENT" and abs(bent.strength - 0.7) < 1e-6
          and bent.uv_map == "Second" and bent.texture.name == image.name_full and not bent.texture.srgb
          and converted.normal_image == image and not converted.notes,
          f"Principled Normal <- Normal Map <- Image Texture: {bent}, notes {converted.notes}")
    mode = "tangent" if bpy.app.version >= (4, 0, 0) else "blend"
    check(bent.strength_mode == mode, f"strength rule of Blender {bpy.app.version_string}: {bent.strength_mode}")
    args = converted.spec.arguments(1, -1, 5)
    check(args["normal_map"] == 5 and args["normal_space"] == "TANGENT", f"sent with the texture id: {args}")
    if hasattr(node, "convention"):
        node.convention = "DIRECTX"
        spec = materials.material_spec(mat).spec.normal_map
        check(spec.convention == "DIRECTX", f"convention DirectX: {spec}")
    else:
        check(bent.convention == "OPENGL", f"no convention property on {bpy.app.version_string}: OpenGL")
    diffuse = kit.diffuse("plain")
    kit.normal_map(diffuse, image, space="OBJECT")
    spec = materials.material_spec(diffuse).spec.normal_map
    check(spec is not None and spec.space == "OBJECT", f"Diffuse BSDF, object space: {spec}")


def test_bump_node_becomes_the_spec():
    from render_toyrt import materials
    from render_toyrt.material_normal import tangent_uv_map

    kit.clear_scene()
    heights = kit.height_image("heights", size=16)
    mat = kit.principled("bumped", (0.5, 0.5, 0.5))
    node = kit.bump(mat, heights, strength=0.5, distance=0.2, invert=True)
    c = materials.material_spec(mat)
    b = c.spec.normal_map
    check(b is not None and b.space == "BUMP" and abs(b.strength - 0.5) < 1e-6 and abs(b.distance + 0.2) < 1e-6
          and b.channel == "gray" and b.texture.name == heights.name_full and c.normal_image == heights,
          f"Principled Normal <- Bump (inverted) <- Image Texture Color: {b}")
    args = c.spec.arguments(-1, -1, 7)
    check(args.get("bump_map") == 7 and "normal_map" not in args and args["bump_distance"] == b.distance,
          f"sent as a bump map: {args}")
    check(tangent_uv_map(mat) is None, "a bump needs no tangents")
    # Before 4.4 (no Filter Width) Cycles differences the height over the ray's footprint: the
    # core is asked to as well, and nothing is noted; 4.4+ takes the slope at the point, the default.
    old = bpy.app.version < (4, 4, 0)
    check(b.footprint == ("pixel" if old else "point") and args.get("bump_footprint") == ("pixel" if old else None),
          f"bump_footprint sent only before 4.4: {args}")
    check(not any("Bump" in n for n in c.notes), f"nothing noted: {c.notes}")
    tex = next(n for n in mat.node_tree.nodes if n.type == "TEX_IMAGE")
    mat.node_tree.links.new(tex.outputs["Alpha"], node.inputs["Height"])
    check(materials.material_spec(mat).spec.normal_map.channel == "alpha", "the height from the Alpha output")


def test_bad_input_keeps_the_surface_normal_with_a_note_and_renders():
    from render_toyrt import materials

    scene = kit.clear_scene()
    kit.standard_view(scene)
    kit.toyrt(scene, seed=0, samples=4)
    image = kit.bump_normal_image("bumps")
    no_image = kit.diffuse("no_image")
    kit.normal_map(no_image, image)
    next(n for n in no_image.node_tree.nodes if n.type == "TEX_IMAGE").image = None
    c = materials.material_spec(no_image)
    check(c.spec.normal_map is None and any("Normal Map without an image" in n for n in c.notes),
          f"no image: the surface normal, noted: {c.notes}")
    bump = kit.diffuse("bump")
    nodes, links = bump.node_tree.nodes, bump.node_tree.links
    links.new(nodes.new("ShaderNodeBump").outputs["Normal"], nodes["Diffuse BSDF"].inputs["Normal"])
    c = materials.material_spec(bump)
    check(c.spec.normal_map is None and any("Bump height from a constant" in n for n in c.notes),
          f"a Bump node without a height: noted {c.notes}")

    kit.plane("floor", 4.0, kit.diffuse("floor"))
    named = kit.diffuse("named_uv")
    kit.normal_map(named, image, uv_map="NoSuchMap")
    kit.plane("tile", 1.5, named, location=(0, 0, 0.2))
    good = kit.principled("good", (0.6, 0.4, 0.2))
    kit.normal_map(good, image)
    kit.uv_sphere("ball", 0.5, (1.2, 0, 0.5), good)   # no UV map at all
    kit.plane("bumped", 1.0, good, location=(-1.2, 0, 0.3))
    kit.sun_light("sun", 3.0, (0.2, 0.1, -1.0))
    kit.camera((0, -3, 3), (0, 0, 0))
    kit.output(scene, 32, 24)
    kit.float_exr(scene)
    path = os.path.join(TMP, "bad_normal.exr")
    result, log = render_still(path)
    px = kit.read_image(path)
    notes = [line for line in log.splitlines() if "TOYRT note" in line]
    check(result == {"FINISHED"} and np.isfinite(px).all() and px[..., :3].max() > 0.0,
          f"F12 renders, finite ({result!r:.80})")
    check(any("NoSuchMap" in n for n in notes) and any("'ball'" in n and "UV map" in n for n in notes),
          f"a missing UV map is noted per object: {notes}")


def test_a_normal_map_added_between_renders_is_seen_by_the_next():
    # F12 keeps its scene between renders and reuses a mesh whose fingerprint did not change: the
    # tangents a new Normal Map needs are part of that fingerprint.
    scene = kit.clear_scene()
    kit.standard_view(scene)
    kit.toyrt(scene, seed=0, samples=2)
    mat = kit.diffuse("later", (0.7, 0.7, 0.7))
    kit.plane("floor", 4.0, mat)
    kit.sun_light("sun", 3.0, (-0.8, 0.3, -0.6))
    kit.camera((0, -3, 3), (0, 0, 0))
    kit.output(scene, 32, 24)
    kit.float_exr(scene)
    images = []
    for i in range(2):
        if i == 1:
            kit.normal_map(mat, kit.bump_normal_image("late_bumps", slope=0.8))
        path = os.path.join(TMP, f"later{i}.exr")
        result, _ = render_still(path)
        images.append(kit.read_image(path)[..., :3])
    flat, bumpy = images
    changed = float(np.abs(bumpy - flat).mean() / max(flat.mean(), 1e-6))
    check(changed > 0.05, f"the second F12 shows the normal map added after the first (mean change {changed:.1%})")


run_script([test_tangents_equal_calc_tangents_on_a_quad_mesh, test_tangents_of_a_mesh_with_an_ngon_are_the_closed_form,
            test_normal_map_node_becomes_the_spec, test_bump_node_becomes_the_spec,
            test_bad_input_keeps_the_surface_normal_with_a_note_and_renders,
            test_a_normal_map_added_between_renders_is_seen_by_the_next],
           "normal_map", TMP)
