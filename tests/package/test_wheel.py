"""The installed wheel itself, run by fresh_venv.sh inside a fresh virtual environment next to
tests/python/test_ray_api.py: the module comes from site-packages (not a build folder), TBB and the
OpenCL loader are the copies auditwheel put in toyrt.libs/, and that loader still finds the
system's OpenCL driver (PoCL), so LBVH builds run on it."""
import os
import sys
import sysconfig

import numpy as np
import toyrt


def loaded_libraries():
    with open("/proc/self/maps") as f:
        return {line.split()[-1] for line in f if "/" in line}


def test_module_comes_from_the_venvs_site_packages():
    site = sysconfig.get_paths()["platlib"]
    assert os.path.dirname(toyrt.__file__) == site
    assert sys.prefix != sys.base_prefix  # a virtual environment, not the system Python


def test_numpy_is_the_version_asked_for():
    # The major version fresh_venv.sh was asked for: the module works with what the venv holds.
    assert np.__version__.split(".")[0] == os.environ["TOYRT_NUMPY_MAJOR"]


def test_tbb_and_the_opencl_loader_are_the_bundled_copies():
    scene = toyrt.Scene()
    scene.add_mesh(np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]])
    scene.commit(builder="lbvh")  # loads the OpenCL loader and runs TBB's pool
    bundled = os.path.join(os.path.dirname(toyrt.__file__), "toyrt.libs")
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
