"""The peer: the forward model as a competent engineer writes it in numpy + scipy,
vectorised over all rows, kept beside the package as the benchmark's yardstick.

theta from eq (4); k' from eqs (5)/(6), tan^2(theta/2) = k'^2 (K - E) / (E - k'^2 K),
by Newton's method in x = ln k' on all rows at once, K = ``scipy.special.ellipkm1(k'^2)``
and E = ``ellipe(1 - k'^2)``; m from eq (5), n = k' m; d/b from eq (16); F from eq (21)
rearranged against cancellation; phi0 by a second Newton solve in ln k', for
g(theta0) = m n theta0 at d/b = 1 (eq 18).

Written for speed as a numerical engineer would: the rows in chunks that stay in the
cache; each Newton step's K and E evaluated once, their derivatives from them (DLMF
19.4.1); the seed of each solve from the small-k' series of K and E to second order in
k'^2 (a few logarithms, no elliptic integral), good to about (k'^2 ln(4/k'))^2, 1e-10
or better on practical rows, so that one Newton step reaches rounding: the step is
below 1e-8, so the root is within about 1e-16 of the point it gives, and the answer
there is taken to first order in that step (its error the step squared) rather than
by another evaluation of K and E. Rows whose step is still larger (large angles: k'
near 1, where the series is poor) iterate alone until they converge. So a practical
row costs one pair of K, E for k' and one for theta0. Checked: the seeds' first steps
on the benchmark's rows (at most 1.3e-12 for k', 1.3e-10 for theta0), and the answers
against Newton's method iterated until its steps are at rounding, over theta in
[1e-7, 1.5] rad and ln g in [-20, ln(pi/2)] (tools/python/tests/test_peer.py).

Its error against the 50-digit data of tests/data and its speed are measured by the
benchmark, which writes them beside the package's and asserts the error below 2e-14
relative on d/b, F and phi0. Elliptic contact only, one scene or a scene per row; no
validity flags, no p0, P*, P0*; no input checks (NaN in, NaN out).
"""

import numpy as np
from scipy.special import ellipe, ellipkm1

_PI = np.pi
#: Rows per chunk: every temporary of a chunk stays in the core's cache.
CHUNK = 16384
#: A Newton step below this (in ln k') has converged: the root is within its square.
_CONVERGED = 1e-8
_LN4 = np.log(4.0)
_C_G = 2.0 / 3.0 * np.log(2.0 / np.pi) + np.log(2.0)


def _pair(x):
    """At x = ln k': ln tan^2(theta/2) and its derivative in x; ln A, ln B, k^2 and
    d ln A/dx, d ln B/dx, where A = K - E, B = E - k'^2 K (eqs 5, 6)."""
    p = np.exp(2.0 * x)
    k2 = 1.0 - p
    K = ellipkm1(p)
    E = ellipe(k2)
    A = K - E
    B = E - p * K
    # dK/dx = -B/k^2, dE/dx = p A/k^2 (DLMF 19.4.1, with dk'/dx = k').
    dA = (-B - p * A) / (k2 * A)
    dB = (p * A / k2 - 2.0 * p * K + p * B / k2) / B
    lnA, lnB = np.log(A), np.log(B)
    return 2.0 * x + lnA - lnB, 2.0 + dA - dB, lnA, lnB, k2, dA, dB


def _solve(residual, x):
    """Newton's method in x = ln k' on every row: ``residual(x, rows)`` returns the
    value, its slope and what the caller needs at the root as (values, slopes in x).
    Returns x and those at the root, to first order in the last step."""
    value, slope, at, d_at = residual(x, slice(None))
    step = value / slope
    x = np.minimum(x - step, 0.0)
    at = [a - d * step for a, d in zip(at, d_at)]
    # Rows whose step was not below _CONVERGED (a poor seed: large angles) iterate
    # alone, gathered by index.
    todo = np.flatnonzero(np.abs(step) >= _CONVERGED)
    for _ in range(60):
        if todo.size == 0:
            break
        value, slope, at_t, d_t = residual(x[todo], todo)
        step = value / slope
        x[todo] = np.minimum(x[todo] - step, 0.0)
        for a, a_t, d in zip(at, at_t, d_t):
            a[todo] = a_t - d * step
        todo = todo[np.abs(step) >= _CONVERGED]
    return x, at


def _lam(a, q):
    """lam with lam - q ln lam = a (lam = ln(4/k') - 1, the small-k' variable), by
    Newton's method from lam = a + q ln a: two steps reach 1e-12 for a >= 5."""
    a = np.maximum(a, 1.0)
    lam = a + q * np.log(a)
    for _ in range(2):
        lam = np.maximum(lam - (lam - q * np.log(lam) - a) / (1.0 - q / lam), 1.0)
    return lam


