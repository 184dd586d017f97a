"""The benchmark's peer (tools/python/bench/peer.py) takes one Newton step a solve
from a series seed: its answers must be those of Newton's method iterated to
convergence, over every angle the elliptic solution takes, not only the benchmark's."""

import sys

import numpy as np
import pytest

from conftest import ROOT

pytest.importorskip("scipy")
sys.path.insert(0, str(ROOT / "tools" / "python" / "bench"))
import peer  # noqa: E402

#: The peer's stated accuracy (the benchmark asserts it against the 50-digit data): the
#: two evaluations round differently by up to about 1e-14 (ln g = -20 carries 2e-15).
BOUND = 2e-14


def _converged(residual, x):
    """Plain Newton in x = ln k' from x until every step is below 1e-15; what the
    residual carries, taken at the last point (no first-order finish)."""
    for _ in range(200):
        value, slope, _, _ = residual(x)
        step = value / slope
        x = np.minimum(x - step, 0.0)
        if np.all(np.abs(step) < 1e-15):
            break
    return x


def test_ellipse_equals_newton_to_convergence():
    theta = np.geomspace(1e-7, 1.5, 3000)
    half = np.tan(0.5 * theta)
    target = np.log(half * half)

    def residual(x):
        lt, dlt, *_ = peer._pair(x)
        return lt - target, dlt, None, None

    x = _converged(residual, np.log(np.minimum(theta / 2.0, 0.9)))
    lnA = peer._pair(x)[2]
    k2 = 1.0 - np.exp(2.0 * x)
    m = np.cbrt(2.0 * np.exp(lnA) * (1.0 + half * half) / (np.pi * k2 * half * half))
    got_m, got_n = peer._ellipse(theta)
    assert np.max(np.abs(got_m / m - 1.0)) < BOUND
    assert np.max(np.abs(got_n / (np.exp(x) * m) - 1.0)) < BOUND


def test_critical_angle_equals_newton_to_convergence():
    log_g = np.linspace(-20.0, np.log(np.pi / 2) - 1e-3, 3000)

    def residual(x):
        lt, dlt, _, lnB, k2, _, dB = peer._pair(x)
        t2 = np.exp(lt)
        s = np.sqrt(t2)
        theta = 2.0 * np.arctan(s)
        ln_m3 = np.log(2.0 / np.pi) + lnB + np.log1p(t2) - np.log(k2) - 2.0 * x
        d_ln_m3 = dB + t2 / (1.0 + t2) * dlt + 2.0 * (1.0 - k2) / k2 - 2.0
        value = x + (2.0 / 3.0) * ln_m3 + np.log(theta) - log_g
        slope = 1.0 + (2.0 / 3.0) * d_ln_m3 + s * dlt / ((1.0 + t2) * theta)
        return value, slope, theta, None

    # From the peer's seed, but iterated until the steps are at rounding.
    x = _converged(residual, peer._seed_x_of_g(log_g))
    theta0 = residual(x)[2]
    assert np.all(np.isfinite(theta0))
    assert np.max(np.abs(peer._theta_of_g(log_g) / theta0 - 1.0)) < BOUND
