"""Bad input: a message per bad row, the others their values; a clear ValueError for
shapes, dtypes and options; never a crash."""

import numpy as np
import pytest

import misalign

SCENE = (0.05, 0.05, 79.3e9, 0.3, 0.3)


def test_bad_rows_get_nan_and_their_message():
    P = np.array([1e3, np.nan, np.inf, -1.0, 0.0, 1e3, 1e3, 1e3])
    phi = np.array([2e-4, 2e-4, 2e-4, 2e-4, 2e-4, np.nan, -np.inf, 2.0])
    for model in ["reference", "f32", "fixed"]:
        r = misalign.estimate(*SCENE, P, phi, model=model)
        bad = r["error"] != ""
        assert list(bad) == [False, True, True, True, False, True, True, True], model
        assert np.isnan(r["s"][bad]).all() and np.isnan(r["F"][bad]).all()
        assert np.isnan(r["phi0"][bad]).all()
        assert (r["regime"][bad] == "").all() and (r["model"][bad] == "").all()
        assert "load" in r["error"][1] and "misalignment" in r["error"][5]
        # Zero load: gross slip (d/b = inf), no force, phi0 = 0: an answer, not an error.
        assert r["s"][4] == np.inf and r["F"][4] == 0 and r["regime"][4] == "gross"
        assert np.isfinite(r["s"][0])


def test_bad_scene_per_row():
    mu = np.array([0.3, 0.0, -0.3, np.nan])
    nu = np.array([0.3, 0.3, 0.3, 0.7])
    r = misalign.estimate(0.05, 0.05, 79.3e9, nu, mu, 1e3, 2e-4)
    assert r["error"][0] == ""
    assert all("friction" in e for e in r["error"][1:3])
    assert "friction" in r["error"][3] or "Poisson" in r["error"][3]
    r = misalign.estimate(0.05, [0.05, -1.0, 0.0], 79.3e9, 0.3, 0.3, 1e3, 2e-4,
                          length=[0.1, 0.1, 0.1])
    assert r["error"][0] == "" and "radius" in r["error"][1] and "radius" in r["error"][2]
    r = misalign.estimate(*SCENE, 1e3, 2e-4, length=[0.1, 0.0, np.nan, -1.0])
    assert r["error"][0] == "" and all("length" in e for e in r["error"][1:])


def test_plane_and_forced_ellipse():
    r = misalign.estimate(0.05, np.inf, 79.3e9, 0.3, 0.3, 1e3, 2e-4, contact="elliptic")
    assert "plane" in r["error"][()]
    r = misalign.estimate(0.05, np.inf, 79.3e9, 0.3, 0.3, 1e3, 2e-4)
    assert r["model"][()] == "line" and r["error"][()] == ""


def test_shapes_broadcast_and_mismatches_raise():
    r = misalign.estimate(*SCENE, np.full((3, 1), 1e3), np.full((1, 4), 2e-4))
    assert r["s"].shape == (3, 4) and r["error"].shape == (3, 4)
    r = misalign.estimate(*SCENE, 1e3, 2e-4)
    assert r["s"].shape == () and np.isfinite(r["s"])
    with pytest.raises(ValueError, match="broadcast"):
        misalign.estimate(*SCENE, np.ones(3), np.ones(4))
    with pytest.raises(ValueError, match="broadcast"):
        misalign.solve_mu(*SCENE[:4], np.ones(3), np.ones(4), 1.0)


def test_empty_arrays():
    r = misalign.estimate(*SCENE, np.array([]), 2e-4)
    assert r["s"].shape == (0,) and r["error"].shape == (0,)
    r = misalign.solve_phi(*SCENE, np.array([]), 1.0)
    assert r["phi"].shape == (0,)
    with pytest.raises(ValueError):
        misalign.replay(np.array([]), np.array([1.0]), np.array([1.0]))


def test_dtypes():
    ref = misalign.estimate(*SCENE, np.array([1000.0, 2000.0]), 2e-4)["s"]
    ints = misalign.estimate(*SCENE, np.array([1000, 2000]), 2e-4)["s"]
    np.testing.assert_array_equal(ints, ref)
    f32 = misalign.estimate(*SCENE, np.array([1000, 2000], dtype=np.float32), 2e-4)["s"]
    np.testing.assert_array_equal(f32, ref)  # both loads are exact in f32
    obj = misalign.estimate(*SCENE, np.array([1000.0, 2000], dtype=object), 2e-4)["s"]
    np.testing.assert_array_equal(obj, ref)
    lists = misalign.estimate(*SCENE, [1000, 2000], 2e-4)["s"]
    np.testing.assert_array_equal(lists, ref)
    with pytest.raises(ValueError, match="P"):
        misalign.estimate(*SCENE, np.array(["a", None], dtype=object), 2e-4)
    with pytest.raises(ValueError, match="P"):
        misalign.estimate(*SCENE, np.array(["1000", "2000"]), 2e-4)
    with pytest.raises(ValueError, match="P"):
        misalign.estimate(*SCENE, np.array([1 + 1j]), 2e-4)
    with pytest.raises(ValueError, match="P"):
        misalign.estimate(*SCENE, np.array([True]), 2e-4)


def test_non_contiguous_arrays():
    P = np.linspace(100.0, 5e3, 40)
    phi = np.linspace(1e-5, 1e-3, 40)
    ref = misalign.estimate(*SCENE, P[::2], phi[::2])
    view = np.stack([P, phi])[:, ::2]  # strided rows
    r = misalign.estimate(*SCENE, view[0], view[1])
    np.testing.assert_array_equal(r["s"], ref["s"])
    F = np.asfortranarray(np.outer(P[:5], np.ones(3)))
    r = misalign.estimate(*SCENE, F, 2e-4)
    assert r["s"].shape == (5, 3)
    np.testing.assert_array_equal(r["s"][:, 0], r["s"][:, 2])


