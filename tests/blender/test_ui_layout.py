"""TOYRT's settings in Blender's real Properties editor: every label fits, in the default layout.

Run by `make test-blender` as `blender -b --python tests/blender/test_ui_layout.py`. The outer part
starts a second Blender with a window under Xvfb on a 1920 x 1080 screen (the default startup
layout, no file), `xvfb-run ... blender --python this_file -- --inner result.json`, whose timer
(the inner part) selects TOYRT, shows the Render tab in the layout's Properties editor, screenshots
it (build/ui/, for docs/blender.md) and measures, with Blender's own font engine (blf) at the UI's
scale, every label TOYRT's panels put in the left column of a split layout against that column's
width in the real region; the outer part checks them:

1. each label of the Render tab's TOYRT panels fits its column (Blender would cut it to
   "Viewport S..." otherwise: the flat panel of before did, and its labels are measured too, so
   the check is shown to fail where it should);
2. the settings are where Cycles keeps its own: Sampling > Viewport / Render (each with Denoise),
   Lights, Advanced; Light Paths; Performance.

Labels are gathered by calling each panel's draw with a recorder standing in for the layout: the
texts are what the panel passes to Blender (or the property's own UI name), measured by Blender.
"""
import json
import os
import pathlib
import subprocess
import sys
import tempfile

REPO = pathlib.Path(__file__).resolve().parents[2]
OUT = pathlib.Path(os.environ.get("TOYRT_BUILD_DIR", REPO / "build")) / "ui"
# Labels of the flat panel of before that Blender 3.4 cut in this layout ("Viewport S...", "Max
# Specu..."), measured beside ours: the check fails where it should. (Its "Light Sampling", reported
# cut too, measures 82 px here, in the column's last 6 px: not counted.)
OLD_LABELS = ("Viewport Samples", "Max Specular Depth")


# =================================================================================================
# outer: plain `blender -b`
def outer():
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="toyrt-ui-") as tmp:
        result = os.path.join(tmp, "result.json")
        proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", "blender",
                               "--python", __file__, "--", "--inner", result, str(OUT)],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=600)
        tail = "\n".join(proc.stdout.splitlines()[-30:])
        assert os.path.exists(result), f"the UI run wrote no result (exit {proc.returncode}):\n{tail}"
        with open(result) as f:
            r = json.load(f)
    assert not r.get("error"), r.get("error") + "\n" + tail
    print(json.dumps({k: v for k, v in r.items() if k != "labels"}, indent=1))
    check(r)
    print("test_ui_layout: all checks passed")


def check(r):
    column = r["label_column_px"]
    assert r["region_width_px"] > 100 and column > 40, r
    too_long = [(panel, text, w) for panel, text, w in r["labels"] if w > column]
    for panel, text, w in r["labels"]:
        print(f"  {w:6.1f} px of {column:.1f}  {panel}: {text}")
    assert not too_long, f"labels wider than the column of {column:.1f} px: {too_long}"
    # The measurement can fail: the old flat panel's labels are cut in this layout, as users saw.
    old = {text: w for text, w in r["old_labels"]}
    assert all(w > column for w in old.values()), f"the old labels should not fit ({old}, column {column:.1f})"
    # Cycles' grouping of the settings.
    assert r["tree"] == {
        "RENDER_PT_toyrt_sampling": ["Viewport", "Render", "Lights", "Advanced"],
        "RENDER_PT_toyrt_sampling_viewport": ["Denoise"],
        "RENDER_PT_toyrt_sampling_render": ["Denoise"],
        "RENDER_PT_toyrt_light_paths": ["Max Bounces"],
    }, r["tree"]
    assert r["top_level"] == ["Sampling", "Light Paths", "Performance"], r["top_level"]
    assert os.path.getsize(r["screenshot"]) > 10_000, r["screenshot"]