def _seed_x(half):
    """ln k' where tan^2(theta/2) = half^2, from the small-k' series of K and E to
    second order (K = L + k'^2 (L - 1)/4, E = 1 + k'^2 (L - 1/2)/2, L = ln(4/k')):
    2 ln k' + ln lam + c = ln tan^2(theta/2), c = k'^2 (L/2 + 1/4 - L/(4 lam)),
    lam = L - 1. Good to about (k'^2 L)^2."""
    lam = _lam(_LN4 - 1.0 - np.log(half), 0.5)
    x = _LN4 - 1.0 - lam
    L = lam + 1.0
    c = np.exp(2.0 * x) * (0.5 * L + 0.25 - 0.25 * L / lam)
    return np.minimum(x - c / (2.0 - 1.0 / lam), np.log(0.9))


def _seed_x_of_g(log_g):
    """ln k' where g = m n theta reaches e^log_g, from the same series: ln g =
    2/3 ln k' + 2/3 ln(2/pi) + ln 2 + 1/2 ln lam + c_g, c_g = k'^2 (lam/4 + 5/12 -
    1/(8 lam))."""
    lam = _lam(1.5 * (_C_G - log_g) + _LN4 - 1.0, 0.75)
    x = _LN4 - 1.0 - lam
    c = np.exp(2.0 * x) * (0.25 * lam + 5.0 / 12.0 - 0.125 / lam)
    return np.minimum(x - c / (2.0 / 3.0 - 0.5 / lam), np.log(0.9))


def _ellipse(theta):
    """m and n at theta (eqs 5, 6)."""
    half = np.tan(0.5 * theta)
    target = np.log(half * half)

    def residual(x, rows=slice(None)):
        lt, dlt, lnA, _, _, dA, _ = _pair(x)
        return lt - target[rows], dlt, [lnA], [dA]

    x, (lnA,) = _solve(residual, _seed_x(half))
    t2 = half * half
    k2 = 1.0 - np.exp(2.0 * x)
    m = np.cbrt(2.0 * np.exp(lnA) * (1.0 + t2) / (_PI * k2 * t2))
    return m, np.exp(x) * m


def _theta_of_g(log_g):
    """theta0 with ln(m n theta0) = log_g, by Newton in ln k' (g < pi/2)."""

    def residual(x, rows=slice(None)):
        lt, dlt, _, lnB, k2, _, dB = _pair(x)
        t2 = np.exp(lt)
        s = np.sqrt(t2)
        theta = 2.0 * np.arctan(s)
        # m^3 = 2 B (1 + t2) / (pi k^2 k'^2); ln g = x + 2/3 ln m^3 + ln theta.
        ln_m3 = np.log(2.0 / _PI) + lnB + np.log1p(t2) - np.log(k2) - 2.0 * x
        d_ln_m3 = dB + t2 / (1.0 + t2) * dlt + 2.0 * (1.0 - k2) / k2 - 2.0
        d_ln_theta = s * dlt / ((1.0 + t2) * theta)
        value = x + (2.0 / 3.0) * ln_m3 + np.log(theta) - log_g[rows]
        return value, 1.0 + (2.0 / 3.0) * d_ln_m3 + d_ln_theta, [np.log(theta)], [d_ln_theta]

    _, (ln_theta,) = _solve(residual, _seed_x_of_g(log_g))
    return np.exp(ln_theta)


def axial_force_ratio(s):
    """F/(mu P), eq (21), with 1 - (1 + s^2/2) sqrt(1 - s^2) rearranged so that
    nothing cancels; 1 in gross slip."""
    sc = np.minimum(s, 1.0)
    s2 = sc * sc
    root = np.sqrt((1.0 - sc) * (1.0 + sc))
    first = s2 * s2 * (3.0 + s2) / (4.0 * (1.0 + (1.0 + 0.5 * s2) * root))
    return np.where(s >= 1.0, 1.0, np.minimum(first + 1.5 * sc * np.arccos(sc), 1.0))


def _forward(R1, R2, G, nu, mu, P, phi):
    c = 2.0 * np.sqrt(R1 * R2) / (R1 + R2)
    abs_phi = np.abs(phi)
    m, n = _ellipse(c * abs_phi)  # eq (4)
    v2 = np.cbrt(1.5 * (1.0 - nu) * R1 * R2 / (G * (R1 + R2))) ** 2  # L = v P^(1/3)
    cbrt_p = np.cbrt(P)
    s = _PI * G * m * n * v2 * abs_phi / (3.0 * mu * cbrt_p)  # eq (16)
    F = np.copysign(mu * P * axial_force_ratio(s), phi)  # eq (21)
    log_g0 = np.log(c * 3.0 * mu * cbrt_p / (_PI * G * v2))  # m n theta0 at d/b = 1
    phi0 = _theta_of_g(log_g0) / c
    return s, F, phi0


def forward(R1, R2, G, nu, mu, P, phi):
    """d/b, F (N) and phi0 (rad) per row (arrays that broadcast), in chunks."""
    args = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64)
                                 for a in (R1, R2, G, nu, mu, P, phi)))
    shape = args[0].shape
    flat = [a.reshape(-1) for a in args]
    n = flat[0].size
    out = [np.empty(n) for _ in range(3)]
    for start in range(0, n, CHUNK):
        part = slice(start, min(n, start + CHUNK))
        for o, r in zip(out, _forward(*(a[part] for a in flat))):
            o[part] = r
    return tuple(o.reshape(shape) for o in out)
