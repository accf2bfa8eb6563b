# TOYRT: the entry point. `make demo` and `make test` are all a newcomer needs;
# `make setup` (which `make test` runs first) installs everything and is a fast no-op when done.
#
#   make setup        Debian packages, .venv with pytest, native build, add-on installed + enabled
#   make test         lint, C++ tests (ctest), Python tests (pytest), Blender tests (tests/blender), fuzz, sanitize
#   make test-quick   lint, C++ and Python tests only (about a minute once built: the loop while coding)
#   make lint         clang-format check of the C++ and ruff over the Python;  make format: apply clang-format
#   make package      wheels for Python 3.10, 3.11 and 3.13, the Blender extension and the legacy add-on zip -> dist/
#   make test-package installs them where users are (fresh venvs, bpy 5.0.1 and 5.3.0, Blender 3.4) and renders
#   make demo         renders the seed's Cornell box with TOYRT -> out/demo_0001.png
#   make bench-trace  ray-tracing benchmark against Embree -> docs/bench-trace.md
#   make bench-lbvh   builders (LBVH, SAH, Embree) from 10K to 4M triangles -> docs/lbvh-bench.md, lbvh.png
#   make parity-refs  render the Cycles references of the parity scenes (3.4 and bpy) -> tests/blender/parity_refs/
#   make bench-blender TOYRT against Cycles in Blender: time to Cycles' 64-spp error, peak memory -> docs/blender-bench.md
#   make bench        speed against accuracy vs Cycles, Mitsuba 3, Embree, Open3D -> docs/results.md, denoising -> docs/denoise-bench.md (BENCH_QUICK=1: smoke run)
#   make fuzz         libFuzzer over scene building and ray queries (FUZZ_SECONDS=60) -> docs/robustness.md
#   make sanitize     C++ and Python tests on an AddressSanitizer + UBSan build (build-asan/)
#   make test-levels  the watertight, oracle, BVH, query and fuzz suites at each x86-64 level of the wheels (build-levels/)
#   make clean        remove build/ (and its stamps), build-fuzz/, build-asan/;  make distclean: also .venv

SHELL := /bin/bash
.SHELLFLAGS := -eu -o pipefail -c
.DEFAULT_GOAL := help

BUILD    := build
VENV     := .venv
# Debian's Python, never a pyenv shim: the module must match the Python Blender 3.4 runs (3.11).
SYS_PY   := /usr/bin/python3
BLENDER  ?= blender
JOBS     ?= 2
# Extra arguments for the first configure, e.g. CMAKE_ARGS=-DTOYRT_NATIVE_ARCH=OFF
CMAKE_ARGS ?=

APT_PACKAGES := cmake g++ make libglm-dev pybind11-dev python3-dev python3-numpy python3-venv \
	libembree-dev libtbb-dev libgtest-dev googletest ocl-icd-opencl-dev opencl-headers \
	pocl-opencl-icd clinfo blender python3-matplotlib clang clang-format-14 libclang-rt-14-dev \
	xvfb xauth libgl1-mesa-dri assimp-testmodels python3-openimageio ccache ninja-build
# The stamp's name carries a hash of the list, so adding a package re-runs the check.
APT_STAMP   := $(BUILD)/.stamp-apt-$(firstword $(shell printf '%s' '$(APT_PACKAGES)' | md5sum))
VENV_STAMP  := $(VENV)/.stamp-requirements
# The other Pythons the wheels are built and tested for, from pyenv, each with its own venv:
# 3.13 (Blender 5.1+; with bpy 5.3) and 3.10 (blender.org's Blender 3.4-4.0: the legacy zip).
PYENV_ROOT  ?= $(shell pyenv root 2>/dev/null || echo $(HOME)/.pyenv)
PY313       ?= $(PYENV_ROOT)/versions/3.13.0/bin/python
PY310       ?= $(PYENV_ROOT)/versions/3.10.13/bin/python
VENV313     := $(VENV)-3.13
VENV310     := $(VENV)-3.10
PKG_STAMP   := $(VENV)/.stamp-package-requirements
VENV313_STAMP := $(VENV313)/.stamp-requirements
VENV310_STAMP := $(VENV310)/.stamp-requirements
DIST        := dist
VERSION     := $(shell sed -n 's/^project(toyrt LANGUAGES CXX VERSION \([0-9.]*\))/\1/p' CMakeLists.txt)

