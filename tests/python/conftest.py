"""Lets `pytest tests/python` find the freshly built module without setting PYTHONPATH.

A PYTHONPATH given by the caller wins (`make test-python BUILD=build-x` tests build-x's module):
build/python is only appended, as the fallback for a bare `pytest tests/python`."""
import pathlib
import sys

BUILD_PYTHON = pathlib.Path(__file__).resolve().parents[2] / "build" / "python"
if BUILD_PYTHON.is_dir() and str(BUILD_PYTHON) not in sys.path:
    sys.path.append(str(BUILD_PYTHON))
