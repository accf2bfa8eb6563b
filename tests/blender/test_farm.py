# Runs inside Blender:  blender -b --python-exit-code 1 --python tests/blender/test_farm.py
# TOYRT on render farms: the exact command lines Flamenco 3 and Deadline run, and the repeated
# bpy.ops.render.render() calls of a Deadline Cloud session, on one tiny scene rendered by TOYRT
# and by Cycles. Every regular expression of those managers' parsers that Cycles' output matches
# on this Blender must match TOYRT's too; the last Sample line of a frame says N/N; nothing trips
# Deadline Cloud's strict mode although the scene has what TOYRT approximates (a Principled BSDF,
# a Diffuse BSDF's roughness) and the LBVH builds on the host where OpenCL is missing; the exit codes
# with and without -E TOYRT where the add-on is missing; the longest silence while a large mesh is exported and
# its BVH built. The command lines run against a copy of the installed add-on in an empty user
# folder, as on a fresh farm worker; under the bpy module (no blender executable,
# TOYRT_NO_BLENDER_BINARY) only the in-process session runs.
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "scenes")]  # harness and the scene kit (see harness)
import kit  # noqa: E402
from harness import captured_output, check, run_script  # noqa: E402

SAMPLES = 8
FRAMES = (1, 2, 3)
TMP = tempfile.mkdtemp(prefix="toyrt-farm-")
NO_BINARY = bool(os.environ.get("TOYRT_NO_BLENDER_BINARY")) or not bpy.app.binary_path

# The farm managers' parsers, as they are written (each applied to one line, re.match).
PARSERS = {
    "Flamenco  ^Saved: '(.*)'": r"^Saved: '(.*)'",
    "Flamenco  ^Time: ([0-9:.]+)": r"^Time: ([0-9:.]+)",
    "Deadline  .*Sample ([0-9]+)/([0-9]+).*": r".*Sample ([0-9]+)/([0-9]+).*",
    "Deadline  .*Saved:.*": r".*Saved:.*",
    "Deadline Cloud  ^Fra:.*Sample\\s(\\d+)\\/(\\d+)$": r"^Fra:.*Sample\s(\d+)\/(\d+)$",
}
STRICT = re.compile(r".*Exception:.*|.*Error:.*|.*Warning.*")  # Deadline Cloud's strict mode fails on these
SAMPLE = re.compile(r"^Fra:(\d+) .*Sample (\d+)/(\d+)$")
MEASURED = {}  # what the docs quote, printed at the end


def build_scene(engine, path, builder="sah"):
    """A 32 x 32 view of a rough Diffuse BSDF plane (TOYRT: Lambert, noted) under a point light and
    an area light, three frames, PNG output; saved to `path` for `engine`."""
    s = kit.clear_scene()
    # The material's name carries one of the strict-mode words into TOYRT's note on purpose.
    floor = kit.diffuse("WarningStripes", (0.8, 0.6, 0.2))
    kit.input_of(floor.node_tree.nodes["Diffuse BSDF"], "Roughness").default_value = 0.5
    kit.plane("floor", 10.0, floor)
    kit.point_light("lamp", (0, 0, 1), 100.0)
    kit.area_light("panel", (0, 0, 2), 50.0, 0.5)
    kit.camera((0, 0, 5), ortho_scale=2.0)
    kit.output(s, 32, 32)
    if engine == "CYCLES":
        kit.cycles(s, SAMPLES, 0)
    else:
        kit.toyrt(s, samples=SAMPLES, builder=builder)
    s.render.image_settings.file_format = "PNG"
    s.frame_start, s.frame_end = FRAMES[0], FRAMES[-1]
    bpy.ops.wm.save_as_mainfile(filepath=path)
    return path


def matched(lines):
    """The PARSERS keys some line of `lines` matches."""
    return {name for name, rx in PARSERS.items() if any(re.match(rx, line) for line in lines)}


