# Writes docs/results.md and its charts (docs/results/*.png) from what bench/run.py measured in its
# work folder. Every number in the report is read from those files; the prose around them only
# states which way the numbers point, decided here from the numbers themselves.
#     python3 bench/report.py out/bench [--blender blender]
import argparse
import csv
import json
import math
import os
import platform
import subprocess
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "results.md"
FIG = REPO / "docs" / "results"
COLORS = {"TOYRT solid_angle/all": "#1f77b4", "TOYRT solid_angle/one": "#6baed6", "TOYRT area/all": "#d62728",
          "TOYRT area/one": "#ff9896", "Cycles": "#2ca02c", "Mitsuba 3 direct": "#9467bd",
          "Mitsuba 3 path": "#8c564b"}


def mitsuba_method(runs):
    """The Mitsuba method of a scene's runs: its `direct` integrator, or `path` where the reference
    follows glossy bounces through a scene with nothing diffuse (bench/mitsuba_bench.py: integrator)."""
    return next((r["method"] for r in runs if r["renderer"] == "mitsuba"), "Mitsuba 3 direct")


def sh(*cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, timeout=60).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        return ""


def load(path):
    return json.loads(path.read_text()) if path.exists() else None


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    if x == 0:
        return "0"
    if abs(x) >= 1000 or abs(x) < 0.01:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


# ---- section 1: error against time ------------------------------------------------------------

def curve(runs, method, metric):
    """(seconds, error) of a method's points in order of samples per pixel."""
    pts = sorted((r["spp"], r["seconds"], r[metric]) for r in runs if r["method"] == method)
    return np.array([p[1] for p in pts]), np.array([p[2] for p in pts])


class Fit:
    """A method's cost and error as functions of samples per pixel, fitted to its points, so that
    single noisy timings (a busy shared machine) do not decide a ratio: error = a spp^b (log-log
    least squares) and seconds = t0 + c spp (least squares, t0 >= 0: the fixed cost of export, BVH
    build and start-up, then a cost per sample)."""

    def __init__(self, runs, method, metric):
        pts = [(r["spp"], r["seconds"], r[metric]) for r in runs if r["method"] == method and r[metric] > 0]
        self.ok = len(pts) >= 2
        if not self.ok:
            return
        spp, t, e = (np.array(x, float) for x in zip(*pts))
        self.b, self.log_a = np.polyfit(np.log(spp), np.log(e), 1)
        c, t0 = np.polyfit(spp, t, 1)
        if t0 < 0 or c <= 0:
            t0, c = max(t0, 0.0), max(float(np.sum((t - max(t0, 0.0)) * spp) / np.sum(spp * spp)), 1e-12)
        self.t0, self.c = t0, c
        self.spp_range = (spp.min() / 2, spp.max() * 2)  # how far the fit is trusted

    def seconds_for(self, error, below=False):
        """Seconds to reach `error`; None outside the trusted range. With below=True an error already
        beaten at the fewest samples measured gives that render's time (an upper bound)."""
        if not self.ok or self.b >= 0:
            return None
        spp = math.exp((math.log(error) - self.log_a) / self.b)
        if below and spp < self.spp_range[0]:
            spp = self.spp_range[0] * 2
        if not self.spp_range[0] <= spp <= self.spp_range[1]:
            return None
        return self.t0 + self.c * spp


def speedup(runs, method, peer, metric):
    """Geometric mean, over the errors the peer measured, of (the peer's time to that error) /
    (the method's time to it), both from their fits (Fit) within the sample counts measured
    (halved and doubled): > 1 means the method is faster. (ratio, how many errors compared)."""
    fp, fm = Fit(runs, peer, metric), Fit(runs, method, metric)
    if not (fp.ok and fm.ok):
        return None, 0
    exact, bounds = [], []
    for target in (r[metric] for r in runs if r["method"] == peer and r[metric] > 0):
        a, b = fp.seconds_for(target), fm.seconds_for(target)
        if a and b:
            exact.append(a / b)
        elif a and fm.seconds_for(target, below=True):
            # The method beats this error at its fewest samples already: its time there bounds it.
            bounds.append(a / fm.seconds_for(target, below=True))
    # Errors both fits cover decide; only when there are none do the bounds stand in ('>=').
    ratios, bounded = (exact, False) if exact else (bounds, True)
    if not ratios:
        return None, 0
    return (float(np.exp(np.mean(np.log(ratios)))), bounded), len(ratios)


def ref_noise(runs, ref_spp):
    """Cycles' own RMSE at the reference's sample count, from its fit (the RMSE of an independent
    render at that count; the reference's error is the same in expectation)."""
    f = Fit(runs, "Cycles", "rmse")
    if not f.ok or not ref_spp:
        return "n/a"
    return fmt(math.exp(f.log_a + f.b * math.log(ref_spp)))


def fixed_costs(data):
    """The t0 of each renderer's time fit: what it pays before the first sample."""
    lights = data.get("scene_stats", {}).get("lights", 0)
    out = []
    for m in ("Cycles", f"TOYRT solid_angle/{'one' if lights > 4 else 'all'}", mitsuba_method(data["runs"])):
        f = Fit(data["runs"], m, "relmse")
        out.append(fmt(f.t0) if f.ok else "-")
    return " / ".join(out)


