"""Lets `pytest tests/python` find the freshly built module without setting PYTHONPATH."""
import pathlib
import sys

BUILD_PYTHON = pathlib.Path(__file__).resolve().parents[2] / "build" / "python"
if BUILD_PYTHON.is_dir() and str(BUILD_PYTHON) not in sys.path:
    sys.path.insert(0, str(BUILD_PYTHON))
