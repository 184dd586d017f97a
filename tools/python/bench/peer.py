"""The peer: the forward model as a competent engineer writes it in numpy + scipy,
vectorised over all rows, kept beside the package as the benchmark's yardstick.

theta from eq (4); k' from eqs (5)/(6), tan^2(theta/2) = k'^2 (K - E) / (E - k'^2 K),
by Newton's method in ln k' on all rows at once, K = ``scipy.special.ellipkm1(k'^2)``
and E = ``ellipe(1 - k'^2)``, seeded by the small-theta asymptotics; m from eq (5),
n = k' m; d/b from eq (16); F from eq (21) rearranged against cancellation; phi0 by a
second vectorised Newton solve, for g(theta0) = m n theta0 at d/b = 1 (eq 18).

Its own error against the 50-digit data of tests/data: the benchmark measures it,
writes it beside its speed, and asserts it below 2e-14 relative on d/b, F and phi0. Elliptic
contact only, one scene or a scene per row; no validity flags, no p0, P*, P0*; no
input checks (NaN in, NaN out).
"""

import numpy as np
from scipy.special import ellipe, ellipkm1

_PI = np.pi


def _shape(kp):
    """K - E, E - k'^2 K, k^2 and K at k' (arrays)."""
    p = kp * kp
    K = ellipkm1(p)
    E = ellipe(1.0 - p)
    return K - E, E - p * K, 1.0 - p, K


def _log_tan2_and_slope(x):
    """ln tan^2(theta/2) as a function of x = ln k', and its derivative in x."""
    kp = np.exp(x)
    A, B, k2, K = _shape(kp)
    p = kp * kp
    # dK/dk' = -B/(k^2 k'), dE/dk' = k' A / k^2 (DLMF 19.4.1).
    dA = (-B / k2 - p * A / k2) / A
    dB = (p * A / k2 - 2.0 * p * K + p * B / k2) / B
    return 2.0 * x + np.log(A) - np.log(B), 2.0 + dA - dB, A, k2


def _seed(theta):
    """k' from the small-theta asymptotics, Lam = ln(4/k') - 1 = ln(8 sqrt(Lam)/theta) - 1."""
    lam = np.log(8.0 / theta) - 1.0
    for _ in range(2):
        lam = np.log(8.0 * np.sqrt(lam) / theta) - 1.0
    return np.minimum(theta / (2.0 * np.sqrt(lam)), 0.9)


def _newton(f, x, near=1e-9, iterations=20):
    """Newton's method on every row at once: once every step is below ``near``
    (relative, as x = ln k'), one more step takes the root to rounding (quadratic
    convergence: the next step would be below 1e-18), and the loop ends. On practical
    rows that is two or three steps from the asymptotic seed."""
    for _ in range(iterations):
        value, slope = f(x)
        step = value / slope
        x = np.minimum(x - step, 0.0)
        if np.nanmax(np.abs(step), initial=0.0) < near:
            value, slope = f(x)
            return np.minimum(x - value / slope, 0.0)
    return x


def ellipse(theta):
    """k', m, n at theta (eqs 5, 6)."""
    target = np.log(np.tan(0.5 * theta) ** 2)
    x = _newton(lambda x: (lambda v: (v[0] - target, v[1]))(_log_tan2_and_slope(x)),
                np.log(_seed(theta)))
    kp = np.exp(x)
    A, _, k2, _ = _shape(kp)
    t2 = np.tan(0.5 * theta) ** 2
    m = np.cbrt(2.0 * A * (1.0 + t2) / (_PI * k2 * t2))
    return kp, m, kp * m


def _log_g_and_slope(x):
    """ln g = ln(m n theta) along x = ln k', and its derivative."""
    lt, dlt, A, k2 = _log_tan2_and_slope(x)
    kp = np.exp(x)
    t2 = np.exp(lt)
    theta = 2.0 * np.arctan(np.sqrt(t2))
    m3 = 2.0 * A * (1.0 + t2) / (_PI * k2 * t2)
    log_g = x + 2.0 / 3.0 * np.log(m3) + np.log(theta)
    # d ln A/dx is in dlt: dlt = 2 + dlnA - dlnB; take it apart again.
    p = kp * kp
    _, B, _, K = _shape(kp)
    dlnA = (-B / k2 - p * A / k2) / A
    dln_m3 = dlnA + t2 / (1.0 + t2) * dlt + 2.0 * p / k2 - dlt
    dln_theta = np.sqrt(t2) / ((1.0 + t2) * theta) * dlt
    return log_g, 1.0 + 2.0 / 3.0 * dln_m3 + dln_theta


def theta_for_g(g):
    """theta0 with m n theta0 = g (g < pi/2), by Newton in ln k'."""
    # Seed: g ~ (8 sqrt(Lam) theta^2 / pi^2)^(1/3) for small theta.
    theta = np.sqrt(_PI**2 * g**3 / 8.0)
    for _ in range(3):
        lam = np.log(8.0 / theta) - 1.0
        theta = np.sqrt(_PI**2 * g**3 / (8.0 * np.sqrt(lam)))
    target = np.log(g)
    x = _newton(lambda x: (lambda v: (v[0] - target, v[1]))(_log_g_and_slope(x)),
                np.log(_seed(np.minimum(theta, 1.0))))
    lt, _, _, _ = _log_tan2_and_slope(x)
    return 2.0 * np.arctan(np.sqrt(np.exp(lt)))


def axial_force_ratio(s):
    """F/(mu P), eq (21), with 1 - (1 + s^2/2) sqrt(1 - s^2) rearranged so that
    nothing cancels; 1 in gross slip."""
    sc = np.minimum(s, 1.0)
    s2 = sc * sc
    root = np.sqrt((1.0 - sc) * (1.0 + sc))
    first = s2 * s2 * (3.0 + s2) / (4.0 * (1.0 + (1.0 + 0.5 * s2) * root))
    return np.where(s >= 1.0, 1.0, np.minimum(first + 1.5 * sc * np.arccos(sc), 1.0))


def forward(R1, R2, G, nu, mu, P, phi):
    """d/b, F (N) and phi0 (rad) per row (arrays that broadcast)."""
    c = 2.0 * np.sqrt(R1 * R2) / (R1 + R2)
    theta = c * np.abs(phi)  # eq (4)
    _, m, n = ellipse(theta)
    v = np.cbrt(1.5 * (1.0 - nu) * R1 * R2 / (G * (R1 + R2)))  # L = v P^(1/3)
    cbrt_p = np.cbrt(P)
    s = _PI * G * m * n * v * v * np.abs(phi) / (3.0 * mu * cbrt_p)  # eq (16)
    F = np.copysign(mu * P * axial_force_ratio(s), phi)  # eq (21)
    g0 = c * 3.0 * mu * cbrt_p / (_PI * G * v * v)  # m n theta0 at d/b = 1
    phi0 = theta_for_g(g0) / c
    return s, F, phi0
