#!/usr/bin/env bash
# Installs a built wheel into a new, empty virtual environment, with no compiler involved (the wheel
# file itself, binary packages only), and runs the ray-API tests and the wheel's own checks there
# (`make test-package`, docs/install.md):
#
#   tests/package/fresh_venv.sh PYTHON NUMPY_MAJOR WHEEL [LEVEL ...]
#   e.g. tests/package/fresh_venv.sh /usr/bin/python3 1 dist/toyrt-0.1.0-cp311-*.whl   (numpy 1.x)
#
# Each LEVEL (v2, v3, v4: TOYRT_CPU, native/python/toyrt/__init__.py) runs the ray-API tests
# again with that CPU level forced; without, they run at the level the CPU picks.
#
# The tests run from a temporary folder with --noconftest, so neither build/python (which
# tests/python/conftest.py would add) nor the repository can supply `toyrt`: only the wheel can.
set -euo pipefail
REPO=$(cd "$(dirname "$0")/../.." && pwd)
PYTHON=$1
NUMPY_MAJOR=$2
WHEEL=$(realpath "$3")
shift 3
work=$(mktemp -d /tmp/toyrt-wheel-venv.XXXXXX)
trap 'rm -rf "$work"' EXIT

"$PYTHON" -m venv "$work/venv"
"$work/venv/bin/python" -m pip install -q --disable-pip-version-check --only-binary=:all: \
  "$WHEEL" "numpy>=$NUMPY_MAJOR,<$((NUMPY_MAJOR + 1))" pytest==8.3.5
echo "fresh venv: $("$work/venv/bin/python" -V), numpy $("$work/venv/bin/python" -c 'import numpy; print(numpy.__version__)'), $(basename "$WHEEL")"
cp "$REPO/tests/python/test_ray_api.py" "$REPO/tests/package/test_wheel.py" "$work/"
cd "$work"
TOYRT_NUMPY_MAJOR=$NUMPY_MAJOR "$work/venv/bin/python" -m pytest -q --noconftest -p no:cacheprovider test_wheel.py test_ray_api.py
for level in "$@"; do
  echo "fresh venv: the ray-API tests at TOYRT_CPU=$level"
  TOYRT_CPU=$level "$work/venv/bin/python" -m pytest -q --noconftest -p no:cacheprovider test_ray_api.py
done
