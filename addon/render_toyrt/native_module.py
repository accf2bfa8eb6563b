"""Where the add-on's native module `toyrt` comes from, and what the user is told when it cannot load.

The add-on ships in two forms (docs/install.md), with the module in a different place in each:
  - the legacy add-on (the zip for Blender 3.4-4.1, and `make setup`): the module sits in this
    folder and imports as `render_toyrt.toyrt` (`make setup`: one toyrt*.so; the zip: the wheel's
    package toyrt/, a module per CPU level, native/python/toyrt/__init__.py);
  - the extension (Blender 4.2+): the module comes from the wheel listed in blender_manifest.toml,
    which Blender installs into the extension's site-packages, and imports as `toyrt`.
Trying the folder first keeps a developer's fresh build ahead of any wheel. A module that another
copy of the add-on already imported in this Blender session (the extension, then the legacy add-on
enabled after it) is reused: pybind11 refuses to register the same types twice, and the failed
second load leaves the heap corrupt (an abort at exit). A module built for
another Python (a 3.11 .so under Blender 5.1+'s 3.13) fails with "No module named"; the message then
names both Pythons, since that is the failure users of other engines meet most.
"""
import glob
import os
import re
import sys
import types

HERE = os.path.dirname(os.path.abspath(__file__))


def load() -> types.ModuleType:
    """The native module, from this folder or from site-packages; ImportError saying why not."""
    loaded = already_loaded()
    if loaded is not None:
        return loaded
    failures = []
    try:
        from . import toyrt  # the legacy add-on: the .so beside this file
        return toyrt
    except ImportError as err:
        failures.append(f"in {HERE}: {err}")
    try:
        import toyrt  # the extension: its wheel, installed by Blender into site-packages
        return toyrt
    except ImportError as err:
        failures.append(f"from site-packages: {err}")
    raise ImportError(explain(failures))


def already_loaded() -> types.ModuleType | None:
    """A native toyrt module (or the wheels' package of them) imported in this process under any
    name (`toyrt`, `<package>.toyrt`); a failed import leaves nothing in sys.modules."""
    for name, module in list(sys.modules.items()):
        if (name == "toyrt" or name.endswith(".toyrt")) and hasattr(module, "Scene"):
            return module
    return None


def explain(failures: list[str]) -> str:
    """One message for the console and the UI: what was tried, and the likely fix."""
    running = f"{sys.version_info.major}.{sys.version_info.minor}"
    found = sorted(os.path.basename(p) for pattern in ("toyrt*.so", os.path.join("toyrt", "_core_*.so"))
                   for p in glob.glob(os.path.join(HERE, pattern)))
    built_for = {f"{m[1]}.{m[2]}" for f in found if (m := re.search(r"cpython-(\d)(\d+)", f))}
    files = found[0] + (f" and {len(found) - 1} more" if len(found) > 1 else "") if found else ""
    if built_for and running not in built_for:
        hint = (f"the module in the add-on ({files}) is built for Python {', '.join(sorted(built_for))}, "
                f"but this Blender runs Python {running}: install the TOYRT extension for Blender 4.2+ "
                "(render_toyrt-*-linux_x64.zip), or the legacy zip made for this Blender's Python")
    elif found:
        hint = f"the module in the add-on ({files}) does not load on this system"
    else:
        hint = (f"no native module for Python {running} was found: install TOYRT from its release zip "
                "(docs/install.md), or build it with `make setup` in the TOYRT repository")
    return f"TOYRT: cannot import the native module: {hint} ({'; '.join(failures)})"
