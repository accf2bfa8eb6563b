"""The installed wheel itself, run by fresh_venv.sh inside a fresh virtual environment next to
tests/python/test_ray_api.py: the module comes from site-packages (not a build folder), TBB and the
OpenCL loader are the copies auditwheel put in toyrt.libs/, and that loader still finds the
system's OpenCL driver (PoCL), so LBVH builds run on it."""
import os
import sys
import sysconfig

import numpy as np
import toyrt

# The wheel installs the package toyrt/ (a module per CPU level) and its libraries beside it.
SITE = os.path.dirname(os.path.dirname(toyrt.__file__))


def loaded_libraries():
    with open("/proc/self/maps") as f:
        return {line.split()[-1] for line in f if "/" in line}


def test_module_comes_from_the_venvs_site_packages():
    assert SITE == sysconfig.get_paths()["platlib"]
    assert os.path.dirname(toyrt._core.__file__) == os.path.join(SITE, "toyrt")
    assert sys.prefix != sys.base_prefix  # a virtual environment, not the system Python


def test_numpy_is_the_version_asked_for():
    # The major version fresh_venv.sh was asked for: the module works with what the venv holds.
    assert np.__version__.split(".")[0] == os.environ["TOYRT_NUMPY_MAJOR"]


def test_tbb_and_the_opencl_loader_are_the_bundled_copies():
    scene = toyrt.Scene()
    scene.add_mesh(np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]])
    scene.commit(builder="lbvh")  # loads the OpenCL loader and runs TBB's pool
    bundled = os.path.join(SITE, "toyrt.libs")
    libs = loaded_libraries()
    tbb = {p for p in libs if os.path.basename(p).startswith("libtbb")}
    opencl = {p for p in libs if os.path.basename(p).startswith("libOpenCL")}
    assert tbb and all(p.startswith(bundled) for p in tbb), tbb
    assert opencl and all(p.startswith(bundled) for p in opencl), opencl


def test_lbvh_runs_on_the_systems_opencl_driver_through_the_bundled_loader():
    rng = np.random.default_rng(3)
    vertices = rng.uniform(0, 1, (3000, 3)).astype(np.float32)
    scene = toyrt.Scene()
    scene.add_mesh(vertices, np.arange(3000).reshape(-1, 3))
    scene.commit(builder="lbvh")
    assert scene.last_commit["lbvh_meshes"] == 1 and scene.last_commit["warning"] == ""
    # Rays straight down through each triangle's centroid hit that triangle's mesh.
    centroids = vertices.reshape(-1, 3, 3).mean(axis=1)
    origins = centroids + np.float32([0, 0, 2])
    hits = scene.intersect(origins, np.tile(np.float32([0, 0, -1]), (len(origins), 1)))
    assert np.isfinite(hits["t"]).all()


# ---- runtime CPU dispatch (native/python/toyrt/__init__.py) ------------------------------------------

def cpu_flags():
    with open("/proc/cpuinfo") as f:
        return set(next(line for line in f if line.startswith("flags")).split(":", 1)[1].split())


def run_with_level(level, code):
    """`code` run by this venv's Python with TOYRT_CPU=level (None: unset): (exit status, output)."""
    import subprocess

    env = {k: v for k, v in os.environ.items() if k != "TOYRT_CPU"}
    if level is not None:
        env["TOYRT_CPU"] = level
    run = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    return run.returncode, run.stdout + run.stderr


def test_the_default_level_is_the_best_this_cpu_runs():
    flags = cpu_flags()
    best = "v4" if "avx512bw" in flags and "avx512vl" in flags else "v3" if "avx2" in flags and "fma" in flags else "v2"
    code, out = run_with_level(None, "import toyrt; print(toyrt.cpu_level)")
    assert code == 0 and out.split() == [best], out


def test_a_forced_level_loads_that_levels_module():
    code = ("import toyrt\n"
            "maps = open('/proc/self/maps').read()\n"
            "print(toyrt.cpu_level, sorted({l.split('/')[-1].split('.')[0] for l in maps.split()"
            " if '/toyrt/_core_' in l}))")
    for level, alias in (("v2", "sse4.2"), ("v3", "avx2")):
        status, out = run_with_level(alias, code)
        assert status == 0 and out.split() == [level, f"['_core_{level}']"], out


def test_an_unknown_level_is_refused_with_a_message():
    status, out = run_with_level("sse9", "import toyrt")
    assert status != 0 and "TOYRT_CPU='sse9' is not a CPU level" in out


def test_every_level_gives_the_same_bits():
    # -ffp-contract=off at every level: no FMA in the arithmetic, so hits and pixels are identical.
    code = (
        "import hashlib, numpy as np, toyrt\n"
        "rng = np.random.default_rng(5)\n"
        "v = rng.uniform(-1, 1, (3000, 3)).astype(np.float32)\n"
        "s = toyrt.Scene(); s.add_mesh(v, np.arange(3000).reshape(-1, 3)); s.add_point_light((0, 0, 3), power=50.0)\n"
        "s.commit(builder='sah')\n"
        "o = rng.uniform(-1, 1, (20000, 3)).astype(np.float32); d = rng.normal(size=(20000, 3)).astype(np.float32)\n"
        "h = s.intersect(o, d)\n"
        "cam = dict(type='PERSP', lens=35, sensor_width=36, resolution_x=64, resolution_y=48,\n"
        "           matrix_world=np.array([[1, 0, 0, 0], [0, 0, -1, -4], [0, 1, 0, 0], [0, 0, 0, 1.0]]))\n"
        "img = s.render(cam, samples=4, seed=1)\n"
        "parts = [h['t'], h['u'], h['v'], h['prim'], img]\n"
        "print(hashlib.sha256(b''.join(np.ascontiguousarray(p).tobytes() for p in parts)).hexdigest())\n"
    )
    flags = cpu_flags()
    levels = ["v2"] + (["v3"] if "avx2" in flags else []) + (["v4"] if "avx512bw" in flags else [])
    digests = {}
    for level in levels:
        status, out = run_with_level(level, code)
        assert status == 0, out
        digests[level] = out.strip()
    assert len(set(digests.values())) == 1, digests
