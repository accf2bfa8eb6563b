"""Installs the release zips into a current Blender as a user does, and renders with them: the `bpy`
module from PyPI (Blender 5.0.1 on Python 3.11 in .venv, 5.3.0 on 3.13 in .venv-3.13), an empty
user folder (BLENDER_USER_RESOURCES), the extension zip through Blender's own extension API
(`bpy.ops.extensions.package_install_files(..., enable_on_install=True)`), so its wheel is
installed by Blender, not by us (`make test-package`, docs/install.md):

    .venv-3.13/bin/python tests/package/install_extension.py dist/render_toyrt-0.1.0-linux_x64.zip \
        dist/render_toyrt-0.1.0-legacy-linux_x64.zip

With the bad inputs: the legacy zip (modules for Python 3.10 and 3.11) on 3.13 (a message naming both
Pythons, a render that fails cleanly), the extension installed twice, the legacy add-on enabled
beside it (refused with a message; the extension keeps rendering), then the legacy add-on alone.
"""
import atexit
import os
import shutil
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXTENSION_ZIP, LEGACY_ZIP = (Path(p).resolve() for p in sys.argv[1:3])
home = Path(tempfile.mkdtemp(prefix="toyrt-ext-"))
# Removed after Blender's exit handlers (registered later, by `import bpy`, so run earlier): they
# disable the add-ons, whose unregister() still imports from this folder.
atexit.register(shutil.rmtree, home, True)
# Blender reads these when bpy is imported: everything of the user's (config, scripts, extensions)
# under one empty folder; the other variables would override parts of it, so they go.
for name in ("BLENDER_USER_CONFIG", "BLENDER_USER_SCRIPTS", "BLENDER_USER_EXTENSIONS", "BLENDER_USER_DATAFILES"):
    os.environ.pop(name, None)
os.environ["BLENDER_USER_RESOURCES"] = str(home)

import bpy  # noqa: I001  (Blender starts here, reading the variables above)
import addon_utils

sys.path[:0] = [str(HERE.parent / "blender"), str(HERE.parent.parent / "scenes")]
from closed_form import build_scene, denoiser_lowers_noise, render_error
from harness import captured_output, check, run_script

EXT_MODULE = "bl_ext.user_default.render_toyrt"
PYTHON = f"{sys.version_info.major}.{sys.version_info.minor}"


def toyrt_engines():
    """The registered render engines named TOYRT: (the module defining each)."""
    return [cls.__module__ for cls in bpy.types.RenderEngine.__subclasses__()
            if getattr(cls, "bl_idname", None) == "TOYRT" and cls.is_registered]


def install_extension():
    """One install of the extension zip into the user repository, enabled on install."""
    with captured_output() as out:
        result = bpy.ops.extensions.package_install_files(filepath=str(EXTENSION_ZIP), repo="user_default",
                                                          enable_on_install=True)
    return result, out[0]


def the_extension_installs_and_renders():
    check(toyrt_engines() == [], f"Blender {bpy.app.version_string} (Python {PYTHON}) starts without TOYRT")
    result, log = install_extension()
    check(result == {"FINISHED"}, f"package_install_files finished ({result})")
    enabled = {a.module for a in bpy.context.preferences.addons}
    check(EXT_MODULE in enabled, f"{EXT_MODULE} is enabled ({sorted(enabled)})")
    check(toyrt_engines() == [f"{EXT_MODULE}.engine"], f"one TOYRT engine, the extension's ({toyrt_engines()})")
    addon = sys.modules[EXT_MODULE]
    toyrt = addon.native()
    # The wheel, installed by Blender into the extensions' own site-packages under the user folder.
    check(Path(toyrt.__file__).is_relative_to(home) and "site-packages" in toyrt.__file__,
          f"toyrt is imported from the wheel Blender installed ({toyrt.__file__})")
    core = toyrt._core.__file__  # the module of the CPU level the wheel's package picked
    check(f"cpython-{PYTHON.replace('.', '')}" in core, f"the wheel for Python {PYTHON} ({Path(core).name})")
    check(addon.load_error == "", "no load error")
    build_scene()
    err = render_error(home / "extension.exr")
    check(err < 0.01, f"the render matches I cos / r^2 (max error {err:.4f} of the peak)")
    # Blender installed the denoiser's wheels beside toyrt's (a venv's own pyoidn may come first on the path).
    installed = sorted(p.parent.name for p in home.rglob("site-packages/*/__init__.py")
                       if p.parent.name in ("pyoidn", "cffi", "pycparser"))
    check(len(installed) == 3, f"pyoidn, cffi and pycparser are installed from the extension's wheels ({installed})")
    ok, where, noise = denoiser_lowers_noise(EXT_MODULE)
    check(ok, f"and Open Image Denoise denoises ({where}; noise {noise})")


