# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_passes.py
# Render passes as a compositor or a farm meets them: turned on with the View Layer's own switches,
# rendered with F12 into a multilayer OpenEXR, read back (Debian's python3-openimageio) and checked
# per pass against closed forms (depth and normal of planes at known places, albedo = the material
# colour, the pass indices, Cycles' mist ramp, the emitted radiance) and against Cycles' own passes
# of the same scene (same names and channels; equal values on hit pixels away from edges). A pass
# TOYRT cannot produce is there, black, with one note.
import math
import os
import sys
import tempfile

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, render_multilayer, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-passes-")
W, H = 64, 48
TILT = math.radians(30.0)
COLOURS = {"floor": (0.8, 0.2, 0.1), "box": (0.1, 0.6, 0.3), "ramp": (0.3, 0.3, 0.9)}
SWITCHES = ("use_pass_z", "use_pass_normal", "use_pass_diffuse_color", "use_pass_object_index",
            "use_pass_material_index", "use_pass_mist", "use_pass_position", "use_pass_emit",
            "use_pass_ambient_occlusion")
NEW = bpy.app.version >= (5, 0, 0)
NAMES = dict(depth="Depth", mist="Mist", position="Position", normal="Normal",
             diffuse="Diffuse Color" if NEW else "DiffCol", emit="Emission" if NEW else "Emit",
             object="Object Index" if NEW else "IndexOB", material="Material Index" if NEW else "IndexMA",
             ao="Ambient Occlusion" if NEW else "AO", glossy="Glossy Color" if NEW else "GlossCol",
             env="Environment" if NEW else "Env")


def build_scene():
    """From a perspective camera 5 m above the origin looking down (3.6 x 2.7 m at z = 0): a 3 m
    floor at z = 0 (the world beside it), a 1 m box on it under the camera (only its top face,
    z = 1, in view), a ramp tilted 30 degrees about X, an emitting square; each object and
    material with its own pass index; linear mist from 1 m over 10 m."""
    s = kit.clear_scene()
    mats = {name: kit.diffuse(name, c) for name, c in COLOURS.items()}
    glow = kit.emission("glow", (1.0, 0.5, 0.25), strength=2.0)
    objects = [kit.plane("floor", 3.0, mats["floor"]), kit.box("box", 1.0, (0.0, 0.0, 0.5), mats["box"]),
               kit.plane("ramp", 1.4, mats["ramp"], location=(-1.0, 0.3, 0.4)),
               kit.plane("glow", 0.6, glow, location=(0.6, -0.8, 0.01))]
    objects[2].rotation_euler = (TILT, 0.0, 0.0)
    for k, obj in enumerate(objects):
        obj.pass_index = 2 + k
    for k, mat in enumerate([*mats.values(), glow]):
        mat.pass_index = 10 + 3 * k
    kit.point_light("lamp", (0.0, 0.0, 4.0), 500.0)
    kit.camera((0.0, 0.0, 5.0))
    world = kit.world((0.0, 0.0, 0.0))
    world.mist_settings.start, world.mist_settings.depth, world.mist_settings.falloff = 1.0, 10.0, "LINEAR"
    kit.output(s, W, H)
    layer = bpy.context.view_layer
    for prop in SWITCHES:
        setattr(layer, prop, True)
    return s


def read_layers(path):
    """{view layer: {pass name: (h, w, channels) float32, rows from the top}} of a multilayer EXR,
    each pass's channels in their registered order. Blender 3.4 writes one part holding every
    channel, 5.x a part per pass (OpenImageIO's subimages): both are read."""
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise RuntimeError(f"cannot open {path}: {oiio.geterror()}")
    grouped = {}
    try:
        part = 0
        while inp.seek_subimage(part, 0):
            names = list(inp.spec().channelnames)
            pixels = inp.read_image(format="float")
            for k, full in enumerate(names):
                layer_pass, _, chan = full.rpartition(".")
                layer, _, name = layer_pass.partition(".")
                grouped.setdefault(layer, {}).setdefault(name, []).append((chan, pixels[:, :, k]))
            part += 1
    finally:
        inp.close()
    order = "RGBAXYZWUV"  # Blender's channel ids: put each pass back in its registered order
    return {layer: {name: np.stack([px for _, px in sorted(ch, key=lambda c: order.index(c[0][0].upper()))], -1)
                    for name, ch in passes.items()} for layer, passes in grouped.items()}


