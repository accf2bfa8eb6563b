"""TOYRT's native core, as the wheels install it: the package `toyrt` holds the module built once per
x86-64 microarchitecture level (_core_v2: SSE4.2; _core_v3: AVX2 + FMA; _core_v4: AVX-512; see
native/CMakeLists.txt) and imports the fastest one this CPU runs, so a portable wheel runs at the
speed of a -march=native build (docs/install.md). Everything the module defines is re-exported
here: `import toyrt; toyrt.Scene()` as with `make setup`'s single module. `toyrt.cpu_level` says
which level was loaded.

TOYRT_CPU=v2|v3|v4 (or sse4.2|avx2|avx512) forces a level, for tests and measurements; a level the
CPU lacks is refused with a message rather than crashing on its first instruction.
"""
import importlib
import os

# Each level's CPU flags (as Linux's /proc/cpuinfo names them) that its -march=x86-64-vN may use,
# lowest level first; each level includes those below it. The kernel lists AVX-512 only where it
# also saves those registers on a context switch.
LEVELS = {
    "v2": ("sse4_2", "ssse3", "popcnt", "cx16"),
    "v3": ("avx2", "fma", "bmi1", "bmi2", "f16c", "movbe", "abm"),
    "v4": ("avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl"),
}
ALIASES = {"sse4.2": "v2", "avx2": "v3", "avx512": "v4", "avx-512": "v4"}


def _cpu_flags() -> set:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("flags"):
                    return set(line.split(":", 1)[1].split())
    except OSError:
        pass
    return set()


def _supported(flags: set) -> list:
    """The levels this CPU runs, fastest first."""
    runs = []
    for level, needs in LEVELS.items():
        if not flags.issuperset(needs):
            break
        runs.append(level)
    return runs[::-1]


def _choose() -> str:
    supported = _supported(_cpu_flags())
    asked = os.environ.get("TOYRT_CPU", "").strip().lower()
    if asked:
        level = ALIASES.get(asked, asked)
        if level not in LEVELS:
            raise ImportError(f"toyrt: TOYRT_CPU={asked!r} is not a CPU level: use one of v2 (sse4.2), "
                              "v3 (avx2), v4 (avx512), or unset it")
        if level not in supported:
            raise ImportError(f"toyrt: TOYRT_CPU={asked!r} asks for {level}, which this CPU does not run "
                              f"(it runs: {', '.join(supported) or 'none of them'})")
        return level
    if not supported:
        raise ImportError("toyrt: this CPU lacks SSE4.2 (x86-64-v2), the least the wheel is built for; "
                          "build TOYRT from source (`make setup`)")
    return supported[0]


cpu_level = _choose()
_core = importlib.import_module(f"._core_{cpu_level}", __name__)
globals().update({name: getattr(_core, name) for name in dir(_core) if not name.startswith("__")})
__version__ = _core.__version__
__doc__ = _core.__doc__ + "\n\n" + __doc__
