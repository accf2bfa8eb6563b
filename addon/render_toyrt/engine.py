"""The render engine: exports the depsgraph (export.py), forwards it to the native renderer, and
streams finished tiles into Blender's render result. No rendering logic here."""
import time

import bpy
import numpy as np


class TOYRTRenderEngine(bpy.types.RenderEngine):
    bl_idname = "TOYRT"
    bl_label = "TOYRT"
    bl_use_preview = False
    bl_use_shading_nodes_custom = False  # the user's node materials are read, not replaced

    def __init__(self, *args, **kwargs):
        # Blender 4.4 passes arguments to __init__ and requires super().__init__ to receive them.
        super().__init__(*args, **kwargs)

    def render(self, depsgraph):
        from . import export, native

        try:
            self._render(depsgraph, native(), export)
        except Exception as err:  # reaches the user (and makes a farm's frame fail), never crashes Blender
            self.report({"ERROR"}, f"TOYRT: {err}")
            print(f"TOYRT: render failed: {err}", flush=True)

    def _render(self, depsgraph, toyrt, export):
        scene = depsgraph.scene
        settings = scene.toyrt
        started = time.perf_counter()
        self.update_stats("TOYRT", "Exporting scene")
        t_scene, camera, stats = export.export_scene(depsgraph, toyrt, report=self.report)
        if self.test_break():
            return
        window = toyrt.camera_window(camera)
        width, height = window["x1"] - window["x0"], window["y1"] - window["y0"]
        samples = settings.samples
        rays_per_sample = 2 + stats.get("lights", 0)  # camera ray, shadow rays, a specular step
        self.update_stats("TOYRT", "Building BVH")
        t_scene.commit(builder=settings.builder, threads=self._threads(scene),
                       expected_rays=float(width * height * samples * rays_per_sample))
        build_ms = t_scene.last_commit["build_ms"]
        if self.test_break():
            return

        # The native renderer fills the camera's pixel window (the border, if any) with rows from
        # the top; Blender's result covers that window only (the border: Blender places it in the
        # full image itself when not cropping), with rows from the bottom.
        tiles_done = [0]
        tile = 32
        tiles_total = max(1, -(-width // tile) * -(-height // tile))
        last_print = [time.perf_counter()]
        frame = scene.frame_current

        def on_tile(x, y, w, h, pixels):
            bottom = height - (y + h)
            result = self.begin_result(x, bottom, w, h)
            _set_rect(result.layers[0].passes["Combined"].rect, np.ascontiguousarray(pixels[::-1]))
            self.end_result(result)
            tiles_done[0] += 1
            self.update_progress(tiles_done[0] / tiles_total)
            now = time.perf_counter()
            if now - last_print[0] > 5.0:  # a sign of life for farm managers that watch stdout
                print(f"TOYRT: frame {frame}: {tiles_done[0]} tiles done, {now - started:.1f} s", flush=True)
                last_print[0] = now

        self.update_stats("TOYRT", f"Rendering {samples} samples")
        image = t_scene.render(
            camera, samples=samples, seed=settings.seed + frame, max_specular_depth=settings.max_specular_depth,
            area_light_sampling=settings.area_light_sampling, light_sampling=settings.light_sampling,
            threads=self._threads(scene), tile_size=tile, on_tile=on_tile, should_cancel=self.test_break)
        info = t_scene.last_render
        if info["tiles_total"]:
            self.update_progress(info["tiles_done"] / info["tiles_total"])
        elapsed = time.perf_counter() - started
        self.update_stats(
            "TOYRT",
            f"Samples {samples} | Export {stats['export_s'] * 1000:.0f} ms | BVH {build_ms:.0f} ms | "
            f"Render {info['render_ms'] / 1000:.2f} s | {stats.get('triangles', 0):,} triangles | {elapsed:.2f} s")
        print(f"TOYRT: frame {frame} done in {elapsed:.2f} s ({image.shape[1]}x{image.shape[0]}, {samples} samples)",
              flush=True)

    @staticmethod
    def _threads(scene):
        # Blender's own render-threads setting: 0 (auto) means all cores.
        return 0 if scene.render.threads_mode == "AUTO" else scene.render.threads


_RECT_FLAT = [None]  # does this Blender's pass.rect.foreach_set take a flat buffer? (found on first use)


def _set_rect(rect, pixels):
    """One foreach_set of an (h, w, 4) tile: Blender 3.x wants it as (N, 4), 5.0 as a flat
    buffer of N * 4 floats (each refuses the other's shape); tried once, then remembered."""
    if _RECT_FLAT[0] is None:
        try:
            rect.foreach_set(pixels.reshape(-1, 4))
            _RECT_FLAT[0] = False
            return
        except (TypeError, RuntimeError, ValueError):
            _RECT_FLAT[0] = True
    rect.foreach_set(pixels.ravel() if _RECT_FLAT[0] else pixels.reshape(-1, 4))


def register():
    bpy.utils.register_class(TOYRTRenderEngine)


def unregister():
    bpy.utils.unregister_class(TOYRTRenderEngine)
