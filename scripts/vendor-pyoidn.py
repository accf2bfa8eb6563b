"""Vendors Intel Open Image Denoise for a Blender whose Python cannot pip-install it: the pyoidn
binding (PyPI, MIT, OIDN bundled), cffi, which it loads OIDN with, and cffi's pycparser, into one
folder that the add-on puts first on sys.path when it denoises (addon/render_toyrt/denoise.py:
first, since a system may hold another cffi's compiled half, Debian's among them). Used for Debian's Blender 3.4
(`make setup`: scripts/install-addon.sh, Python 3.11, whose system Python is externally managed)
and the legacy add-on zip (scripts/build-extension.py: Pythons 3.10 and 3.11, blender.org's
Blender 3.4-4.1).

pyoidn is one py3 wheel for every Python; cffi is compiled per Python, and the compiled modules of
several Pythons can share one folder (each carries its ABI tag in its file name). Only the CPU
device of OIDN is kept: the GPU devices (CUDA, HIP, SYCL, Level Zero: about 120 MB of the wheel's
180 MB) and the command-line tools are left out, so the folder holds 56 MB.

    python scripts/vendor-pyoidn.py --target build/vendor --python 3.11
"""
import argparse
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
# What OIDN's CPU device needs in pyoidn/oidn/lib: the library pyoidn opens, the core it links, the
# CPU device the core opens by name, and TBB, which that device links.
KEEP_LIBS = re.compile(r"^lib(OpenImageDenoise\.so|OpenImageDenoise_core\.so\..*|OpenImageDenoise_device_cpu\.so\..*"
                       r"|tbb\.so\.12)$")
STAMP = "VENDORED.txt"


def pinned(name: str) -> str:
    """The version requirements-test.txt pins (the one the tests under bpy use)."""
    for line in (REPO / "requirements-test.txt").read_text().splitlines():
        if line.split("==")[0].strip().lower() == name:
            return line.strip()
    sys.exit(f"vendor-pyoidn: {name} is not pinned in requirements-test.txt")


def pip_target(target: Path, requirement: str, python: str | None = None) -> None:
    cmd = [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--only-binary=:all:", "--upgrade",
           "--target", str(target), requirement]
    if python:
        cmd += ["--python-version", python, "--implementation", "cp", "--platform", "manylinux2014_x86_64"]
    subprocess.run(cmd, check=True)


def prune(pyoidn: Path) -> None:
    """The CPU device only: no GPU devices, tools, headers or CMake files."""
    for sub in ("bin", "include", "lib/cmake", "share"):
        shutil.rmtree(pyoidn / "oidn" / sub, ignore_errors=True)
    for lib in (pyoidn / "oidn" / "lib").iterdir():
        if not KEEP_LIBS.match(lib.name):
            lib.unlink()
    shutil.rmtree(pyoidn / "__pycache__", ignore_errors=True)


def vendor(target: Path, pythons: list[str]) -> None:
    requirements = [pinned("pyoidn"), pinned("cffi"), pinned("pycparser")]
    stamp = "\n".join(requirements + [f"python {p}" for p in pythons]) + "\n"
    if (target / STAMP).is_file() and (target / STAMP).read_text() == stamp:
        print(f"vendor-pyoidn: {target} is up to date")
        return
    # Staged beside the target (the same file system), then moved in whole.
    with tempfile.TemporaryDirectory(prefix="toyrt-vendor-", dir=target.parent) as tmp:
        stage = Path(tmp) / "vendor"
        pip_target(stage, requirements[0])
        pip_target(stage, requirements[2])  # cffi's C parser, pure Python
        for python in pythons:
            # One folder for every Python: a later install of the same cffi adds its compiled module.
            cffi_stage = Path(tmp) / f"cffi-{python}"
            pip_target(cffi_stage, requirements[1], python)
            shutil.copytree(cffi_stage, stage, dirs_exist_ok=True)
        prune(stage / "pyoidn")
        shutil.rmtree(stage / "bin", ignore_errors=True)  # pip's console scripts: nothing a Blender runs
        for cache in list(stage.rglob("__pycache__")):
            shutil.rmtree(cache)
        for meta in stage.glob("*.dist-info"):
            (meta / "RECORD").unlink(missing_ok=True)  # it lists the files pruned above
        (stage / STAMP).write_text(stamp)
        shutil.rmtree(target, ignore_errors=True)
        shutil.move(str(stage), str(target))
    size = sum(f.stat().st_size for f in target.rglob("*") if f.is_file())
    print(f"vendor-pyoidn: {target} holds {', '.join(requirements)} for Python {', '.join(pythons)} "
          f"({size / 1e6:.0f} MB)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--target", type=Path, required=True)
    parser.add_argument("--python", action="append", required=True, help="a Python version, e.g. 3.11 (repeatable)")
    args = parser.parse_args()
    args.target.parent.mkdir(parents=True, exist_ok=True)
    vendor(args.target.resolve(), args.python)


if __name__ == "__main__":
    main()