BLENDER_TESTS := $(sort $(wildcard tests/blender/test_*.py))

.PHONY: bench help setup apt venv configure native addon tables test test-native test-python test-blender test-bpy bench-blender parity-refs \
	demo bench-trace bench-lbvh clean distclean fuzz sanitize test-levels lint format test-quick venv-package package test-package

help:
	@sed -n '2,18p' Makefile | sed 's/^# \{0,1\}//'

# ---- setup ------------------------------------------------------------------------------------------
setup: apt venv venv-package native addon

apt: $(APT_STAMP)
$(APT_STAMP):
	@mkdir -p $(BUILD)
	scripts/ensure-apt.sh $(APT_PACKAGES)
	@rm -f $(BUILD)/.stamp-apt-*
	@touch $@

venv: $(VENV_STAMP)
$(VENV_STAMP): requirements-test.txt | $(APT_STAMP)
	@# Recreate a venv that was not made from Debian's Python (e.g. by a pyenv shim).
	@if [ -d $(VENV) ] && ! grep -qx 'home = /usr/bin' $(VENV)/pyvenv.cfg 2>/dev/null; then \
		echo "venv: $(VENV) was not made by $(SYS_PY); recreating"; rm -rf $(VENV); fi
	@[ -x $(VENV)/bin/python ] || { echo "venv: creating $(VENV)"; $(SYS_PY) -m venv --system-site-packages $(VENV); }
	$(VENV)/bin/python -m pip install -q -r requirements-test.txt
	@touch $@

# The packaging tools in both venvs (requirements-package.txt), and bpy 5.3 in the 3.13 one.
venv-package: $(PKG_STAMP) $(VENV313_STAMP) $(VENV310_STAMP)
$(PKG_STAMP): requirements-package.txt $(VENV_STAMP)
	$(VENV)/bin/python -m pip install -q -r requirements-package.txt
	@touch $@
$(VENV313_STAMP): requirements-package.txt requirements-test-3.13.txt
	@[ -x $(PY313) ] || { echo "venv: no CPython 3.13 at $(PY313) (pyenv install 3.13.0, or make PY313=...)" >&2; exit 1; }
	@[ -x $(VENV313)/bin/python ] || { echo "venv: creating $(VENV313)"; $(PY313) -m venv $(VENV313); }
	$(VENV313)/bin/python -m pip install -q -r requirements-package.txt -r requirements-test-3.13.txt
	@touch $@
$(VENV310_STAMP): requirements-package.txt
	@[ -x $(PY310) ] || { echo "venv: no CPython 3.10 at $(PY310) (pyenv install 3.10.13, or make PY310=...)" >&2; exit 1; }
	@[ -x $(VENV310)/bin/python ] || { echo "venv: creating $(VENV310)"; $(PY310) -m venv $(VENV310); }
	$(VENV310)/bin/python -m pip install -q -r requirements-package.txt
	@touch $@

configure: $(BUILD)/CMakeCache.txt
$(BUILD)/CMakeCache.txt: | $(APT_STAMP)
	@# A failed configure leaves a CMakeCache.txt behind: remove it so the next run configures again.
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS) || { rm -f $@; exit 1; }

# Always asks CMake: it knows what changed, and does nothing in well under a second when nothing did.
native: $(BUILD)/CMakeCache.txt
	@# (run as a top-level make: no "Entering directory" noise, its own -j)
	@env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL cmake --build $(BUILD) -j$(JOBS)

# Regenerates the GGX albedo tables (native/sampling/ggx_albedo_tables.inc) from their estimators,
# after a change to the GGX lobe; ggx_albedo_test fails until the committed file matches.
tables: native
	$(BUILD)/tests/native/ggx_albedo_tables native/sampling/ggx_albedo_tables.inc
	@env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL cmake --build $(BUILD) -j$(JOBS)

# Copies addon/render_toyrt + the module into Blender's user add-ons folder when they changed, and
# enables the add-on in the user's preferences once (see the script).
addon: native venv
	@BLENDER=$(BLENDER) BUILD_DIR=$(BUILD) scripts/install-addon.sh

