"""The 3D viewport's Rendered mode: a progressive render on a background thread.

    engine.view_update -> ViewportSession.update: stop the render thread, apply depsgraph.updates
                          to the SceneSync (sync.py), commit, mark the image stale
    engine.view_draw   -> ViewportSession.draw: the view's camera; a new view (camera or
                          navigation) or a stale image restarts the render; upload the newest
                          accumulated image as a GPUTexture and draw it through Blender's
                          display-space shader (colour management applies)
    render thread      -> a coarse pass (1 sample at 1/4 resolution), then passes of 1, 1, 2, 4,
                          ... 16 samples of the one Sobol-Owen sequence (render(first_sample=...)),
                          accumulated up to scene.toyrt.viewport_samples (each shown denoised
                          with Viewport Denoise on: denoise.py); then it ends: no CPU
                          used until the next change. The native render releases the GIL and
                          polls a stop flag every 10 ms, so a restart waits a few ms at most.

The thread never touches the scene while it is being edited (update() joins it first), and
never outlives its engine: close() (engine.__del__, a file load, unregister, exit) joins it."""
import threading
import weakref

import numpy as np

from . import report

_sessions = weakref.WeakSet()  # every live session, for close_all()

COARSE_DIVIDER = 4      # the first pass renders 1/4 of the width and height
MAX_PASS_SAMPLES = 16   # samples per pass once the image is refined: a restart never waits long


def close_all() -> None:
    """Stop every viewport render (file load, unregister, Blender quitting)."""
    for session in list(_sessions):
        session.close()


def view_camera(region, rv3d) -> dict:
    """The camera dict of what a 3D view shows, from its projection (window_matrix) and view
    matrix, at the region's size. The projection is read back into Blender's own camera
    parameters (horizontal sensor fit), so camera view, zoom and pan come for free."""
    w, h = int(region.width), int(region.height)
    p = np.array(rv3d.window_matrix, np.float64)
    to_world = np.array(rv3d.view_matrix.inverted(), np.float64)
    d = dict(resolution_x=w, resolution_y=h, resolution_percentage=100, sensor_fit="HORIZONTAL",
             sensor_width=36.0, sensor_height=24.0)
    if rv3d.is_perspective:
        # OpenGL frustum: p[0][0] = 2 n / (r - l) = 2 lens / sensor_width, p[0][2] = (r + l) / (r - l)
        # = 2 shift_x, and the vertical shift is in units of the width (Blender's shift).
        near = p[2][3] / (p[2][2] - 1.0)
        far = p[2][3] / (p[2][2] + 1.0)
        d.update(type="PERSP", lens=p[0][0] * 36.0 / 2.0, shift_x=p[0][2] / 2.0, shift_y=p[1][2] / 2.0 * h / w,
                 clip_start=near, clip_end=far)
    else:
        near = (p[2][3] + 1.0) / p[2][2]
        far = (p[2][3] - 1.0) / p[2][2]
        if near < 0.0:
            # Orthographic views clip from behind the view point; the camera takes clip_start >= 0,
            # so the origin moves back instead.
            to_world[:3, 3] += to_world[:3, 2] * -near
            far, near = far - near, 0.0
        d.update(type="ORTHO", ortho_scale=2.0 / p[0][0], shift_x=-p[0][3] / 2.0, shift_y=-p[1][3] / 2.0 * h / w,
                 clip_start=near, clip_end=far)
    d["matrix_world"] = to_world
    return d


def _view_key(camera):
    return tuple((k, v.tobytes() if isinstance(v, np.ndarray) else v) for k, v in sorted(camera.items()))


