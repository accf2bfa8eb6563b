# The noise a glossy vertex leaves when it samples emissive triangles and the environment map
# beside its lobe (render/glossy_lighting.h), against a module that found them by the lobe's ray
# alone: on the parity scenes emitters_glossy and hdri_glossy (tests/blender/test_cycles_parity.py),
# the RMSE over the mean of a module's render at 16, 64 and 256 samples against one converged
# render (16,384 samples, written by the first run to --reference and read by the others: the
# estimators have the same mean, which the parity scenes check against Cycles), and the render
# time (median of 3). One module per Blender process (pybind11 registers a module's types once):
#     blender -b --factory-startup --python bench/glossy_light_sampling.py -- --module DIR --label new --reference R.npz
import argparse
import importlib.util
import statistics
import sys
import time
from pathlib import Path

import bpy  # noqa: F401  (runs inside Blender)
import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scenes"))
import kit  # noqa: E402


def load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def native(directory):
    so = next(Path(directory).glob("toyrt.cpython-*.so"))
    spec = importlib.util.spec_from_file_location("toyrt", so)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--module", default=str(REPO / "build" / "python"), help="DIR of a built toyrt module")
    parser.add_argument("--label", default="new")
    parser.add_argument("--reference", required=True, help=".npz of the converged renders (written if absent)")
    parser.add_argument("--scenes", default="emitters_glossy,hdri_glossy")
    args = parser.parse_args(argv)
    toyrt = native(args.module)
    parity = load("toyrt_parity", REPO / "tests" / "blender" / "test_cycles_parity.py")
    sync = parity.load_sync()
    specs = {name: (build, params, depth) for name, build, params, depth in parity.SCENES_SPEC}
    reference_file = Path(args.reference)
    references = dict(np.load(reference_file)) if reference_file.exists() else {}
    for name in args.scenes.split(","):
        build, params, depth = specs[name]
        kit.clear_scene()
        build(params)
        kit.output(bpy.context.scene, parity.WIDTH, parity.HEIGHT)
        bpy.context.view_layer.update()
        s, cam, _ = sync.export_scene(bpy.context.evaluated_depsgraph_get(), toyrt, report=lambda kind, msg: None)
        s.commit()
        if name not in references:
            references[name] = s.render(cam, samples=16384, seed=99, max_specular_depth=depth)[..., :3]
            np.savez(reference_file, **references)
        reference = references[name]
        for spp in (16, 64, 256):
            times = []
            for _ in range(3):
                t = time.perf_counter()
                img = s.render(cam, samples=spp, seed=0, max_specular_depth=depth)[..., :3]
                times.append(time.perf_counter() - t)
            error = float(np.sqrt(((img - reference) ** 2).mean()) / reference.mean())
            print(f"| {name} | {args.label} | {spp} | {error:.4f} | {statistics.median(times):.3f} |", flush=True)


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
