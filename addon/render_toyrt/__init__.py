# TOYRT add-on for Blender (legacy add-on layout: a package in the user's scripts/addons folder).
#
# `make setup` copies this folder there together with the native module built from native/
# (build/python/toyrt.cpython-311-x86_64-linux-gnu.so), so the module sits beside this file and
# imports as `render_toyrt.toyrt`. It is built for Debian's Python 3.11, the one Blender 3.4 runs.
#
# For now the add-on only loads the native module; the RenderEngine comes with a later issue.

bl_info = {
    "name": "TOYRT",
    "author": "TOYRT developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "description": "Ray-tracing render engine with a fast, exact native C++ core",
    "category": "Render",
}

_native = None  # the imported native module, once native() has succeeded


def native():
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


def register():
    # Load the native module now so a broken install shows up at once, but never let it stop
    # Blender or the add-on from loading: print the reason and carry on.
    try:
        native()
    except Exception as err:  # ImportError above, or anything the module's own init raises
        print(err if isinstance(err, ImportError) else f"TOYRT: loading the native module failed: {err!r}")


def unregister():
    # Nothing registered with Blender yet. An extension module cannot be unloaded from a
    # running Python, so the native module stays imported until Blender exits.
    pass
