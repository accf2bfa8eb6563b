# TOYRT add-on for Blender: a render engine with a fast, exact native core.
#
# Installs as a legacy add-on (bl_info, a package in scripts/addons) and as a 4.2+ extension
# (blender_manifest.toml). `make setup` copies this folder there together with the native module
# built from native/ (toyrt.cpython-311-x86_64-linux-gnu.so), so the module sits beside this file
# and imports as `render_toyrt.toyrt`; it is built for Debian's Python 3.11, Blender 3.4's.
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


def native() -> types.ModuleType:
    """Return the native `toyrt` module shipped in this add-on's folder, importing it on first use.

    Raises ImportError with a hint when the module is missing or cannot be loaded (for example
    built for another Python), so callers fail with a message rather than an obscure error.
    """
    global _native
    if _native is None:
        try:
            from . import toyrt  # the extension module beside this file
        except ImportError as err:
            raise ImportError(
                f"TOYRT: cannot import the native module from {__path__[0]} ({err}); "
                "build and install it with `make setup` in the TOYRT repository"
            ) from err
        _native = toyrt
    return _native


def register() -> None:
    from . import engine, properties, ui

    properties.register()
    engine.register()
    ui.register()
    # Load the native module now so a broken install shows up at once, but never let it stop
    # Blender or the add-on from loading: the engine reports the error when asked to render.
    try:
        native()
    except Exception as err:  # ImportError above, or anything the module's own init raises
        print(err if isinstance(err, ImportError) else f"TOYRT: loading the native module failed: {err!r}")


def unregister() -> None:
    from . import engine, properties, ui

    ui.unregister()
    engine.unregister()
    properties.unregister()
    # An extension module cannot be unloaded from a running Python: it stays imported until exit.