def test_bad_options_raise():
    with pytest.raises(ValueError, match="model"):
        misalign.estimate(*SCENE, 1e3, 2e-4, model="double")
    with pytest.raises(ValueError, match="contact"):
        misalign.estimate(*SCENE, 1e3, 2e-4, contact="ellipse")
    with pytest.raises(ValueError, match="no inverse"):
        misalign.solve_mu(*SCENE[:4], 1e3, 2e-4, 10.0, model="fixed")
    with pytest.raises(ValueError, match="model"):
        misalign.replay([0.0, 1.0], [1e3, 1e3], [2e-4, 2e-4], model="reference")
    with pytest.raises(ValueError, match="config"):
        misalign.replay([0.0, 1.0], [1e3, 1e3], [2e-4, 2e-4], config={"no_such": 1})
    with pytest.raises(ValueError):
        misalign.replay([0.0, 1.0], [1e3, 1e3], [2e-4, 2e-4], config={"warning": -1.0})
    with pytest.raises(ValueError, match="scene"):
        misalign.replay([0.0, 1.0], [1e3, 1e3], [2e-4, 2e-4], scene=(0.05, 0.05, -1, 0.3, 0.3))


def test_trace_time_backwards_and_repeated():
    t = np.array([0.0, 1.0, 2.0, 2.0, 1.5, 3.0, 4.0, 5.0])
    r = misalign.replay(t, np.full(8, 2e3), np.full(8, 2e-4), V=2.0)
    assert r.summary["faults"]["time_backwards"] >= 1
    assert r.summary["repeated_timestamps"] >= 1
    with pytest.raises(ValueError, match="t is not a finite"):
        misalign.replay([0.0, np.nan], [1e3, 1e3], [2e-4, 2e-4])
    with pytest.raises(ValueError, match="samples"):
        misalign.replay([0.0, 1.0], [1e3, 1e3, 1e3], [2e-4, 2e-4])
    # Bad samples are the monitor's counted faults, not an exception.
    r = misalign.replay(np.arange(5.0), [1e3, np.nan, -np.inf, 1e3, 1e3], [2e-4] * 5)
    assert r.summary["faults"]["non_finite"] >= 1


def test_times_the_nodes_counter_cannot_hold_raise():
    # t in ns since the epoch: refused, not saturated into repeated timestamps.
    t = 1.7e18 + 1e9 * np.arange(300)
    with pytest.raises(ValueError, match=r"sample 0: t = 1.7e18 s is beyond .* is t in ns"):
        misalign.replay(t, np.full(300, 2e3), np.full(300, 2e-4))
    # A year ahead, in a later chunk: refused, not taken modulo 2^32 ms.
    t = np.array([0.0, 1.0, 2.0, 31557602.0])
    with pytest.raises(ValueError, match="sample 3: t steps forward by 3.15576e7 s"):
        misalign.replay(t, np.full(4, 2e3), np.full(4, 2e-4), chunk=2)


def test_extreme_values_never_give_a_silent_nan():
    special = np.array([0.0, -0.0, 1e-320, 5e-324, 1e-300, 1e300, 1.7e308, np.inf, -np.inf,
                        np.nan, -1.0, 0.5, np.pi / 2, 2.0, 0.05, 79.3e9, 0.3, 1e3, 2e-4, 1e20,
                        3.4e38, 1e-45])
    rng = np.random.default_rng(0)
    cols = [rng.choice(special, 20_000) for _ in range(8)]
    for model in ["reference", "f32", "fixed"]:
        for contact in ["auto", "elliptic", "line"]:
            r = misalign.estimate(*cols[:7], length=cols[7], model=model, contact=contact)
            ok = r["error"] == ""
            assert ok.any() and (~ok).any()
            assert not np.isnan(r["s"][ok]).any() and not np.isnan(r["F"][ok]).any()
            # phi0 is NaN exactly where the flag says there is no critical angle.
            none = np.array(["no_critical_angle" in f for f in r["flags"][ok]], dtype=bool)
            assert (np.isnan(r["phi0"][ok]) == none).all(), (model, contact)
    for model in ["reference", "f32"]:
        for contact in ["auto", "elliptic", "line"]:
            a = misalign.solve_mu(*cols[:4], cols[5], cols[6], cols[7], model=model,
                                  contact=contact)
            b = misalign.solve_phi(*cols[:5], cols[5], cols[7], model=model, contact=contact)
            for r, k in [(a, "mu"), (b, "phi")]:
                assert not (np.isnan(r[k]) & (r["error"] == "")).any(), (model, contact, k)


def test_every_model_draws_the_right_angle_at_the_f64_given():
    # f64's pi/2 lies below the true pi/2 and is answered; the f64 above it is refused,
    # also by the f32 core, whose rounding would carry it onto f32's pi/2.
    half_pi = np.pi / 2
    phi = np.array([half_pi, np.nextafter(half_pi, 4.0)])
    for model in ["reference", "f32", "fixed"]:
        # The default angle count (the finest the tables allow) ends below a right
        # angle; counts of 1 urad reach it.
        for lsb in [{}, {"counts": "adc", "angle_lsb": 1e-6}] if model == "fixed" else [{}]:
            r = misalign.estimate(*SCENE, 1e3, phi, model=model, **lsb)
            assert r["error"][0] == "", (model, lsb, r["error"])
            assert "misalignment" in r["error"][1], (model, lsb, r["error"])
    for model in ["reference", "f32"]:
        m = misalign.solve_mu(*SCENE[:4], 1e3, phi, 100.0, model=model)
        assert "pi/2" not in m["error"][0], (model, m["error"])
        assert "misalignment" in m["error"][1], (model, m["error"])
