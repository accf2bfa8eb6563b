"""Builds the two add-on zips of a release from addon/render_toyrt and the repaired wheels in dist/
(scripts/build-wheel.sh), as `make package` runs it (docs/install.md):

  - the extension for Blender 4.2+: the add-on with the wheels listed under `wheels` in its
    blender_manifest.toml, built and then validated by Blender's own extension tool
    (blender_ext.py, from the bpy package: Debian's Blender 3.4 has no `--command extension`),
    one zip per platform (--split-platforms): dist/render_toyrt-<version>-linux_x64.zip;
  - the legacy add-on for Blender 3.4-4.1: the add-on folder with the package `toyrt` (its modules
    per CPU level, native/python/toyrt/) and their bundled libraries (toyrt.libs/, found through the
    modules' RPATH $ORIGIN/../toyrt.libs) taken out of the cp310 and cp311 wheels (blender.org's
    3.4-4.0 run Python 3.10, 4.1 and Debian's 3.4 run 3.11; each Python imports the modules named
    for it, so both sit in one folder), without the manifest (Blender 4.2+ would take a zip holding
    one for an extension): dist/render_toyrt-<version>-legacy-linux_x64.zip.

Both carry Open Image Denoise for the Denoise setting: the extension lists the wheels of pyoidn,
cffi and pycparser beside TOYRT's, the legacy zip holds them unpacked in vendor/
(scripts/vendor-pyoidn.py: the CPU device only), since its Blenders cannot pip-install.

    .venv/bin/python scripts/build-extension.py --dist dist
"""
import argparse
import glob
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ADDON = "render_toyrt"
# Never shipped: caches, and a module a developer's `make setup` may have left in the folder.
IGNORE = shutil.ignore_patterns("__pycache__", "*.pyc", "*.so", "toyrt.libs")