# The per-level builds (three wheels and build-levels) compile the same core for the same three
# CPU levels four times: under ccache (from APT_PACKAGES) later builds reuse earlier compiles (the
# core's command lines name no build folder: native/CMakeLists.txt). ccache hashes the compiler's
# name too, and each Python's sysconfig named another (Debian's 3.11 x86_64-linux-gnu-g++, pyenv's
# g++): so every one of these builds runs g++ through Ninja, the same command lines, and a later
# build hits 35 of 39 compiles (scripts/build-wheel.sh; test-levels below). Only for these builds:
# their flags name the level, where -march=native (the main build) would not say which CPU.
LEVELS_CCACHE = CMAKE_CXX_COMPILER_LAUNCHER=$(shell command -v ccache)
# The release files (docs/install.md): a portable wheel per Python, repaired by auditwheel
# (scripts/build-wheel.sh; incremental in build/wheel/), then the extension zip, built and
# validated by Blender's own tool, and the legacy zip (scripts/build-extension.py).
package: venv-package
	@rm -f $(DIST)/toyrt-*.whl $(DIST)/render_toyrt-*.zip
	@$(LEVELS_CCACHE) JOBS=$(JOBS) scripts/build-wheel.sh $(VENV)/bin/python $(DIST)
	@$(LEVELS_CCACHE) JOBS=$(JOBS) scripts/build-wheel.sh $(VENV313)/bin/python $(DIST)
	@$(LEVELS_CCACHE) JOBS=$(JOBS) scripts/build-wheel.sh $(VENV310)/bin/python $(DIST)
	@$(VENV)/bin/python scripts/build-extension.py --dist $(DIST)

# ---- tests ------------------------------------------------------------------------------------------
TEST_STAGES := lint test-native test-python test-blender test-bpy test-package fuzz test-levels sanitize
# Each stage's wall time is printed as it ends ("make test: <stage> took N s"), so a slow one shows.
test: setup
	@for stage in $(TEST_STAGES); do start=$$(date +%s); \
		$(MAKE) --no-print-directory $$stage || exit 1; \
		echo "make test: $$stage took $$(( $$(date +%s) - start )) s"; done

test-quick: native venv
	@$(MAKE) --no-print-directory lint test-native test-python

# Every C++ file we wrote (not the generated ones in build*/) and every Python file: one style each
# (.clang-format, ruff.toml), checked, never rewritten, by `make test`.
CXX_SOURCES = $(shell git ls-files '*.cpp' '*.h' 2>/dev/null || find native tests bench -name '*.cpp' -o -name '*.h')
PY_SOURCES  := addon scenes tests bench scripts native/python

lint: venv
	@clang-format-14 --dry-run --Werror $(CXX_SOURCES) && echo "lint: clang-format: $(words $(CXX_SOURCES)) C++ files formatted"
	@$(VENV)/bin/ruff check $(PY_SOURCES)

format:
	clang-format-14 -i $(CXX_SOURCES)

test-native:
	ctest --test-dir $(BUILD) --output-on-failure --no-tests=error -j$(JOBS)

test-python:
	PYTHONPATH=$(BUILD)/python $(VENV)/bin/python -m pytest tests/python -q

# No --factory-startup: these tests check the add-on as installed and enabled in the user's
# preferences (factory settings would start Blender without it).
test-blender:
	@[ -n "$(BLENDER_TESTS)" ] || { echo "no tests/blender/test_*.py found" >&2; exit 1; }
	@passed=0; for t in $(BLENDER_TESTS); do \
		echo "blender: $$t"; start=$$(date +%s); \
		TOYRT_BUILD_DIR=$(abspath $(BUILD)) $(BLENDER) -b --python-exit-code 1 --python $$t || { echo "FAILED: $$t" >&2; echo "blender: $$passed passed, 1 failed"; exit 1; }; \
		echo "blender: $$t took $$(( $$(date +%s) - start )) s"; passed=$$((passed + 1)); \
	done; echo "blender: $$passed passed, 0 failed"

