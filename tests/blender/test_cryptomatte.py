# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_cryptomatte.py
# Cryptomatte as a compositor meets it: turned on with the View Layer's own switches, rendered with
# F12 into a multilayer OpenEXR, read back (Debian's python3-openimageio) with its metadata, and
# checked against Cycles' render of the same scene (pass names and channels, rank-0 ids per pixel,
# the manifests) and against known answers (coverage sums to 1 where the pixel lies wholly on the
# floor, 0 where it sees only the world; ranks sorted); Blender's largest depth, names in any
# Unicode, and the time and memory of a 10,000-object scene's manifest.
import json
import os
import struct
import sys
import tempfile
import time
import tracemalloc

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from cycles_like_toyrt import configure_cycles  # noqa: E402
from harness import check, render_multilayer, render_still, run_script  # noqa: E402

TMP = tempfile.mkdtemp(prefix="toyrt-crypto-")
W, H = 96, 72
KINDS = ("Object", "Material", "Asset")
FLOOR = 1.5  # the floor's half size, metres
VIEW = 5.0 * 36.0 / 50.0  # the 50 mm lens's field at the floor, 5 m below: 3.6 m across


def build_scene(depth=6):
    """From 5 m above, looking down: a 3 m floor (the world around it), a box under an empty
    'Root' (its asset), a box without a material, a collection instance of a parented box, and
    names in two- to four-byte UTF-8."""
    s = kit.clear_scene()
    floor_mat, box_mat = kit.diffuse("red", (0.8, 0.1, 0.1)), kit.diffuse("grün ✓", (0.1, 0.8, 0.1))
    kit.plane("floor", 2 * FLOOR, floor_mat)
    root = bpy.data.objects.new("Root", None)
    s.collection.objects.link(root)
    box = kit.box("box ü", 0.8, (0.5, 0.3, 0.4), box_mat)
    box.parent = root
    kit.box("🎲 dice", 0.5, (-0.6, 0.5, 0.25), None)  # no material: Cycles' default_surface
    group = bpy.data.collections.new("Group")
    holder = bpy.data.objects.new("inst_root", None)
    group.objects.link(holder)
    inner = kit.box("inst_box", 0.5, (0.0, 0.0, 0.25), floor_mat)
    for c in inner.users_collection:
        c.objects.unlink(inner)
    group.objects.link(inner)
    inner.parent = holder
    instancer = bpy.data.objects.new("Instancer", None)
    s.collection.objects.link(instancer)
    instancer.instance_type, instancer.instance_collection = "COLLECTION", group
    instancer.location = (-0.5, -0.6, 0.0)
    kit.point_light("lamp", (0.0, 0.0, 4.0), 500.0)
    kit.camera((0.0, 0.0, 5.0))
    kit.world((0.0, 0.0, 0.0))
    kit.output(s, W, H)
    layer = bpy.context.view_layer
    layer.use_pass_cryptomatte_object = layer.use_pass_cryptomatte_material = True
    layer.use_pass_cryptomatte_asset = True
    layer.pass_cryptomatte_depth = depth
    return s


def read_exr(path):
    """({pass name: (h, w, channels) float32} of the ViewLayer, channels in file order r, g, b, a;
    {metadata key: value} of the cryptomatte/ keys, and 'channels': the Crypto channels' full names)
    of a multilayer EXR (3.4: one part, 5.x: a part per pass)."""
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise RuntimeError(f"cannot open {path}: {oiio.geterror()}")
    grouped, meta = {}, {}
    try:
        part = 0
        while inp.seek_subimage(part, 0):
            spec = inp.spec()
            pixels = inp.read_image(format="float")
            for k, full in enumerate(spec.channelnames):
                layer_pass, _, chan = full.rpartition(".")
                layer, _, name = layer_pass.partition(".")
                if layer == "ViewLayer":
                    grouped.setdefault(name, []).append((chan, pixels[:, :, k]))
            meta.update({a.name: a.value for a in spec.extra_attribs if a.name.startswith("cryptomatte/")})
            meta.setdefault("channels", []).extend(n for n in spec.channelnames if ".Crypto" in n)
            part += 1
    finally:
        inp.close()
    order = "RGBAXYZ"
    passes = {n: np.stack([p for _, p in sorted(ch, key=lambda c: order.index(c[0].upper()))], -1)
              for n, ch in grouped.items()}
    return passes, meta


