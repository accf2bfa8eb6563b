"""Installs the legacy add-on zip into Debian's Blender 3.4 as a user of Blender 3.4-4.1 does
(Preferences > Add-ons > Install: `bpy.ops.preferences.addon_install`), into empty user folders,
and renders the closed-form scene with it (`make test-package`, docs/install.md):

    /usr/bin/python3 tests/package/install_legacy.py dist/render_toyrt-0.1.0-legacy-linux_x64.zip [--blender blender]

Run with a plain Python, this starts `blender -b` on itself with BLENDER_USER_SCRIPTS and
BLENDER_USER_CONFIG pointing at a new temporary folder (an empty BLENDER_USER_CONFIG alone would
still let Blender see the add-on `make setup` installed in ~/.config/blender); inside Blender it
runs the checks.
"""
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent


def launch():
    import argparse
    import shutil

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("zip", help="the legacy add-on zip")
    parser.add_argument("--blender", default="blender")
    args = parser.parse_args()
    home = Path(tempfile.mkdtemp(prefix="toyrt-legacy-"))
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(home / "scripts"), BLENDER_USER_CONFIG=str(home / "config"))
    for name in ("BLENDER_USER_RESOURCES", "BLENDER_USER_EXTENSIONS", "BLENDER_USER_DATAFILES"):
        env.pop(name, None)
    command = [args.blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", __file__, "--",
               str(Path(args.zip).resolve()), str(home)]
    try:
        run = subprocess.run(command, env=env)
        if run.returncode == 0:
            run = without_an_opencl_driver(command, env, home)
    finally:
        shutil.rmtree(home, ignore_errors=True)
    sys.exit(run.returncode)


def without_an_opencl_driver(command, env, home):
    """A user machine with no OpenCL driver (OCL_ICD_VENDORS: an empty folder, so the zip's bundled
    loader finds no platform) and the LBVH builder asked for: the host builds it (the kernels run on
    OpenCL GPUs only), so the render says nothing about LBVH or OpenCL, no words a farm's strict
    mode fails on, and the closed form still holds."""
    vendors = home / "no-opencl-vendors"
    vendors.mkdir()
    run = subprocess.run(command + ["--lbvh"], env=dict(env, OCL_ICD_VENDORS=str(vendors)),
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print(run.stdout, end="")
    lines = run.stdout.splitlines()
    notes = [line for line in lines if "LBVH" in line]
    # AWS Deadline Cloud's strict mode (docs/farm.md), on the lines naming TOYRT, LBVH or OpenCL
    # (Blender's own start-up lines are not TOYRT's to judge).
    strict = [line for line in lines if re.search("TOYRT|LBVH|OpenCL", line)
              and re.search(r"Exception:|Error:|Warning", line)]
    ok = run.returncode == 0 and not notes and not strict
    print(f"{'ok  ' if ok else 'FAIL'}  without an OpenCL driver the LBVH builds on the host, with nothing said "
          f"({notes[:1]}; lines a strict farm parser fails on: {strict[:2]})")
    return run if run.returncode else subprocess.CompletedProcess(run.args, 0 if ok else 1)


def inside_blender():
    import addon_utils
    import bpy

    sys.path[:0] = [str(HERE.parent / "blender"), str(HERE.parent.parent / "scenes")]
    from closed_form import build_scene, denoiser_lowers_noise, render_error
    from harness import check, run_script

    zip_path, home = (Path(p) for p in sys.argv[sys.argv.index("--") + 1:][:2])
    lbvh = "--lbvh" in sys.argv[sys.argv.index("--") + 1:]

    def the_legacy_zip_installs_and_renders():
        engines = [c for c in bpy.types.RenderEngine.__subclasses__() if getattr(c, "bl_idname", "") == "TOYRT"]
        check(not engines and not any(a.module == "render_toyrt" for a in bpy.context.preferences.addons),
              f"Blender {bpy.app.version_string} starts without TOYRT (empty user folders)")
        result = bpy.ops.preferences.addon_install(filepath=str(zip_path))
        check(result == {"FINISHED"} and (home / "scripts" / "addons" / "render_toyrt" / "__init__.py").exists(),
              "addon_install put the add-on into the empty BLENDER_USER_SCRIPTS")
        mod = addon_utils.enable("render_toyrt", default_set=True, handle_error=lambda err: print(err))
        check(mod is not None and mod.load_error == "", "it enables, and its native module loads")
        toyrt = mod.native()
        # The wheel's package toyrt/ inside the add-on, with the module of the CPU level it picked.
        core = Path(toyrt._core.__file__)
        check(core.parent == home / "scripts" / "addons" / "render_toyrt" / "toyrt",
              f"the module is the zip's, inside the add-on folder ({core}, CPU level {toyrt.cpu_level})")
        check(list(core.parent.glob(f"_core_{toyrt.cpu_level}.cpython-310-*.so")),
              "beside the modules for Python 3.10 (blender.org's Blender 3.4-4.0)")
        with open("/proc/self/maps") as f:
            tbb = {line.split()[-1] for line in f if "libtbb" in line}
        # Debian's Blender links the system's TBB itself: the module's own copy loads beside it.
        check(any("/render_toyrt/toyrt.libs/" in p for p in tbb), f"with its bundled TBB ({sorted(tbb)})")
        build_scene()
        if lbvh:
            bpy.context.scene.toyrt.builder = "lbvh"
        err = render_error(home / "legacy.exr")
        check(err < 0.01, f"the render matches I cos / r^2 (max error {err:.4f} of the peak;"
              f" builder {bpy.context.scene.toyrt.builder})")
        ok, where, noise = denoiser_lowers_noise("render_toyrt")
        check(ok and "/render_toyrt/vendor/pyoidn/" in where,
              f"the zip's Open Image Denoise loads from its vendor/ folder and denoises ({where}; noise {noise})")

    run_script([the_legacy_zip_installs_and_renders], f"legacy add-on (Blender {bpy.app.version_string})")


if __name__ == "__main__":
    if "bpy" in sys.modules:  # run by blender --python
        inside_blender()
    else:
        launch()
