# TOYRT add-on for Blender: a render engine with a fast, exact native core.
#
# Installs as a legacy add-on (bl_info, a package in scripts/addons: the zip for Blender 3.4-4.1
# and `make setup`, with the native module built from native/ beside this file) and as a 4.2+
# extension (blender_manifest.toml, the module from its wheel); native_module.py finds it in either.
# Blender ignores bl_info in an extension (addon_utils removes it), so one folder serves both.
#
# The parts: properties.py (settings at scene.toyrt), ui.py (panels), sync.py (the one walker of
# the depsgraph and the one writer of the native scene) over the converters that return plain
# data (mesh.py, materials.py, lights.py, world.py, camera.py), engine.py (the render loop) and
# viewport.py (the 3D viewport's Rendered mode). No rendering logic in Python.

import types

bl_info = {
    "name": "TOYRT",
    "author": "TOYRT developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "description": "Ray-tracing render engine with a fast, exact native C++ core",
    "category": "Render",
}

_native = None  # the imported native module, once native() has succeeded
load_error = ""  # why the module did not load at register(), for the TOYRT panel; "" when it did


def native() -> types.ModuleType:
    """Return the native `toyrt` module (native_module.py: beside this file, or from the
    extension's wheel), importing it on first use.

    Raises ImportError saying what was tried and the likely fix (for example a module built for
    another Python), so callers fail with a message rather than an obscure error.
    """
    global _native
    if _native is None:
        from . import native_module

        _native = native_module.load()
    return _native


def release_cached_memory() -> None:
    """Gives back the memory the native module keeps for the next commit (freed BVH and commit
    arrays, up to a 32nd of the machine's memory): after every final render, and when a viewport render
    stops. A no-op when the module cannot be imported (whoever needed it has reported why) or
    predates the call (a stale module beside the add-on): never an error after a good render."""
    try:
        release = getattr(native(), "release_cached_memory", None)
    except ImportError:
        return
    if release is not None:
        release()


def _other_copy() -> str:
    """The module name and folder of another enabled copy of TOYRT (the legacy add-on beside the extension, or the
    reverse), or "". Both would register the engine "TOYRT" and scene.toyrt, and disabling one
    would unregister the other's engine."""
    import os
    import sys

    import bpy

    for cls in bpy.types.RenderEngine.__subclasses__():
        package = cls.__module__.rpartition(".")[0]
        if getattr(cls, "bl_idname", None) == "TOYRT" and cls.is_registered and package != __name__:
            where = getattr(sys.modules.get(package), "__file__", None)
            return f"{package} ({os.path.dirname(where)})" if where else package
    return ""


def register() -> None:
    from . import engine, properties, ui

    other = _other_copy()
    if other:
        # Raised before anything is registered: Blender shows it where the add-on is enabled.
        raise RuntimeError(f"TOYRT is already enabled from {other}: disable or remove that copy first "
                           "(Preferences > Add-ons), then enable this one")
    properties.register()
    engine.register()
    ui.register()
    # Load the native module now so a broken install shows up at once, but never let it stop
    # Blender or the add-on from loading: the engine reports the error when asked to render.
    global load_error
    try:
        native()
        load_error = ""
    except Exception as err:  # ImportError above, or anything the module's own init raises
        load_error = str(err) if isinstance(err, ImportError) else f"TOYRT: loading the native module failed: {err!r}"
        print(load_error, flush=True)


def unregister() -> None:
    from . import engine, properties, ui

    ui.unregister()
    engine.unregister()
    properties.unregister()
    # An extension module cannot be unloaded from a running Python: it stays imported until exit.
