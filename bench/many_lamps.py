# What many lamps cost a render: a floor of one material (diffuse, Principled or glossy) under N
# round point lamps scattered over it, 160 x 120, 4 samples, 2 threads; the render time of each
# module (each in its own subprocess, interleaved, median of the repeats) and the image's mean,
# which every module must agree on within the noise.
#     .venv/bin/python bench/many_lamps.py [--module NAME=DIR ...] [--repeats 3] [--lamps 10,100,1000]
# DIR holds a built toyrt module (build/python by default).
import argparse
import json
import os
import statistics
import time

from interleaved import modules_from, run_interleaved


def child(lamps):
    import numpy as np
    import toyrt

    m = np.eye(4)
    m[:3, :3] = [[1, 0, 0], [0, 0.6, -0.8], [0, 0.8, 0.6]]
    m[:3, 3] = [0, -20, 15]
    camera = dict(type="PERSP", lens=35.0, resolution_x=160, resolution_y=120, matrix_world=m)
    out = {}
    for material in ("diffuse", "principled", "glossy"):
        for n in lamps:
            s = toyrt.Scene()
            if material == "diffuse":
                s.add_material("diffuse", color=(0.8, 0.8, 0.8))
            elif material == "principled":
                s.add_material("principled", color=(0.8, 0.8, 0.8), roughness=0.4)
            else:
                s.add_material("glossy", color=(0.8, 0.8, 0.8), roughness=0.3)
            h = 20.0
            s.add_mesh(np.float32([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]]), [[0, 1, 2], [0, 2, 3]],
                       material_ids=0)
            rng = np.random.default_rng(1)
            for p in rng.uniform([-15, -15, 0.5], [15, 15, 3.0], (n, 3)):
                s.add_point_light(tuple(p), 2000.0 / n, radius=0.1)
            s.commit()
            s.render(camera, samples=1, threads=2)  # warm
            t = time.perf_counter()
            img = s.render(camera, samples=4, threads=2)
            out[f"{material} {n}"] = (time.perf_counter() - t, float(img[..., :3].mean()))
    print(json.dumps(out))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--module", action="append", default=[])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--lamps", default="10,100,1000")
    parser.add_argument("--child", action="store_true")
    args = parser.parse_args()
    lamps = [int(n) for n in args.lamps.split(",")]
    if args.child:
        child(lamps)
        return
    modules = modules_from(args.module, os.path.dirname(os.path.abspath(__file__)))
    runs = run_interleaved(__file__, modules, args.repeats, ["--lamps", args.lamps])
    print("| scene | " + " | ".join(f"{name} s | {name} mean" for name, _ in modules) + " |")
    print("|---|" + "---|---|" * len(modules))
    for key in runs[modules[0][0]][0]:
        cells = []
        for name, _ in modules:
            cells.append(f"{statistics.median(run[key][0] for run in runs[name]):.3f}")
            cells.append(f"{runs[name][0][key][1]:.4f}")
        print(f"| {key} lamps | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
