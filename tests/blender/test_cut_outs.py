# Alpha cut-outs as the add-on converts them (addon/render_toyrt/material_alpha.py): Principled
# Alpha, a Transparent BSDF alone, a Mix Shader with a Transparent BSDF in either input, factors
# constant or from an Image Texture's Alpha or Color output; bad input (Alpha outside [0, 1],
# NaN) clamped or made opaque with a note, and a render of it through F12 finite. Cycles parity of
# the rendered result is tests/blender/test_cycles_parity.py's cut_out scene.
#     blender -b --python-exit-code 1 --python tests/blender/test_cut_outs.py
import os
import sys
import tempfile

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-test-cut-outs-")


def mask():
    rgba = np.ones((2, 2, 4), np.float32)
    rgba[0, 0, 3] = 0.0
    return kit.image("mask", rgba, alpha=True)


def test_the_three_shapes_become_opacity_and_a_transparent_colour():
    from render_toyrt import materials

    image = mask()
    leaf = materials.material_spec(kit.cut_out("leaf", (0.2, 0.6, 0.1), image)).spec
    check(leaf.kind == "diffuse" and leaf.opacity_texture is not None and leaf.opacity_texture.alpha
          and leaf.opacity_channel == "alpha" and not leaf.opacity_invert and leaf.transparent_color == (1, 1, 1),
          f"Mix(Fac = image Alpha, Transparent, Diffuse): the diffuse cut out by the alpha: {leaf}")
    args = leaf.arguments(3, 7)
    check(args["opacity_texture"] == 7 and args["texture"] == 3 and args["opacity_channel"] == "alpha",
          f"the core gets the opacity texture's id: {args}")
    p = materials.material_spec(kit.cut_out("p_leaf", (0.7, 0.3, 0.1), image, "principled")).spec
    check(p.kind == "principled" and p.opacity_texture is not None and p.opacity_channel == "alpha",
          f"Principled Alpha from the image: {p}")

    mat, mix = kit.surface("swapped", "ShaderNodeMixShader")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    transparent = nodes.new("ShaderNodeBsdfTransparent")
    transparent.inputs["Color"].default_value = (1.0, 0.5, 0.25, 1.0)
    links.new(diffuse.outputs[0], mix.inputs[1])
    links.new(transparent.outputs[0], mix.inputs[2])
    mix.inputs[0].default_value = 0.3
    s = materials.material_spec(mat).spec
    check(s.kind == "diffuse" and abs(s.opacity - 0.7) < 1e-6 and s.opacity_texture is None
          and s.transparent_color == (1.0, 0.5, 0.25), f"Transparent in the second input, Fac 0.3: opacity 0.7: {s}")
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = image
    links.new(tex.outputs["Color"], mix.inputs[0])
    s = materials.material_spec(mat).spec
    check(s.opacity_channel == "gray" and s.opacity_invert, f"Fac from the image's Color, second input: {s}")

    alone, node = kit.surface("glass_pane", "ShaderNodeBsdfTransparent")
    node.inputs["Color"].default_value = (0.9, 0.8, 0.7, 1.0)
    a = materials.material_spec(alone).spec
    check(a.opacity == 0.0 and abs(a.transparent_color[2] - 0.7) < 1e-6, f"a Transparent BSDF alone: {a}")
    plain = materials.material_spec(kit.principled("opaque", (0.5, 0.5, 0.5))).spec
    check(not plain.transparent and "opacity" not in plain.arguments(), f"Alpha 1: no cut-out sent: {plain}")


def test_alpha_out_of_range_is_clamped_and_nan_is_opaque_and_renders():
    from render_toyrt import materials

    scene = kit.clear_scene()
    kit.standard_view(scene)
    kit.toyrt(scene, seed=0, samples=4)
    results = []
    for name, alpha in (("over", 1.7), ("under", -0.5), ("nan", float("nan"))):
        mat = kit.principled(name, (0.5, 0.5, 0.5))
        mat.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = alpha
        results.append(materials.material_spec(mat))
    over, under, nan = results
    check(not over.spec.transparent, f"Alpha 1.7: opaque (Alpha 1 and above adds nothing): {over}")
    check(under.spec.opacity == 0.0 and any("clamped" in n for n in under.notes), f"Alpha -0.5: 0, noted: {under}")
    check(nan.spec.opacity == 1.0 and any("NaN" in n for n in nan.notes), f"Alpha NaN: opaque, noted: {nan}")

    kit.plane("floor", 4.0, kit.diffuse("floor_grey"))
    mat = kit.principled("nan_leaf", (0.5, 0.5, 0.5))
    mat.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = float("nan")
    kit.plane("leaf", 1.0, mat, location=(0, 0, 0.5))
    kit.plane("hole", 1.0, kit.principled("hole", (0.5, 0.5, 0.5)), location=(0.8, 0, 0.6))
    bpy.data.materials["hole"].node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = -3.0
    missing = kit.cut_out("no_mask", (0.2, 0.6, 0.1), mask())
    next(n for n in missing.node_tree.nodes if n.type == "TEX_IMAGE").image = None
    converted = materials.material_spec(missing)
    check(converted.spec.opacity_texture is not None and converted.spec.opacity_texture.placeholder
          and any("without an image" in n for n in converted.notes),
          f"a cut-out whose Image Texture has no image: the placeholder (opaque), noted: {converted.notes}")
    kit.plane("no_mask", 1.0, missing, location=(-0.8, 0, 0.6))
    kit.sun_light("sun", 3.0, (0.2, 0.1, -1.0))
    kit.camera((0, -3, 3), (0, 0, 0))
    kit.output(scene, 32, 24)
    kit.float_exr(scene)
    path = os.path.join(TMP, "bad_alpha.exr")
    result, log = render_still(path)
    px = kit.read_image(path)
    check(result == {"FINISHED"} and np.isfinite(px).all() and px[..., :3].max() > 0.0,
          f"NaN and negative Alpha and a missing mask render, finite ({result!r:.80})")


run_script([test_the_three_shapes_become_opacity_and_a_transparent_colour,
            test_alpha_out_of_range_is_clamped_and_nan_is_opaque_and_renders], "cut_outs", TMP)