# The same tests under a current Blender: the bpy module from PyPI (requirements-test.txt), one
# process per file, the add-on and the module copied into a temporary user folder
# (tests/blender/run_with_bpy.py). Command-line parts are skipped there (no blender executable).
# test_viewport.py, test_ui_layout.py and test_material_preview.py drive Debian's Blender with a window
# under Xvfb (the bpy module has no UI, and renders no previews).
BPY_TESTS := $(filter-out tests/blender/test_viewport.py tests/blender/test_ui_layout.py tests/blender/test_material_preview.py,$(BLENDER_TESTS))
# The Cycles references of tests/blender/test_cycles_parity.py, committed so that a fresh clone's
# `make test` renders none (about 12 minutes of Cycles). After a change to how its scenes are built,
# stale references are rendered by the test itself (slower, never wrong); this writes them back.
parity-refs: addon venv
	TOYRT_PARITY_SAVE_REFS=1 TOYRT_BUILD_DIR=$(abspath $(BUILD)) $(BLENDER) -b --python-exit-code 1 \
		--python tests/blender/test_cycles_parity.py
	TOYRT_PARITY_SAVE_REFS=1 $(VENV)/bin/python tests/blender/run_with_bpy.py tests/blender/test_cycles_parity.py \
		--build $(BUILD)

test-bpy:
	@passed=0; for t in $(BPY_TESTS); do \
		echo "bpy: $$t"; start=$$(date +%s); \
		$(VENV)/bin/python tests/blender/run_with_bpy.py $$t --build $(BUILD) || { echo "FAILED (bpy): $$t" >&2; echo "bpy: $$passed passed, 1 failed"; exit 1; }; \
		echo "bpy: $$t took $$(( $$(date +%s) - start )) s"; passed=$$((passed + 1)); \
	done; echo "bpy: $$passed passed, 0 failed"

# The release files installed where users are: each wheel in a fresh venv (numpy 1.x and 2.x on 3.11,
# 2.x on 3.13, 1.x on 3.10 as blender.org's 3.4-4.0 bundle) running the ray-API tests; the extension
# zip in bpy 5.0.1 (3.11) and 5.3.0 (3.13) through Blender's extension API, and the legacy zip in
# Debian's Blender 3.4, each rendering a closed form; the bad inputs on the way (tests/package/).
# The CPU levels of the wheels' dispatch (native/python/toyrt/) this CPU runs, each forced once in the
# 3.13 venv (the best one is also what the other runs pick).
CPU_LEVELS = $(shell grep -qw sse4_2 /proc/cpuinfo && echo v2) $(shell grep -qw avx2 /proc/cpuinfo && echo v3) \
	$(shell grep -qw avx512bw /proc/cpuinfo && echo v4)
EXT_ZIP    = $(DIST)/render_toyrt-$(VERSION)-linux_x64.zip
LEGACY_ZIP = $(DIST)/render_toyrt-$(VERSION)-legacy-linux_x64.zip
test-package: package
	@# The glibc floor docs/install.md states: a symbol from a newer glibc would raise every wheel's tag.
	@n=$$(ls $(DIST)/toyrt-$(VERSION)-cp*-manylinux_2_34_x86_64.whl 2>/dev/null | wc -l); \
		[ $$n -eq 3 ] || { echo "test-package: expected 3 manylinux_2_34 wheels, found: $$(ls $(DIST))" >&2; exit 1; }
	tests/package/fresh_venv.sh $(SYS_PY) 1 $(DIST)/toyrt-$(VERSION)-cp311-*.whl
	tests/package/fresh_venv.sh $(SYS_PY) 2 $(DIST)/toyrt-$(VERSION)-cp311-*.whl
	tests/package/fresh_venv.sh $(PY313) 2 $(DIST)/toyrt-$(VERSION)-cp313-*.whl $(CPU_LEVELS)
	tests/package/fresh_venv.sh $(PY310) 1 $(DIST)/toyrt-$(VERSION)-cp310-*.whl
	$(VENV)/bin/python tests/package/install_extension.py $(EXT_ZIP) $(LEGACY_ZIP)
	$(VENV313)/bin/python tests/package/install_extension.py $(EXT_ZIP) $(LEGACY_ZIP)
	$(SYS_PY) tests/package/install_legacy.py $(LEGACY_ZIP) --blender $(BLENDER)
	tests/package/numpy2_guard.sh $(BUILD)/python

# ---- the rest ---------------------------------------------------------------------------------------
demo: setup
	@mkdir -p out
	$(BLENDER) -b --python-exit-code 1 --python scenes/cornell_demo.py -- $(CURDIR)/out/demo.blend > out/demo-build.log 2>&1 \
		|| { cat out/demo-build.log; exit 1; }
	$(BLENDER) -b out/demo.blend -E TOYRT -o $(CURDIR)/out/demo_ -F PNG -f 1 | grep -E 'TOYRT|Saved|Error' || true
	@test -f out/demo_0001.png || { echo "make demo: the render failed (see above)"; exit 1; }
	@echo "make demo: wrote $(CURDIR)/out/demo_0001.png"

