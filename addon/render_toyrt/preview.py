"""Material, world and light previews: the preview sphere of the Material tab (and the icons of the
material slots, the asset browser, the world and light tabs) rendered by TOYRT, as Cycles renders
its own (`bl_use_preview`).

Blender renders a preview with its own small preview scene (a camera, a floor, the preview shape
carrying the material, lamps and a world, or the user's world when "World" is ticked in the
Preview panel), in a job thread, cancelling it (test_break) whenever the material changes. So a
preview:
- syncs into a SceneSync of its own, dropped afterwards: the F12 render cache (render_cache.py)
  stays the user's scene's, and nothing of the preview scene is kept alive;
- takes the preview scene's Viewport Samples (its `scene.toyrt` holds the defaults: 32), so the
  128-256 px images of the panel finish in well under a second on a laptop's cores;
- streams tiles as F12 does, so the sphere appears while it renders, and stops within a tile of
  a cancel;
- says nothing about what it approximates (the floor's checker texture, say): a warning on every
  edit of a material would bury the user's own reports. Failures are still errors (engine.py).

`last_preview` keeps the numbers of the last finished preview for the tests and docs/blender.md."""
from __future__ import annotations

import time

import numpy as np

last_preview: dict = {}  # size, samples, seconds, triangles, approximated (of the last finished preview)


def render_preview(engine, depsgraph, toyrt, set_rect) -> None:
    """Renders the preview scene of `depsgraph` into `engine`'s result (Combined only)."""
    from .camera import export_camera
    from .sync import ExportCancelled, SceneSync

    started = time.perf_counter()
    scene = depsgraph.scene
    settings = scene.toyrt
    samples = settings.viewport_samples
    camera = export_camera(depsgraph)
    cache = SceneSync(toyrt)
    try:
        cache.sync(depsgraph, should_cancel=engine.test_break)
    except ExportCancelled:
        return
    if engine.test_break():
        return
    window = toyrt.camera_window(camera)
    width, height = window["x1"] - window["x0"], window["y1"] - window["y0"]
    threads = engine._threads(scene)  # Blender's render-threads setting, as F12 reads it
    cache.commit(builder="sah", threads=threads, should_cancel=engine.test_break)
    if engine.test_break():
        return
    layer_name = depsgraph.view_layer.name

    def on_tile(x, y, w, h, pixels):
        result = engine.begin_result(x, height - (y + h), w, h, layer=layer_name)
        set_rect(result.layers[0].passes["Combined"].rect, np.ascontiguousarray(pixels[::-1]))
        engine.end_result(result)

    t_scene = cache.scene
    t_scene.render(camera, samples=samples, seed=settings.seed, max_specular_depth=settings.max_specular_depth,
                   area_light_sampling=settings.area_light_sampling, light_sampling=settings.light_sampling,
                   threads=threads, tile_size=32, on_tile=on_tile, should_cancel=engine.test_break)
    if t_scene.last_render["cancelled"]:
        return
    last_preview.clear()
    last_preview.update(size=(width, height), samples=samples, seconds=time.perf_counter() - started,
                        export_s=cache.stats.get("export_s", 0.0), build_ms=t_scene.last_commit["build_ms"],
                        render_s=t_scene.last_render["render_ms"] / 1000, triangles=cache.stats.get("triangles", 0),
                        approximated=list(cache.approximated), scene=scene.as_pointer())