def render(engine, samples=32, tag=""):
    path = os.path.join(TMP, f"{engine.lower()}{tag}.exr")
    result, printed = render_multilayer(engine, samples, path)
    passes, meta = read_exr(path) if os.path.exists(path) else ({}, {})
    return passes, meta, result


def pairs(passes, kind):
    """The (h, w, pairs, 2) ids and coverages of a kind, its layers in order."""
    names = sorted(n for n in passes if n.startswith("Crypto" + kind))
    if not names:
        return np.zeros((H, W, 0, 2), np.float32)
    stacked = np.concatenate([passes[n] for n in names], -1)
    return stacked.reshape(stacked.shape[0], stacked.shape[1], -1, 2)


def manifests(meta):
    """{'Object' | 'Material' | 'Asset': {name: hex}} and the keys, from the cryptomatte/ metadata."""
    out = {}
    for key, value in meta.items():
        if key != "channels" and key.endswith("/name") and value.startswith("ViewLayer.Crypto"):
            prefix = key[:-len("name")]
            out[value[len("ViewLayer.Crypto"):]] = json.loads(meta.get(prefix + "manifest", "{}"))
    return out


def as_float(hex_id):
    """A manifest's 8 hex digits as the id the passes hold (the conversion is the identity on
    Blender's names: their hashes rarely have exponent 0 or 255; the unit test covers that rule)."""
    return struct.unpack("<f", struct.pack("<I", int(hex_id, 16)))[0]


def wholly_on_floor_and_world():
    """Pixels whose square lies wholly on the floor, and wholly off it (only the world)."""
    xs = (np.arange(W + 1) / W - 0.5) * VIEW
    ys = (0.5 - np.arange(H + 1) / H) * VIEW * H / W
    x_in = (xs[:-1] > -FLOOR) & (xs[1:] < FLOOR)
    y_in = (ys[1:] > -FLOOR) & (ys[:-1] < FLOOR)
    x_out = (xs[1:] < -FLOOR) | (xs[:-1] > FLOOR)
    y_out = (ys[:-1] < -FLOOR) | (ys[1:] > FLOOR)
    return y_in[:, None] & x_in[None, :], y_out[:, None] | x_out[None, :]


STATE = {}


