# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_animation_memory.py
# (`make test` runs it). A 100-frame animation rendered with TOYRT in one Blender process:
#   - meshes that do not change between frames are exported once (a static plane; a cube that only
#     moves keeps its mesh and gets a new transform), a mesh deformed by an animated Wave modifier
#     is exported again every frame, in place: the cache's counters say exactly that;
#   - the engine gives back the arrays commits freed after each final render (a throwaway scene's,
#     built before the animation through the native module, are gone after it);
#   - memory stays flat: the process's resident memory (VmRSS) grows by less than one frame's mesh
#     data plus 8 MB between frame 10 and frame 100. A leak of the re-exported mesh (its native
#     copy is about 10 MB) would add that every frame, about 900 MB over 90 frames; the first 10
#     frames are left out because allocators and Blender's render pipeline warm up there;
#   - each frame's picture is right: the moving cube is where the camera puts it (checked on the
#     first and last frames).
import os
import sys
import tempfile

import bpy
import render_toyrt

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import check, run_script  # noqa: E402

FRAMES = 100
TMP = tempfile.mkdtemp(prefix="toyrt-test-animation-")


def rss():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    raise RuntimeError("no VmRSS")


def build():
    scene = kit.clear_scene()
    # Standard, not the default view transform: 4.x's AgX maps the cube's top and the floor beside
    # it (radiance 0.45 and 0.40) to the same 8-bit value.
    kit.output(scene, 16, 16)
    kit.toyrt(scene, samples=1)
    scene.frame_start, scene.frame_end = 1, FRAMES
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = os.path.join(TMP, "frame_")

    kit.plane("floor", 20.0)                                                   # static
    cube = kit.box("cube", 1.0, (-2, 0, 0.5))                                  # moves
    cube.keyframe_insert("location", frame=1)
    cube.location.x = 2
    cube.keyframe_insert("location", frame=FRAMES)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=1, location=(0, 3, 1))  # deforms
    sphere = bpy.context.object
    wave = sphere.modifiers.new("wave", "WAVE")
    wave.height = 0.1
    wave.time_offset = 0.0
    kit.point_light("light", (0, 0, 5), 500.0, radius=0.25)     # Blender 3.4's default radius
    kit.camera((0, 0, 10), ortho_scale=10.0)
    return scene, sphere


def fill_cache():
    """Builds a throwaway 180,000-triangle grid twice through the native module and drops it: the
    arrays its commits freed (each over 2 MB) are kept for a next commit. Returns their bytes."""
    import numpy as np

    toyrt = render_toyrt.native()
    n = 300
    xs, ys = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    vertices = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1).astype(np.float32)
    i = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    triangles = np.concatenate([np.stack([i, i + 1, i + n + 2], 1), np.stack([i, i + n + 2, i + n + 1], 1)])
    s = toyrt.Scene()
    mesh = s.add_mesh(vertices, triangles.astype(np.uint32))
    s.commit()
    s.replace_mesh(mesh, vertices, triangles.astype(np.uint32))
    s.commit()
    del s
    return toyrt.cached_memory_bytes()


def main():
    from render_toyrt import render_cache

    before = fill_cache()
    check(before > 0, f"a throwaway scene's freed arrays cached before the animation ({before / 1e6:.1f} MB)")
    scene, sphere = build()
    samples = {}

    def after_frame(scn, *_):
        samples[scn.frame_current] = rss()

    bpy.app.handlers.render_post.append(after_frame)
    try:
        bpy.ops.render.render(animation=True)
    finally:
        bpy.app.handlers.render_post.remove(after_frame)

    files = sorted(f for f in os.listdir(TMP) if f.endswith(".png"))
    check(len(files) == FRAMES, f"{FRAMES} frames written ({len(files)})")
    caches = render_cache.render_caches()
    check(len(caches) == 1, "one render cache for the scene")
    cache = caches[0]
    c = cache.counters
    # Frame 1: plane, cube, sphere; frames 2..100: the deformed sphere only.
    check(c["meshes_exported"] == 3 + (FRAMES - 1),
          f"meshes exported: {c['meshes_exported']} (expected {3 + FRAMES - 1})")
    check(c["transforms_set"] >= FRAMES - 1, f"the cube's transform set each frame ({c['transforms_set']})")
    check(c["instance_resets"] == 1, f"instances laid out once ({c['instance_resets']})")
    check(cache.scene.mesh_count == 3,
          f"the native scene holds 3 meshes after {FRAMES} frames ({cache.scene.mesh_count})")

    # What a commit frees is kept for the next commit, but the engine gives it back after every
    # render (engine.py): what fill_cache() left is gone.
    cached = render_toyrt.native().cached_memory_bytes()
    check(cached == 0, f"no freed BVH arrays kept after the render ({cached / 1e6:.1f} MB)")

    sphere_bytes = cache.scene.memory_bytes  # the whole scene: a bound above the sphere's own bytes
    growth = samples[FRAMES] - samples[10]
    bound = sphere_bytes + 8e6
    print(f"  RSS: frame 1 {samples[1] / 1e6:.1f} MB, frame 10 {samples[10] / 1e6:.1f} MB, "
          f"frame {FRAMES} {samples[FRAMES] / 1e6:.1f} MB; native scene {sphere_bytes / 1e6:.1f} MB", flush=True)
    check(growth < bound, f"memory growth frames 10-{FRAMES}: {growth / 1e6:.1f} MB < {bound / 1e6:.1f} MB")

    # The cube (x from -2 to 2 over the animation) under the ortho camera, 10 m across 16 pixels:
    # its column moves from about 8 - 2 * 1.6 to 8 + 2 * 1.6, and the light above the origin casts
    # its shadow on the floor just outside it (the first column past its outer side is black).
    # A shadow, not the cube's top against the floor: at 1 sample those two can round to the same
    # 8-bit value (0.399 and 0.402 measured).
    for frame, expect_x in ((1, -2.0), (FRAMES, 2.0)):
        px = kit.read_image(os.path.join(TMP, f"frame_{frame:04d}.png"))
        row = px[8, :, 0]  # through the cube's centre (y = 0), rows from the bottom
        col = (expect_x + 5.0) / 10.0 * 16.0
        shadow = int(col) - 1 if expect_x < 0 else int(col) + 1
        lit = int(col) + 3 if expect_x < 0 else int(col) - 3
        check(row[shadow] < 0.5 * row[lit],
              f"frame {frame}: the cube's shadow at column {shadow} ({row[shadow]:.3f}), lit floor at {lit} "
              f"({row[lit]:.3f})")


run_script([main], "animation memory", TMP)
