"""The render engine: syncs the depsgraph into the native scene (sync.py, kept between frames),
has the native renderer render it, and streams finished tiles into Blender's render result; in
the 3D viewport's Rendered mode, viewport.py renders progressively. No rendering logic here."""
import time

import bpy
import numpy as np
from bpy.app.handlers import persistent


class TOYRTRenderEngine(bpy.types.RenderEngine):
    bl_idname = "TOYRT"
    bl_label = "TOYRT"
    bl_use_preview = True  # the Material tab's preview sphere and the slots' icons (preview.py)
    bl_use_shading_nodes_custom = False  # the user's node materials are read, not replaced

    def __init__(self, *args, **kwargs):
        # Blender 4.4 passes arguments to __init__ and requires super().__init__ to receive them.
        super().__init__(*args, **kwargs)
        self._viewport = None  # viewport.ViewportSession while this engine draws a 3D view

    def __del__(self):
        # Blender frees the engine when the view leaves Rendered mode, the engine changes or the
        # file closes: stop and join the render thread with it.
        session = getattr(self, "_viewport", None)
        if session is not None:
            session.close()

    # ---- 3D viewport (viewport.py) ----------------------------------------------------------------
    def view_update(self, context, depsgraph) -> None:
        from . import native, report, viewport

        try:
            if self._viewport is None:
                self._viewport = viewport.ViewportSession(native(), self)
            self._viewport.update(context, depsgraph)
        except Exception as err:  # shown in the viewport's header, never raised into Blender's UI
            report.error(f"viewport update failed: {err}", self.report)

    def view_draw(self, context, depsgraph) -> None:
        if self._viewport is not None:
            self._viewport.draw(context, depsgraph)

    # ---- F12 and command-line renders ---------------------------------------------------------------
    def update_render_passes(self, scene=None, renderlayer=None) -> None:
        """The passes the View Layer turns on, named and laid out as Cycles does (passes.py)."""
        from . import passes

        passes.register(self, scene, renderlayer)

    def render(self, depsgraph) -> None:
        from . import native, release_cached_memory, report

        try:
            if self.is_preview:
                from .preview import render_preview

                render_preview(self, depsgraph, native(), _set_rect)
            else:
                self._render(depsgraph, native())
        except Exception as err:  # reaches the user (and makes a farm's frame fail), never crashes Blender
            report.error(f"render failed: {err}", self.report)
        finally:
            # The arrays a commit freed stay mapped in Blender's process for the next commit (up to
            # a 32nd of the machine's memory): give them back to the system after a final render,
            # since the next one is seconds away at the soonest (its commit then maps its arrays
            # afresh). Not after a material preview: its arrays are small, and the viewport's
            # re-commits may be using what is kept.
            if not self.is_preview:
                release_cached_memory()

    def _render(self, depsgraph, toyrt):
        from . import denoise, passes, render_cache, report, sync
        from .camera import export_camera

        scene = depsgraph.scene
        settings = scene.toyrt
        started = time.perf_counter()
        samples = settings.samples
        # The stats line farms parse, Cycles' layout; progress.poll is every phase's cancel poll.
        progress = report.Progress(self, depsgraph, samples)
        progress.phase("Exporting scene")
        camera = export_camera(depsgraph)  # fails early without a camera
        # One cache per Blender scene: the frames of an animation reuse the meshes that did not
        # change, and the native scene is edited in place, so memory stays flat.
        cache = render_cache.for_render(depsgraph, toyrt)
        t_scene = cache.scene
        progress.memory = lambda: t_scene.memory_bytes
        try:
            cache.sync(depsgraph, should_cancel=progress.poll)
        except sync.ExportCancelled:
            render_cache.discard_render_cache(depsgraph)  # half updated: the next F12 starts afresh
            return
        except Exception:
            # Any other failure mid-walk leaves it half updated too (meshes neither kept nor freed).
            render_cache.discard_render_cache(depsgraph)
            raise
        stats = cache.stats
        if cache.approximated:
            report.note("approximated: " + "; ".join(cache.approximated), self.report)
        if self.test_break():
            return
        window = toyrt.camera_window(camera)
        width, height = window["x1"] - window["x0"], window["y1"] - window["y0"]
        rays_per_sample = 2 + stats.get("lights", 0)  # camera ray, shadow rays, a specular step
        progress.phase("Building BVH", locked=True)
        # Esc is polled during the build too: a million-triangle SAH build takes about a second.
        built = cache.commit(builder=settings.builder, threads=self._threads(scene),
                             expected_rays=float(width * height * samples * rays_per_sample),
                             should_cancel=progress.poll)
        if built:
            report.commit_notes(t_scene, self.report)  # the LBVH builder's fallback on SAH
        build_ms = t_scene.last_commit["build_ms"] if built else 0.0
        if self.test_break():
            return

        # The native renderer fills the camera's pixel window (the border, if any) with rows from
        # the top; Blender's result covers that window only (the border: Blender places it in the
        # full image itself when not cropping), with rows from the bottom.
        tiles_done = [0]
        tile = 32
        tiles_total = max(1, -(-width // tile) * -(-height // tile))
        frame = scene.frame_current
        # Blender renders each view layer in turn: the result of this one only (without the name,
        # layers[0] is the first layer, and a second layer's pixels would land on it).
        layer_name = depsgraph.view_layer.name

        time_limit = settings.time_limit
        progress.time_limit = time_limit

        def on_tile(x, y, w, h, pixels):
            bottom = height - (y + h)
            result = self.begin_result(x, bottom, w, h, layer=layer_name)
            _set_rect(result.layers[0].passes["Combined"].rect, np.ascontiguousarray(pixels[::-1]))
            self.end_result(result)
            if not time_limit:
                tiles_done[0] += 1
                progress.tiles(tiles_done[0], tiles_total)

        wanted = passes.enabled(depsgraph.view_layer)
        if passes.black(wanted):
            report.note("passes left black (TOYRT does not produce them yet): " + ", ".join(passes.black(wanted)),
                        self.report)
        computed = list(dict.fromkeys(p.native for p in wanted if p.native))  # once each (Normal, Denoising Normal)
        denoising = settings.use_denoising and denoise.available() is None
        if settings.use_denoising and not denoising:
            report.note(denoise.available(), self.report)  # the frame is still rendered, not denoised
        if denoising:
            computed += [a for a in denoise.AUXILIARIES if a not in computed]
        tables = cache.pass_tables
        crypto = tables.cryptomatte  # the Cryptomatte kinds asked for (cryptomatte.py)
        progress.rendering()
        image = t_scene.render(
            camera, samples=samples, seed=settings.seed + frame, max_specular_depth=settings.max_specular_depth,
            transparent_max_bounces=settings.transparent_max_bounces,
            area_light_sampling=settings.area_light_sampling, light_sampling=settings.light_sampling,
            threads=self._threads(scene), tile_size=tile, on_tile=on_tile, should_cancel=progress.poll,
            passes=computed, mist=passes.mist(scene.world),
            object_index=np.array(tables.object_pass_index, np.float32),
            material_index=np.array(tables.material_pass_index, np.float32),
            cryptomatte=tables.cryptomatte_ids(),
            cryptomatte_depth=tables.cryptomatte_depth,
            use_adaptive_sampling=settings.use_adaptive_sampling, adaptive_threshold=settings.adaptive_threshold,
            adaptive_min_samples=settings.adaptive_min_samples, time_limit=time_limit,
            # A time limit renders passes over the whole image: the native count of samples done.
            on_progress=progress.samples_done if time_limit else None)
        info = t_scene.last_render
        if info["cancelled"]:
            return
        if denoising:
            progress.phase("Denoising")
            noisy, image = image, denoise.denoise(image, t_scene.last_passes)
        else:
            noisy = image
        if wanted or settings.use_denoising or crypto:
            self._write_passes(image, t_scene.last_passes, wanted, noisy if settings.use_denoising else None,
                               layer_name, tables)
        elapsed = time.perf_counter() - started
        done = info["samples_done"]
        progress.finished(f"Export {stats['export_s'] * 1000:.0f} ms, BVH {build_ms:.0f} ms, "
                          f"Render {info['render_ms'] / 1000:.2f} s, {stats.get('triangles', 0):,} triangles",
                          samples_done=done)
        taken = f"{samples} samples" if done == samples else f"{done} of {samples} samples: time limit"
        if settings.use_adaptive_sampling:
            taken += f", adaptive: {info['mean_samples']:.1f} per pixel"
        print(f"TOYRT: frame {frame} done in {elapsed:.2f} s ({image.shape[1]}x{image.shape[0]}, {taken})",
              flush=True)

    def _write_passes(self, image, computed, wanted, noisy, layer_name, tables):
        """The whole frame once more, every pass beside Combined (tiles stream Combined only) and,
        when denoising, the render before it as the Noisy Image pass; the Cryptomatte layers and
        their manifests in the result's metadata."""
        from . import cryptomatte, denoise
        from .passes import NOISY

        height, width = image.shape[:2]
        result = self.begin_result(0, 0, width, height, layer=layer_name)
        layer = result.layers[0].passes
        _set_rect(layer["Combined"].rect, np.ascontiguousarray(image[::-1]))
        if noisy is not None and layer.get(NOISY) is not None:
            _set_rect(layer[NOISY].rect, np.ascontiguousarray(noisy[::-1]))
        for p in wanted:
            target = layer.get(p.name) if hasattr(layer, "get") else None
            if target is None:
                continue  # not registered by Blender for this layer (it should be): nothing to fill
            values = computed.get(p.native) if p.native else None
            if values is not None and p.albedo:
                values = denoise.albedo(values)
            if values is None:
                values = np.zeros((height, width, len(p.channels)), np.float32)  # a pass TOYRT leaves black
            _set_rect(target.rect, np.ascontiguousarray(values[::-1]))
        for kind in tables.cryptomatte:
            # None for a kind with no id to look up (a scene without objects): no id anywhere.
            pairs = computed.get("cryptomatte_" + kind.native)
            if pairs is None:
                pairs = np.zeros((height, width, tables.cryptomatte_depth * 2), np.float32)
            rgba = cryptomatte.split(pairs)
            for name, values in zip(cryptomatte.pass_names(kind, len(rgba)), rgba):
                if layer.get(name) is not None:
                    _set_rect(layer[name].rect, np.ascontiguousarray(values[::-1]))
        self.end_result(result)
        if tables.cryptomatte:
            # Into the engine's whole result, as Cycles does: a partial result's metadata is not
            # merged by end_result.
            full = self.get_result()
            for kind in tables.cryptomatte:
                cryptomatte.stamp(full, layer_name, kind, tables.manifest_names(kind.native), tables.hashes)

    @staticmethod
    def _threads(scene):
        # Blender's own render-threads setting: 0 (auto) means all cores.
        return 0 if scene.render.threads_mode == "AUTO" else scene.render.threads


_RECT_FLAT = [None]  # does this Blender's pass.rect.foreach_set take a flat buffer? (found on first use)


def _set_rect(rect, pixels):
    """One foreach_set of an (h, w, c) tile: Blender 3.x wants it as (N, c), 5.0 as a flat
    buffer of N * c floats (each refuses the other's shape); tried once, then remembered."""
    channels = pixels.shape[2]
    if _RECT_FLAT[0] is None:
        try:
            rect.foreach_set(pixels.reshape(-1, channels))
            _RECT_FLAT[0] = False
            return
        except (TypeError, RuntimeError, ValueError):
            _RECT_FLAT[0] = True
    rect.foreach_set(pixels.ravel() if _RECT_FLAT[0] else pixels.reshape(-1, channels))


def _free_everything() -> None:
    """Stop every viewport render, drop the final-render cache and give the freed memory back."""
    from . import release_cached_memory, render_cache, viewport

    viewport.close_all()
    render_cache.free_render_caches()
    release_cached_memory()  # the freed scenes' arrays, kept by the module until now


@persistent
def _on_load_pre(*_args):
    """A file is about to close: nothing of its scenes stays in memory."""
    _free_everything()


def register() -> None:
    import atexit

    from . import report, viewport

    report.register()
    bpy.utils.register_class(TOYRTRenderEngine)
    bpy.app.handlers.load_pre.append(_on_load_pre)
    atexit.register(viewport.close_all)  # Blender quitting: no render thread may outlive it


def unregister() -> None:
    import atexit

    from . import viewport

    _free_everything()
    atexit.unregister(viewport.close_all)
    if _on_load_pre in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(_on_load_pre)
    bpy.utils.unregister_class(TOYRTRenderEngine)
