# Runs inside Blender, once per benchmark scene (bench/run.py starts it):
#     blender -b --python-exit-code 1 --python bench/blender_bench.py -- JOB.json
# Builds the scene with its script (scenes/bench/*.py), renders the converged reference with Cycles
# (cached: see cache_key), then the sample sweeps of Cycles and of TOYRT's methods, and writes their
# times and errors to the job's output JSON. With "mitsuba_dir" it also writes the scene as PLY
# meshes and a JSON description for bench/mitsuba_bench.py; with "economy" it times TOYRT on the
# scene as the job's list of feature steps switches features on.
#
# Times are wall-clock seconds from the Blender scene to an image, for every renderer:
#   Cycles: bpy.ops.render.render() (its scene sync, BVH build and render; the EXR is written after);
#   TOYRT:  the add-on's sync.export_scene() + commit() (BVH build) + render().
import hashlib
import importlib.util
import json
import sys
import time
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scenes"))  # the scene kit
import kit  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
CYCLES_SETUP_REVISION = 1  # bump when the Cycles settings change meaning in a way their text does not show


def load_scene_module(name):
    path = REPO / "scenes" / "bench" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"bench_scene_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module, path


def scene_sources(path):
    """The files a scene's pixels depend on: its script, the scene kit, the Cycles settings and
    (Cornell) the seed's scene."""
    files = [path, REPO / "scenes" / "kit.py", REPO / "scenes" / "cycles_like_toyrt.py"]
    if path.stem == "cornell":
        files.append(REPO / "scenes" / "cornell_demo.py")
    return files


def render_cycles(scene, tmp):
    """(image (h, w, 3) float64 rows from the top, seconds of the render call)."""
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    seconds = time.perf_counter() - t0
    bpy.data.images["Render Result"].save_render(str(tmp))
    image = kit.read_image(tmp)
    tmp.unlink(missing_ok=True)
    return image[::-1, :, :3].astype(np.float64), seconds


LIGHT_SEEN = 20.0  # W/(m^2 sr): above any lit diffuse surface in the bench scenes, below their lights


def error_mask(ref):
    """Pixels whose error counts: not those that see a light directly (reference above LIGHT_SEEN)
    nor their 8 neighbours. A light's edge pixels carry pixel-jitter noise of the light's full
    radiance, common to every method, that would otherwise be most of the RMSE."""
    seen = ref.max(axis=2) >= LIGHT_SEEN
    grown = seen.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= np.roll(np.roll(seen, dy, 0), dx, 1)
    return ~grown


def errors(img, ref, mask):
    """RMSE over the counted pixels' channels, and relative MSE: mean of (x - r)^2 / (r^2 + 0.01),
    which weighs dark and bright regions alike (the 0.01 keeps black pixels from dividing by zero)."""
    d = (img[..., :3].astype(np.float64) - ref)[mask]
    r = ref[mask]
    return float(np.sqrt(np.mean(d * d))), float(np.mean(d * d / (r * r + 1e-2)))


def cache_key(job, path):
    h = hashlib.sha256()
    for f in scene_sources(path):
        h.update(f.read_bytes())
    h.update(json.dumps(dict(options=job.get("options", {}), size=(job["width"], job["height"]),
                             spp=job["ref_spp"], depth=job["specular_depth"], blender=bpy.app.version_string,
                             revision=CYCLES_SETUP_REVISION), sort_keys=True).encode())
    return h.hexdigest()[:16]