class ViewportSession:
    def __init__(self, toyrt, engine) -> None:
        from .sync import SceneSync

        self.cache = SceneSync(toyrt)
        self._engine = weakref.ref(engine)  # a strong reference would keep Blender's engine alive
        self._thread = None
        self._stop = threading.Event()
        self._stale = True          # the scene changed since the render started
        self._view = None           # the view the current render is of
        self._settings = None
        self._latest = None         # (version, image (h, w, 4) float32 rows from the top, samples)
        self._drawn = None          # (version, GPUTexture)
        self.samples_done = 0       # of the current view, read by tests and the status text
        self.passes = 0
        self.restarts = 0
        self.error = None           # why the last render thread stopped early, shown in the view's header
        self._notes_shown = set()   # the fallback notes this session reported (report.commit_notes)
        self.first_pass_ms = None   # time from a restart to its first image (the coarse pass)
        self.denoised_passes = 0    # passes shown denoised (Viewport Denoise)
        _sessions.add(self)

    # ---- on Blender's main thread -----------------------------------------------------------------
    def update(self, context, depsgraph) -> None:
        self._stop_thread()  # the thread reads the native scene: never edit it under its feet
        first = not self.cache.synced
        self.cache.sync(depsgraph, None if first else depsgraph.updates)
        scene = depsgraph.scene
        s = scene.toyrt
        self._settings = self._render_settings(scene)
        threads = self._settings["threads"]
        region = context.region
        rays = float(region.width * region.height * s.viewport_samples * (2 + self.cache.stats.get("lights", 0)))
        # The cost model picks the builder: interactive work (few rays) favours the fast LBVH builds,
        # whose fallback on SAH (a GPU that cannot build its kernels) is a note in the view's
        # header, once per session.
        if self.cache.commit(builder=s.builder, threads=threads, expected_rays=rays):
            engine = self._engine()
            report.commit_notes(self.cache.scene, engine.report if engine is not None else None, self._notes_shown)
        self._stale = True

    def _render_settings(self, scene) -> dict:
        """What the render thread renders with, from TOYRT's settings and Blender's threads."""
        s = scene.toyrt
        threads = 0 if scene.render.threads_mode == "AUTO" else scene.render.threads
        return dict(samples=int(s.viewport_samples), seed=int(s.seed), max_specular_depth=int(s.max_specular_depth),
                    transparent_max_bounces=int(s.transparent_max_bounces),
                    area_light_sampling=s.area_light_sampling, light_sampling=s.light_sampling, threads=threads,
                    denoise=self._denoising(s))

    def _denoising(self, settings) -> bool:
        """Viewport Denoise (scene.toyrt.use_preview_denoising, Cycles' name) when the denoiser loads;
        when it does not, the one note, once per session, and the image undenoised."""
        from . import denoise

        if not settings.use_preview_denoising:
            return False
        why = denoise.available()
        if why is not None and why not in self._notes_shown:
            self._notes_shown.add(why)
            engine = self._engine()
            report.note(why, engine.report if engine is not None else None)
        return why is None

    def draw(self, context, depsgraph) -> None:
        import gpu
        from gpu_extras.presets import draw_texture_2d

        engine = self._engine()
        if engine is None or self._settings is None:
            return
        camera = view_camera(context.region, context.region_data)
        key = _view_key(camera)
        # A change of TOYRT's settings alone (samples, seed, Viewport Denoise...) brings no
        # view_update: it is seen here, as the view is.
        settings = self._render_settings(depsgraph.scene)
        if settings != self._settings:
            self._settings, self._stale = settings, True
        if self._stale or key != self._view:
            self._restart(camera, key)
        if self.error is not None:
            engine.update_stats("", f"TOYRT: {self.error}")  # the viewport's header text, as Cycles' status
        latest = self._latest
        if latest is None:
            return
        version, image, _ = latest
        if self._drawn is None or self._drawn[0] != version:
            h, w = image.shape[:2]
            # GL rows go from the bottom; a numpy array is handed over as a buffer, not a list.
            pixels = np.ascontiguousarray(image[::-1]).ravel()
            data = gpu.types.Buffer("FLOAT", pixels.size, pixels)
            texture = gpu.types.GPUTexture((w, h), format="RGBA16F", data=data)
            self._drawn = (version, texture)
        texture = self._drawn[1]
        gpu.state.blend_set("ALPHA_PREMULT")
        engine.bind_display_space_shader(depsgraph.scene)
        # The coarse pass's small texture is stretched over the region.
        draw_texture_2d(texture, (0, 0), context.region.width, context.region.height)
        engine.unbind_display_space_shader()
        gpu.state.blend_set("NONE")

    def close(self) -> None:
        """Stop and join the render thread, drop the texture and the native scene."""
        self._engine = lambda: None
        self._stop_thread()
        self._drawn = None
        self._latest = None
        _sessions.discard(self)
        from . import release_cached_memory
        from .sync import SceneSync

        # The native scene freed now (an update after a close syncs a new one from scratch), so
        # that its arrays are among what the release gives back: the edits' re-commits reused
        # that memory, and nothing does now.
        self.cache = SceneSync(self.cache.toyrt)
        release_cached_memory()

    @property
    def rendering(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    # ---- the render thread -------------------------------------------------------------------------
    def _restart(self, camera, key):
        import time

        self._stop_thread()
        self.error = None
        self._stale = False
        self._view = key
        self.samples_done = 0
        self.restarts += 1
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, args=(camera, dict(self._settings), self._stop,
                                                                time.perf_counter()),
                                        name="toyrt-viewport", daemon=True)
        self._thread.start()

    def _stop_thread(self):
        if self._thread is not None:
            self._stop.set()
            self._thread.join()
            self._thread = None

    def _run(self, camera, settings, stop, started):
        import time

        from . import denoise

        scene = self.cache.scene
        target = settings.pop("samples")
        denoising = settings.pop("denoise")
        version = 0
        try:
            w, h = camera["resolution_x"], camera["resolution_y"]
            coarse = dict(camera, resolution_x=max(1, w // COARSE_DIVIDER), resolution_y=max(1, h // COARSE_DIVIDER))
            image = scene.render(coarse, samples=1, should_cancel=stop.is_set, **settings)
            if stop.is_set():
                return
            self.first_pass_ms = (time.perf_counter() - started) * 1000.0
            version += 1
            self._publish(version, image, 0)
            total, done, count = None, 0, 1
            aux = {}
            while done < target and not stop.is_set():
                count = min(count, target - done)
                image = scene.render(camera, samples=count, first_sample=done, should_cancel=stop.is_set,
                                     passes=list(denoise.AUXILIARIES) if denoising else None, **settings)
                if scene.last_render["cancelled"]:
                    return
                image *= count
                total = image if total is None else total + image
                if denoising:
                    # The albedo and normal of every sample so far, weighted as the image is.
                    for name in denoise.AUXILIARIES:
                        aux[name] = aux.get(name, 0.0) + scene.last_passes[name] * count
                done += count
                version += 1
                self.samples_done = done
                self.passes += 1
                mean = total / done
                if denoising:
                    mean = denoise.denoise(mean, {name: value / done for name, value in aux.items()})
                    self.denoised_passes += 1
                self._publish(version, mean, done)
                count = min(count * 2, MAX_PASS_SAMPLES)
        except Exception as err:  # shown by draw() in the view's header; the thread ends either way
            self.error = str(err)
            report.error(f"viewport render failed: {err}")

    def _publish(self, version, image, samples):
        self._latest = (version, image, samples)  # one assignment: view_draw sees old or new, whole
        engine = self._engine()
        if engine is not None:
            try:
                engine.tag_redraw()  # only sets a flag Blender's event loop reads: safe off the main thread
            except ReferenceError:  # the engine was freed meanwhile; close() is joining this thread
                pass
