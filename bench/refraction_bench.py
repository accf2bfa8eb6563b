# Energy through glass, rendered by toyrt.Scene.render against closed forms (docs/results.md,
# section 3):
#   slab    a glass slab between an orthographic camera and a large light behind it, black world:
#           a pixel is L T with T = (1 - F) / (1 + F), the sum over the slab's internal
#           reflections (1 - F)^2 (1 + F^2 + F^4 + ...), F from Fresnel's equations at the
#           camera ray's incidence angle (the same at both faces of a parallel slab), truncated
#           where max_specular_depth cuts the series;
#   sphere  a glass sphere in a uniform white world (a furnace): without absorption every path
#           ends in the world, so every pixel on the sphere is 1 once max_specular_depth is deep
#           enough; what it lacks is the energy the depth limit cuts off, including the paths
#           trapped by total internal reflection.
# Runs with Debian's Python and PYTHONPATH=BUILD/python:
#     /usr/bin/python3 bench/refraction_bench.py OUT.json [--quick]
import argparse
import json
import math

import numpy as np
import toyrt

IOR = 1.5


def fresnel(cos_i, eta):
    """Unpolarised reflectance, eta = n_t / n_i; 1 beyond the critical angle."""
    sin2_t = (1 - cos_i * cos_i) / (eta * eta)
    if sin2_t >= 1:
        return 1.0
    cos_t = math.sqrt(1 - sin2_t)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp)


def box(size, center):
    sx, sy, sz = size
    v = np.array([(x, y, z) for x in (-sx / 2, sx / 2) for y in (-sy / 2, sy / 2) for z in (-sz / 2, sz / 2)]) + center
    q = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return v, np.array([t for a, b, c, d in q for t in ((a, b, c), (a, c, d))])


def sphere(rings=48, segments=96):
    th = np.pi * np.arange(1, rings) / rings
    ph = 2 * np.pi * np.arange(segments) / segments
    T, P = np.meshgrid(th, ph, indexing="ij")
    v = np.vstack([[0, 0, 1], np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3),
                   [0, 0, -1]])
    idx = lambda i, j: 1 + i * segments + j % segments  # noqa: E731
    j = np.arange(segments)
    tris = [np.stack([np.zeros(segments, int), idx(0, j), idx(0, j + 1)], 1)]
    for i in range(rings - 2):
        tris += [np.stack([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)], 1),
                 np.stack([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)], 1)]
    tris.append(np.stack([idx(rings - 2, j), np.full(segments, len(v) - 1), idx(rings - 2, j + 1)], 1))
    return v, np.vstack(tris)


def ortho_camera(tilt_deg, size=16, scale=0.5, height=3.0):
    """Looking down -Z, turned by tilt_deg about the x axis, from `height` above the origin."""
    a = math.radians(tilt_deg)
    rot = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    m = np.eye(4)
    m[:3, :3] = rot
    m[:3, 3] = rot @ np.array([0, 0, height])
    return dict(type="ORTHO", ortho_scale=scale, resolution_x=size, resolution_y=size, resolution_percentage=100,
                clip_start=0.01, clip_end=100.0, matrix_world=m)


def slab(material, angles, spp, depth):
    out = []
    for deg in angles:
        s = toyrt.Scene()
        glass = s.add_material(material, ior=IOR)
        v, t = box((60.0, 60.0, 0.2), (0, 0, 0))
        s.add_mesh(v, t, material_ids=glass)
        light = np.diag([1.0, -1.0, -1.0, 1.0])  # turned over: emits up (+Z), towards the camera
        light[2, 3] = -2.0
        size, power = 200.0, 4.0 * 200.0 * 200.0  # radiance P / (4 area) = 1 W/(m^2 sr)
        s.add_area_light(light, shape="SQUARE", size=size, power=power)
        s.background = (0.0, 0.0, 0.0)
        s.commit()
        # High enough that the film's lower edge stays above the slab at grazing tilts.
        img = s.render(ortho_camera(deg, height=10.0), samples=spp, seed=1, max_specular_depth=depth)
        f = fresnel(math.cos(math.radians(deg)), IOR)
        # Paths that leave through the bottom after k internal round trips use 2 + 2k specular
        # events; the depth limit keeps k <= (depth - 2) / 2.
        k_max = (depth - 2) // 2
        expected = (1 - f) ** 2 * sum(f ** (2 * k) for k in range(k_max + 1)) if material == "glass" else 1.0
        out.append(dict(material=material, deg=deg, depth=depth, measured=float(img[..., :3].mean()),
                        expected=expected))
    return out


def furnace(material, depths, spp):
    v, t = sphere()
    out = []
    for depth in depths:
        s = toyrt.Scene()
        s.add_mesh(v, t, normals=v[t].astype(np.float32), material_ids=s.add_material(material, ior=IOR))
        s.background = (1.0, 1.0, 1.0)
        s.commit()
        # The sphere fills the central disc of a 2.2 m wide orthographic view.
        cam = ortho_camera(0.0, size=48, scale=2.2, height=4.0)
        img = s.render(cam, samples=spp, seed=2, max_specular_depth=depth)[..., :3].mean(axis=2)
        y, x = (np.mgrid[0:48, 0:48] + 0.5) / 48 * 2.2 - 1.1
        inside = x * x + y * y < 0.95 ** 2
        out.append(dict(material=material, depth=depth, mean=float(img[inside].mean()),
                        min=float(img[inside].min()), pixels=int(inside.sum())))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    spp = 64 if args.quick else 512
    angles = [0, 30, 60, 75, 85]
    result = dict(ior=IOR, spp=spp,
                  slab=(slab("glass", angles, spp, 64) + slab("glass", angles, spp, 2)
                        + slab("refraction", angles, spp, 64)),
                  sphere=furnace("glass", [1, 2, 4, 8, 16, 64], spp) + furnace("refraction", [2, 4, 8, 16, 64], spp))
    for r in result["slab"]:
        print(f"bench: slab {r['material']} {r['deg']} deg depth {r['depth']}: {r['measured']:.4f} "
              f"(closed form {r['expected']:.4f})")
    for r in result["sphere"]:
        print(f"bench: furnace sphere {r['material']} depth {r['depth']}: mean {r['mean']:.4f}")
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