def worst_share(work, name):
    """How much of the squared error of TOYRT's last saved render (the first method at the most
    samples) sits in its worst 1 % of counted pixels: near 1, RMSE is a few pixels' fireflies."""
    try:
        ref, img = np.load(work / f"render-{name}.ref.npy"), np.load(work / f"render-{name}.toyrt.npy")
        mask = np.load(work / f"render-{name}.mask.npy")
    except OSError:
        return "n/a"
    e = np.sort(((img - ref) ** 2).sum(axis=2)[mask])[::-1]
    return f"{100 * e[:max(len(e) // 100, 1)].sum() / max(e.sum(), 1e-300):.0f} %"


def slope(runs, method, metric):
    """Fitted exponent of error against samples per pixel (log-log): -0.5 for independent samples
    of RMSE, lower (steeper) for stratified ones."""
    pts = [(r["spp"], r[metric]) for r in runs if r["method"] == method and r[metric] > 0]
    if len(pts) < 2:
        return None
    x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(x, y, 1)[0])


def variance_ratio(e):
    """One estimator sweep point's one-sample variance of the area estimator over the solid-angle one's."""
    return (e["area_rel_std"] * e["area_mean"]) ** 2 / max((e["solid_rel_std"] * e["solid_mean"]) ** 2, 1e-300)


def save_figure(fig, name):
    """Writes a matplotlib figure to docs/results/<name> (90 dpi, tight layout) and closes it: its path."""
    fig.tight_layout()
    path = FIG / name
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def error_charts(scenes):
    paths = []
    for name, data in scenes.items():
        runs = data["runs"]
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        for ax, metric, label in ((axes[0], "rmse", "RMSE"), (axes[1], "relmse", "relative MSE")):
            for method in dict.fromkeys(r["method"] for r in runs):
                t, e = curve(runs, method, metric)
                ax.loglog(t, e, "o-", ms=3, label=method, color=COLORS.get(method))
            ax.set_xlabel("seconds, scene to image (wall clock)")
            ax.set_ylabel(label)
            ax.grid(True, which="both", alpha=0.3)
        axes[0].legend(fontsize=7)
        fig.suptitle(f"{name}: error against the Cycles reference vs time")
        paths.append(save_figure(fig, f"error-{name}.png"))
    return paths


def scene_montage(work, scenes):
    names = list(scenes)
    fig, axes = plt.subplots(1, len(names), figsize=(2.6 * len(names), 2.9))
    for ax, name in zip(np.atleast_1d(axes), names):
        ref = np.load(work / f"render-{name}.ref.npy")
        srgb = np.where(ref <= 0.0031308, 12.92 * ref, 1.055 * np.clip(ref, 0.0031308, None) ** (1 / 2.4) - 0.055)
        ax.imshow(np.clip(srgb, 0, 1))
        ax.set_title(name, fontsize=9)
        ax.axis("off")
    return save_figure(fig, "scenes.png")


# ---- section 2: acceleration structures -------------------------------------------------------

def accel_rows(work):
    path = work / "accel.csv"
    if not path.exists():
        return []
    with open(path) as f:
        return [dict(r) for r in csv.DictReader(f)]


def total_seconds(build_ms, p, d, s, rays_per_type):
    """Build + trace of rays_per_type rays of each kind at the measured Mrays/s."""
    return build_ms / 1e3 + sum(rays_per_type / (v * 1e6) for v in (p, d, s))


