"""What a traced ray executes, instruction by instruction, in TOYRT and in Embree: the per-ray
instruction counts of one ray set by kind (general-purpose, 128-bit xmm, 256-bit ymm vector
instructions) and mnemonic, from valgrind's callgrind (exact counts, unlike timings on a shared
machine). Zen 1 and other CPUs with 128-bit vector units split every ymm instruction in two, so the
mix says more about the time there than the instruction total does (docs/trace-speed.md).

    python3 bench/instruction_mix.py build/bench/trace_only [diffuse|primary|shadow] [rings] [room|soup]
        [--lines N]
    (soup: bench_trace's triangle soup of rings x 1000 triangles instead of the sphere; --lines N:
    TOYRT's N most executed source lines, innermost inlined line first, for a build with -g, e.g.
    cmake -S . -B /tmp/build-v3g -DCMAKE_BUILD_TYPE=Release -DTOYRT_NATIVE_ARCH=OFF
    "-DCMAKE_CXX_FLAGS=-march=x86-64-v3 -g"; TOYRT_FRAME=1024x768 in the environment gives
    bench_trace's camera frame, see trace_only.cpp)

The stack column counts the instructions that read or write the stack frame (an operand on %rbp
or %rsp, push and pop): most of them are a register allocator's spills and reloads.

Needs valgrind (apt-get install valgrind) and objdump. Each engine runs the set once and three
times; the difference over the extra rays is what a ray costs, without the scene's build and the
ray generation. TOYRT is counted in its own functions (all of namespace toyrt but the test
harness's toyrt::testing), Embree inside libembree3.
"""
import argparse
import collections
import re
import subprocess
import sys
import tempfile
from pathlib import Path


def costs_by_address(profile, keep):
    """Instruction counts per (object, address) from a callgrind profile written with
    --dump-instr=yes, for the functions and objects `keep(object, function)` accepts. Inclusive
    cost lines of calls are skipped, so each address holds its own instructions only."""
    names = {"ob": {}, "fn": {}}
    obj = fn = ""
    address = 0
    after_calls = False
    counts = collections.Counter()
    for line in Path(profile).read_text().splitlines():
        # The layout this parser reads: an instruction address and a line, then Ir alone.
        if line.startswith("positions:") and line.split()[1:] != ["instr", "line"]:
            raise SystemExit(f"{profile}: positions {line!r}, expected 'instr line'")
        if line.startswith("events:") and line.split()[1:] != ["Ir"]:
            raise SystemExit(f"{profile}: events {line!r}, expected 'Ir' alone")
        m = re.match(r"(c?)(ob|fn)=\((\d+)\)(?: (.*))?$", line)
        if m:
            table = names[m.group(2)]
            if m.group(4):
                table[m.group(3)] = m.group(4)
            if not m.group(1):  # ob= / fn= set the current position; cob= / cfn= name a callee
                if m.group(2) == "ob":
                    obj = table[m.group(3)]
                else:
                    fn = table[m.group(3)]
            continue
        if line.startswith("calls="):
            after_calls = True
            continue
        if not line or line[0] not in "+-*0123456789":
            continue
        fields = line.split()
        token = fields[0]
        if token[0] == "+":
            address += int(token[1:], 0)
        elif token[0] == "-":
            address -= int(token[1:], 0)
        elif token != "*":
            address = int(token, 0)
        if after_calls:
            after_calls = False
            continue
        if len(fields) > 2 and keep(obj, fn):
            counts[(obj, address)] += int(fields[-1])
    return counts


