"""Final renders: one SceneSync (sync.py) per Blender scene, so the frames of an animation
rendered in one Blender process reuse what did not change (Blender makes a new engine object for
every F12; an animation's frames share one engine and depsgraph on 3.4, but not their mesh
datablocks)."""
from .sync import SceneSync

_render_caches: dict[int, SceneSync] = {}


def _scene_key(depsgraph) -> int:
    scene = depsgraph.scene
    return (getattr(scene, "original", scene) or scene).as_pointer()


def for_render(depsgraph, toyrt) -> SceneSync:
    """The final-render SceneSync of the depsgraph's scene (made on first use)."""
    key = _scene_key(depsgraph)
    cache = _render_caches.get(key)
    if cache is None:
        _render_caches.clear()  # one scene at a time: another scene's meshes are not kept alive
        cache = _render_caches[key] = SceneSync(toyrt)
    return cache


def discard_render_cache(depsgraph) -> None:
    """Drops the scene's SceneSync after a cancelled sync (it may be half updated)."""
    _render_caches.pop(_scene_key(depsgraph), None)


def free_render_caches() -> None:
    """On file load and unregister: the Blender data the keys point to is gone."""
    _render_caches.clear()


def render_caches() -> list[SceneSync]:
    """The final-render SceneSyncs alive (at most one), for tests and statistics."""
    return list(_render_caches.values())
