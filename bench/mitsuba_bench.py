# Mitsuba 3 as the renderer a user might pick instead: the scene that bench/blender_bench.py wrote
# (PLY meshes, lights in Blender's units, camera) given to Mitsuba through its Python API, rendered
# by its `direct` integrator on the CPU at a sweep of sample counts and compared with the same
# Cycles reference as TOYRT; a scene whose reference follows glossy bounces (its specular depth) and
# has no diffuse surface by its `path` integrator to the same depth (`integrator`). Runs in .venv
# (requirements-bench.txt):
#     .venv/bin/python bench/mitsuba_bench.py SCENE_DIR REF.npy OUT.json --spp 1 4 16
#
# Units. Cycles' (measured in shared/BLENDER_UNITS.md, as TOYRT uses them): a point light of power
# P and colour c has radiant intensity P c / (4 pi), which is Mitsuba's `point` `intensity`; an area
# light has radiance P c / (4 area), Mitsuba's `area` `radiance`. Diffuse BSDFs are albedo / pi in
# both. Blender's area lights emit along their local -Z; Mitsuba's rectangle along +Z, so the
# rectangle is turned over.
#
# Also converted: a sun (Mitsuba's `directional`, irradiance = strength), a spot (`spot`, intensity
# P / (4 pi)), Emission materials (an `area` emitter of radiance colour x strength on the mesh, on
# both sides as Cycles' mesh lights: blender_bench.py writes a turned-over copy just behind the
# surface; no BSDF), an Environment Texture world (`envmap`, its frame turned to Blender's
# equirectangular convention and the Mapping node's rotation) and the Glossy BSDF (`roughconductor`
# of Fresnel 1 and the colour as its reflectance: glossy_bsdf). What Mitsuba cannot express is
# rendered its nearest way and listed in the output's "approximations": a sun's disc (Mitsuba's
# directional light is a delta), a spot's smoothstep edge and radius (Mitsuba's spot is a point with
# a falloff linear in angle), an area lamp under a world (Mitsuba's rectangle is opaque, rays go on
# through Cycles' lamps: under a constant world the rectangle adds the world's radiance it hides).
#
# Time: wall-clock seconds from the scene description to an image, as for the others: mi.load_dict
# (which builds Mitsuba's BVH) plus mi.render.
import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np


def probe_variant():
    """llvm_ad_rgb (vectorised, JIT-compiled) when its kernels compile here, else scalar_rgb. The
    probe runs in a child process because a failing LLVM back end can abort the interpreter."""
    code = ("import mitsuba as mi; mi.set_variant('llvm_ad_rgb'); "
            "s = mi.load_dict(mi.cornell_box()); mi.render(s, spp=1); print('ok')")
    try:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
        if out.returncode == 0 and "ok" in out.stdout:
            return "llvm_ad_rgb", ""
        last = (out.stderr.strip().splitlines() or ["no output"])[-1]
        return "scalar_rgb", f"llvm_ad_rgb failed here ({last[:160]})"
    except subprocess.TimeoutExpired:
        return "scalar_rgb", "llvm_ad_rgb timed out compiling its kernels"


def blender_matrix(m):
    return np.array(m, np.float64)


def to_transform(mi, m):
    return mi.ScalarTransform4f(np.asarray(m, np.float64).tolist())


# Blender's equirectangular map in Mitsuba's envmap frame: Blender looks up u = 1/2 - atan2(y, x) / 2 pi,
# v = asin(z) / pi + 1/2 (rows from the bottom); Mitsuba u = atan2(x', -z') / 2 pi, v = acos(y') / pi
# (rows from the top, which the dump wrote). Both agree when (x', y', z') = (y, z, x).
BLENDER_TO_ENVMAP = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])


