#!/usr/bin/env bash
# The `make setup` build links Debian's pybind11 2.10, which predates numpy 2's C API and would read
# numpy 2 arrays with the old layout (wrong strides, wrong answers): under numpy 2 that module must
# refuse to import with a message naming both, never load and answer wrongly (`make test-package`).
#
#   tests/package/numpy2_guard.sh BUILD_PYTHON_DIR
set -euo pipefail
BUILD_PY=$(realpath "$1")
work=$(mktemp -d /tmp/toyrt-numpy2.XXXXXX)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 -m venv "$work/venv"
"$work/venv/bin/python" -m pip install -q --disable-pip-version-check --only-binary=:all: "numpy>=2,<3"
out=$(cd "$work" && PYTHONPATH="$BUILD_PY" "$work/venv/bin/python" -c "
import numpy
try:
    import toyrt
except ImportError as e:
    print('REFUSED', e)
else:
    print('LOADED', toyrt.__file__)
" 2>&1)
echo "numpy 2 guard: $out"
case $out in
  *"REFUSED"*"cannot read numpy 2"*) echo "numpy 2 guard: 1 passed, 0 failed" ;;
  *"LOADED"*) # a build with a pybind11 that reads numpy 2 (>= 2.12) may load: then it must answer right
    PYTHONPATH="$BUILD_PY" "$work/venv/bin/python" -c "
import numpy as np, toyrt
s = toyrt.Scene(); s.add_mesh(np.float32([[0, 0, 1], [1, 0, 1], [0, 1, 1]]), [[0, 1, 2]]); s.commit()
h = s.intersect(np.float32([[0.2, 0.2, 0], [5, 5, 0]]), np.float32([[0, 0, 1], [0, 0, 1]]))
assert list(h['t']) == [1.0, float('inf')], h['t']
print('numpy 2 guard: 1 passed, 0 failed (this build reads numpy 2)')" ;;
  *) echo "numpy 2 guard: 0 passed, 1 failed"; exit 1 ;;
esac