def toyrt_cryptomatte_against_known_answers():
    panel = getattr(bpy.types, "VIEWLAYER_PT_toyrt_passes_cryptomatte", None)
    check(panel is not None and panel.bl_parent_id == "VIEWLAYER_PT_toyrt_passes",
          "a Cryptomatte panel under TOYRT's Passes (View Layer tab), as Cycles has")
    build_scene()
    t, meta, result = render("TOYRT")
    STATE["toyrt"] = (t, meta)
    check(result == {"FINISHED"}, f"F12 with Cryptomatte on finishes ({result})")
    want = [f"Crypto{k}{i:02d}" for k in KINDS for i in range(3)]
    check(all(n in t and t[n].shape[2] == 4 for n in want), f"depth 6: three RGBA layers per kind ({sorted(t)})")
    on, off = wholly_on_floor_and_world()
    for kind in KINDS:
        p = pairs(t, kind)
        if p.shape[2] == 0:
            check(False, f"no Crypto{kind} passes")
            continue
        cov = p[..., 1]
        total = cov.sum(-1)
        check(on.sum() > 100 and np.allclose(total[on], 1.0, atol=1e-6),
              f"{kind}: coverage sums to 1 on the {on.sum()} pixels wholly on the floor "
              f"(off by {np.abs(total[on] - 1).max():.1e})")
        check(off.sum() > 100 and np.all(p[off] == 0.0),
              f"{kind}: no id on the {off.sum()} pixels seeing only the world")
        check(np.all(np.diff(cov, axis=-1) <= 0.0), f"{kind}: ranks sorted by coverage")
        check(np.all((p[..., 0] == 0.0) == (cov == 0.0)), f"{kind}: an id wherever a coverage, zeros after the last")
    m = manifests(meta)
    check(sorted(m) == sorted(KINDS), f"a manifest per kind in the metadata ({sorted(m)})")
    names = {o.name for o in bpy.data.objects if o.type == "MESH"}
    check(set(m.get("Object", {})) == names,
          f"the object manifest names every mesh object ({sorted(m.get('Object', {}))})")
    check(set(m.get("Asset", {})) == {"floor", "Root", "🎲 dice", "inst_root"},
          f"assets are the top-level parents ({sorted(m.get('Asset', {}))})")
    check(set(m.get("Material", {})) == {"red", "grün ✓", "default_surface"},
          f"materials by name, Cycles' default_surface for none ({sorted(m.get('Material', {}))})")
    seen = {as_float(h): n for n, h in m.get("Object", {}).items()}
    STATE["box_id"] = as_float(m.get("Object", {}).get("box ü", "0"))
    rank0 = pairs(t, "Object")[..., 0, 0]
    shown = {seen.get(float(v), v) for v in np.unique(rank0) if v != 0.0}
    check(shown == names, f"every object is someone's rank 0, by its manifest id ({sorted(map(str, shown))})")


def toyrt_cryptomatte_equals_cycles():
    if "toyrt" not in STATE:
        check(False, "no TOYRT render to compare")
        return
    t, t_meta = STATE["toyrt"]
    c, c_meta, result = render("CYCLES")
    check(result == {"FINISHED"}, "Cycles renders the same scene")
    crypto = sorted(n for n in c if n.startswith("Crypto"))
    check(crypto == sorted(n for n in t if n.startswith("Crypto")), f"the same Cryptomatte passes as Cycles ({crypto})")
    check(sorted(t_meta.get("channels", [])) == sorted(c_meta.get("channels", [])),
          f"the same channels, named as Cycles' ({c_meta.get('channels', [])[:4]} ...)")
    for kind in KINDS:
        tp, cp = pairs(t, kind), pairs(c, kind)
        if tp.shape != cp.shape:
            check(False, f"{kind}: shapes differ {tp.shape} {cp.shape}")
            continue
        same = float(np.mean(tp[..., 0, 0] == cp[..., 0, 0]))
        # Coverage is each renderer's own sample positions: equal inside objects, close on edges.
        d = np.abs(tp[..., 0, 1] - cp[..., 0, 1])[tp[..., 0, 0] == cp[..., 0, 0]]
        edges = int(np.sum((tp[..., 0, 1] > 0) & (tp[..., 0, 1] < 1)))
        print(f"  {kind}: rank-0 ids equal to Cycles' on {100 * same:.2f} % of {W * H} pixels; their coverage "
              f"differs by {d.mean():.4f} on average, {d.max():.3f} at most ({edges} pixels partly covered)",
              flush=True)
        check(same >= 0.99, f"{kind}: rank-0 ids equal Cycles' on >= 99 % of pixels ({100 * same:.2f} %)")
    tm, cm = manifests(t_meta), manifests(c_meta)
    # Cycles lists its own shaders (default_volume, ...) and, on 5.x, lights: TOYRT's names are a
    # subset; each has Cycles' id.
    for kind in KINDS:
        a, b = tm.get(kind, {}), cm.get(kind, {})
        check(a and all(b.get(n) == h for n, h in a.items()), f"{kind} manifest: each name has Cycles' id ({a})")
    check({k.rsplit("/", 1)[0] for k in t_meta} == {k.rsplit("/", 1)[0] for k in c_meta}
          and all(t_meta[k] == c_meta[k] for k in t_meta if k != "channels" and not k.endswith("/manifest")),
          "the metadata keys, layer names, hash and conversion equal Cycles'")