def build_dict(mi, scene_dir, desc, approximations=None):
    approximations = [] if approximations is None else approximations
    d = {"type": "scene"}
    bsdfs = {}

    def bsdf_for(mat):
        key = json.dumps(mat, sort_keys=True)
        if key in bsdfs:
            return {"type": "ref", "id": bsdfs[key]}
        name = f"bsdf{len(bsdfs)}"
        bsdfs[key] = name
        if mat["type"] == "glass":
            d[name] = {"type": "dielectric", "int_ior": float(mat["ior"]), "ext_ior": 1.0}
        elif mat["type"] == "glossy":
            d[name] = glossy_bsdf(mat, approximations)
        elif "texture" in mat:
            rgb = np.load(scene_dir / mat["texture"])
            bitmap = mi.Bitmap(rgb)
            if mat.get("srgb", True):
                bitmap.set_srgb_gamma(True)  # 8-bit sRGB-encoded: Mitsuba decodes to linear on load
            d[name] = {"type": "diffuse", "reflectance": {"type": "bitmap", "bitmap": bitmap,
                                                          "filter_type": "bilinear", "wrap_mode": "repeat"}}
        else:
            d[name] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [float(c) for c in mat["color"]]}}
        return {"type": "ref", "id": name}

    for s, shape in enumerate(desc["shapes"]):
        instanced = len(shape["instances"]) > 1
        for p, part in enumerate(shape["parts"]):
            mat = part["material"]
            if mat["type"] == "emission":
                if instanced:
                    raise ValueError("instanced emitters are not converted for Mitsuba")
                radiance = (np.array(mat["color"], np.float64) * mat["strength"]).tolist()
                for side, ply in (("front", part["ply"]), ("back", part["ply_back"])):
                    d[f"shape{s}_{p}_{side}"] = {
                        "type": "ply", "filename": str(scene_dir / ply),
                        "to_world": to_transform(mi, shape["instances"][0]),
                        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}},
                        "emitter": {"type": "area", "radiance": {"type": "rgb", "value": radiance}}}
                continue
            ply = {"type": "ply", "filename": str(scene_dir / part["ply"]), "bsdf": bsdf_for(mat)}
            if not instanced:
                ply["to_world"] = to_transform(mi, shape["instances"][0])
                d[f"shape{s}_{p}"] = ply
            else:
                d[f"group{s}_{p}"] = {"type": "shapegroup", "mesh": ply}
                for i, m in enumerate(shape["instances"]):
                    d[f"inst{s}_{p}_{i}"] = {"type": "instance", "to_world": to_transform(mi, m),
                                             "shapegroup": {"type": "ref", "id": f"group{s}_{p}"}}
    for k, light in enumerate(desc["lights"]):
        color = np.array(light["color"], np.float64) * light["power"]
        m = blender_matrix(light["matrix"])
        if light["type"] == "POINT":
            d[f"light{k}"] = {"type": "point", "position": m[:3, 3].tolist(),
                              "intensity": {"type": "rgb", "value": (color / (4 * math.pi)).tolist()}}
        elif light["type"] == "AREA" and light["shape"] in ("RECTANGLE", "SQUARE"):
            sx = light["size"]
            sy = light["size_y"] if light["shape"] == "RECTANGLE" else sx
            scale = np.linalg.norm(m[:3, :3], axis=0)
            area = sx * scale[0] * sy * scale[1]
            # Mitsuba's rectangle spans [-1, 1]^2 with normal +Z: scale to half sizes, turn over.
            local = np.diag([sx / 2, -sy / 2, -1.0, 1.0])
            radiance = color / (4 * area)
            # Cycles' lamp is no surface: a ray that meets it takes its light and goes on, to the world
            # behind it, and shadow rays pass it. Mitsuba's rectangle is opaque: it hides the part of
            # the world behind it. Seen from the front, a lamp of radiance L + the world's constant
            # colour gives back what it hides (exactly); from behind it stays a black patch.
            world = desc["world"]
            if isinstance(world, list) and any(c > 0 for c in world):
                radiance = radiance + np.array(world, np.float64)
                approximations.append("area lamp under a constant world: Mitsuba's rectangle is opaque, so its "
                                      "radiance is the lamp's plus the world's it hides (exact from the front; "
                                      "from behind it hides the world, which Cycles' lamp does not)")
            elif isinstance(world, dict):
                approximations.append("area lamp: Mitsuba's rectangle is opaque and hides the map behind it "
                                      "(Cycles' lamp does not)")
            # Black: a shape without a BSDF gets Mitsuba's grey diffuse one, which would reflect the
            # scene's light off the lamp (Cycles' lamps reflect nothing).
            d[f"light{k}"] = {"type": "rectangle", "to_world": to_transform(mi, m @ local),
                              "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}},
                              "emitter": {"type": "area", "radiance": {"type": "rgb", "value": radiance.tolist()}}}
        elif light["type"] == "SUN":
            direction = -m[:3, 2] / np.linalg.norm(m[:3, 2])  # Blender's sun shines along its local -Z
            d[f"light{k}"] = {"type": "directional", "direction": direction.tolist(),
                              "irradiance": {"type": "rgb", "value": color.tolist()}}
            if light.get("angle", 0.0) > 0.0:
                approximations.append(f"sun of {math.degrees(light['angle']):.1f} degree disc: a delta direction")
        elif light["type"] == "SPOT":
            half = 0.5 * light["spot_size"]
            # Blender's edge: smoothstep from cos(half) to cos(half) + (1 - cos(half)) blend; Mitsuba's
            # falls linearly in angle from beam_width to cutoff_angle.
            inner = math.acos(min(1.0, math.cos(half) + (1.0 - math.cos(half)) * light["spot_blend"]))
            rotation = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)
            frame = np.eye(4)
            frame[:3, :3], frame[:3, 3] = rotation @ np.diag([1.0, -1.0, -1.0]), m[:3, 3]  # +Z: Blender's -Z
            d[f"light{k}"] = {"type": "spot", "to_world": to_transform(mi, frame),
                              "intensity": {"type": "rgb", "value": (color / (4 * math.pi)).tolist()},
                              "cutoff_angle": math.degrees(half), "beam_width": math.degrees(inner)}
            approximations.append("spot: a point with Mitsuba's linear edge (Blender: smoothstep"
                                  + (f", radius {light['radius']:g} m" if light.get("radius", 0.0) > 0 else "") + ")")
        else:
            raise ValueError(f"light {light['type']}/{light.get('shape')} is not converted for Mitsuba")
    world = desc["world"]
    if isinstance(world, dict):  # an Environment Texture: Mitsuba's local frame -> Blender's world
        to_world = np.eye(4)
        to_world[:3, :3] = np.linalg.inv(BLENDER_TO_ENVMAP @ np.array(world["matrix"], np.float64))
        d["world"] = {"type": "envmap", "bitmap": mi.Bitmap(np.load(scene_dir / world["image"])),
                      "scale": float(world["strength"]), "to_world": to_transform(mi, to_world)}
    elif world is not None:
        d["world"] = {"type": "constant", "radiance": {"type": "rgb", "value": world}}
    cam = desc["camera"]
    m = blender_matrix(cam["matrix"])
    origin, forward, up = m[:3, 3], -m[:3, 2], m[:3, 1]
    w, h = desc["width"], desc["height"]
    # Blender's AUTO sensor fit puts the sensor width across the larger image side.
    fov = math.degrees(2 * math.atan(cam["sensor_width"] / (2 * cam["lens"])))
    d["sensor"] = {"type": "perspective", "fov": fov, "fov_axis": "larger" if cam["sensor_fit"] == "AUTO" else "x",
                   "near_clip": cam["clip_start"], "far_clip": cam["clip_end"],
                   "to_world": mi.ScalarTransform4f().look_at(origin=origin.tolist(),
                                                              target=(origin + forward).tolist(), up=up.tolist()),
                   "film": {"type": "hdrfilm", "width": w, "height": h, "pixel_format": "rgb",
                            "rfilter": {"type": "box"}},  # Cycles' and TOYRT's Box filter of one pixel
                   "sampler": {"type": "independent", "sample_count": 1}}
    # Blender can hide a light from camera rays; Mitsuba only hides all emitters seen directly,
    # which is the same picture when nothing else (no world) is seen directly.
    hidden = [not light.get("visible_camera", True) for light in desc["lights"] if light["type"] == "AREA"]
    if any(hidden) and not all(hidden):
        raise ValueError("some area lights are hidden from the camera and some not: Mitsuba cannot show that")
    if any(hidden) and desc["world"] is not None:
        raise ValueError("a hidden area light and a world colour: Mitsuba cannot hide one and show the other")
    d["integrator"] = integrator(desc)
    d["integrator"]["hide_emitters"] = any(hidden)
    return d


