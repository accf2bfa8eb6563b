"""How TOYRT tells the user something: the one reporting policy of the add-on. Every message of
the add-on goes through here, so the rule is kept in one place:

- A failure is an error (error()): Blender's ERROR report, so F12 shows it and `blender -b`
  exits non-zero, failing the farm's task as it should.
- What TOYRT approximates or falls back on (a Principled BSDF rendered as its Lambert base, a lamp
  type it skips, the SAH builder standing in for LBVH kernels a GPU cannot build) is a note (note()): a
  WARNING report in Blender's UI, but in background mode (bpy.app.background: farms) a printed
  `TOYRT note: ...` line containing none of the words warning, error or exception in any case.
  A report would print `Warning: ...` there, and farm managers fail a task on those words (AWS
  Deadline Cloud's strict mode: `.*Exception:.*|.*Error:.*|.*Warning.*`), though the frame is
  fine. The LBVH builder's fallback on SAH (kernels that cannot run where they were to: without
  an OpenCL driver the host builds the LBVH and nothing is said) is such a note (commit_notes()),
  in place of the RuntimeWarning the native module raises for it.
- Progress (Progress) is the render engine's stats line in the layout Cycles gives it, which
  Blender prints in background mode as `Fra:N Mem:.. | Time:.. | Remaining:.. | Mem:.., Peak:.. |
  Scene, ViewLayer | Sample k/N`, the line farm managers parse, and which comes at least every
  HEARTBEAT_S seconds in every phase (export, BVH build, render), from the cancel polls the
  phases already make: no thread of its own."""
from __future__ import annotations

import os
import re
import time
import warnings
from collections.abc import Callable

import bpy

NOTE_PREFIX = "TOYRT note: "


def _seconds(name: str, default: float) -> float:
    try:
        return max(float(os.environ.get(name, default)), 0.0)
    except ValueError:
        return default


# A sign of life at least this often (s) in every phase: Flamenco fails a task silent for 10
# minutes, other managers sooner. A poll adds one clock read; the line itself comes every few
# seconds at most. The farm test sets TOYRT_PROGRESS_SECONDS lower to see the longest step
# between two polls.
HEARTBEAT_S = _seconds("TOYRT_PROGRESS_SECONDS", 5.0)
# Sample lines no more often than this (s) while the count moves: Cycles, too, skips counts.
SAMPLE_LINE_S = 1.0

# The words farm managers' strict parsers take for a failure; user names (a material called
# "Error") may carry them into a note, which then breaks them with a hyphen: "Err-or".
_FARM_WORDS = re.compile(r"(warn)(ing)|(err)(or)|(excep)(tion)", re.IGNORECASE)

Report = Callable[[set, str], None] | None  # a RenderEngine's or an operator's report()


def farm_safe(text: str) -> str:
    """`text` without the words warning, error and exception (any case), each split by a hyphen."""
    return _FARM_WORDS.sub(lambda m: "-".join(g for g in m.groups() if g), text)


def note(text: str, report: Report = None) -> None:
    """Something TOYRT approximated or fell back on: shown as a warning in the UI (through
    `report`), printed as a `TOYRT note:` line in background mode or without a report."""
    if report is not None and not bpy.app.background:
        report({"WARNING"}, f"TOYRT {text}")
    else:
        print(NOTE_PREFIX + farm_safe(text), flush=True)


def error(text: str, report: Report = None) -> None:
    """A failure: Blender's ERROR report (printed as `Error: TOYRT: ...` in background mode, where
    it makes the render exit non-zero), and on the console in the UI, where reports are not."""
    if report is not None:
        report({"ERROR"}, f"TOYRT: {text}")
    if report is None or not bpy.app.background:
        print(f"TOYRT: {text}", flush=True)


def commit_notes(scene, report: Report = None, once: set | None = None) -> None:
    """After a commit that built: the builder's fallback (toyrt.Scene.last_commit["warning"]) as a
    note, each text once when a set `once` keeps those already noted (the viewport commits often)."""
    text = scene.last_commit.get("warning", "")
    if text and (once is None or text not in once):
        note(text, report)
        if once is not None:
            once.add(text)


def register() -> None:
    """The module's own RuntimeWarning for the LBVH fallback, raised under the add-on's commit
    (sync.py), is silenced: commit_notes() says it, as a note. A warnings filter rather than
    catch_warnings() around each commit, which is process-wide state and not safe while F12's
    render thread and the viewport commit at once. Scripts calling toyrt themselves still get it."""
    warnings.filterwarnings("ignore", message="LBVH builder unavailable", category=RuntimeWarning,
                            module=r".*render_toyrt\.sync")