bench-trace: native
	$(if $(filter /%,$(BUILD)),,./)$(BUILD)/bench/bench_trace --out docs/bench-trace.md

# Builders from 10K to 4M triangles (LBVH on PoCL, SAH, Embree): docs/lbvh.md and its chart.
# TOYRT against Cycles in Blender: time to Cycles' 64-sample error on the seed's scene, peak memory of
# 10,000 instances (bench/blender/bench_blender.py, about 4 minutes) -> docs/blender-bench.md
bench-blender: addon
	$(SYS_PY) bench/blender/bench_blender.py --blender $(BLENDER) --out docs/blender-bench.md

bench-lbvh: native
	$(if $(filter /%,$(BUILD)),,./)$(BUILD)/bench/bench_lbvh --out docs/lbvh-bench.md --csv docs/lbvh.csv
	$(SYS_PY) bench/plot_lbvh.py docs/lbvh.csv docs/lbvh.png

# The speed/accuracy report (bench/run.py): scenes from scenes/bench/, Cycles references cached in
# out/bench-cache/, work files in out/bench/ -> docs/results.md and docs/results/*.png. Mitsuba 3
# and Open3D come from requirements-bench.txt, installed here only (not by setup: CI stays fast).
BENCH_QUICK ?=
BENCH_STAMP := $(VENV)/.stamp-bench-requirements
$(BENCH_STAMP): requirements-bench.txt $(VENV_STAMP)
	$(VENV)/bin/python -m pip install -q --no-deps -r requirements-bench.txt
	@# Open3D may have no wheel for this machine: the report then says so; Mitsuba must import.
	$(VENV)/bin/python -c "import sys; sys.path.insert(0, 'bench'); import mitsuba, accel_python; \
		m, why = accel_python.import_open3d(); print('bench: mitsuba', mitsuba.__version__, '/ open3d', m.__version__ if m else why)"
	@touch $@

bench: addon $(BENCH_STAMP)
	$(VENV)/bin/python bench/run.py --build $(BUILD) --blender $(BLENDER) $(if $(BENCH_QUICK),--quick)
	@# The exact queries against Open3D and trimesh: wrong answers on aligned sets, speed -> docs/queries-bench.md
	$(VENV)/bin/python bench/queries_bench.py --build $(BUILD) $(if $(BENCH_QUICK),--quick)
	@# Denoising (OIDN in both engines) and adaptive sampling against Cycles, under bpy 5.0 -> docs/denoise-bench.md
	$(VENV)/bin/python tests/blender/run_with_bpy.py bench/denoise_bench.py --build $(BUILD) $(if $(BENCH_QUICK),--quick)

# ---- robustness: fuzzing and sanitizers (docs/robustness.md) ----------------------------------------
# Both use their own build directories beside $(BUILD): a clang build for libFuzzer
# (build-fuzz/ by default) and a sanitizer build of everything (build-asan/).
FUZZ_BUILD   ?= $(BUILD)-fuzz
FUZZ_SECONDS ?= 60
# A fixed seed makes `make test` repeatable; FUZZ_SEED=0 picks a new one each run.
FUZZ_SEED    ?= 1
SAN_BUILD    ?= $(BUILD)-asan
SANITIZE_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
# -O1 and line tables only (-g1: file and line in every report, no variables): the build is the
# stage's largest part, and this compiles in 421 s what -O2 -g did in 735 s on a first-generation
# EPYC, the tests then taking 381 s instead of 344 s. (A build-asan/ configured before keeps its
# flags: `make clean` first.)
SANITIZE_OPT   := -O1 -g1 -DNDEBUG
# UBSan stops at the first finding; Python's interpreter keeps memory until exit, so leak checks are
# for the C++ tests only.
SAN_ENV := UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitize/lsan.supp:print_suppressions=0

fuzz: apt
	@[ -f $(FUZZ_BUILD)/CMakeCache.txt ] || CC=clang CXX=clang++ cmake -S tests/fuzz -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
		|| { rm -f $(FUZZ_BUILD)/CMakeCache.txt; exit 1; }
	@env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL cmake --build $(FUZZ_BUILD) -j$(JOBS) --target scene_fuzzer
	@mkdir -p $(FUZZ_BUILD)/corpus
	@# New inputs go to the build's corpus; the seeds in tests/fuzz/corpus are only read.
	TOYRT_OPENCL=off $(FUZZ_BUILD)/scene_fuzzer -max_total_time=$(FUZZ_SECONDS) -seed=$(FUZZ_SEED) -print_final_stats=1 \
		-artifact_prefix=$(FUZZ_BUILD)/ $(FUZZ_BUILD)/corpus tests/fuzz/corpus