# =================================================================================================
# inner: Blender with its UI, driven by a timer
class LabelRecorder:
    """Stands in for a panel's layout to list the texts it would show in the split layout's left
    column: a prop's text (or its property's UI name) and the headings of rows and columns. Full-
    width labels (layout.label) span the whole row and are listed apart."""

    def __init__(self, sink, wide):
        self._sink, self._wide = sink, wide
        self.active = self.enabled = True
        self.use_property_split = self.use_property_decorate = True

    def prop(self, data, prop, text=None, **_kw):
        if text != "":
            self._sink.append(text if text is not None else data.bl_rna.properties[prop].name)

    def label(self, text="", **_kw):
        if text:
            self._wide.append(text)

    def _child(self, heading=""):
        if heading:
            self._sink.append(heading)
        return LabelRecorder(self._sink, self._wide)

    def row(self, heading="", **_kw):
        return self._child(heading)

    def column(self, heading="", **_kw):
        return self._child(heading)


def inner(result_path, out_dir):
    import time

    import blf
    import bpy
    from render_toyrt import ui

    state = {"deadline": time.perf_counter() + 120.0}

    def properties_area():
        for window in bpy.context.window_manager.windows:
            for area in window.screen.areas:
                if area.type == "PROPERTIES":
                    return window, area
        return None, None

    def measure():
        window, area = properties_area()
        if area is None:
            return False
        region = next(r for r in area.regions if r.type == "WINDOW")
        prefs = bpy.context.preferences
        scale = prefs.system.ui_scale * prefs.system.pixel_size
        unit = 20.0 * scale  # U.widget_unit
        style = prefs.ui_styles[0]
        # Blender's split layout (use_property_split) gives the label 40 % of the panel's row,
        # right-aligned, with a text margin; the row is the region less the panels' margins.
        row = region.width - 2.0 * unit
        column = 0.4 * row - 0.8 * unit
        if bpy.app.version >= (4, 0, 0):
            blf.size(0, style.widget_label.points * scale)
        else:
            blf.size(0, style.widget_label.points * scale, 72)

        def width(text):
            return blf.dimensions(0, text)[0]

        labels, wide = [], []
        scene = bpy.context.scene
        for panel in ui.RENDER_PANELS:
            sink = []
            panel.draw_settings(panel, LabelRecorder(sink, wide), scene.toyrt)
            labels += [(panel.__name__, t, width(t)) for t in sink]
        tree = {}
        for panel in ui.RENDER_PANELS:
            parent = getattr(panel, "bl_parent_id", "")
            if parent:
                tree.setdefault(parent, []).append(panel.bl_label)
        top = [p.bl_label for p in ui.RENDER_PANELS if not getattr(p, "bl_parent_id", "")]
        shot = os.path.join(out_dir, "render-properties.png")
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screenshot_area(filepath=shot)
        out = dict(region_width_px=region.width, ui_scale=scale, label_column_px=column, labels=labels,
                   wide_labels=[(t, width(t)) for t in wide], old_labels=[(t, width(t)) for t in OLD_LABELS],
                   tree=tree, top_level=top, screenshot=shot, blender=bpy.app.version_string)
        with open(result_path, "w") as f:
            json.dump(out, f)
        return True

    def tick():
        try:
            scene = bpy.context.scene
            scene.render.engine = "TOYRT"
            window, area = properties_area()
            if area is not None and area.spaces[0].context != "RENDER":
                area.spaces[0].context = "RENDER"
                return 0.5  # let Blender draw the tab before the screenshot
            if state.get("drawn") is None:
                state["drawn"] = True
                return 0.5
            if measure():
                bpy.ops.wm.quit_blender()
                return None
            if time.perf_counter() > state["deadline"]:
                raise RuntimeError("no Properties editor in the default layout")
            return 0.2
        except Exception as err:
            import traceback

            traceback.print_exc()
            with open(result_path, "w") as f:
                json.dump({"error": f"{type(err).__name__}: {err}"}, f)
            bpy.ops.wm.quit_blender()
            return None

    bpy.app.timers.register(tick, first_interval=1.0)


if "--inner" in sys.argv:
    i = sys.argv.index("--inner")
    inner(sys.argv[i + 1], sys.argv[i + 2])
else:
    outer()