def the_farm_recipe_enables_it_with_addons():
    """`blender -b --addons bl_ext.user_default.render_toyrt ...` (docs/farm.md) on a worker where the
    extension is installed but not enabled: Blender hands the argument to
    _bpy_internal.addons.cli.set_from_cli, called here as the command line does."""
    from _bpy_internal.addons.cli import set_from_cli

    addon_utils.disable(EXT_MODULE, default_set=True)
    check(toyrt_engines() == [], "the extension installed but disabled: no TOYRT engine")
    set_from_cli(EXT_MODULE)
    check(toyrt_engines() == [f"{EXT_MODULE}.engine"], f"--addons {EXT_MODULE} enables it ({toyrt_engines()})")
    build_scene()
    err = render_error(home / "addons.exr")
    check(err < 0.01, f"and it renders the closed form (max error {err:.4f})")
    # The rest runs as a user left it: enabled in the preferences (--addons does not save it there).
    addon_utils.disable(EXT_MODULE)
    addon_utils.enable(EXT_MODULE, default_set=True)
    check(toyrt_engines() == [f"{EXT_MODULE}.engine"], "enabled again from the preferences")


def installing_it_again_keeps_one_working_copy():
    result, log = install_extension()
    check(result == {"FINISHED"}, f"the second install finished ({result})")
    check(toyrt_engines() == [f"{EXT_MODULE}.engine"], f"still one TOYRT engine ({toyrt_engines()})")
    build_scene()
    err = render_error(home / "again.exr")
    check(err < 0.01, f"it still renders the closed form (max error {err:.4f})")


def the_legacy_addon_beside_it_is_refused():
    bpy.ops.preferences.addon_install(filepath=str(LEGACY_ZIP))
    with captured_output() as out:
        mod = addon_utils.enable("render_toyrt", default_set=True, handle_error=lambda err: print(err))
    check(mod is None or "render_toyrt" not in {a.module for a in bpy.context.preferences.addons},
          "enabling the legacy add-on beside the extension fails")
    check(f"TOYRT is already enabled from {EXT_MODULE}" in out[0],
          "with a message naming the enabled extension: " + next(
              (line for line in out[0].splitlines() if "already enabled" in line), out[0][-300:]))
    check(toyrt_engines() == [f"{EXT_MODULE}.engine"], f"the extension's engine stays ({toyrt_engines()})")
    build_scene()
    err = render_error(home / "beside.exr")
    check(err < 0.01, f"and still renders (max error {err:.4f})")


def the_legacy_addon_for_another_python_says_so():
    """Blender 5.1+ (Python 3.13) given the legacy zip, whose modules are for 3.10 and 3.11. Run first, while no
    wheel is installed: nothing else could supply a module."""
    if PYTHON == "3.11":
        print("  skipped: the legacy zip's module is for this Python (the last part checks that it loads)")
        return
    bpy.ops.preferences.addon_install(filepath=str(LEGACY_ZIP))
    with captured_output() as out:
        mod = addon_utils.enable("render_toyrt", default_set=True, handle_error=lambda err: print(err))
    check(mod is not None and toyrt_engines() == ["render_toyrt.engine"], "the add-on itself enables")
    # A clear message at enable time, kept for the TOYRT panel and printed on the console ...
    check("built for Python 3.10, 3.11" in mod.load_error and f"runs Python {PYTHON}" in mod.load_error
          and "extension" in mod.load_error, f"the load error names both Pythons: {mod.load_error[:150]}...")
    check(mod.load_error in out[0], "and is printed on the console")
    # ... and a render that fails with it instead of crashing.
    build_scene()
    with captured_output() as out:
        try:
            bpy.ops.render.render(write_still=False)
            raised = ""
        except RuntimeError as err:
            raised = str(err)
    check("built for Python 3.10, 3.11" in raised + out[0], "a render reports the same error and Blender goes on")
    addon_utils.disable("render_toyrt", default_set=True)
    check(toyrt_engines() == [], "the legacy add-on disabled")


def the_legacy_addon_alone_enables_after_the_extension():
    addon_utils.disable(EXT_MODULE, default_set=True)
    check(toyrt_engines() == [], "the extension disabled")
    mod = addon_utils.enable("render_toyrt", default_set=True, handle_error=lambda err: print(err))
    check(mod is not None and toyrt_engines() == ["render_toyrt.engine"], "the legacy add-on enables alone")
    # A native module loads once per process: the one the extension imported is reused (loading the
    # add-on's own copy beside it would fail, and on 3.13 it is for the wrong Python anyway).
    where = mod.native().__file__
    check(mod.native() is sys.modules["toyrt"] and mod.load_error == "",
          f"it reuses the module the extension loaded ({where})")
    build_scene()
    err = render_error(home / "legacy.exr")
    check(err < 0.01, f"and renders the closed form (max error {err:.4f})")


run_script([the_legacy_addon_for_another_python_says_so, the_extension_installs_and_renders,
            the_farm_recipe_enables_it_with_addons, installing_it_again_keeps_one_working_copy,
            the_legacy_addon_beside_it_is_refused,
            the_legacy_addon_alone_enables_after_the_extension],
           f"extension (Blender {bpy.app.version_string}, Python {PYTHON})")
