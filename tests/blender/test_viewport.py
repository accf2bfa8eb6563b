"""TOYRT in the 3D viewport's Rendered mode, in Blender's real user interface under Xvfb.

Run by `make test-blender` as `blender -b --python tests/blender/test_viewport.py`: this outer
part builds the Cornell box (scenes/cornell_demo.py) and starts a second Blender with a window,
`xvfb-run ... blender cornell.blend --python this_file -- --inner result.json`, whose timer-driven
steps (the inner part) switch a 3D view to camera view and Rendered shading with TOYRT, wait for
the progressive render, screenshot the area and measure; the outer part checks the results:

1. the red wall shows red and the green wall green where Blender's own projection of the walls
   (view3d_utils.location_3d_to_region_2d) puts them in the region, once all viewport samples are in;
2. the camera moves: the walls are found again where the new projection puts them, and nothing
   was exported or committed for it (the cache's counters);
3. edits in the UI: moving an object sets a transform and rebuilds no mesh BVH; editing a mesh
   re-exports that mesh only; editing a material converts that material only;
4. Rendered mode and the render engine toggled 50 times: no viewport session or render thread is
   left, the OS thread count and the memory do not grow from toggle 10 to toggle 50;
5. a file is opened while a viewport render is running: the session and its thread are gone;
6. Blender quits while a viewport render is running (the process exits 0);
7. Viewport Denoise (scene.toyrt.use_preview_denoising) shows each pass denoised: the noise of a
   patch of wall drops to under half.
"""
import json
import os
import pathlib
import subprocess
import sys
import tempfile

REPO = pathlib.Path(__file__).resolve().parents[2]


# =================================================================================================
# outer: plain `blender -b`
def outer():
    with tempfile.TemporaryDirectory(prefix="toyrt-viewport-") as tmp:
        blend = os.path.join(tmp, "cornell.blend")
        subprocess.run(["blender", "-b", "--python-exit-code", "1", "--python",
                        str(REPO / "scenes" / "cornell_demo.py"), "--", blend], check=True,
                       stdout=subprocess.DEVNULL)
        result = os.path.join(tmp, "result.json")
        # No --factory-startup: the add-on is enabled in the user's preferences. A generous
        # ceiling only guards against a hang (it is not a timing check).
        proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "blender", blend,
                               "--python", __file__, "--", "--inner", result],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=1200)
        tail = "\n".join(proc.stdout.splitlines()[-40:])
        assert os.path.exists(result), f"the UI run wrote no result (exit {proc.returncode}):\n{tail}"
        with open(result) as f:
            r = json.load(f)
        print(json.dumps(r, indent=1))
        assert not r.get("error"), r.get("error") + "\n" + tail
        assert proc.returncode == 0, f"Blender did not quit cleanly while rendering: exit {proc.returncode}\n{tail}"
        check(r)
    print("test_viewport: all checks passed")


def check(r):
    first = r["first"]
    assert first["samples_done"] == r["viewport_samples"], first
    for phase in ("first", "moved"):
        walls = r[phase]["walls"]
        assert walls["red"]["dominant"] == "red", (phase, walls)
        assert walls["green"]["dominant"] == "green", (phase, walls)
    # The camera moved enough for the walls to land elsewhere in the region.
    shift = abs(r["moved"]["walls"]["red"]["xy"][0] - r["first"]["walls"]["red"]["xy"][0])
    assert shift > 40, shift
    c0, c1 = r["first"]["counters"], r["moved"]["counters"]
    for k in ("meshes_exported", "commits", "mesh_bvhs_built", "light_sends", "materials_converted"):
        assert c1[k] == c0[k], (k, c0, c1)  # a camera move re-exports and rebuilds nothing
    assert r["moved"]["restarts"] > r["first"]["restarts"]

    t = r["transform_edit"]
    assert t["transforms_set"] >= 1 and t["mesh_bvhs_built"] == 0 and t["meshes_exported"] == 0, t
    assert t["top_level_builds"] == 1, t
    m = r["mesh_edit"]
    assert m["meshes_exported"] == 1 and m["mesh_bvhs_built"] == 1, m
    mat = r["material_edit"]
    assert mat["materials_converted"] == 1 and mat["meshes_exported"] == 0 and mat["mesh_bvhs_built"] == 0, mat

    # Viewport Denoise: every pass after the coarse one shown denoised (the vendored pyoidn on Debian's
    # Blender, scripts/vendor-pyoidn.py), the wall's noise well down.
    d = r["denoise"]
    assert d["error"] is None and d["denoised_passes"] >= 3, d
    assert d["denoised"] < 0.5 * d["plain"], d

    assert r["file_load"] == dict(sessions_left=0, viewport_threads_left=0), r["file_load"]
    tog = r["toggles"]
    assert tog["sessions_left"] == 0 and tog["viewport_threads_left"] == 0, tog
    assert tog["os_threads_50"] <= tog["os_threads_10"], tog
    # Memory: a leaked session would keep its native scene and images (tens of MB each, times 40
    # toggles); the bound is two sessions' worth plus allocator noise.
    assert tog["rss_50"] - tog["rss_10"] < 2 * tog["session_bytes"] + 16e6, tog


