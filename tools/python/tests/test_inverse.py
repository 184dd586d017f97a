"""The inverses: F from the forward model gives back mu and phi."""

import numpy as np

import misalign

SCENE = (0.05, 0.05, 79.3e9, 0.3)


def test_mu_and_phi_back_from_the_forward_force():
    P = np.geomspace(200.0, 2e4, 25)[:, None]
    phi = np.geomspace(1e-5, 3e-3, 20)[None, :]
    mu = 0.3
    fwd = misalign.estimate(*SCENE, mu, P, phi)
    partial = fwd["regime"] == "partial"
    assert partial.any() and (~partial).any()
    m = misalign.solve_mu(*SCENE, P, phi, fwd["F"])
    assert (m["bound"][partial] == "exact").all()
    assert np.abs(m["mu"][partial] / mu - 1).max() < 1e-12
    assert (m["error"][partial] == "").all()
    # Gross slip: F = mu P fixes mu exactly; d/b = 1 exactly is not reached.
    assert np.isfinite(m["mu"]).all()
    p = misalign.solve_phi(*SCENE, mu, P, fwd["F"])
    assert np.abs(p["phi"][partial] / np.broadcast_to(phi, partial.shape)[partial] - 1).max() < 1e-10
    assert (p["bound"][~partial] == "at_least").all()
    assert (np.abs(p["phi"][~partial]) <= np.broadcast_to(phi, partial.shape)[~partial] * (1 + 1e-12)).all()
    # The sign of F is phi's.
    q = misalign.solve_phi(*SCENE, mu, P, -fwd["F"])
    np.testing.assert_array_equal(q["phi"], -p["phi"])


def test_f32_inverse_near_the_reference():
    P = np.geomspace(500.0, 1e4, 10)
    phi = np.full(10, 2e-4)
    fwd = misalign.estimate(*SCENE, 0.3, P, phi)
    ok = fwd["regime"] == "partial"
    m = misalign.solve_mu(*SCENE, P, phi, fwd["F"], model="f32")
    assert np.abs(m["mu"][ok] / 0.3 - 1).max() < 1e-4
    assert (m["sensitivity"][ok] > 0).all()


def test_inconsistent_force_says_why():
    r = misalign.solve_phi(*SCENE, 0.3, 1e3, [0.5 * 1e3, 10.0])
    assert r["bound"][0] == "inconsistent" and r["error"][0] == "above_model"
    assert np.isnan(r["phi"][0]) and r["bound"][1] == "exact"
    r = misalign.solve_mu(*SCENE, 1e3, 2e-4, [np.nan, 10.0])
    assert r["bound"][0] == "" and "axial force" in r["error"][0]