def reference(job, path, cache):
    """The converged Cycles image, rendered once per scene version and Blender version."""
    cache.mkdir(parents=True, exist_ok=True)
    key = cache_key(job, path)
    npy, meta = cache / f"{job['name']}-{key}.npy", cache / f"{job['name']}-{key}.json"
    if npy.exists() and meta.exists():
        info = json.loads(meta.read_text())
        info["cached"] = True
        return np.load(npy), info
    scene = bpy.context.scene
    kit.cycles(scene, job["ref_spp"], job["specular_depth"])
    print(f"bench: {job['name']}: Cycles reference at {job['ref_spp']} spp (cached after this run)", flush=True)
    img, seconds = render_cycles(scene, cache / f"{job['name']}-{key}.exr")
    np.save(npy, img)
    info = dict(seconds=seconds, spp=job["ref_spp"], blender=bpy.app.version_string, key=key,
                date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
    meta.write_text(json.dumps(info))
    info["cached"] = False
    return img, info


def toyrt_render(sync, toyrt, spp, area, lights, depth, seed=0):
    """(image, seconds from scene to image, seconds of render() alone, last_render, export stats)."""
    t0 = time.perf_counter()
    scene_t, cam, stats = sync.export_scene(bpy.context.evaluated_depsgraph_get(), toyrt)
    scene_t.commit()
    t1 = time.perf_counter()
    img = scene_t.render(cam, samples=spp, seed=seed, max_specular_depth=depth, area_light_sampling=area,
                         light_sampling=lights)
    t2 = time.perf_counter()
    return img[..., :3].astype(np.float64), t2 - t0, t2 - t1, dict(scene_t.last_render), stats


# ---- Mitsuba: the same scene as files ----------------------------------------------------------

def write_ply(path, positions, normals, uvs):
    """Binary little-endian PLY, three unshared vertices per triangle (corner normals and UVs)."""
    n = len(positions)
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")]
    if uvs is not None:
        fields += [("u", "<f4"), ("v", "<f4")]
    vert = np.empty(n, fields)
    vert["x"], vert["y"], vert["z"] = positions.T
    vert["nx"], vert["ny"], vert["nz"] = normals.T
    if uvs is not None:
        vert["u"], vert["v"] = uvs.T
    faces = np.empty(n // 3, [("k", "u1"), ("i", "<i4", (3,))])
    faces["k"] = 3
    faces["i"] = np.arange(n, dtype=np.int32).reshape(-1, 3)
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {n}"]
    header += [f"property float {name}" for name, _ in fields]
    header += [f"element face {n // 3}", "property list uchar int vertex_indices", "end_header", ""]
    with open(path, "wb") as f:
        f.write("\n".join(header).encode())
        f.write(vert.tobytes())
        f.write(faces.tobytes())


def material_description(mat, out_dir):
    """The subset of node materials the bench scenes use: Diffuse BSDF (colour or image), Glass,
    Emission (colour x strength), Glossy BSDF (colour, roughness and distribution, all constant)."""
    if mat is None or not mat.use_nodes:
        return dict(type="diffuse", color=[0.8, 0.8, 0.8])
    out = next(n for n in mat.node_tree.nodes if n.type == "OUTPUT_MATERIAL")
    bsdf = out.inputs["Surface"].links[0].from_node
    if bsdf.type == "BSDF_GLASS":
        return dict(type="glass", ior=bsdf.inputs["IOR"].default_value)
    if bsdf.type in ("BSDF_GLOSSY", "BSDF_ANISOTROPIC"):  # 4.0+: the Glossy BSDF is the anisotropic node
        linked = [s.name for s in bsdf.inputs if s.is_linked and s.name in ("Color", "Roughness", "Anisotropy")]
        anisotropy = bsdf.inputs["Anisotropy"].default_value if "Anisotropy" in bsdf.inputs else 0.0
        if linked or anisotropy != 0.0:
            raise ValueError(f"material {mat.name}: a Glossy BSDF with linked {linked} or anisotropy {anisotropy} "
                             "is not converted for Mitsuba")
        return dict(type="glossy", color=list(bsdf.inputs["Color"].default_value)[:3],
                    roughness=bsdf.inputs["Roughness"].default_value, distribution=bsdf.distribution)
    if bsdf.type == "EMISSION":
        return dict(type="emission", color=list(bsdf.inputs["Color"].default_value)[:3],
                    strength=bsdf.inputs["Strength"].default_value)
    color = bsdf.inputs["Color"]
    if color.is_linked and color.links[0].from_node.type == "TEX_IMAGE":
        image = color.links[0].from_node.image
        w, h = image.size[:]
        px = np.empty(w * h * 4, np.float32)
        image.pixels.foreach_get(px)
        # Byte images hold sRGB-encoded values. Rows stay bottom-first: Mitsuba's PLY loader flips
        # v (flip_tex_coords), which turns that into its top-first bitmap order.
        rgb = (np.round(px.reshape(h, w, 4)[:, :, :3] * 255)).astype(np.uint8)
        path = out_dir / f"tex-{mat.name}.npy"
        np.save(path, rgb)
        return dict(type="diffuse", texture=path.name, srgb=image.colorspace_settings.name == "sRGB")
    return dict(type="diffuse", color=list(color.default_value)[:3])


def world_description(scene, out_dir):
    """A plain world's colour, or an Environment Texture's image (rows from the top, as Mitsuba's
    bitmaps) with the matrix taking world directions to the map's frame (the add-on's own reading of
    a Mapping node) and the Background's strength; None without a world."""
    if scene.world is None or not scene.world.use_nodes:
        return None
    background = scene.world.node_tree.nodes["Background"]
    color = background.inputs["Color"]
    if not color.is_linked:
        return list(color.default_value)[:3]
    node = color.links[0].from_node
    if node.type != "TEX_ENVIRONMENT":
        raise ValueError(f"world colour from {node.bl_idname} is not converted for Mitsuba")
    from render_toyrt.world import mapping_matrix

    w, h = node.image.size[:]
    px = np.empty(w * h * 4, np.float32)
    node.image.pixels.foreach_get(px)
    np.save(out_dir / "envmap.npy", px.reshape(h, w, 4)[::-1, :, :3].copy())
    matrix = mapping_matrix(scene.world.name, node.inputs["Vector"], [])
    return dict(type="envmap", image="envmap.npy", matrix=np.asarray(matrix).tolist(),
                strength=background.inputs["Strength"].default_value)


def dump_for_mitsuba(mesh, out_dir, specular_depth=0):
    """Meshes (one PLY per mesh and material, in object space), their instances' world matrices,
    lights in Blender's units, the camera, the world colour and the reference's specular depth (the
    glossy bounces Cycles followed): bench/mitsuba_bench.py converts."""
    out_dir.mkdir(parents=True, exist_ok=True)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    shapes, lights = {}, []
    for inst in depsgraph.object_instances:
        obj = inst.object
        matrix = [list(r) for r in inst.matrix_world]
        if obj.type == "LIGHT":
            light = obj.data
            lights.append(dict(type=light.type, power=light.energy, color=list(light.color), matrix=matrix,
                               shape=getattr(light, "shape", None), size=getattr(light, "size", 0.0),
                               size_y=getattr(light, "size_y", 0.0), angle=getattr(light, "angle", 0.0),
                               spot_size=getattr(light, "spot_size", 0.0), spot_blend=getattr(light, "spot_blend", 0.0),
                               radius=getattr(light, "shadow_soft_size", 0.0),
                               visible_camera=bool(getattr(obj, "visible_camera", True))))
            continue
        if obj.type != "MESH" or not (inst.is_instance or inst.show_self):
            continue
        key = obj.original.data.name
        if key not in shapes:
            verts, tris, normals, uvs, mat_idx = mesh.mesh_arrays(obj.data)[:5]
            if normals is None:  # flat shading (the exporter sends no corner normals then)
                p = verts[tris]
                n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
                n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
                normals = np.repeat(n[:, None, :], 3, axis=1)
            elif normals.ndim == 2:  # per vertex (all faces smooth): to corners
                normals = normals[tris]
            parts = []
            for m in np.unique(mat_idx):
                sel = mat_idx == m
                mat = obj.material_slots[int(m)].material if len(obj.material_slots) > m else None
                ply = out_dir / f"mesh{len(shapes)}-{int(m)}.ply"
                write_ply(ply, verts[tris[sel]].reshape(-1, 3), normals[sel].reshape(-1, 3),
                          None if uvs is None else uvs[sel].reshape(-1, 2))
                part = dict(ply=ply.name, material=material_description(mat, out_dir))
                if part["material"]["type"] == "emission":
                    # Cycles' mesh lights emit from both sides, Mitsuba's area emitters from the
                    # front: a turned-over copy, moved behind the surface by 1e-5 of the mesh's size
                    # so that each side's rays meet their own copy first.
                    corners = tris[sel][:, [0, 2, 1]]
                    n = normals[sel][:, [0, 2, 1]].reshape(-1, 3)
                    eps = 1e-5 * float(np.linalg.norm(verts.max(0) - verts.min(0)))
                    back = out_dir / f"mesh{len(shapes)}-{int(m)}-back.ply"
                    write_ply(back, verts[corners].reshape(-1, 3) - eps * n, -n,
                              None if uvs is None else uvs[sel][:, [0, 2, 1]].reshape(-1, 2))
                    part["ply_back"] = back.name
                parts.append(part)
            shapes[key] = dict(parts=parts, instances=[])
        shapes[key]["instances"].append(matrix)
    scene = depsgraph.scene
    cam = scene.camera
    r = scene.render
    desc = dict(shapes=list(shapes.values()), lights=lights, world=world_description(scene, out_dir),
                camera=dict(matrix=[list(row) for row in cam.matrix_world], lens=cam.data.lens,
                            sensor_width=cam.data.sensor_width, sensor_fit=cam.data.sensor_fit,
                            clip_start=cam.data.clip_start, clip_end=cam.data.clip_end),
                width=r.resolution_x, height=r.resolution_y, specular_depth=specular_depth)
    (out_dir / "scene.json").write_text(json.dumps(desc))


# ---- the job --------------------------------------------------------------------------------------

def main():
    job = json.loads(Path(sys.argv[sys.argv.index("--") + 1]).read_text())
    out = Path(job["out"])
    out.parent.mkdir(parents=True, exist_ok=True)
    import render_toyrt
    from render_toyrt import mesh, sync

    toyrt = render_toyrt.native()
    module, path = load_scene_module(job["module"])
    result = dict(name=job["name"], blender=bpy.app.version_string, toyrt_version=getattr(toyrt, "__version__", "?"))

    if "economy" in job:
        # One scene, features switched on one at a time; the best of `repeats` runs of each step.
        steps = []
        for label, options in job["economy"]:
            module.build(**options)
            kit.output(bpy.context.scene, job["width"], job["height"])
            bpy.context.view_layer.update()
            runs = [toyrt_render(sync, toyrt, job["spp"], "solid_angle", "auto", job["specular_depth"])
                    for _ in range(job["repeats"])]
            best = min(runs, key=lambda r: r[1])
            stats = best[4]
            steps.append(dict(label=label, seconds=best[1], render_seconds=min(r[2] for r in runs),
                              triangles=stats["triangles"], instances=stats["instances"], lights=stats["lights"],
                              textures=stats["textures"], light_sampling=best[3].get("light_sampling")))
            print(f"bench: economy {label}: {best[1]:.3f} s", flush=True)
        result["economy"] = steps
        result["spp"] = job["spp"]
        out.write_text(json.dumps(result, indent=1))
        return

    t0 = time.perf_counter()
    module.build(**job.get("options", {}))
    result["build_seconds"] = time.perf_counter() - t0
    scene = bpy.context.scene
    kit.output(scene, job["width"], job["height"])
    bpy.context.view_layer.update()
    depth = job["specular_depth"]

    ref, info = reference(job, path, Path(job["cache"]))
    result["reference"] = info
    np.save(out.with_suffix(".ref.npy"), ref.astype(np.float32))
    mask = error_mask(ref)
    np.save(out.with_suffix(".mask.npy"), mask)
    result["masked_fraction"] = float(1.0 - mask.mean())

    runs = []
    cycles_tmp = out.with_suffix(".cycles.exr")
    kit.cycles(scene, 1, depth)
    render_cycles(scene, cycles_tmp)  # warm-up: the first render in a process loads Cycles' kernels
    for spp in job["cycles_spp"]:
        kit.cycles(scene, spp, depth)
        best = None
        for _ in range(job["repeats"]):
            img, seconds = render_cycles(scene, cycles_tmp)
            best = (img, seconds) if best is None or seconds < best[1] else best
        rmse, relmse = errors(best[0], ref, mask)
        runs.append(dict(renderer="cycles", method="Cycles", spp=spp, seconds=best[1], rmse=rmse, relmse=relmse))
        print(f"bench: {job['name']}: Cycles {spp} spp {best[1]:.3f} s rmse {rmse:.4g}", flush=True)

    for area, lights in job["methods"]:
        for spp in job["toyrt_spp"]:
            best = None
            for _ in range(job["repeats"]):
                r = toyrt_render(sync, toyrt, spp, area, lights, depth)
                best = r if best is None or r[1] < best[1] else best
            img, seconds, render_s, last, stats = best
            rmse, relmse = errors(img, ref, mask)
            runs.append(dict(renderer="toyrt", method=f"TOYRT {area}/{lights}", area_light_sampling=area,
                             light_sampling=lights, resolved_light_sampling=last.get("light_sampling"), spp=spp,
                             seconds=seconds, render_seconds=render_s, rmse=rmse, relmse=relmse))
            if spp == job["toyrt_spp"][-1] and (area, lights) == tuple(job["methods"][0]):
                np.save(out.with_suffix(".toyrt.npy"), img.astype(np.float32))
            print(f"bench: {job['name']}: TOYRT {area}/{lights} {spp} spp {seconds:.3f} s rmse {rmse:.4g}", flush=True)
    result["scene_stats"] = {k: v for k, v in stats.items() if k != "approximated"}
    result["approximated"] = stats.get("approximated", [])
    result["runs"] = runs
    if job.get("mitsuba_dir"):
        dump_for_mitsuba(mesh, Path(job["mitsuba_dir"]), depth)
    out.write_text(json.dumps(result, indent=1))


if __name__ == "__main__":  # as blender --python runs it; bench/denoise_bench.py imports its parts
    try:
        main()
    except Exception:
        import traceback
        traceback.print_exc()
        sys.exit(1)