def compare(label, toyrt_lines, cycles_lines, frames):
    """TOYRT matches every parser Cycles matches; each frame's last Sample line says N/N; every
    TOYRT Sample line has the layout of a Cycles one (digits aside); nothing trips strict mode."""
    want, got = matched(cycles_lines), matched(toyrt_lines)
    MEASURED[label] = (sorted(want), sorted(got))
    check(want <= got, f"{label}: TOYRT matches every parser Cycles matches {sorted(want)}"
                       + (f" -- missing {sorted(want - got)}" if want - got else ""))
    samples = [SAMPLE.match(line) for line in toyrt_lines]
    last = {int(m[1]): (int(m[2]), int(m[3])) for m in samples if m}
    if any(SAMPLE.match(line) for line in cycles_lines):
        check(sorted(last) == list(frames) and all(k == n == SAMPLES for k, n in last.values()),
              f"{label}: each frame's last Sample line says {SAMPLES}/{SAMPLES}: {last}")
        shape = re.compile(r"\d+")
        cycles_shapes = {shape.sub("#", line) for line in cycles_lines if SAMPLE.match(line)}
        odd = [line for line in toyrt_lines if SAMPLE.match(line) and shape.sub("#", line) not in cycles_shapes]
        mine = [line for line in toyrt_lines if SAMPLE.match(line)]
        check(mine and not odd, f"{label}: TOYRT's Sample lines have Cycles' layout: {(odd or mine)[-1:]}")
    strict = [line for line in toyrt_lines if STRICT.match(line)]
    notes = [line for line in toyrt_lines if line.startswith("TOYRT note: approximated")]
    check(not strict and len(notes) == len(frames) and "roughness" in notes[0],
          f"{label}: one 'TOYRT note:' per frame, no line trips strict mode: {strict[:2] or notes[:1]}")


# ---- command lines (Debian's Blender 3.4: a blender executable) -------------------------------

