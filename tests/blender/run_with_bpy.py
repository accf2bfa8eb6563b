# Runs one Blender test file (tests/blender/test_*.py) under the `bpy` module from PyPI (Blender
# 4.x/5.x as a Python package, installed into .venv by requirements-test.txt) instead of inside
# Debian's Blender 3.4, so the API changes of current Blender are exercised, not guessed:
#
#   .venv/bin/python tests/blender/run_with_bpy.py tests/blender/test_export.py --build build
#
# (`make test-bpy`, part of `make test`, runs every test file this way.)
#
# bpy is imported once per process and keeps its state, so each test file gets its own process,
# as each gets its own `blender -b` under 3.4. Before the import, Blender's user folders are
# pointed at a temporary directory (the user's own ~/.config/blender is never read or written);
# the add-on folder is copied there with the built native module beside it, exactly as
# scripts/install-addon.sh installs it, and enabled with addon_utils. Then the test file runs as
# __main__; its exit status (the tests end with sys.exit) is this process's status.
#
# The bpy module has no blender executable (bpy.app.binary_path is empty): the tests skip their
# command-line parts (`blender -b file.blend -E TOYRT ...`) when TOYRT_NO_BLENDER_BINARY is set,
# and say so.
import argparse
import atexit
import glob
import os
import runpy
import shutil
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ADDON = "render_toyrt"


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("test", help="a tests/blender/test_*.py file")
    parser.add_argument("--build", default="build", help="build folder holding python/toyrt*.so")
    parser.add_argument("--addon", default=str(REPO / "addon" / ADDON), help="the add-on folder to install")
    args, rest = parser.parse_known_args()   # the rest goes to the test as its sys.argv[1:]

    build = Path(args.build) if os.path.isabs(args.build) else REPO / args.build
    modules = glob.glob(str(build / "python" / "toyrt*.so"))
    if len(modules) != 1:
        sys.exit(f"run_with_bpy: expected one {build}/python/toyrt*.so, found {len(modules)} (make native first)")

    home = Path(tempfile.mkdtemp(prefix="toyrt-bpy-"))
    # Removed at exit, after Blender's own exit handlers (registered later by `import bpy`, so run
    # earlier): they disable the add-on, whose unregister() still imports from this folder.
    atexit.register(shutil.rmtree, home, True)
    scripts = home / "scripts"
    addon_dir = scripts / "addons" / ADDON
    shutil.copytree(args.addon, addon_dir, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    shutil.copy2(modules[0], addon_dir)
    # Read by Blender when bpy is imported: the user scripts folder (with addons/ in it) and
    # a throw-away config folder, so nothing of the user's Blender setup is involved.
    os.environ["BLENDER_USER_SCRIPTS"] = str(scripts)
    os.environ["BLENDER_USER_CONFIG"] = str(home / "config")
    os.environ["BLENDER_USER_EXTENSIONS"] = str(home / "extensions")
    os.environ["TOYRT_NO_BLENDER_BINARY"] = "1"
    # The parity test keeps its Cycles references in the build folder it is given.
    os.environ.setdefault("TOYRT_BUILD_DIR", str(build))

    import bpy  # noqa: F401, I001  (Blender starts here: before addon_utils)
    import addon_utils

    if str(scripts / "addons") not in sys.path:
        sys.path.append(str(scripts / "addons"))   # in case this Blender did not add it
    mod = addon_utils.enable(ADDON, default_set=True, handle_error=None)
    if mod is None:
        sys.exit(f"run_with_bpy: addon_utils.enable('{ADDON}') failed")
    print(f"run_with_bpy: Blender {bpy.app.version_string} (bpy module), add-on from {mod.__file__}", flush=True)

    test = Path(args.test).resolve()
    sys.argv = [str(test)] + rest
    code = 0
    try:
        runpy.run_path(str(test), run_name="__main__")
    except SystemExit as stop:
        code = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
    sys.stdout.flush()
    sys.exit(code)


if __name__ == "__main__":
    main()