def timecode(seconds: float) -> str:
    """Seconds as Cycles prints them: MM:SS.hh, or HH:MM:SS.hh from an hour on."""
    hundredths = int(max(seconds, 0.0) * 100)
    hours, rest = divmod(hundredths, 360000)
    minutes, rest = divmod(rest, 6000)
    text = f"{minutes:02d}:{rest // 100:02d}.{rest % 100:02d}"
    return f"{hours:02d}:{text}" if hours else text


class Progress:
    """The stats line of one final render, as Cycles writes it: update_stats("", info) with info
    `[Remaining:T | ]Mem:M, Peak:P | Scene, ViewLayer | status`, Blender adding `Fra:N Mem:..
    (Peak ..) | Time:.. | ` in front when it prints it (background mode).

    The status is the phase ("Exporting scene", "Building BVH"), then `Sample k/N`. TOYRT renders
    each tile to all N samples, so k counts the samples done over the whole image: N times the
    finished fraction of its pixels, which is what farm managers turn into a percentage; the last
    line of a finished render says N/N. poll() is the cancel callback handed to the export, the
    build and the render: it asks Blender's test_break and keeps the line coming."""

    def __init__(self, engine: bpy.types.RenderEngine, depsgraph, samples: int) -> None:
        self.engine = engine
        self.where = f"{depsgraph.scene.name}, {depsgraph.view_layer.name}"
        self.samples = max(int(samples), 1)
        self.memory: Callable[[], int] = lambda: 0  # bytes the native scene holds, once there is one
        self.memory_mb = self.peak_mb = 0.0
        self.locked = False  # the phase runs native code holding the scene's lock (build, render)
        self.status = ""
        self.render_started: float | None = None
        self.fraction = 0.0
        self.shown_samples = -1
        self.last_shown = 0.0
        self.time_limit = 0.0  # seconds of rendering (the scene's time_limit), 0: none

    def phase(self, status: str, locked: bool = False) -> None:
        """A new phase; locked: its polls come from native code that holds the scene's lock."""
        self.status, self.locked = status, locked
        self._measure()
        self._show()

    def poll(self) -> bool:
        if time.perf_counter() - self.last_shown >= HEARTBEAT_S:
            if not self.locked:
                self._measure()
            self._show()
        return self.engine.test_break()

    def rendering(self) -> None:
        self._measure()
        self.locked = True
        self.render_started = time.perf_counter()
        self.fraction = 0.0
        self._show_samples(force=True)

    def tiles(self, done: int, total: int) -> None:
        self.fraction = done / total if total else 1.0
        self.engine.update_progress(self.fraction)
        self._show_samples(force=done == total)

    def samples_done(self, samples: float) -> None:
        """The native render's own count of the samples done over the whole image (its
        on_progress): what a time-limited render, rendered in passes, reports."""
        self.fraction = min(max(samples / self.samples, 0.0), 1.0)
        self.engine.update_progress(self.fraction)
        self._show_samples(force=False)

    def finished(self, summary: str, samples_done: int | None = None) -> None:
        """The render is complete: a last Sample k/N line (k = N, or the samples a time limit
        left it), then `Finished | summary`."""
        done = self.samples if samples_done is None else min(int(samples_done), self.samples)
        self.fraction = done / self.samples
        if self.shown_samples != done:
            self._show_samples(force=True)
        self.fraction = 1.0
        self.phase(f"Finished | {summary}")  # after the render: the lock is free again

    # ---------------------------------------------------------------------------------------
    def _show_samples(self, force: bool) -> None:
        k = min(int(self.samples * self.fraction), self.samples)
        now = time.perf_counter()
        if force or (k != self.shown_samples and now - self.last_shown >= SAMPLE_LINE_S):
            self.shown_samples = k
            self.status = f"Sample {k}/{self.samples}"
            self._show()

    def _measure(self) -> None:
        # Never from a locked phase's polls or tiles: they come while the scene's lock is held
        # (the build holds it exclusively), and memory_bytes would wait for it forever.
        self.memory_mb = self.memory() / 2**20
        self.peak_mb = max(self.peak_mb, self.memory_mb)

    def _show(self) -> None:
        now = time.perf_counter()
        info = f"Mem:{self.memory_mb:.2f}M, Peak:{self.peak_mb:.2f}M | {self.where} | {self.status}"
        if self.render_started is not None and 0.0 < self.fraction < 1.0:
            spent = now - self.render_started
            remaining = spent * (1.0 - self.fraction) / self.fraction
            if self.time_limit > 0.0:
                remaining = min(remaining, max(self.time_limit - spent, 0.0))
            info = f"Remaining:{timecode(remaining)} | {info}"
        self.engine.update_stats("", info)
        self.last_shown = now