def worker(name, installed=True):
    """The environment of a fresh farm worker: empty user folders (an empty BLENDER_USER_CONFIG
    alone still sees the add-on `make setup` installed), with a copy of the installed add-on
    enabled in its preferences when `installed`."""
    import render_toyrt

    home = os.path.join(TMP, name)
    env = dict(os.environ, BLENDER_USER_SCRIPTS=os.path.join(home, "scripts"),
               BLENDER_USER_CONFIG=os.path.join(home, "config"))
    os.makedirs(os.path.join(home, "scripts", "addons"), exist_ok=True)
    if installed:
        shutil.copytree(os.path.dirname(render_toyrt.__file__),
                        os.path.join(home, "scripts", "addons", "render_toyrt"),
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        enable = ("import addon_utils, bpy\n"
                  "assert addon_utils.enable('render_toyrt', default_set=True, handle_error=None)\n"
                  "bpy.ops.wm.save_userpref()")
        run = subprocess.run([bpy.app.binary_path, "-b", "--python-exit-code", "1", "--python-expr", enable],
                             env=env, capture_output=True, text=True, timeout=120)
        assert run.returncode == 0, run.stdout + run.stderr
    return env


def blender(args, env):
    """`blender ARGS` as a farm runs it: (exit code, stdout + stderr lines)."""
    run = subprocess.run([bpy.app.binary_path] + args, env=env, capture_output=True, text=True, timeout=300)
    return run.returncode, (run.stdout + run.stderr).splitlines()


def test_flamenco():
    """Flamenco 3's render command: -y, --render-output DIR/######, --render-frame 1..3."""
    env = worker("flamenco")
    runs = {}
    for engine in ("CYCLES", "TOYRT"):
        blend = build_scene(engine, os.path.join(TMP, f"flamenco_{engine}.blend"))
        out = os.path.join(TMP, f"flamenco_{engine}_out")
        t0 = time.perf_counter()
        code, lines = blender(["-b", "-y", blend, "--render-output", out + "/######", "--render-format", "PNG",
                               "--render-frame", "1..3"], env)
        files = [os.path.join(out, f"{f:06d}.png") for f in FRAMES]
        check(code == 0 and all(map(os.path.exists, files)),
              f"Flamenco, {engine}: exit {code}, frames 1..3 written ({time.perf_counter() - t0:.1f} s)")
        runs[engine] = lines
    compare("Flamenco", runs["TOYRT"], runs["CYCLES"], FRAMES)
    MEASURED["Flamenco TOYRT lines of frame 1"] = [line for line in runs["TOYRT"] if line.startswith(
        ("Fra:1 ", "TOYRT", "Saved: '", " Time:")) and "000002" not in line][:9]


def test_deadline():
    """Deadline 10's Blender plugin: -t 2 -x 1 -o OUT -s 1 -e 2 -a; for TOYRT without OpenCL
    (OCL_ICD_VENDORS: an empty folder) and the LBVH builder asked for: the host builds it, so the
    log says nothing about it. The test adds one argument to Deadline's line, a --python-expr
    before -a whose render_post handler prints each frame's builders (not something Deadline runs:
    it shows that the LBVH built the mesh)."""
    env = worker("deadline")
    no_opencl = os.path.join(TMP, "no-opencl-vendors")
    os.makedirs(no_opencl, exist_ok=True)
    runs = {}
    # After each TOYRT frame, the builders of its commit (toyrt.Scene.last_commit), printed by a
    # render_post handler that the command line adds before -a: the log shows the LBVH ran.
    # A failure in the handler is printed by its type's name alone (a traceback's "KeyError:"
    # line would fail the strict-mode check above with a misleading message).
    said_builders = ("import bpy\n"
                     "def said(*_):\n"
                     "    try:\n"
                     "        from render_toyrt import render_cache\n"
                     "        for c in render_cache.render_caches():\n"
                     "            n = c.scene.last_commit\n"
                     "            print('toyrt-test: meshes built', n['lbvh_meshes'], 'lbvh', n['sah_meshes'], 'sah',\n"
                     "                  flush=True)\n"
                     "    except BaseException as e:\n"
                     "        print('toyrt-test: the handler failed:', type(e).__name__, flush=True)\n"
                     "bpy.app.handlers.render_post.append(said)\n")
    for engine in ("CYCLES", "TOYRT"):
        blend = build_scene(engine, os.path.join(TMP, f"deadline_{engine}.blend"), builder="lbvh")
        out = os.path.join(TMP, f"deadline_{engine}_out", "frame_####")
        code, lines = blender(["-b", blend, "-t", "2", "-x", "1", "-o", out, "-s", "1", "-e", "2"]
                              + (["--python-expr", said_builders] if engine == "TOYRT" else []) + ["-a"],
                              dict(env, OCL_ICD_VENDORS=no_opencl))
        files = [out.replace("####", f"{f:04d}") + ".png" for f in (1, 2)]
        check(code == 0 and all(map(os.path.exists, files)), f"Deadline, {engine}: exit {code}, frames 1-2 written")
        runs[engine] = lines
    compare("Deadline", runs["TOYRT"], runs["CYCLES"], (1, 2))
    said = [line for line in runs["TOYRT"] if "LBVH" in line or "OpenCL" in line]
    check(not said, f"Deadline: without OpenCL the LBVH builds on the host, with nothing to report: {said[:1]}")
    built = [line for line in runs["TOYRT"] if line.startswith("toyrt-test: meshes built")]
    check(built and built[0].endswith(" 0 sah") and not built[0].startswith("toyrt-test: meshes built 0 "),
          f"Deadline: frame 1's commit built its meshes with the LBVH (on the host), none with SAH: {built[:2]}")
    MEASURED["Deadline TOYRT builders by frame"] = built


def test_exit_codes():
    """A .blend saved with TOYRT on a worker without the add-on: with -E TOYRT Blender refuses the
    unknown engine and exits non-zero; without it, it renders the file with EEVEE and exits 0."""
    env = worker("bare", installed=False)
    blend = build_scene("TOYRT", os.path.join(TMP, "saved_with_toyrt.blend"))
    out = os.path.join(TMP, "bare_out", "frame_####")
    with_e, lines_e = blender(["-b", blend, "-E", "TOYRT", "-o", out, "-F", "PNG", "-f", "1"], env)
    without_e, lines = blender(["-b", blend, "-o", out, "-F", "PNG", "-f", "1"], env)
    MEASURED["exit codes without the add-on"] = dict(with_E=with_e, without_E=without_e)
    MEASURED["printed without -E"] = [x for x in lines if "TOYRT" in x][:1]
    check(with_e != 0, f"-E TOYRT without the add-on exits {with_e}: {[x for x in lines_e if 'TOYRT' in x][:1]}")
    # Which engine that was: the file as this worker opens it.
    _, engine = blender(["-b", blend, "--python-expr", "import bpy; print('engine:', bpy.context.scene.render.engine)"],
                        env)
    engine = [line for line in engine if line.startswith("engine:")]
    written = os.path.exists(out.replace("####", "0001") + ".png")
    check(without_e == 0 and written and engine == ["engine: BLENDER_EEVEE"],
          f"without -E it renders with {engine} and exits {without_e}: a farm would accept the wrong image")


def test_silence_gap():
    """The longest interval between two output lines while TOYRT exports a 3.1M-triangle mesh (a
    Simple subdivision of a 24 x 16 grid, evaluated by Blender before the render starts) and builds
    its BVH, with the stats line asked for every 0.25 s: the longest step between two polls. Without
    the heartbeat it would be a whole phase (the build: over half of the time)."""
    env = dict(worker("silence"), TOYRT_PROGRESS_SECONDS="0.25")
    kit.clear_scene()
    s = bpy.context.scene
    grid = [(x, y, 0.0) for y in range(17) for x in range(25)]
    quads = [(y * 25 + x, y * 25 + x + 1, (y + 1) * 25 + x + 1, (y + 1) * 25 + x) for y in range(16) for x in range(24)]
    obj = kit.mesh_object("grid", grid, quads, kit.diffuse("grey"), location=(-12, -8, 0))
    sub = obj.modifiers.new("subdivide", "SUBSURF")
    sub.subdivision_type, sub.levels, sub.render_levels = "SIMPLE", 0, 6  # 384 x 4^6 quads
    kit.point_light("lamp", (0, 0, 5), 500.0)
    kit.camera((0, 0, 20), ortho_scale=30.0)
    kit.output(s, 16, 16)
    kit.toyrt(s, samples=1, builder="sah")
    blend = os.path.join(TMP, "large.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    t0 = time.monotonic()
    proc = subprocess.Popen([bpy.app.binary_path, "-b", blend, "-o", os.path.join(TMP, "large_"), "-F", "PNG",
                             "-f", "1"], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    stamped = [(time.monotonic(), line.rstrip("\n")) for line in proc.stdout]
    code = proc.wait(timeout=300)
    start = next((t for t, line in stamped if line.endswith("| Exporting scene")), None)
    end = next((t for t, line in stamped if line.endswith("| Sample 0/1")), None)
    if start is None or end is None:
        check(False, f"the large mesh's render prints its phases (exit {code}): {[x for _, x in stamped][-3:]}")
        return
    inside = [t for t, _ in stamped if start <= t <= end]
    gap = max(b - a for a, b in zip(inside, inside[1:]))
    builds = sum(line.endswith("| Building BVH") for _, line in stamped)
    tris = next((line.split(", ")[-1] for _, line in stamped if "| Finished |" in line), "?")
    MEASURED["silence gap"] = dict(triangles=tris, before_export_s=round(start - t0, 2),
                                   export_and_build_s=round(end - start, 2), lines=len(inside),
                                   build_lines=builds, longest_gap_s=round(gap, 2))
    check(code == 0 and tris == "3,145,728 triangles", f"the large mesh renders (exit {code}, {tris})")
    check(gap < 0.5 * (end - start) and builds >= 2,
          f"export + build of {tris}: {len(inside)} lines ({builds} 'Building BVH') in {end - start:.1f} s, "
          f"the longest silence {gap:.2f} s")


# ---- the persistent session (Deadline Cloud): in this process, under every Blender -----------

def test_session():
    """bpy.ops.render.render() once per frame in one process, as Deadline Cloud's Blender adaptor
    does, for each engine: the same parser comparison; then no non-daemon thread is left."""
    runs = {}
    for engine in ("CYCLES", "TOYRT"):
        build_scene(engine, os.path.join(TMP, f"session_{engine}.blend"))
        s = bpy.context.scene
        text = []
        for frame in FRAMES:
            s.frame_set(frame)
            s.render.filepath = os.path.join(TMP, f"session_{engine}_{frame}")
            with captured_output() as out:
                result = bpy.ops.render.render(write_still=True)
            text += out[0].splitlines()
            check(result == {"FINISHED"} and os.path.exists(s.render.filepath + ".png"),
                  f"session, {engine}, frame {frame}: {result}, written")
        runs[engine] = text
    compare(f"session (Blender {bpy.app.version_string})", runs["TOYRT"], runs["CYCLES"], FRAMES)
    alive = [t.name for t in threading.enumerate() if not t.daemon and t is not threading.main_thread()]
    check(not alive, f"no non-daemon thread is left after the renders: {alive}")


def test_time_limit():
    """Cycles' time limit and adaptive sampling under their Cycles names: a frame of 2^20 samples with
    a 0.5 s limit finishes, written, its last Sample line says the samples it took (k/N with k < N),
    and TOYRT's own line says the same count; nothing in it trips a strict farm. With adaptive
    sampling on too, the line says the mean samples per pixel."""
    build_scene("TOYRT", os.path.join(TMP, "time_limit.blend"))
    s = bpy.context.scene
    s.toyrt.samples = 1 << 20
    s.toyrt.time_limit = 0.5
    s.render.filepath = os.path.join(TMP, "time_limit")
    with captured_output() as out:
        result = bpy.ops.render.render(write_still=True)
    lines = out[0].splitlines()
    check(result == {"FINISHED"} and os.path.exists(s.render.filepath + ".png"), f"time limit: {result}, written")
    samples = [re.search(r"Sample (\d+)/(\d+)", line) for line in lines]
    samples = [(int(m.group(1)), int(m.group(2))) for m in samples if m]
    done = [re.search(r"\((\d+)x(\d+), (\d+) of (\d+) samples: time limit", line) for line in lines]
    done = [int(m.group(3)) for m in done if m]
    check(done and 1 <= done[0] < 1 << 20, f"the limit stopped the frame after {done} of {1 << 20} samples")
    if samples or not NO_BINARY:  # the bpy module prints no stats lines
        check(samples and samples[-1] == (done[0], 1 << 20),
              f"the last Sample line {samples[-1] if samples else None} says the samples taken ({done})")
    strict = [line for line in lines if re.search(r"Warning|Error|Exception", line)]
    check(not strict, f"no line a strict farm fails on: {strict[:3]}")
    # Adaptive sampling: this flat scene's pixels stop at the first tests (the automatic minimum for
    # Cycles' default threshold, 64, then a test after sample 79), long before 2^20; its Principled
    # floor's specular layer is noisier than a Lambert floor, so the limit is raised far above what
    # that takes (were it reached, the line would say so too).
    s.toyrt.use_adaptive_sampling = True
    s.toyrt.time_limit = 30.0   # a bound far above what adaptive sampling needs here
    with captured_output() as out:
        result = bpy.ops.render.render(write_still=True)
    mean = [re.search(r"\(\d+x\d+, (\d+ of )?(\d+) samples(: time limit)?, adaptive: ([0-9.]+) per pixel\)", line)
            for line in out[0].splitlines()]
    mean = [float(m.group(4)) for m in mean if m]
    check(result == {"FINISHED"} and mean and 80 <= mean[0] < 1 << 20,
          f"adaptive sampling with the limit: {mean} samples per pixel of {1 << 20}")
    s.toyrt.time_limit = 0.0
    s.toyrt.use_adaptive_sampling = False


def report():
    for key, value in MEASURED.items():
        print(f"  measured: {key}: {value}", flush=True)


if NO_BINARY:
    print("test_farm: the command lines are skipped (bpy module: no blender executable of this version)", flush=True)
PARTS = [test_session, test_time_limit]
PARTS += [] if NO_BINARY else [test_flamenco, test_deadline, test_exit_codes, test_silence_gap]
run_script(PARTS + [report], "test_farm", TMP)