# =================================================================================================
# inner: Blender with its UI, driven by timers
def inner(result_path):
    import threading
    import time

    import bpy
    import numpy as np
    from bpy_extras.view3d_utils import location_3d_to_region_2d
    from render_toyrt import viewport

    out = {"viewport_samples": 16}
    scene = bpy.context.scene

    def view3d():
        for window in bpy.context.window_manager.windows:
            for area in window.screen.areas:
                if area.type == "VIEW_3D":
                    region = next(r for r in area.regions if r.type == "WINDOW")
                    return window, area, region
        raise RuntimeError("no 3D view")

    def session():
        live = list(viewport._sessions)
        return live[0] if len(live) == 1 else None

    def rss():
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
        return 0

    def screenshot():
        window, area, region = view3d()
        path = os.path.join(os.path.dirname(result_path), "shot.png")
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screenshot_area(filepath=path)
        img = bpy.data.images.load(path, check_existing=False)
        w, h = img.size
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
        bpy.data.images.remove(img)
        # rows from the bottom, like region coordinates; the window region's offset in the area
        return px.reshape(h, w, 4), region.x - area.x, region.y - area.y

    def wall_colour(point):
        """Mean colour around where Blender projects `point`, and which channel dominates."""
        window, area, region = view3d()
        xy = location_3d_to_region_2d(region, area.spaces[0].region_3d, point)
        img, ox, oy = screenshot()
        x, y = int(xy.x) + ox, int(xy.y) + oy
        patch = img[y - 4:y + 5, x - 4:x + 5, :3].reshape(-1, 3).mean(0)
        names = ("red", "green", "blue")
        k = int(np.argmax(patch))
        dominant = names[k] if patch[k] > 1.5 * np.delete(patch, k).max() else "none"
        return dict(xy=[float(xy.x), float(xy.y)], rgb=patch.tolist(), dominant=dominant)

    def snapshot():
        s = session()
        return dict(samples_done=s.samples_done, restarts=s.restarts, counters=dict(s.cache.counters),
                    first_pass_ms=s.first_pass_ms,
                    walls=dict(red=wall_colour((-0.999, 0.3, 1.2)), green=wall_colour((0.999, 0.3, 1.2))))

    def done_rendering(min_restarts=0):
        s = session()
        return (s is not None and s.restarts > min_restarts and not s.rendering
                and s.samples_done == out["viewport_samples"])

    # Steps run one after another; each may wait (return False) until its condition holds.
    steps = []
    state = {"deadline": None, "restarts": 0, "counters": None}

    def wait_for(cond, label):
        def step():
            if cond():
                return True
            if time.perf_counter() > state["deadline"]:
                s = session()
                seen = s and dict(restarts=s.restarts, samples_done=s.samples_done, rendering=s.rendering,
                                  error=s.error, denoised_passes=s.denoised_passes)
                raise RuntimeError(f"waited 120 s for: {label} (session: {seen}, restarts before: {state['restarts']})")
            return False
        step.label = label
        return step

    def do(fn):
        def step():
            fn()
            return True
        step.label = fn.__name__
        return step

    def start():
        scene.render.engine = "TOYRT"
        scene.toyrt.viewport_samples = out["viewport_samples"]
        window, area, region = view3d()
        space = area.spaces[0]
        space.overlay.show_overlays = False
        space.show_gizmo = False
        space.region_3d.view_perspective = "CAMERA"
        space.shading.type = "RENDERED"

    def first():
        out["first"] = snapshot()
        state["restarts"] = session().restarts

    def move_camera():
        cam = scene.camera
        cam.location.x += 0.35
        cam.rotation_euler.z -= 0.1  # turn right too: both move the walls left in the picture

    def moved():
        out["moved"] = snapshot()
        state["restarts"] = session().restarts

    def counter_delta(name):
        def before():
            state["counters"] = dict(session().cache.counters)
            state["restarts"] = session().restarts

        def after():
            now = session().cache.counters
            out[name] = {k: now[k] - state["counters"][k] for k in now}
        before.__name__, after.__name__ = f"{name}_before", f"{name}_after"
        return before, after

    def edit_transform():
        bpy.data.objects["Cube"].location.x += 0.05

    def edit_mesh():
        mesh = bpy.data.objects["Cube"].data
        mesh.vertices[0].co.z += 0.05
        mesh.update()

    def edit_material():
        bpy.data.materials["red"].node_tree.nodes["Diffuse BSDF"].inputs["Color"].default_value = (0.9, 0.1, 0.1, 1)

    def wall_noise():
        """Pixel noise of the newest viewport image on a 15 x 15 patch of the red wall: the standard
        deviation of each pixel's difference from the mean of its 8 neighbours (what the lighting's
        smooth gradient leaves out), in the red channel."""
        window, area, region = view3d()
        xy = location_3d_to_region_2d(region, area.spaces[0].region_3d, (-0.999, 0.3, 1.2))
        image = session()._latest[1][..., 0]
        row, col = image.shape[0] - 1 - int(xy.y), int(xy.x)
        patch = image[row - 8:row + 9, col - 8:col + 9]
        around = sum(np.roll(np.roll(patch, dy, 0), dx, 1) for dy in (-1, 0, 1) for dx in (-1, 0, 1)) - patch
        return float((patch - around / 8.0)[1:-1, 1:-1].std())

    def noise_plain():
        out["denoise"] = dict(plain=wall_noise())
        state["restarts"] = session().restarts
        scene.toyrt.use_preview_denoising = True

    def noise_denoised():
        s = session()
        out["denoise"].update(denoised=wall_noise(), denoised_passes=s.denoised_passes, error=s.error)
        scene.toyrt.use_preview_denoising = False

    toggles = {"n": 0}

    def toggle_once():
        window, area, region = view3d()
        space = area.spaces[0]
        n = toggles["n"]
        if n % 2 == 0:
            space.shading.type = "SOLID"
            scene.render.engine = "BLENDER_WORKBENCH" if n % 4 == 0 else "TOYRT"
        else:
            scene.render.engine = "TOYRT"
            space.shading.type = "RENDERED"
        toggles["n"] += 1
        if toggles["n"] == 20:
            out.setdefault("toggles", {}).update(rss_10=rss(), os_threads_10=len(os.listdir("/proc/self/task")))
        return toggles["n"] >= 100  # 50 times into Rendered mode and 50 times out

    toggle_once.label = "toggle"

    def after_toggles():
        window, area, region = view3d()
        area.spaces[0].shading.type = "SOLID"

    def toggles_done():
        out["toggles"].update(
            rss_50=rss(), os_threads_50=len(os.listdir("/proc/self/task")), sessions_left=len(viewport._sessions),
            viewport_threads_left=sum(t.name == "toyrt-viewport" for t in threading.enumerate()),
            session_bytes=state["session_bytes"])

    def measure_session():
        s = session()
        window, area, region = view3d()
        state["session_bytes"] = s.cache.scene.memory_bytes + region.width * region.height * 16 * 3

    def render_long():
        bpy.context.scene.toyrt.viewport_samples = 100000
        window, area, region = view3d()
        area.spaces[0].shading.type = "RENDERED"

    def reload_file():
        # The file closes while its viewport renders: load_pre must stop and free the session.
        bpy.ops.wm.open_mainfile(filepath=bpy.data.filepath)

    def after_reload():
        out["file_load"] = dict(sessions_left=len(viewport._sessions),
                                viewport_threads_left=sum(t.name == "toyrt-viewport" for t in threading.enumerate()))

    def quit_while_rendering():
        bpy.context.scene.render.engine = "TOYRT"
        bpy.context.scene.toyrt.viewport_samples = 100000
        window, area, region = view3d()
        area.spaces[0].shading.type = "RENDERED"

    def write_and_quit():
        with open(result_path, "w") as f:
            json.dump(out, f)
        bpy.ops.wm.quit_blender()

    tr_before, tr_after = counter_delta("transform_edit")
    me_before, me_after = counter_delta("mesh_edit")
    ma_before, ma_after = counter_delta("material_edit")
    restarted = lambda: done_rendering(state["restarts"])  # noqa: E731
    steps += [do(start), wait_for(lambda: done_rendering(0), "first render"), do(first),
              do(move_camera), wait_for(restarted, "render after the camera move"), do(moved),
              do(tr_before), do(edit_transform), wait_for(restarted, "render after a transform edit"), do(tr_after),
              do(me_before), do(edit_mesh), wait_for(restarted, "render after a mesh edit"), do(me_after),
              do(ma_before), do(edit_material), wait_for(restarted, "render after a material edit"), do(ma_after),
              do(noise_plain), wait_for(restarted, "render with Viewport Denoise"), do(noise_denoised),
              do(measure_session), toggle_once, do(after_toggles),
              wait_for(lambda: not viewport._sessions, "sessions freed after leaving Rendered mode"),
              do(toggles_done),
              do(render_long), wait_for(lambda: session() is not None and session().passes > 0,
                                        "a render running before the file closes"),
              do(reload_file), wait_for(lambda: not viewport._sessions, "sessions freed by loading a file"),
              do(after_reload),
              do(quit_while_rendering), wait_for(lambda: session() is not None and session().passes > 0,
                                                 "a render running before quitting"),
              do(write_and_quit)]

    def tick():
        try:
            while steps:
                if state["deadline"] is None:
                    state["deadline"] = time.perf_counter() + 120.0
                if not steps[0]():
                    return 0.1
                print(f"viewport test: {steps[0].label} done", flush=True)
                steps.pop(0)
                state["deadline"] = None
                return 0.2  # let Blender redraw and run view_update between steps
        except Exception as err:
            import traceback

            traceback.print_exc()
            out["error"] = f"{type(err).__name__}: {err}"
            with open(result_path, "w") as f:
                json.dump(out, f)
            bpy.ops.wm.quit_blender()
        return None

    bpy.app.timers.register(tick, first_interval=1.0, persistent=True)  # survives the file load


if "--inner" in sys.argv:
    inner(sys.argv[sys.argv.index("--inner") + 1])
else:
    outer()