# The wheels run one of three builds of the core (v2 SSE4.2, v3 AVX2, v4 AVX-512; native/CMakeLists.txt):
# each level this CPU runs builds the suites of tests/levels against its own core and runs them, with
# the corpus `make fuzz` grew when it is there (make test runs fuzz first). The suites' LBVH variants
# are left to the native build: PoCL compiles the LBVH kernels for this CPU whatever the level, and the
# host code they would add (traversal, triangle tests) is what the SAH variants run at every level.
LEVELS_BUILD ?= $(BUILD)-levels
space := $(subst ,, )
test-levels: apt
	@[ -f $(LEVELS_BUILD)/CMakeCache.txt ] || $(LEVELS_CCACHE) CXX=g++ cmake -G Ninja -S . -B $(LEVELS_BUILD) -DCMAKE_BUILD_TYPE=Release \
		-DTOYRT_CPU_DISPATCH=ON -DTOYRT_NATIVE_ARCH=OFF -DTOYRT_TEST_LEVELS="$(subst $(space),;,$(strip $(CPU_LEVELS)))" \
		|| { rm -f $(LEVELS_BUILD)/CMakeCache.txt; exit 1; }
	@env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL cmake --build $(LEVELS_BUILD) -j$(JOBS) --target toyrt_level_tests
	@corpus=$(abspath $(FUZZ_BUILD))/corpus; if [ -d $$corpus ]; then export TOYRT_FUZZ_CORPUS=$$corpus; fi; \
		ctest --test-dir $(LEVELS_BUILD) -E '/Lbvh' --output-on-failure --no-tests=error -j$(JOBS) > $(LEVELS_BUILD)/ctest.log \
		|| { cat $(LEVELS_BUILD)/ctest.log; exit 1; }
	@grep -h 'corpus_replay: .* inputs, every' $(LEVELS_BUILD)/Testing/Temporary/LastTest.log | sed 's/^/test-levels: /'
	@tail -n 3 $(LEVELS_BUILD)/ctest.log

sanitize: apt venv
	@[ -f $(SAN_BUILD)/CMakeCache.txt ] || cmake -S . -B $(SAN_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
		-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$(SANITIZE_OPT)" \
		-DCMAKE_CXX_FLAGS="$(SANITIZE_FLAGS)" -DCMAKE_EXE_LINKER_FLAGS="$(SANITIZE_FLAGS)" \
		-DCMAKE_SHARED_LINKER_FLAGS="$(SANITIZE_FLAGS)" -DTOYRT_BUILD_BENCH=OFF $(CMAKE_ARGS) \
		|| { rm -f $(SAN_BUILD)/CMakeCache.txt; exit 1; }
	@env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL cmake --build $(SAN_BUILD) -j$(JOBS)
	$(SAN_ENV) ctest --test-dir $(SAN_BUILD) --output-on-failure --no-tests=error -j$(JOBS)
	@# The interpreter is not built with ASan: its runtime must be loaded first, and libstdc++ with
	@# it (else ASan cannot find __cxa_throw and aborts on the first C++ exception). --noconftest:
	@# the conftest would put build/python (not the sanitized module) first on the path.
	@# allocator_may_return_null: the bad-input tests ask for copies of terabytes, which must fail as
	@# malloc fails without ASan (a MemoryError), not stop the run as ASan's allocator does by default.
	$(SAN_ENV) ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:allocator_may_return_null=1 \
		LD_PRELOAD="$$(g++ -print-file-name=libasan.so) $$(g++ -print-file-name=libstdc++.so)" \
		PYTHONPATH=$(SAN_BUILD)/python $(VENV)/bin/python -m pytest tests/python -q --noconftest -p no:cacheprovider

clean:
	rm -rf $(BUILD) $(FUZZ_BUILD) $(SAN_BUILD) $(LEVELS_BUILD)

distclean: clean
	rm -rf $(VENV) $(VENV313) $(VENV310) $(DIST)