def blender_ext() -> Path:
    """Blender's extension command-line tool inside the installed bpy package (found without
    importing bpy, which would start Blender)."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        sys.exit("build-extension: the bpy package is not installed (requirements-test.txt)")
    found = glob.glob(os.path.join(spec.submodule_search_locations[0], "*", "scripts", "addons_core", "bl_pkg",
                                   "cli", "blender_ext.py"))
    if len(found) != 1:
        sys.exit(f"build-extension: expected one blender_ext.py in the bpy package, found {found}")
    return Path(found[0])


def run_tool(tool: Path, *args: str) -> str:
    run = subprocess.run([sys.executable, str(tool), *args], capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"build-extension: blender_ext.py {args[0]} failed:\n{run.stdout}{run.stderr}")
    return run.stdout


def manifest_version(manifest: Path) -> str:
    import tomllib

    with open(manifest, "rb") as f:
        return tomllib.load(f)["version"]


def build_extension(wheels: list[Path], dist: Path, work: Path) -> list[Path]:
    """The extension zip(s), validated; the manifest gets the wheels of this build (3.11 and newer:
    Blender 4.2, the first with extensions, runs 3.11)."""
    wheels = [w for w in wheels if "-cp310-" not in w.name]
    stage = work / "extension" / ADDON
    shutil.copytree(REPO / "addon" / ADDON, stage, ignore=IGNORE)
    (stage / "wheels").mkdir()
    for wheel in wheels:
        shutil.copy2(wheel, stage / "wheels")
    # Open Image Denoise for the Denoise setting (addon/render_toyrt/denoise.py): pyoidn and cffi for
    # each Python of the build, pycparser (cffi's parser); Blender installs them with the add-on.
    pythons = sorted({w.name.split("-")[2].replace("cp3", "3.") for w in wheels})
    denoiser = denoiser_wheels(pythons, work / "denoiser-wheels")
    for wheel in denoiser:
        shutil.copy2(wheel, stage / "wheels")
    listed = ", ".join(f'"./wheels/{w.name}"' for w in wheels + denoiser)
    with open(stage / "blender_manifest.toml", "a") as f:
        f.write(f"\n# Added by scripts/build-extension.py: the wheels of this build.\nwheels = [{listed}]\n")
    tool = blender_ext()
    before = set(dist.glob(f"{ADDON}-*.zip"))
    print(run_tool(tool, "build", "--source-dir", str(stage), "--output-dir", str(dist), "--split-platforms"), end="")
    built = sorted(set(dist.glob(f"{ADDON}-*.zip")) - before - set(dist.glob("*-legacy-*.zip")))
    if not built:
        sys.exit("build-extension: blender_ext.py build wrote no zip")
    for zip_path in built:
        run_tool(tool, "validate", str(zip_path))
        print(f"extension: {zip_path} ({zip_path.stat().st_size // 1024} KB; validated by {tool.name})")
    return built


def denoiser_wheels(pythons: list[str], folder: Path) -> list[Path]:
    """The wheels of pyoidn, pycparser and cffi (one per Python) at the versions
    requirements-test.txt pins, downloaded from PyPI (pip's cache makes a second build offline)."""
    pins = {line.split("==")[0]: line.strip() for line in (REPO / "requirements-test.txt").read_text().splitlines()
            if line.startswith(("pyoidn==", "cffi==", "pycparser=="))}
    base = [sys.executable, "-m", "pip", "download", "-q", "--no-deps", "--only-binary=:all:", "-d", str(folder),
            "--platform", "manylinux2014_x86_64", "--implementation", "cp"]
    for python in pythons:
        subprocess.run(base + ["--python-version", python] + list(pins.values()), check=True)
    return sorted(folder.glob("*.whl"))


def build_legacy(wheels: list[Path], dist: Path, version: str) -> Path:
    """The legacy add-on zip, with the cp310 and cp311 modules of the wheels and their libraries."""
    legacy = [w for w in wheels if "-cp310-" in w.name or "-cp311-" in w.name]
    if not any("-cp311-" in w.name for w in legacy):
        sys.exit(f"build-extension: the legacy zip needs the cp311 wheel, found {[w.name for w in wheels]}")
    out = dist / f"{ADDON}-{version}-legacy-linux_x64.zip"
    source = REPO / "addon" / ADDON
    written = set()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for path in sorted(source.rglob("*")):
            rel = path.relative_to(source)
            if path.is_file() and path.name != "blender_manifest.toml" and not IGNORE(str(path.parent), rel.parts):
                z.write(path, f"{ADDON}/{rel}")
        for wheel_path in legacy:
            with zipfile.ZipFile(wheel_path) as wheel:
                for name in wheel.namelist():
                    # toyrt/__init__.py and the bundled libraries are the same in every wheel: once.
                    if name.startswith(("toyrt/", "toyrt.libs/")) and not name.endswith("/") and name not in written:
                        info = zipfile.ZipInfo(f"{ADDON}/{name}", wheel.getinfo(name).date_time)
                        info.external_attr = 0o755 << 16
                        z.writestr(info, wheel.read(name), zipfile.ZIP_DEFLATED)
                        written.add(name)
        # Open Image Denoise for these Pythons, which cannot pip-install into Blender: vendor/.
        vendor = REPO / "build" / "vendor-legacy"
        subprocess.run([sys.executable, str(REPO / "scripts" / "vendor-pyoidn.py"), "--target", str(vendor),
                        "--python", "3.10", "--python", "3.11"], check=True)
        for path in sorted(vendor.rglob("*")):
            if path.is_file():
                info = zipfile.ZipInfo(f"{ADDON}/vendor/{path.relative_to(vendor)}", (2026, 1, 1, 0, 0, 0))
                info.external_attr = (path.stat().st_mode & 0o777) << 16
                z.writestr(info, path.read_bytes(), zipfile.ZIP_DEFLATED)
    pythons = ", ".join(sorted(w.name.split("-")[2].replace("cp3", "3.") for w in legacy))
    print(f"legacy add-on: {out} ({out.stat().st_size // 1024} KB; Python {pythons}; with Open Image Denoise)")
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dist", default="dist", help="folder holding the wheels; the zips are written there")
    args = parser.parse_args()
    dist = Path(args.dist).resolve()
    version = manifest_version(REPO / "addon" / ADDON / "blender_manifest.toml")
    wheels = sorted(dist.glob(f"toyrt-{version}-cp3*-manylinux_*.whl"))
    if not wheels:
        sys.exit(f"build-extension: no toyrt-{version} wheels in {dist} (scripts/build-wheel.sh first)")
    for old in dist.glob(f"{ADDON}-*.zip"):
        old.unlink()
    with tempfile.TemporaryDirectory(prefix="toyrt-package-") as work:
        build_extension(wheels, dist, Path(work))
    build_legacy(wheels, dist, version)


if __name__ == "__main__":
    main()
