# The report's time-to-equal-error arithmetic (bench/report.py) on synthetic sweeps with known
# answers, so that a change to the fits cannot silently skew docs/results.md.
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
report = pytest.importorskip("report")  # needs matplotlib (Debian's python3-matplotlib)


def sweep(method, t0, per_sample, a, b, spps=(1, 2, 4, 8, 16, 32)):
    return [dict(method=method, spp=n, seconds=t0 + per_sample * n, rmse=a * n ** b, relmse=(a * n ** b) ** 2)
            for n in spps]


def test_a_method_twice_as_fast_per_sample_at_equal_error_has_speedup_two():
    runs = sweep("peer", 0.0, 0.02, 0.5, -0.5) + sweep("method", 0.0, 0.01, 0.5, -0.5)
    (ratio, bounded), n = report.speedup(runs, "method", "peer", "rmse")
    assert not bounded and n >= 4
    assert ratio == pytest.approx(2.0, rel=1e-6)


def test_lower_error_at_equal_cost_converts_through_the_convergence_rate():
    # Half the error at every spp with error ~ spp^-0.5: the peer needs 4x the samples.
    runs = sweep("peer", 0.0, 0.01, 0.4, -0.5) + sweep("method", 0.0, 0.01, 0.2, -0.5, spps=(1, 2, 4, 8, 16, 32, 64))
    (ratio, _), _ = report.speedup(runs, "method", "peer", "rmse")
    assert ratio == pytest.approx(4.0, rel=1e-6)


def test_the_fixed_cost_is_fitted_apart_from_the_cost_per_sample():
    fit = report.Fit(sweep("m", 1.5, 0.01, 0.5, -0.5), "m", "rmse")
    assert fit.t0 == pytest.approx(1.5) and fit.c == pytest.approx(0.01)
    assert fit.b == pytest.approx(-0.5)
    assert fit.seconds_for(0.5 * 16 ** -0.5) == pytest.approx(1.5 + 0.16)


def test_errors_outside_what_was_measured_are_not_extrapolated():
    fit = report.Fit(sweep("m", 0.0, 0.01, 0.5, -0.5), "m", "rmse")
    assert fit.seconds_for(0.5 * 1e4 ** -0.5) is None
    assert math.isclose(fit.seconds_for(10.0, below=True), 0.01)  # the time of its fewest samples (1)