def compositor_matte(scene, name):
    """Blender's own Cryptomatte node (source: the render) picking the object `name`, its Matte
    into the Composite output: F12 writes the matte. 3.x's scene node tree; 5.x's compositing
    node group with a group output."""
    if hasattr(scene, "compositing_node_group"):
        tree = bpy.data.node_groups.new("matte", "CompositorNodeTree")
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        scene.compositing_node_group = tree
        out = tree.nodes.new("NodeGroupOutput")
    else:
        scene.use_nodes = True
        tree = scene.node_tree
        for n in list(tree.nodes):
            tree.nodes.remove(n)
        out = tree.nodes.new("CompositorNodeComposite")
    layers = tree.nodes.new("CompositorNodeRLayers")
    node = tree.nodes.new("CompositorNodeCryptomatteV2")
    node.source, node.scene = "RENDER", scene
    node.matte_id = name
    tree.links.new(layers.outputs["Image"], node.inputs["Image"])
    tree.links.new(node.outputs["Matte"], out.inputs[0])
    scene.render.use_compositing = True
    st = scene.render.image_settings
    if hasattr(st, "media_type"):
        st.media_type = "IMAGE"
    st.file_format, st.color_depth = "OPEN_EXR", "32"
    path = os.path.join(TMP, f"matte-{scene.render.engine.lower()}.exr")
    result, _ = render_still(path)
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(path) if os.path.exists(path) else None
    matte = inp.read_image(format="float")[..., 0] if inp is not None else None
    scene.render.use_compositing = False
    return result, matte


def blenders_cryptomatte_node_picks_the_matte():
    """The node finds TOYRT's layers by the metadata and the object by its name: its matte is the
    box's coverage in TOYRT's passes, pixel for pixel, and Cycles' matte away from edges."""
    scene = build_scene()
    t, _, _ = render("TOYRT")
    box = STATE.get("box_id")
    result, matte = compositor_matte(scene, "box ü")
    if matte is None:
        check(False, f"the compositor wrote no matte ({result})")
        return
    p = pairs(t, "Object")
    coverage = np.where(p[..., 0] == box, p[..., 1], 0.0).sum(-1)
    check(coverage.max() == 1.0 and np.allclose(matte, coverage, atol=1e-6),
          f"the node's matte of 'box ü' is its coverage in TOYRT's passes (max diff "
          f"{np.abs(matte - coverage).max():.1e}, {int((coverage == 1).sum())} pixels wholly the box)")
    scene.render.engine = "CYCLES"
    configure_cycles(scene, 32, 8)
    _, cycles_matte = compositor_matte(scene, "box ü")
    if cycles_matte is not None:
        differ = float(np.mean(np.abs(cycles_matte - matte) > 0.25))
        check(differ < 0.01, f"and Cycles' matte of the same scene within 0.25 on {100 * (1 - differ):.2f} % of pixels")


def largest_and_odd_depths_are_cycles_layers():
    for depth, layers in ((16, 8), (5, 3), (2, 1)):
        build_scene(depth)
        t, _, result = render("TOYRT", samples=4, tag=f"_depth{depth}")
        got = sorted(n for n in t if n.startswith("CryptoObject"))
        check(result == {"FINISHED"} and got == [f"CryptoObject{i:02d}" for i in range(layers)],
              f"depth {depth}: {layers} layers per kind, as Cycles ({got})")


