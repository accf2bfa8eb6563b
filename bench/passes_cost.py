# What render passes cost, as counted instructions (perf stat -e instructions: a count, not a time,
# so a busy shared machine does not blur it): a Lambert-only scene (a floor and a 20k-triangle
# sphere in four Diffuse colours, a point light), 320 x 240, threads=1, rendered with `samples`
# samples and with the passes named on the command line (none: the plain render). Run it twice
# per module, at 1 and at N samples, and the difference is the cost of N - 1 samples alone:
#     perf stat -x, -e instructions:u env PYTHONPATH=DIR .venv/bin/python bench/passes_cost.py 17 [depth normal ...]
import sys

import numpy as np
import toyrt


def scene():
    s = toyrt.Scene()
    for c in ((0.8, 0.2, 0.2), (0.2, 0.8, 0.2), (0.2, 0.2, 0.8), (0.7, 0.7, 0.7)):
        s.add_material("diffuse", color=c)
    v = np.array([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]], np.float32)
    s.add_mesh(v, [[0, 1, 2], [0, 2, 3]], material_ids=3)
    rings, segs = 100, 100
    th, ph = np.meshgrid(np.linspace(0, np.pi, rings + 1), np.linspace(0, 2 * np.pi, segs, endpoint=False),
                         indexing="ij")
    p = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(rings), np.arange(segs), indexing="ij")
    a, b, c, d = i * segs + j, (i + 1) * segs + j, (i + 1) * segs + (j + 1) % segs, i * segs + (j + 1) % segs
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    s.add_mesh((p + (0, 0, 1)).astype(np.float32), tris.astype(np.uint32), normals=p.astype(np.float32),
               material_ids=(np.arange(len(tris)) % 3).astype(np.int32))
    s.add_point_light((0.5, -0.5, 3.0), 500.0)
    s.commit(builder="sah", threads=1)
    return s


if __name__ == "__main__":
    samples, passes = int(sys.argv[1]), sys.argv[2:]
    mw = np.array([[1, 0, 0, 0], [0, 0.6, -0.8, -6.0], [0, 0.8, 0.6, 5.0], [0, 0, 0, 1]])
    cam = dict(type="PERSP", lens=35.0, resolution_x=320, resolution_y=240, matrix_world=mw)
    s = scene()
    kw = dict(passes=passes) if passes else {}
    s.render(cam, samples=samples, threads=1, **kw)
    print(f"{s.last_render['render_ms']:.1f} ms", file=sys.stderr)
