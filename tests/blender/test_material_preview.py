"""TOYRT renders the Material tab's preview (bl_use_preview), in Blender's real user interface.

Run by `make test-blender` as `blender -b --python tests/blender/test_material_preview.py`. Material
previews exist only where Blender has a window manager running jobs (the `bpy` module and `blender
-b` render none), so the outer part starts a second Blender with a window under Xvfb,
`xvfb-run ... blender --python this_file -- --inner result.json`, whose timer (the inner part)
selects TOYRT and the Standard view transform, gives the startup cube an Emission material and asks
Blender for the material's large preview (the Preview panel's image, `ed.lib_id_generate_preview`),
then reads it back. The outer part checks:

1. TOYRT rendered it: the engine's own record of its last preview (preview.last_preview) names
   Blender's preview scene, not the user's, at the preview's size;
2. the preview shows the material: the preview sphere is seen directly, so its pixels are the
   emission colour through the Standard view transform, exactly: sRGB(c) for strength 1 (a closed
   form; the most frequent colour of the image must be it, within one 8-bit step);
3. a second material (another colour) gives its own colour: nothing is cached from the first;
4. a default Principled material, the startup file's world and its lamp preview too (TOYRT's
   record, a lit image: not black), and their times are printed for docs/blender.md;
5. the user's scene is untouched: no final-render cache was made or replaced by the previews.
"""
import json
import os
import subprocess
import sys
import tempfile

EMISSION = [(0.8, 0.2, 0.05), (0.1, 0.35, 0.7)]
OTHERS = ["principled", "world", "light"]  # previews checked for being TOYRT's and lit


def srgb(c):
    return 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055


# =================================================================================================
# outer: plain `blender -b`
def outer():
    with tempfile.TemporaryDirectory(prefix="toyrt-preview-") as tmp:
        result = os.path.join(tmp, "result.json")
        proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "blender",
                               "--python", __file__, "--", "--inner", result],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=600)
        tail = "\n".join(proc.stdout.splitlines()[-30:])
        assert os.path.exists(result), f"the preview run wrote no result (exit {proc.returncode}):\n{tail}"
        with open(result) as f:
            r = json.load(f)
    assert not r.get("error"), r.get("error") + "\n" + tail
    print(json.dumps(r, indent=1))
    check(r)
    print("test_material_preview: all checks passed")


def check(r):
    assert len(r["previews"]) == len(EMISSION) + len(OTHERS), r
    for p in r["previews"]:
        rec = p["record"]
        assert rec and rec["scene"] != r["user_scene"], f"TOYRT did not render the preview of {p['what']}: {rec}"
        assert tuple(rec["size"]) == tuple(p["image_size"]), (rec, p["image_size"])
        assert p["max_rgb"] > 0.2, f"the preview of {p['what']} is black: {p}"
        print(f"  preview of {p['what']}: {rec['size'][0]}x{rec['size'][1]}, {rec['samples']} samples, "
              f"{rec['seconds']:.2f} s (export {rec['export_s'] * 1000:.0f} ms, render {rec['render_s']:.2f} s)")
    for colour, p in zip(EMISSION, r["previews"]):
        expected = [srgb(c) for c in colour]
        mode = p["mode_rgb"]
        assert all(abs(m - e) <= 1.5 / 255 for m, e in zip(mode, expected)), \
            f"the sphere's colour {mode} is not sRGB{colour} = {expected}"
        assert p["mode_fraction"] > 0.05, p  # the sphere covers a good part of the image
    assert r["render_caches"] == 0, r


# =================================================================================================
# inner: Blender with its UI, driven by a timer
def inner(result_path):
    import bpy
    import numpy as np

    state = {"step": 0, "waited": 0.0, "previews": []}

    def material(colour):
        mat = bpy.data.materials.new(f"Preview {colour}")
        mat.use_nodes = True
        nodes = mat.node_tree.nodes
        nodes.clear()
        out = nodes.new("ShaderNodeOutputMaterial")
        em = nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (*colour, 1.0)
        em.inputs["Strength"].default_value = 1.0
        mat.node_tree.links.new(em.outputs["Emission"], out.inputs["Surface"])
        return mat

    def ask(id_):
        if isinstance(id_, bpy.types.Material):
            obj = bpy.data.objects["Cube"]
            obj.data.materials.clear()
            obj.data.materials.append(id_)
        id_.preview_ensure()
        window = bpy.context.window_manager.windows[0]
        with bpy.context.temp_override(window=window, id=id_):
            bpy.ops.ed.lib_id_generate_preview()

    def read(id_, what):
        from render_toyrt import preview as pv

        w, h = id_.preview.image_size
        px = np.array(id_.preview.image_pixels_float[:], np.float32).reshape(h, w, 4)
        rgb = np.round(px[..., :3] * 255).astype(np.int32).reshape(-1, 3)
        keys, counts = np.unique(rgb, axis=0, return_counts=True)
        top = int(np.argmax(counts))
        return dict(what=what, image_size=[w, h], mode_rgb=[float(v) / 255 for v in keys[top]],
                    mode_fraction=float(counts[top]) / len(rgb), max_rgb=float(px[..., :3].max()),
                    record=dict(pv.last_preview))

    def tick():
        try:
            from render_toyrt import preview as pv

            scene = bpy.context.scene
            if state["step"] == 0:
                scene.render.engine = "TOYRT"
                scene.view_settings.view_transform = "Standard"
                scene.view_settings.look = "None"
                scene.view_settings.exposure = 0.0
                scene.view_settings.gamma = 1.0
                principled = bpy.data.materials.new("Preview Principled")
                principled.use_nodes = True
                state["ids"] = [(material(c), f"emission {c}") for c in EMISSION] + [
                    (principled, "principled"), (scene.world, "world"), (bpy.data.lights["Light"], "light")]
                state["step"] = 1
            i = state["step"] - 1
            if i < len(state["ids"]):
                mat, what = state["ids"][i]
                if not state.get("asked"):
                    pv.last_preview.clear()
                    ask(mat)
                    state["asked"], state["waited"] = True, 0.0
                    return 0.5
                done = pv.last_preview and any(mat.preview.image_pixels_float[:64])
                if not done and state["waited"] < 120:
                    state["waited"] += 0.5
                    return 0.5
                state["previews"].append(read(mat, what))
                state["asked"] = False
                state["step"] += 1
                return 0.2
            from render_toyrt import render_cache

            out = dict(previews=state["previews"], user_scene=scene.as_pointer(),
                       render_caches=len(render_cache.render_caches()), blender=bpy.app.version_string)
            with open(result_path, "w") as f:
                json.dump(out, f)
            bpy.ops.wm.quit_blender()
        except Exception as err:
            import traceback

            traceback.print_exc()
            with open(result_path, "w") as f:
                json.dump({"error": f"{type(err).__name__}: {err}"}, f)
            bpy.ops.wm.quit_blender()
        return None

    bpy.app.timers.register(tick, first_interval=1.0)


if "--inner" in sys.argv:
    args = sys.argv[sys.argv.index("--") + 1:]
    inner(args[1])
else:
    outer()