def integrator(desc):
    """Mitsuba's integrator for the transport of the Cycles reference: `direct` for direct light
    alone (specular depth 0); for a specular depth N (Cycles' glossy and transmission bounces,
    TOYRT's max_specular_depth) `path` with max_depth N + 2, which counts path segments: 2 is
    direct light, and N bounces after the first hit add N segments (Cycles' last bounce is a ray
    that only collects light, Mitsuba's last segment too). Only for scenes without diffuse
    surfaces: TOYRT and the restricted Cycles end a path at a diffuse hit after its direct light,
    which no Mitsuba integrator does."""
    depth = int(desc.get("specular_depth", 0))
    if depth == 0:
        return {"type": "direct"}
    diffuse = sorted({part["ply"] for shape in desc["shapes"] for part in shape["parts"]
                      if part["material"]["type"] == "diffuse"})
    if diffuse:
        raise ValueError(f"specular depth {depth} with diffuse surfaces ({', '.join(diffuse)}): Mitsuba's path "
                         "integrator would go on past them")
    return {"type": "path", "max_depth": depth + 2}


def glossy_bsdf(mat, approximations):
    """Blender's Glossy BSDF: a microfacet reflection whose colour is a constant Fresnel, which is
    Mitsuba's rough conductor of no material (Fresnel 1) scaled by specular_reflectance; alpha =
    roughness^2 (Cycles' convention, roughness clamped to [0, 1]). Both use separable Smith masking
    (Cycles 3.x G1(o) G1(i), Mitsuba's microfacet G) and sample visible normals."""
    color = {"type": "rgb", "value": [float(c) for c in mat["color"]]}
    dist = mat.get("distribution", "GGX")
    if dist == "SHARP":
        return {"type": "conductor", "material": "none", "specular_reflectance": color}
    if dist not in ("GGX", "BECKMANN", "MULTI_GGX"):
        raise ValueError(f"Glossy BSDF distribution {dist} is not converted for Mitsuba")
    if dist == "MULTI_GGX":
        approximations.append("Multiscatter GGX Glossy BSDF: single-scatter GGX (Mitsuba has no multiscatter)")
    alpha = min(max(float(mat["roughness"]), 0.0), 1.0) ** 2
    return {"type": "roughconductor", "material": "none", "specular_reflectance": color,
            "distribution": "beckmann" if dist == "BECKMANN" else "ggx", "alpha": alpha}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene_dir", type=Path)
    ap.add_argument("reference", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--spp", type=int, nargs="+", required=True)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--variant", default="")
    args = ap.parse_args()

    import mitsuba as mi
    variant, note = (args.variant, "") if args.variant else probe_variant()
    mi.set_variant(variant)
    desc = json.loads((args.scene_dir / "scene.json").read_text())
    ref = np.load(args.reference).astype(np.float64)
    # The pixels blender_bench.py counted (lights seen directly and their edges left out).
    mask = np.load(str(args.reference).replace(".ref.npy", ".mask.npy"))
    runs, approximations = [], []
    # Once, for the list of what it approximates and the integrator it picks.
    used = build_dict(mi, args.scene_dir, desc, approximations)["integrator"]
    method = f"Mitsuba 3 {used['type']}"
    approximations = list(dict.fromkeys(approximations))
    for spp in args.spp:
        best = None
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            scene = mi.load_dict(build_dict(mi, args.scene_dir, desc))
            img = np.array(mi.render(scene, spp=spp), np.float64)[..., :3]
            seconds = time.perf_counter() - t0
            best = (img, seconds) if best is None or seconds < best[1] else best
        d, r = (best[0] - ref)[mask], ref[mask]
        rmse, relmse = float(np.sqrt(np.mean(d * d))), float(np.mean(d * d / (r * r + 1e-2)))
        runs.append(dict(renderer="mitsuba", method=method, spp=spp, seconds=best[1], rmse=rmse, relmse=relmse))
        print(f"bench: mitsuba {args.scene_dir.name} {spp} spp {best[1]:.3f} s rmse {rmse:.4g}", flush=True)
    np.save(args.out.with_suffix(".mitsuba.npy"), best[0].astype(np.float32))
    args.out.write_text(json.dumps(dict(variant=variant, variant_note=note, version=mi.__version__, runs=runs,
                                        integrator=used, approximations=approximations), indent=1))


if __name__ == "__main__":
    main()