def a_scene_without_objects_renders_empty_mattes():
    s = kit.clear_scene()
    kit.camera((0.0, 0.0, 5.0))
    kit.world((0.1, 0.1, 0.1))
    kit.output(s, 16, 12)
    layer = bpy.context.view_layer
    layer.use_pass_cryptomatte_object = layer.use_pass_cryptomatte_material = True
    layer.use_pass_cryptomatte_asset = True
    layer.pass_cryptomatte_depth = 6
    t, meta, result = render("TOYRT", samples=2, tag="_empty")
    check(result == {"FINISHED"}, f"F12 of a scene with no object and Cryptomatte on finishes ({result})")
    check(all(np.all(pairs(t, k) == 0.0) and pairs(t, k).shape[2] == 6 for k in KINDS),
          "its Cryptomatte passes are there, with no id")
    # Cycles lists its default shader whatever the scene: so does TOYRT.
    check(manifests(meta) == {"Object": {}, "Asset": {}, "Material": {"default_surface": "78d05529"}},
          f"and empty manifests but for Cycles' default shader ({manifests(meta)})")


def many_objects_manifest_time_and_memory():
    """10,000 objects, each its own name: the sync's names and the manifests' cost, measured."""
    from render_toyrt import cryptomatte, passes

    s = kit.clear_scene()
    mesh = kit.mesh_data("quad", [(-0.01, -0.01, 0), (0.01, -0.01, 0), (0.01, 0.01, 0), (-0.01, 0.01, 0)],
                         [(0, 1, 2, 3)])
    t0 = time.perf_counter()
    count = 10_000
    for k in range(count):
        obj = bpy.data.objects.new(f"Object ✓ {k:05d}", mesh)
        obj.location = ((k % 100) * 0.03 - 1.5, (k // 100) * 0.03 - 1.5, 0.0)
        s.collection.objects.link(obj)
    build_s = time.perf_counter() - t0
    kit.camera((0.0, 0.0, 5.0))
    kit.world((0.0, 0.0, 0.0))
    kit.output(s, 32, 24)
    layer = bpy.context.view_layer
    layer.use_pass_cryptomatte_object = layer.use_pass_cryptomatte_asset = True
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def manifests_of_the_scene():
        tables = passes.PassTables(layer)  # as sync's walk fills it, with a new name -> hash table
        for inst in depsgraph.object_instances:
            if inst.object.type == "MESH":
                tables.add(inst.object)
        return tables.cryptomatte_ids(), [tables.hashes.manifest(tables.names(k)) for k in ("object", "asset")]

    t0 = time.perf_counter()
    ids, text = manifests_of_the_scene()
    total_s = time.perf_counter() - t0
    tracemalloc.start()  # a second time for the memory: tracing slows Python down several times
    manifests_of_the_scene()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    print(f"  {count:,} objects built in {build_s:.1f} s; their names, ids and manifests "
          f"({sum(map(len, text)) / 1e6:.2f} MB of JSON) in {total_s * 1000:.0f} ms, peak Python memory "
          f"{peak / 1e6:.1f} MB", flush=True)
    check(len(ids["object"]) == count and len(json.loads(text[0])) == count, "one id and one manifest entry per object")
    check(total_s < 2.0, f"the manifest of {count:,} objects takes {total_s:.2f} s (< 2 s)")
    kit.toyrt(s, samples=1)
    kit.multilayer_exr(s)
    s.render.engine = "TOYRT"
    t0 = time.perf_counter()
    result, _ = render_still(os.path.join(TMP, "many.exr"))
    print(f"  F12 of the {count:,} objects with Cryptomatte: {time.perf_counter() - t0:.1f} s", flush=True)
    check(result == {"FINISHED"}, f"and F12 of it finishes ({result})")
    check(cryptomatte.MAX_DEPTH == 16, "Blender's largest depth is 16")


run_script([toyrt_cryptomatte_against_known_answers, toyrt_cryptomatte_equals_cycles,
            blenders_cryptomatte_node_picks_the_matte, largest_and_odd_depths_are_cycles_layers,
            a_scene_without_objects_renders_empty_mattes, many_objects_manifest_time_and_memory], "cryptomatte", TMP)