def render(engine, samples=16, tag=""):
    path = os.path.join(TMP, f"{engine.lower()}{tag}.exr")
    result, printed = render_multilayer(engine, samples, path)
    return (read_layers(path).get("ViewLayer", {}) if os.path.exists(path) else {}), result, printed


def interior(index):
    """Pixels whose 3 x 3 neighbourhood shows one object: away from every edge."""
    i = index[..., 0]
    same = np.ones_like(i, bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            same &= np.roll(np.roll(i, dy, 0), dx, 1) == i
    same[[0, -1], :] = same[:, [0, -1]] = False
    return same


STATE = {}


def passes_are_switched_where_blender_users_look():
    check(hasattr(bpy.types, "VIEWLAYER_PT_toyrt_passes"), "a Passes panel in the View Layer tab")
    mist = getattr(bpy.types, "EEVEE_WORLD_PT_mist", None)
    check(mist is not None and "TOYRT" in mist.COMPAT_ENGINES, "Blender's Mist panel (World tab) opened to TOYRT")


def toyrt_passes_against_closed_forms():
    build_scene()
    p, result, printed = render("TOYRT")
    STATE["toyrt"] = p
    check(result == {"FINISHED"}, f"F12 with passes on finishes ({result})")
    want = [NAMES[k] for k in ("depth", "mist", "position", "normal", "object", "material", "diffuse", "emit", "ao")]
    check(all(n in p for n in want), f"the EXR holds {want} (it has {sorted(p)})")
    if not all(n in p for n in want):
        return
    check(all(p[NAMES[k]].shape[2] == c for k, c in (("depth", 1), ("normal", 3), ("diffuse", 3), ("object", 1))),
          "channels as Cycles lays them out: Depth Z, Normal XYZ, Diffuse Color RGB, Object Index X")
    obj, mat = p[NAMES["object"]][..., 0], p[NAMES["material"]][..., 0]
    depth, pos = p[NAMES["depth"]][..., 0], p[NAMES["position"]]
    inner = interior(p[NAMES["object"]])
    masks = {name: inner & (obj == 2 + k) & (depth < 1e9) for k, name in enumerate(("floor", "box", "ramp", "glow"))}
    check(all(m.sum() > 20 for m in masks.values()), "each object covers interior pixels "
          + str({k: int(m.sum()) for k, m in masks.items()}))
    check(set(np.unique(obj)) == {0.0, 2.0, 3.0, 4.0, 5.0},
          f"Object Index holds the objects' pass_index, 0 on the world ({np.unique(obj)})")
    expect_mat = {"floor": 10, "box": 13, "ramp": 16, "glow": 19}
    check(all(np.all(mat[masks[k]] == v) for k, v in expect_mat.items()), "Material Index = each material's pass_index")
    check(np.allclose(depth[masks["floor"]], 5.0, atol=1e-4) and np.allclose(depth[masks["box"]], 4.0, atol=1e-4),
          "Depth is planar camera z: 5 on the floor, 4 on the box top, at every pixel")
    hit = inner & (obj > 0)
    check(np.allclose(depth[hit], 5.0 - pos[..., 2][hit], atol=1e-4), "Depth = 5 - z of the Position pass")
    n = p[NAMES["normal"]]
    ramp_n = (0.0, -math.sin(TILT), math.cos(TILT))
    check(np.allclose(n[masks["floor"] | masks["box"]], (0, 0, 1), atol=1e-5)
          and np.allclose(n[masks["ramp"]], ramp_n, atol=1e-4), "Normal: +Z on the floor and box top, the ramp's tilt")
    dc = p[NAMES["diffuse"]]
    check(all(np.allclose(dc[masks[k]], COLOURS[k], atol=1e-5) for k in COLOURS) and np.all(dc[masks["glow"]] == 0),
          "Diffuse Color = each Diffuse BSDF's colour (0 on the emitter)")
    check(np.allclose(p[NAMES["emit"]][masks["glow"]], (2.0, 1.0, 0.5), atol=1e-5)
          and np.all(p[NAMES["emit"]][masks["floor"]] == 0), "Emission = colour x strength of the emitter, 0 elsewhere")
    dist = np.linalg.norm(pos - (0.0, 0.0, 5.0), axis=-1)
    mist = p[NAMES["mist"]][..., 0]
    err = np.abs(mist - np.clip((dist - 1.0) / 10.0, 0, 1))[hit]
    # Mist is averaged over the pixel, Position is its first sample: apart by up to a pixel (5 cm) / depth.
    check(err.max() < 5e-3, f"Mist = (distance - start) / depth, linear (max error {err.max():.1e})")
    check(np.all(p[NAMES["ao"]] == 0.0), "Ambient Occlusion (not produced) is black")
    notes = [ln for ln in printed.splitlines() if "passes left black" in ln]
    check(len(notes) == 1 and notes[0].startswith("TOYRT note:") and NAMES["ao"] in notes[0]
          and not any(w in notes[0].lower() for w in ("warning", "error", "exception")),
          f"one farm-safe note names the black pass ({notes})")


def toyrt_passes_equal_cycles():
    t = STATE.get("toyrt")
    if not t:
        check(False, "no TOYRT passes to compare")
        return
    c, result, _ = render("CYCLES")
    check(result == {"FINISHED"}, "Cycles renders the same scene")
    check(set(t) == set(c), f"the same pass names as Cycles ({sorted(set(t) ^ set(c)) or 'all equal'})")
    check(all(t[k].shape == c[k].shape for k in set(t) & set(c)), "the same channels per pass as Cycles")
    same_obj = t[NAMES["object"]][..., 0] == c[NAMES["object"]][..., 0]
    inner = interior(t[NAMES["object"]]) & interior(c[NAMES["object"]])
    check(np.all(same_obj[inner]), f"Object Index equals Cycles' on {inner.sum()} interior pixels")
    check(np.array_equal(t[NAMES["material"]][inner], c[NAMES["material"]][inner]), "Material Index equals Cycles'")
    # Depth and Position come from each renderer's own first sample: equal on the faces facing the
    # camera, within what a sub-pixel shift moves them on the ramp (its slope times a pixel, 5 cm).
    flat = inner & (t[NAMES["object"]][..., 0] != 4)
    for key, mask, tol in (("depth", flat, 1e-4), ("depth", inner, 0.05), ("position", inner, 0.05),
                           ("normal", inner, 1e-4), ("diffuse", inner, 1e-5), ("emit", inner, 1e-5),
                           ("mist", inner, 1e-3)):
        d = np.abs(t[NAMES[key]] - c[NAMES[key]])[mask]
        where = "facing pixels" if mask is flat else "interior pixels"
        check(d.max() < tol, f"{NAMES[key]} equals Cycles' on {where} (max diff {d.max():.1e} < {tol})")
    miss = inner & (c[NAMES["object"]][..., 0] == 0) & (t[NAMES["object"]][..., 0] == 0)
    check(miss.sum() > 20 and np.all(t[NAMES["depth"]][miss] == 1e10) and np.all(c[NAMES["depth"]][miss] == 1e10)
          and np.all(t[NAMES["mist"]][miss] == 1.0) and np.all(c[NAMES["mist"]][miss] == 1.0),
          f"where nothing is hit ({miss.sum()} pixels) Depth is 1e10 and Mist 1, as Cycles'")


GLOSSY_SCENE = {  # name: (material maker, location); pass index = 1 + its place here
    "glossy": (lambda: kit.glossy("glossy", (0.9, 0.6, 0.3), 0.3), (-1.2, 0.55)),
    "metal": (lambda: kit.metal("metal", (0.95, 0.64, 0.54), 0.2), (-0.3, 0.55)),
    "dielectric": (lambda: kit.principled_dielectric("dielectric", (0.5, 0.5, 0.5), 0.4), (0.6, 0.55)),
    "matte": (lambda: kit.diffuse("matte", (0.5, 0.5, 0.5)), (-1.2, -0.4)),
    # Multiscatter GGX: 4.0+'s energy compensation, whose share Cycles keeps in the weight.
    "glossy_multiscatter": (lambda: kit.glossy("glossy_multiscatter", (0.9, 0.6, 0.3), 0.5, "MULTI_GGX"),
                            (-0.3, -0.4)),
    # Glass: its reflection (3.x a closure of weight F, 4.0+ the glass closure's reflection).
    "glass": (lambda: kit.glass("glass", 1.5), (1.4, 0.55)),
    "rough_glass": (lambda: rough_glass("rough_glass", 0.3), (1.4, -0.4)),
    # The Principled BSDF's glass (Transmission 1): its reflection's albedo (4.0+) or weight (3.x).
    "principled_glass": (lambda: principled_glass("principled_glass", 0.3), (-1.2, -1.25)),
}
if bpy.app.version >= (4, 0, 0):  # Coat: 4.0+'s Principled only
    GLOSSY_SCENE["coat"] = (lambda: coated("coat"), (-0.3, -1.25))


def principled_glass(name, roughness):
    mat = kit.principled_dielectric(name, (1.0, 1.0, 1.0), roughness, distribution="GGX")
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Transmission Weight" if "Transmission Weight" in bsdf.inputs else "Transmission"].default_value = 1.0
    return mat


def coated(name):
    mat = kit.principled_dielectric(name, (0.8, 0.1, 0.1), 0.5)
    mat.node_tree.nodes["Principled BSDF"].inputs["Coat Weight"].default_value = 1.0
    return mat


def rough_glass(name, roughness):
    mat = kit.glass(name, 1.5)
    bsdf = next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfGlass")
    bsdf.distribution = "GGX"
    bsdf.inputs["Roughness"].default_value = roughness
    return mat


SKY = (0.2, 0.3, 0.4)


def glossy_color_environment_and_lamps_equal_cycles():
    """Glossy Color, Environment and Emission on a scene of a Glossy BSDF (GGX and Multiscatter
    GGX), a Principled metal, a Principled dielectric, a Diffuse BSDF and sharp and rough Glass
    BSDFs beside a constant world
    and an area lamp facing the camera, against closed forms (the Glossy BSDF's colour, 0 on the
    diffuse, the world's colour where nothing is hit, Combined = Environment there) and against
    Cycles' passes."""
    s = kit.clear_scene()
    for k, (name, (make, (x, y))) in enumerate(GLOSSY_SCENE.items()):
        kit.plane(name, 0.8, make(), location=(x, y, 0.0)).pass_index = 1 + k
    kit.area_light("lamp", (0.6, -0.45, 0.5), 30.0, 0.5, rotation=(math.pi, 0.0, 0.0), visible_camera=True)
    kit.camera((0.0, 0.0, 6.0))
    kit.world(SKY)
    kit.output(s, W, H)
    layer = bpy.context.view_layer
    for prop in ("use_pass_glossy_color", "use_pass_environment", "use_pass_emit", "use_pass_object_index"):
        setattr(layer, prop, True)
    t, result, printed = render("TOYRT", 16, "_glossy")
    c, c_result, _ = render("CYCLES", 16, "_glossy")
    names = [NAMES[k] for k in ("glossy", "env", "emit", "object")]
    check(result == c_result == {"FINISHED"} and all(n in t and n in c for n in names),
          f"both render {names} (TOYRT {sorted(t)}, Cycles {sorted(c)})")
    if not all(n in t and n in c for n in names):
        return
    noted = [ln for ln in printed.splitlines() if "passes left black" in ln]
    check(not any(NAMES[k] in ln for ln in noted for k in ("glossy", "env")),
          f"Glossy Color and Environment are not noted as black ({noted})")
    obj = t[NAMES["object"]][..., 0]
    inner = interior(t[NAMES["object"]]) & interior(c[NAMES["object"]])
    gt, gc = t[NAMES["glossy"]], c[NAMES["glossy"]]
    for k, name in enumerate(GLOSSY_SCENE):
        mask = inner & (obj == 1 + k)
        d = np.abs(gt - gc)[mask]
        print(f"  {NAMES['glossy']} on {name} ({mask.sum()} px): TOYRT mean {gt[mask].mean(0).round(4)}, "
              f"Cycles {gc[mask].mean(0).round(4)}, max diff {d.max():.1e}", flush=True)
        check(mask.sum() > 20 and d.max() < 5e-4,
              f"{NAMES['glossy']} equals Cycles' on the {name} (max diff {d.max():.1e})")
    check(np.allclose(gt[inner & (obj == 1)], (0.9, 0.6, 0.3), atol=1e-6),
          "the Glossy BSDF's Glossy Color is its colour")
    check(np.all(gt[inner & (obj == 4)] == 0), "the Diffuse BSDF has no Glossy Color")
    et, ec = t[NAMES["env"]], c[NAMES["env"]]
    emt, emc = t[NAMES["emit"]], c[NAMES["emit"]]
    lamp = interior((emc[..., :1] > 0).astype(np.float32)) & (emc[..., 0] > 0) & (obj == 0)
    sky = inner & (obj == 0) & (c[NAMES["object"]][..., 0] == 0) & ~lamp & (emt[..., 0] == 0)
    check(sky.sum() > 20 and np.allclose(et[sky], SKY, atol=1e-6) and np.allclose(ec[sky], SKY, atol=1e-6),
          f"Environment is the world's colour where nothing is hit ({sky.sum()} px), in both")
    check(np.allclose(t["Combined"][..., :3][sky], et[sky], atol=1e-6), "and Combined equals it there")
    check(np.all(et[inner & (obj > 0)] == 0), "Environment is 0 on surfaces")
    d = np.abs(emt - emc)[lamp] / np.maximum(emc[lamp], 1e-6)
    print(f"  {NAMES['emit']} on the lamp ({lamp.sum()} px): TOYRT {emt[lamp].mean(0).round(3)}, "
          f"Cycles {emc[lamp].mean(0).round(3)}", flush=True)
    check(lamp.sum() > 4 and d.max() < 1e-3, f"{NAMES['emit']} of the lamp seen directly equals Cycles' "
          f"(max relative diff {d.max():.1e})")


def each_view_layer_gets_its_own_passes():
    """A second view layer with Depth only: Blender renders the layers in turn, and each one's
    Combined and passes must land in its own layer of the result, not on the first."""
    build_scene()
    second = bpy.context.scene.view_layers.new("Second")
    second.use_pass_z = True
    try:
        render("TOYRT")
        layers = read_layers(os.path.join(TMP, "toyrt.exr"))
    finally:
        bpy.context.scene.view_layers.remove(second)
    first, other = layers.get("ViewLayer", {}), layers.get("Second", {})
    check(sorted(other) == ["Combined", "Depth"], f"the second layer has its own passes ({sorted(other)})")
    check("Combined" in other and np.array_equal(other["Combined"], first.get("Combined")),
          "its Combined is the same scene's image, not black")
    check("Depth" in other and np.array_equal(other["Depth"], first.get("Depth")), "its Depth equals the first's")


def denoising_lowers_the_error_or_says_why_not():
    """4 samples of a scene lit by a grey world (noisy: one cosine ray per sample) against 1,024.
    The emitter is hidden: its edges are aliasing against a bright radiance, which OIDN keeps."""
    build_scene()
    kit.world((0.6, 0.6, 0.6))
    bpy.data.objects["glow"].hide_render = True
    scene = bpy.context.scene
    reference = render("TOYRT", 1024, "_ref")[0]["Combined"][..., :3]
    plain = render("TOYRT", 4, "_noisy")[0]["Combined"]
    scene.toyrt.use_denoising = True
    try:
        p, result, printed = render("TOYRT", 4, "_denoised")
    finally:
        scene.toyrt.use_denoising = False
    check(result == {"FINISHED"} and "Combined" in p, f"a render with Denoise on finishes ({result})")
    check("Noisy Image" in p and np.array_equal(p["Noisy Image"], plain),
          "the Noisy Image pass (Cycles' name) is the render before denoising, bit for bit")
    try:
        import pyoidn  # noqa: F401
    except ImportError:
        notes = [ln for ln in printed.splitlines() if "denoising skipped" in ln]
        check(len(notes) == 1 and notes[0].startswith("TOYRT note:")
              and not any(w in notes[0].lower() for w in ("warning", "error", "exception")),
              f"without pyoidn: one farm-safe note says denoising was skipped ({notes})")
        check(np.array_equal(p["Combined"], plain), "without pyoidn: Combined is the plain render")
        return
    inner = interior(p[NAMES["object"]])[..., None]

    def rmse(img, mask=True):
        return float(np.sqrt(np.mean(((img[..., :3] - reference) ** 2)[np.broadcast_to(mask, reference.shape)])))

    noisy, denoised = rmse(plain), rmse(p["Combined"])
    noisy_in, denoised_in = rmse(plain, inner), rmse(p["Combined"], inner)
    print(f"  RMSE against 1,024 samples: 4 samples {noisy:.4f}, denoised {denoised:.4f}; away from edges "
          f"{noisy_in:.4f} -> {denoised_in:.4f}", flush=True)
    # The noise of the lighting is what OIDN removes; the edges' aliasing it mostly keeps.
    check(denoised_in < 0.6 * noisy_in,
          f"OIDN lowers the error away from edges to < 60 % ({noisy_in:.4f} -> {denoised_in:.4f})")
    check(denoised < 0.8 * noisy, f"and lowers it over the whole image ({noisy:.4f} -> {denoised:.4f})")
    check(not any("denoising skipped" in ln for ln in printed.splitlines()), "no note when the denoiser runs")


def denoising_data_passes_hold_what_the_denoiser_reads():
    """view_layer.toyrt.denoising_store_passes (Cycles' view_layer.cycles.denoising_store_passes)
    adds Cycles' Denoising Data passes under its names on the running Blender: the albedo is the
    Diffuse Color clipped to [0, 1], the normal the Normal pass, the depth the Depth pass; what
    TOYRT does not produce (5.1+: specular albedo, roughness) is black with the one note."""
    build_scene()
    layer = bpy.context.view_layer
    layer.toyrt.denoising_store_passes = True
    try:
        p, result, printed = render("TOYRT", 4, "_denoising_data")
    finally:
        layer.toyrt.denoising_store_passes = False
    new_list = bpy.app.version >= (5, 1, 0)
    expected = (["Denoising Albedo", "Denoising Specular Albedo", "Denoising Normal", "Denoising Roughness",
                 "Denoising Depth"] if new_list else ["Denoising Normal", "Denoising Albedo", "Denoising Depth"])
    check(result == {"FINISHED"} and all(n in p for n in expected),
          f"Cycles' Denoising Data passes are written ({sorted(n for n in p if n.startswith('Denoising'))})")
    check(np.array_equal(p["Denoising Normal"], p["Normal"]), "Denoising Normal is the Normal pass")
    check(np.array_equal(p["Denoising Depth"][..., 0], p["Depth"][..., 0]), "Denoising Depth is the Depth pass")
    check(np.array_equal(p["Denoising Albedo"], np.clip(p[NAMES["diffuse"]], 0.0, 1.0)),
          "Denoising Albedo is the Diffuse Color within [0, 1]")
    # The floor's albedo is its colour where it is seen (its pass index is 2).
    floor = interior(p[NAMES["object"]]) & (p[NAMES["object"]][..., 0] == 2)
    check(np.allclose(p["Denoising Albedo"][floor], COLOURS["floor"], atol=1e-6),
          "the floor's albedo is its material colour")
    if new_list:
        black = [n for n in ("Denoising Specular Albedo", "Denoising Roughness") if np.any(p[n])]
        check(not black, f"the passes TOYRT does not produce are black ({black})")
        check("Denoising Roughness" in printed, "and named in the note")


run_script([passes_are_switched_where_blender_users_look, toyrt_passes_against_closed_forms,
            toyrt_passes_equal_cycles, glossy_color_environment_and_lamps_equal_cycles,
            each_view_layer_gets_its_own_passes,
            denoising_lowers_the_error_or_says_why_not, denoising_data_passes_hold_what_the_denoiser_reads],
           "passes", TMP)