# ---- the report ----------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("work", type=Path)
    ap.add_argument("--blender", default="blender")
    args = ap.parse_args()
    work = args.work.resolve()
    FIG.mkdir(parents=True, exist_ok=True)
    meta = load(work / "run.json") or {}
    cfg = meta.get("settings", {})
    md = []
    w = md.append

    # -- header: machine, versions, date --
    cpu = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                if line.startswith("model name")), platform.processor())
    commit = sh("git", "rev-parse", "--short=12", "HEAD")
    dirty = sh("git", "status", "--porcelain", "--untracked-files=no", "--", "native", "kernels", "addon")
    mitsuba_info = next((load(p) for p in sorted(work.glob("mitsuba-*.json"))), None) or {}
    py = load(work / "accel-python.json") or {}
    versions = {
        "Blender": sh(args.blender, "-b", "--version").splitlines()[0] if sh(args.blender, "-b", "--version") else "?",
        "Embree": (sh("dpkg-query", "-W", "-f", "${Version}", "libembree3-3")
                   or sh("dpkg-query", "-W", "-f", "${Version}", "libembree-dev")),
        "PoCL": sh("dpkg-query", "-W", "-f", "${Version}", "pocl-opencl-icd"),
        "Mitsuba": f"{mitsuba_info.get('version', 'not run')} ({mitsuba_info.get('variant', '?')})",
        "Open3D": py.get("open3d") or f"not available ({py.get('open3d_error', 'not run')})",
        "TOYRT": f"git {commit}" + (" with uncommitted changes in native/, kernels/ or addon/" if dirty else ""),
        "Python": platform.python_version(),
    }
    w("# Speed against accuracy: TOYRT against Cycles, Mitsuba 3, Embree and Open3D\n")
    w(f"Written by `make bench{' BENCH_QUICK=1' if meta.get('quick') else ''}` (bench/run.py, then bench/report.py) on "
      f"**{meta.get('date', '?')}**, in {meta.get('total_seconds', 0) / 60:.1f} minutes. Machine: {cpu}, "
      f"{os.cpu_count()} hardware threads, shared with other work while it ran (timings are best of "
      f"{cfg.get('repeats', '?')} run(s) and noisy; compare methods side by side, not across reports).\n")
    w("| software | version |\n|---|---|")
    for k, v in versions.items():
        w(f"| {k} | {v} |")
    if mitsuba_info.get("variant_note"):
        w(f"\nMitsuba variant: {mitsuba_info['variant_note']}; its scalar CPU variant (all threads) ran instead.")
    if meta.get("quick"):
        w("\n**Quick run** (`BENCH_QUICK=1`): small images, few sample counts and sizes; a smoke test of the "
          "pipeline, not the measurements to quote.")

    head_at = len(md)  # the headlines go here, once section 1 has computed them

    # -- section 1 --
    scenes = {}
    for name in meta.get("scenes", []):
        data = load(work / f"render-{name}.json")
        if data is None:
            continue
        mi = load(work / f"mitsuba-{name}.json")
        if mi:
            data["runs"] += mi["runs"]
        scenes[name] = data
    w("\n## 1. Error against time\n")
    if scenes:
        ref0 = next(iter(scenes.values()))["reference"]
        w(f"Images of {cfg.get('width')}x{cfg.get('height')} pixels; the reference is Cycles at "
          f"{ref0.get('spp')} samples per pixel, restricted to TOYRT's light transport (direct light, plus "
          "specular chains through glass up to depth 8; Box filter of one pixel; no denoising, adaptive sampling "
          "or clamping; the settings of tests/blender/test_cycles_parity.py), cached in out/bench-cache keyed on the "
          "scene's scripts, the Cycles settings and Blender's version. Every point is one render at a sample count "
          f"from {cfg.get('spp')}. **Time** is wall-clock seconds from the Blender scene to an image for every "
          "renderer: Cycles' `bpy.ops.render.render()` (scene sync, BVH build, render; the image is read "
          "afterwards), TOYRT's add-on exporter + `commit()` + `render()`, Mitsuba's `load_dict()` + `render()` "
          "(from PLY files of the same meshes, lights converted to its units, same camera). **Errors** are "
          "against the reference over all pixels except those that see a light directly and their neighbours "
          "(a light's edge is pixel-jitter noise of its full radiance, the same for every method): RMSE, and "
          "relative MSE = mean((x - ref)^2 / (ref^2 + 0.01)). TOYRT's methods: `area_light_sampling` "
          "solid_angle or area, `light_sampling` all (a shadow ray to every light) or one (one light per hit, "
          "picked by expected contribution). Mitsuba renders the scenes without glass by its `direct` "
          "integrator, which does not follow specular chains, and a scene with nothing diffuse (glossy_metal) by "
          "its `path` integrator to the same depth (max_depth 10 for glossy bounces 8).\n")
        w("![the benchmark scenes: Cycles references](results/scenes.png)\n")
        scene_montage(work, scenes)
        w("The reference has noise of its own: Cycles' RMSE fit (section 1's Fit) extrapolated to the reference's "
          "sample count estimates it (the 'reference RMSE' column). Errors measured near that level are partly the "
          "reference's, so the curves flatten there and the low-error end of the ratios below understates the "
          "faster method.\n")
        w("| scene | triangles (instanced) | instances | lights | pixels left out (lights) | reference s | "
          "reference RMSE (est.) | TOYRT export + BVH build s (median) | fixed cost t0 s (fit, relMSE): Cycles / "
          "TOYRT default / Mitsuba | worst 1 % of pixels' share of TOYRT's squared error |")
        w("|---|---|---|---|---|---|---|---|---|---|")
        for name, data in scenes.items():
            st = data.get("scene_stats", {})
            ref = data["reference"]
            toyrt_fixed = np.median([r["seconds"] - r["render_seconds"] for r in data["runs"]
                                     if r["renderer"] == "toyrt"])
            w(f"| {name} | {st.get('triangles', '?'):,} | {st.get('instances', '?')} | {st.get('lights', '?')} | "
              f"{100 * data.get('masked_fraction', 0):.1f} % | {fmt(ref.get('seconds'))}"
              f"{' (cached)' if ref.get('cached') else ''} | {ref_noise(data['runs'], ref.get('spp'))} | "
              f"{fmt(float(toyrt_fixed))} | "
              f"{fixed_costs(data)} | {worst_share(work, name)} |")
        shares = {n: worst_share(work, n).rstrip(" %") for n in scenes}
        firefly = [n for n in scenes if shares[n].isdigit() and int(shares[n]) >= 90]
        if firefly:
            w("\nIn " + ", ".join(firefly) + " the worst 1 % of pixels hold most of TOYRT's squared error: RMSE there "
              "measures a few fireflies (here: paths that find the bright light through the glass sphere) and falls "
              "slowly; relative MSE weighs them down and is the fairer metric for those scenes.")
        for path in error_charts(scenes):
            w(f"\n![{path.stem}](results/{path.name})")
        w("\n### Time to equal error\n")
        w("Speed-up = the peer's time to reach an error / the method's time to reach the same error, geometric "
          "mean over the errors the peer measured (n: how many). Both times come from fits to each method's "
          "points, not from single timings: error = a spp^b (log-log least squares) and seconds = t0 + c spp "
          "(t0: the fixed cost of export, BVH build, start-up), used only between half the smallest and twice "
          "the largest sample count measured. Above 1: faster than the peer. '>=': the method beat some of the "
          "peer's errors with its fewest samples and no error is covered by both fits: the time of its fewest "
          "samples then stands in for its (longer) true time.\n")
        w("| scene | method | vs Cycles, RMSE (n) | vs Cycles, relMSE (n) | vs Mitsuba, RMSE (n) "
          "| vs Mitsuba, relMSE (n) |")
        w("|---|---|---|---|---|---|")
        summary = {}
        for name, data in scenes.items():
            runs = data["runs"]
            methods = [m for m in dict.fromkeys(r["method"] for r in runs) if m.startswith("TOYRT")]
            for m in methods:
                cells = []
                for peer in ("Cycles", mitsuba_method(runs)):
                    for metric in ("rmse", "relmse"):
                        s, n = speedup(runs, m, peer, metric)
                        summary[(name, m, peer, metric)] = s
                        cells.append(f"**{'>= ' if s[1] else ''}{fmt(s[0])}** ({n})" if s else "n/a")
                w(f"| {name} | {m} | " + " | ".join(cells) + " |")
        w("\nConvergence: fitted slope of log RMSE against log samples per pixel (-0.5 is independent "
          "random sampling; steeper is better):\n")
        w("| scene | " + " | ".join(COLORS) + " |")
        w("|---|" + "---|" * len(COLORS))
        slopes = {}
        for name, data in scenes.items():
            row = []
            for m in COLORS:
                s = slope(data["runs"], m, "rmse")
                slopes[(name, m)] = s
                row.append(fmt(s))
            w(f"| {name} | " + " | ".join(row) + " |")
    else:
        summary, slopes = {}, {}
        w("Not run.")

    # Headlines: TOYRT as shipped (solid angle; light_sampling auto = one light per hit above 4).
    head = ["\n## Headlines\n",
            "TOYRT with its defaults (solid-angle estimator; `light_sampling=\"auto\"`, which picks "
            "one light per hit above 4 lights) against the others, time to equal error (section 1; above 1: TOYRT "
            "faster):\n",
            "| scene | TOYRT method | vs Cycles, RMSE | vs Cycles, relMSE | vs Mitsuba, RMSE | vs Mitsuba, relMSE |",
            "|---|---|---|---|---|---|"]
    for name, data in scenes.items():
        lights = data.get("scene_stats", {}).get("lights", 0)
        m = f"TOYRT solid_angle/{'one' if lights > 4 else 'all'}"
        cells = []
        for peer in ("Cycles", mitsuba_method(data["runs"])):
            for metric in ("rmse", "relmse"):
                r = summary.get((name, m, peer, metric))
                cells.append(f"{'>= ' if r[1] else ''}{fmt(r[0])}" if r else "n/a")
        head.append(f"| {name} | {m} | " + " | ".join(cells) + " |")
    if scenes:
        md[head_at:head_at] = head

    # -- section 2 --
    w("\n## 2. Acceleration structures\n")
    rows = accel_rows(work)
    if rows:
        sizes = sorted({int(r["triangles"]) for r in rows})
        by = {(int(r["triangles"]), r["builder"]): r for r in rows}
        pyrows = {r["triangles"]: r for r in py.get("rows", [])}
        device = rows[0]["device"]
        w(f"Bumpy UV spheres from {sizes[0]:,} to {sizes[-1]:,} triangles (bench/bench_accel.cpp). Build: the "
          "builder alone (binned SAH with TBB, LBVH kernels on "
          f"{device}, Embree 3's default build); Open3D: `add_triangles` plus its first query (it builds lazily). "
          f"Rays: {rows[0]['rays_primary']} primary rays of a pinhole camera, then a cosine-distributed diffuse "
          "bounce and a shadow ray towards a light from each primary hit, traced on all threads "
          "(C++: `Scene::intersect`/`occluded`; Python: TOYRT's `Scene.intersect`/`occluded` and Open3D's "
          "`cast_rays`/`test_occlusions` on the same rays, read from files bench_accel wrote).\n")
        fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
        series = [("SAH", lambda n, k: by.get((n, "sah"), {}).get(k)),
                  ("LBVH", lambda n, k: by.get((n, "lbvh"), {}).get(k)),
                  ("Embree 3", lambda n, k: by.get((n, "embree"), {}).get(k))]
        o3d_names = {"build_ms": "open3d_build_ms", "primary_mrays": "open3d_primary_mrays",
                     "diffuse_mrays": "open3d_diffuse_mrays", "shadow_mrays": "open3d_shadow_mrays"}
        t_names = {"build_ms": "toyrt_build_ms", "primary_mrays": "toyrt_primary_mrays",
                   "diffuse_mrays": "toyrt_diffuse_mrays", "shadow_mrays": "toyrt_shadow_mrays"}
        for ax, key, label in zip(axes, ("build_ms", "primary_mrays", "diffuse_mrays", "shadow_mrays"),
                                  ("build ms", "primary Mrays/s", "diffuse Mrays/s", "shadow Mrays/s")):
            for sname, get in series:
                ax.plot(sizes, [float(get(n, key)) for n in sizes], "o-", label=sname)
            if pyrows and o3d_names[key] in next(iter(pyrows.values())):
                ax.plot(sizes, [pyrows.get(n, {}).get(o3d_names[key], np.nan) for n in sizes], "s--",
                        label="Open3D (Python)")
                ax.plot(sizes, [pyrows.get(n, {}).get(t_names[key], np.nan) for n in sizes], "^--",
                        label="TOYRT SAH (Python)")
            ax.set_xscale("log")
            if key == "build_ms":
                ax.set_yscale("log")
            ax.set_xlabel("triangles")
            ax.set_title(label)
            ax.grid(True, which="both", alpha=0.3)
        axes[0].legend(fontsize=7)
        save_figure(fig, "accel.png")
        w("![build time and trace speed against triangle count](results/accel.png)\n")
        w("| triangles | builder | build ms | SAH cost | primary Mrays/s | diffuse Mrays/s | shadow Mrays/s |")
        w("|---|---|---|---|---|---|---|")
        for n in sizes:
            for b, label in (("sah", "SAH"), ("lbvh", "LBVH"), ("embree", "Embree 3")):
                r = by[(n, b)]
                w(f"| {n:,} | {label} | {fmt(float(r['build_ms']))} | "
                  f"{fmt(float(r['sah_cost'])) if b != 'embree' else '-'} | {fmt(float(r['primary_mrays']))} | "
                  f"{fmt(float(r['diffuse_mrays']))} | {fmt(float(r['shadow_mrays']))} |")
            p = pyrows.get(n)
            if p:
                w(f"| {n:,} | TOYRT SAH, Python API | {fmt(p['toyrt_build_ms'])} | - | "
                  f"{fmt(p['toyrt_primary_mrays'])} | "
                  f"{fmt(p['toyrt_diffuse_mrays'])} | {fmt(p['toyrt_shadow_mrays'])} |")
                if "open3d_build_ms" in p:
                    w(f"| {n:,} | Open3D RaycastingScene, Python API | {fmt(p['open3d_build_ms'])} | - | "
                      f"{fmt(p['open3d_primary_mrays'])} | {fmt(p['open3d_diffuse_mrays'])} | "
                      f"{fmt(p['open3d_shadow_mrays'])} |")
        if pyrows and all("agree_primary" in p for p in pyrows.values()):
            worst = min(min(p[f"agree_{k}"] for k in ("primary", "diffuse", "shadow")) for p in pyrows.values())
            w(f"\nOpen3D and TOYRT agree on hit or miss for at least {100 * worst:.3f} % of the rays at every size.")
        elif py.get("open3d_error"):
            w(f"\nOpen3D could not be imported here: {py['open3d_error']}.")
        workloads = [("preview: 640x360, 1 spp", 640 * 360), ("final: 1920x1080, 64 spp", 1920 * 1080 * 64)]
        w("\n**Total time** (build + trace) of a render with one primary, one diffuse and one shadow ray per "
          "sample, from the measured build times and per-type speeds; `auto` is TOYRT's choice for that ray count "
          "(`commit(builder=\"auto\", expected_rays=...)`, read back from `last_commit`).\n")
        w("| triangles | workload | SAH s | LBVH s | Embree s | fastest | auto builds "
          "| auto's total vs the faster TOYRT builder |")
        w("|---|---|---|---|---|---|---|---|")
        auto_verdicts = []
        for n in sizes:
            for (label, rays), key in zip(workloads, ("auto_preview", "auto_final")):
                tot = {b: total_seconds(float(by[(n, b)]["build_ms"]), float(by[(n, b)]["primary_mrays"]),
                                        float(by[(n, b)]["diffuse_mrays"]), float(by[(n, b)]["shadow_mrays"]), rays)
                       for b in ("sah", "lbvh", "embree")}
                fastest = min(tot, key=tot.get)
                commit_info = pyrows.get(n, {}).get(key, {})
                picked = "lbvh" if commit_info.get("lbvh_meshes") else "sah"
                if not commit_info:
                    picked = by[(n, "sah")][key]
                better = min(tot["sah"], tot["lbvh"])
                loss = tot[picked] / better - 1
                auto_verdicts.append((loss, f"{n:,} triangles, {label.split(':')[0]}"))
                w(f"| {n:,} | {label} | {fmt(tot['sah'])} | {fmt(tot['lbvh'])} | {fmt(tot['embree'])} | "
                  f"{dict(sah='SAH', lbvh='LBVH', embree='Embree')[fastest]} | {picked.upper()} | "
                  f"{100 * loss:+.1f} % |")
        embree_faster = all(float(by[(n, "embree")][k]) > float(by[(n, "sah")][k]) for n in sizes
                            for k in ("primary_mrays", "diffuse_mrays", "shadow_mrays"))
    else:
        auto_verdicts, embree_faster = [], False
        w("Not run.")

    # -- section 3 --
    w("\n## 3. Stability\n")
    st = load(work / "stability.json")
    if st:
        w("### Intersection leaks\n")
        w("Rays from the centre of closed meshes aimed exactly at every vertex, every edge midpoint and random "
          "points on every edge (computed in float, as a renderer would): each must hit, so every miss is a leak. "
          "TOYRT's watertight test runs through its BVH; Moller-Trumbore is the textbook float test, written in "
          "bench/bench_stability.cpp as the non-watertight baseline (only an exact-zero determinant rejected), by "
          "brute force; Embree 3 in its default and its robust mode. The UV sphere has pole fans; the double cone "
          "256 triangles around each apex.\n")
        w("| mesh | placement | rays | TOYRT watertight | Moller-Trumbore | Embree | Embree robust |")
        w("|---|---|---|---|---|---|---|")
        for c in st["leaks"]:
            w(f"| {c['mesh']} | {c['placement']} | {c['rays']} | **{c['watertight']}** | {c['moller_trumbore']} | "
              f"{c['embree']} | {c['embree_robust']} |")
        tot = {k: sum(c[k] for c in st["leaks"])
               for k in ("rays", "watertight", "moller_trumbore", "embree", "embree_robust")}
        w(f"\nIn all: {tot['watertight']} leaks for TOYRT, {tot['moller_trumbore']} for Moller-Trumbore, "
          f"{tot['embree']} for Embree and {tot['embree_robust']} for Embree robust, of {tot['rays']} rays.\n")
        w("### Self-intersection (shadow acne)\n")
        w("Shadow rays from the hit points of camera rays (the point computed from the barycentrics of TOYRT's "
          "hit, as the renderer does) towards a light the hit triangle faces, on a convex surface (a UV sphere) and "
          "a tilted plane of triangles: nothing can block them, so every blocked ray is acne. Surfaces scaled by "
          "`scale` and moved `distance` along a diagonal. From the raw point (tnear 0), with a fixed tnear of 1e-4, "
          "and from `offset_ray_origin(p, n)`. Rows with 0 rays: the camera rays missed (a 1 mm object 1e5 m away "
          "is below float precision).\n")
        w("| surface | scale | distance | rays | acne: raw | acne: tnear 1e-4 | acne: offset_ray_origin |")
        w("|---|---|---|---|---|---|---|")
        for c in st["acne"]:
            pct = lambda k: f"{100 * c[k] / c['rays']:.1f} %" if c["rays"] else "-"  # noqa: E731
            w(f"| {c['surface']} | {fmt(c['scale'])} | {fmt(c['distance'])} | {c['rays']} | {pct('raw')} | "
              f"{pct('epsilon')} | **{pct('offset')}** |")
        w("\n### Area-light estimators\n")
        est = st["estimators"]
        w("One-sample irradiance estimates from a 1 m square light (the relative standard deviation of a single "
          "sample; variance per pixel falls as this squared over the sample count), area sampling against "
          "solid-angle sampling, at a point facing the light straight below its centre as it comes closer, and at "
          "a point 0.1 m below the light's plane moving sideways, where the light is seen at grazing angles.\n")
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
        for ax, sweep, xlabel in ((axes[0], "distance", "distance below the light (m)"),
                                  (axes[1], "sideways", "sideways offset at 0.1 m below (m)")):
            pts = [e for e in est if e["sweep"] == sweep]
            x = [max(e["parameter"], 1e-3) if sweep == "distance" else e["parameter"] for e in pts]
            ax.plot(x, [e["area_rel_std"] for e in pts], "o-", label="area", color=COLORS["TOYRT area/all"])
            ax.plot(x, [e["solid_rel_std"] for e in pts], "o-", label="solid angle",
                    color=COLORS["TOYRT solid_angle/all"])
            if sweep == "distance":
                ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("relative std. dev. of one sample")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend()
        save_figure(fig, "estimators.png")
        w("![estimator noise](results/estimators.png)\n")
        w("| sweep | m | area: mean | area: rel. std | solid angle: mean | solid angle: rel. std "
          "| variance ratio area / solid angle |")
        w("|---|---|---|---|---|---|---|")
        for e in est:
            ratio = variance_ratio(e)
            w(f"| {e['sweep']} | {fmt(e['parameter'])} | {fmt(e['area_mean'])} | {fmt(e['area_rel_std'])} | "
              f"{fmt(e['solid_mean'])} | {fmt(e['solid_rel_std'])} | {fmt(ratio)} |")
        room = st["lbvh_room"]
        w("\n### LBVH on a badly distributed scene\n")
        w(f"A {room['object_triangles']:,}-triangle bumpy sphere of 1 m in a {fmt(room['room_size_m'])} m room "
          f"(12 triangles), {room['rays']:,} primary and diffuse rays at the object. Morton codes quantise the "
          "room's box, so the object gets few distinct codes.\n")
        w("| builder | SAH cost | Mrays/s | speed vs SAH |")
        w("|---|---|---|---|")
        for k, label in (("sah", "binned SAH"), ("lbvh30", "LBVH, 30-bit Morton codes (default)"),
                         ("lbvh63", "LBVH, 63-bit Morton codes")):
            w(f"| {label} | {fmt(room['sah_cost'][k])} | {fmt(room['mrays'][k])} | "
              f"{100 * room['mrays'][k] / room['mrays']['sah']:.0f} % |")
        w("\nThe SAH cost is normalised by the root box, the room, so it hardly separates the trees here; the "
          "trace speed does.")
    else:
        w("Not run.")
    refr = load(work / "refraction.json")
    tir = st["tir"] if st else None
    w("\n### Refraction\n")
    if refr:
        w(f"`toyrt.Scene.render` at {refr['spp']} spp, glass of IOR {refr['ior']}. **Slab**: a glass slab between "
          "an orthographic camera and a large light of radiance 1 behind it, black world: a pixel is T = "
          "(1 - F)^2 (1 + F^2 + F^4 + ...), the series truncated where `max_specular_depth` cuts it, F from "
          "Fresnel's equations at the camera ray's angle; `refraction` (no Fresnel) must pass everything.\n")
        w("| material | angle | max depth | measured | closed form | difference |")
        w("|---|---|---|---|---|---|")
        for r in refr["slab"]:
            w(f"| {r['material']} | {r['deg']} deg | {r['depth']} | {r['measured']:.4f} | {r['expected']:.4f} | "
              f"{100 * (r['measured'] / r['expected'] - 1):+.2f} % |")
        w("\n**Sphere in a furnace**: a glass sphere in a uniform white world; every path ends in the world, so "
          "every pixel is 1 when the depth suffices. What is missing is the energy the depth limit cuts off "
          "(including rays trapped by total internal reflection).\n")
        w("| material | max depth | mean over the sphere | darkest pixel |")
        w("|---|---|---|---|")
        for r in refr["sphere"]:
            w(f"| {r['material']} | {r['depth']} | {r['mean']:.4f} | {r['min']:.4f} |")
    if tir:
        below = [a for a in tir["angles"] if a["deg"] < tir["critical_deg"]]
        above = [a for a in tir["angles"] if a["deg"] > tir["critical_deg"]]
        worst = max(abs(a["transmitted"] - a["expected"]) for a in below)
        w(f"\n**Total internal reflection**: glass (IOR {tir['ior']}) sampled from inside at {len(tir['angles'])} "
          f"angles, {tir['samples']:,} samples each; critical angle {tir['critical_deg']:.2f} deg. Below it the "
          f"transmitted fraction is within {worst:.4f} of 1 - F (Fresnel in double, written independently in the "
          f"bench); above it {sum(a['transmitted'] > 0 for a in above)} of {len(above)} angles transmit anything, and "
          f"the perfect `refraction` material reports total internal reflection at "
          f"{sum(a['refraction_tir'] for a in above)} of {len(above)} of them "
          f"(and at {sum(a['refraction_tir'] for a in below)} below it).")

    # -- section 4 --
    w("\n## 4. Economy: a scene pays for what it uses\n")
    eco = load(work / "economy.json")
    if eco:
        steps = eco["economy"]
        w(f"The seed's Cornell box at {cfg.get('width')}x{cfg.get('height')}, {eco['spp']} spp, TOYRT's defaults, "
          "features switched on one at a time (scenes/bench/cornell.py). Seconds from scene to image (export, "
          "build, render) and of `render()` alone; best of several runs.\n")
        w("| step | triangles | instances | lights | s, scene to image | s, render() | render() vs the bare box "
          "| light sampling used |")
        w("|---|---|---|---|---|---|---|---|")
        base = steps[0]["render_seconds"]
        for s in steps:
            w(f"| {s['label']} | {s['triangles']:,} | {s['instances']} | {s['lights']} | {fmt(s['seconds'])} | "
              f"{fmt(s['render_seconds'])} | {s['render_seconds'] / base:.2f}x | {s['light_sampling']} |")
        fig, ax = plt.subplots(figsize=(8, 3.5))
        ax.barh([s["label"] for s in steps][::-1], [s["render_seconds"] for s in steps][::-1], color="#1f77b4",
                label="render()")
        ax.barh([s["label"] for s in steps][::-1], [s["seconds"] - s["render_seconds"] for s in steps][::-1],
                left=[s["render_seconds"] for s in steps][::-1], color="#aec7e8", label="export + build")
        ax.set_xlabel("seconds")
        ax.legend(fontsize=8)
        save_figure(fig, "economy.png")
        w("\n![render time as features are switched on](results/economy.png)")
    else:
        w("Not run.")

    # -- section 5 --
    w("\n## 5. Defaults\n")
    w("TOYRT's defaults: `area_light_sampling=\"solid_angle\"`, `builder=\"auto\"` (SAH unless a ray count is "
      "given; the add-on gives one), `light_sampling=\"auto\"` (one light per hit above 4 lights, else all), and "
      "Sobol-Owen sample points. What the measurements above say:\n")
    if summary:
        def gm(values):
            values = [v for v in values if v]
            return float(np.exp(np.mean(np.log(values)))) if values else None
        # Estimator: solid angle against area at equal error, from the curves of each scene.
        est_ratios = []
        for name, data in scenes.items():
            runs = data["runs"]
            for ls in ("all", "one"):
                a, b = f"TOYRT solid_angle/{ls}", f"TOYRT area/{ls}"
                s, _ = speedup(runs, a, b, "relmse")
                if s:
                    est_ratios.append((name, ls, s[0]))
        g = gm([r[2] for r in est_ratios])
        w(f"- **Estimator**: solid-angle sampling reaches the area estimator's relative MSE "
          f"{fmt(g)}x as fast (geometric mean over scenes and light-sampling modes; per scene: "
          + ", ".join(f"{n}/{ls} {fmt(s)}" for n, ls, s in est_ratios) + "). "
          + ((f"Averaged over these scenes the two are within 10 % of each other at equal error, though single "
              f"scenes range from {fmt(min(r[2] for r in est_ratios))}x to {fmt(max(r[2] for r in est_ratios))}x; "
              "near a light area sampling's variance explodes (section 3), so the data supports keeping solid "
              "angle as the default.") if g and 1 / 1.1 <= g <= 1.1 else
             "The data supports the default." if g and g > 1.1 else
             "On these scenes, whose lights are far from most shaded points, the cheaper area estimator wins at equal "
             "error, so the data does not support solid angle as the one default; but near a light (section 3) "
             "area sampling's variance explodes, so the change it argues for is a per-shading-point choice "
             "(solid angle when the light subtends a large solid angle, area otherwise), a native change, rather "
             "than a switch to area.")
          + (f" Near a light its one-sample variance is up to {fmt(max(variance_ratio(e) for e in st['estimators']))}x "
             "lower (section 3)." if st else ""))
        ls_ratios = []
        for name, data in scenes.items():
            s, _ = speedup(data["runs"], "TOYRT solid_angle/one", "TOYRT solid_angle/all", "relmse")
            lights = data.get("scene_stats", {}).get("lights", 0)
            if s:
                ls_ratios.append((name, lights, s[0]))
        single = [(n, s) for n, lights, s in ls_ratios if lights == 1]
        # A one-light scene renders the same image both ways: its ratio is the timing noise, and only
        # ratios beyond it count as disagreeing with auto's threshold.
        # Ratios within 10 % of 1 (or within that noise, if larger) count as ties.
        noise = max([max(s, 1 / s) for n, s in single] + [1.1])
        disagree = [(n, lights, s) for n, lights, s in ls_ratios
                    if lights > 1 and ((lights > 4 and s < 1 / noise) or (lights <= 4 and s > noise))]
        w("- **Light sampling** (one light per hit against all, solid angle, relative MSE; above 1: one is faster): "
          + ", ".join(f"{n} ({lights} light{'s' if lights != 1 else ''}) {fmt(s)}" for n, lights, s in ls_ratios) + ". "
          + "".join(f"{n} has one light, so both modes render the same image and {fmt(s)} is the timing noise of "
                    "this run. " for n, s in single)
          + ("`auto` (one light above 4) matches every scene here." if not disagree else
             "`auto` switches to one light above 4 lights; the measurements disagree with that for "
             + ", ".join(f"{n} ({lights} lights, {fmt(s)})" for n, lights, s in disagree)
             + (": with many lights a shadow ray to every light still converged faster per second than one light "
                "chosen by expected contribution, so the threshold should move up (or the selection improve) "
                "before `one` pays off." if any(lights > 4 for n, lights, s in disagree) else ".")))
        if auto_verdicts:
            right = sum(v <= 1e-9 for v, _ in auto_verdicts)
            missed = [row for v, row in auto_verdicts if v > 1e-9]
            w(f"- **Builder**: `auto` picked the faster of SAH and LBVH in {right} of {len(auto_verdicts)} "
              "workloads of section 2" + (f"; where it did not ({', '.join(missed)}), its pick cost "
                             f"{100 * max(v for v, _ in auto_verdicts):.1f} % at most." if missed else ".")
              + (" Embree's trees traced faster than TOYRT's SAH trees for every ray type at every size, so "
                 "final-render totals would gain most from faster traversal, not from another builder policy."
                 if embree_faster else ""))
        sl = [(n, slopes.get((n, "TOYRT solid_angle/all")), slopes.get((n, mitsuba_method(scenes[n]["runs"]))),
               slopes.get((n, "Cycles"))) for n in scenes]
        w("- **Sample pattern**: TOYRT's RMSE slopes against spp (Sobol-Owen) are "
          + ", ".join(f"{n} {fmt(a)}" for n, a, b, c in sl)
          + "; Cycles' " + ", ".join(f"{fmt(c)}" for n, a, b, c in sl)
          + "; Mitsuba's independent sampler " + ", ".join(f"{fmt(b)}" for n, a, b, c in sl if b is not None)
          + ". A slope steeper than -0.5 is the stratification paying off; TOYRT has no switch to another "
            "pattern, so this is the only comparison made.")
    # Measured by hand, not by make bench (tests/blender/test_passes.py, bench/passes_cost.py): kept
    # in its own file so that a new report carries it over unchanged.
    passes = DOC.parent / "results" / "passes.md"
    if passes.exists():
        w("\n" + passes.read_text().rstrip())
    w("\n## Reproducing\n")
    w(f"`make bench` ({meta.get('total_seconds', 0) / 60:.0f} minutes here, with the Cycles references "
      f"{'cached' if all(d['reference'].get('cached') for d in scenes.values()) else 'rendered'}; "
      "`make bench BENCH_QUICK=1` for a smoke run of a minute or two) installs "
      "requirements-bench.txt (Mitsuba 3, Dr.Jit, Open3D) into .venv, builds and installs the add-on, then runs "
      "bench/run.py. Scenes: scenes/bench/; programs: bench/. Stage times of this run: "
      + ", ".join(f"{k} {v:.0f} s" for k, v in meta.get("timings", {}).items()) + ".")
    DOC.write_text("\n".join(md) + "\n")
    print(f"bench: wrote {DOC.relative_to(REPO)} and {len(list(FIG.glob('*.png')))} charts in docs/results/")


if __name__ == "__main__":
    main()