def disassemble(obj, addresses):
    """objdump's text of the instructions at `addresses` of `obj` (file addresses, as callgrind
    reports them for shared objects and position-independent executables)."""
    text = {}
    spans = []
    for a in sorted(addresses):
        if spans and a - spans[-1][1] < 4096:
            spans[-1][1] = a
        else:
            spans.append([a, a])
    for lo, hi in spans:
        out = subprocess.run(["objdump", "-d", "--no-show-raw-insn", f"--start-address={lo:#x}",
                              f"--stop-address={hi + 16:#x}", obj], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            m = re.match(r"\s*([0-9a-f]+):\s*(\S.*)$", line)
            if m:
                text[int(m.group(1), 16)] = m.group(2)
    return text


def touches_stack(instruction):
    mnemonic, _, operands = instruction.partition(" ")
    return mnemonic.startswith(("push", "pop")) or re.search(r"\(%r[bs]p[,)]", operands) is not None


def source_lines(obj, addresses):
    """file:line of each address of `obj` (the innermost inlined function's line), from addr2line:
    '??:0' where the build has no debug information."""
    addresses = sorted(addresses)
    out = subprocess.run(["addr2line", "-e", obj, "-a"] + [f"{a:#x}" for a in addresses], capture_output=True,
                         text=True, check=True).stdout.splitlines()
    # Two lines an address: the address echoed, then file:line (with " (discriminator N)" at times).
    return {int(out[2 * i], 16): Path(out[2 * i + 1].split(" ")[0]).name for i in range(len(addresses))}


def kind_of(instruction):
    mnemonic, _, operands = instruction.partition(" ")
    if "%ymm" in operands or "%zmm" in operands:
        return mnemonic, "ymm"
    if "%xmm" in operands:
        return mnemonic, "xmm"
    return mnemonic, "general"


def mix(trace_only, ray_set, rings, extra, engine, with_lines=False):
    # (A name may begin with its return type: "bool toyrt::Mesh::trace<false>(...)".)
    keep_toyrt = lambda obj, fn: "trace_only" in obj and "toyrt::" in fn and "toyrt::testing::" not in fn  # noqa: E731
    keep_embree = lambda obj, fn: "libembree" in obj  # noqa: E731
    keep = keep_embree if engine == "embree" else keep_toyrt
    last = extra + ([engine] if engine == "embree" else [])  # trace_only's words after the repeats
    with tempfile.TemporaryDirectory() as tmp:
        counts = []
        for repeats in (1, 3):
            profile = f"{tmp}/callgrind.{repeats}"
            run = [str(trace_only), ray_set, str(rings), str(repeats)] + last
            valgrind = ["valgrind", "--tool=callgrind", "--dump-instr=yes", f"--callgrind-out-file={profile}"]
            # trace_only's own report ("diffuse: 15819 rays x 3, ...") gives the rays of one repeat.
            report = subprocess.run(valgrind + run, capture_output=True, text=True, check=True).stdout
            counts.append(costs_by_address(profile, keep))
    rays = int(re.search(r"(\d+) rays", report).group(1)) * 2  # the extra two repeats
    per_ray = {k: (counts[1][k] - counts[0].get(k, 0)) / rays for k in counts[1]}
    by_kind, by_mnemonic, by_line = collections.Counter(), collections.Counter(), collections.Counter()
    for obj in {o for o, _ in per_ray}:
        addresses = [a for o, a in per_ray if o == obj]
        text = disassemble(obj, addresses)
        lines = source_lines(obj, addresses) if with_lines else {}
        for a in addresses:
            mnemonic, kind = kind_of(text[a]) if a in text else ("(not disassembled)", "general")
            by_kind[kind] += per_ray[(obj, a)]
            if a in text and touches_stack(text[a]):
                by_kind["stack"] += per_ray[(obj, a)]
            by_mnemonic[(mnemonic, kind)] += per_ray[(obj, a)]
            by_line[lines.get(a, "?")] += per_ray[(obj, a)]
    return by_kind, by_mnemonic, by_line


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("trace_only", type=Path)
    parser.add_argument("ray_set", nargs="?", default="diffuse", choices=["diffuse", "primary", "shadow"])
    parser.add_argument("rings", nargs="?", type=int, default=71, help="71: the 10K-triangle sphere")
    parser.add_argument("mesh", nargs="?", choices=["room", "soup"],
                        help="room: inside bench_trace's closed room (TOYRT only); soup: the triangle soup")
    parser.add_argument("--lines", type=int, default=0, metavar="N",
                        help="TOYRT's N most executed source lines (a build with -g)")
    args = parser.parse_args()
    if args.lines < 0:
        parser.error("--lines: a count of lines, 0 or more")
    room = args.mesh == "room"
    engines = ["toyrt"] + ([] if room else ["embree"])
    what = {"room": f"{args.rings} rings in the closed room", "soup": f"a soup of {args.rings}K triangles"}
    print(f"{args.ray_set} rays, {what.get(args.mesh, f'{args.rings} rings')}: instructions a ray")
    print(f"{'engine':8} {'total':>7} {'general':>8} {'xmm':>6} {'ymm':>6} {'vector uops, 128-bit units':>27} "
          f"{'stack':>6}")
    mnemonics, lines = {}, {}
    for engine in engines:
        by_kind, mnemonics[engine], lines[engine] = mix(args.trace_only, args.ray_set, args.rings,
                                                        [args.mesh] if args.mesh else [], engine,
                                                        with_lines=engine == "toyrt" and args.lines > 0)
        total = by_kind["general"] + by_kind["xmm"] + by_kind["ymm"]
        print(f"{engine:8} {total:7.0f} {by_kind['general']:8.0f} {by_kind['xmm']:6.0f} {by_kind['ymm']:6.0f} "
              f"{by_kind['xmm'] + 2 * by_kind['ymm']:27.0f} {by_kind['stack']:6.0f}")
    for engine in engines:
        top = sorted(mnemonics[engine].items(), key=lambda kv: -kv[1])[:16]
        print(f"\n{engine}, the most executed: " + ", ".join(f"{m} ({k}) {c:.1f}" for (m, k), c in top))
    if args.lines:
        top = sorted(lines["toyrt"].items(), key=lambda kv: -kv[1])[:args.lines]
        if all(line.startswith("??") for line, _ in top):
            print("\ntoyrt: no source lines (build with -g)")
        else:
            print("\ntoyrt, by source line: " + ", ".join(f"{line} {c:.1f}" for line, c in top))
    return 0


if __name__ == "__main__":
    sys.exit(main())
