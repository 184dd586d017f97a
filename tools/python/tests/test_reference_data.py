"""The package against the independent 50-digit values of tests/data: every column it
returns, at the reference's bounds (4e-15 relative on d/b, F, phi0; 1e-12 on the
others, as tests/reference_vectors.rs), and the f32 core at its own (2e-6)."""

import numpy as np
import pandas as pd
import pytest

import misalign
from conftest import DATA

MAIN = 4e-15
REST = 1e-12
F32 = 2e-6


def rel(got, want):
    got, want = np.asarray(got, float), np.asarray(want, float)
    same = (got == want) | (np.isnan(got) & np.isnan(want))
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.abs((got - want) / want)
    return np.where(same, 0.0, np.nan_to_num(e, nan=np.inf))


def want(df, c):
    """The data's column c; phi0 and theta0 NaN where phi0 passes pi/2: eq (4) with
    unequal radii gives phi0 = theta0 / c beyond a right angle, where every model
    answers no critical angle (as tests/common's phi0 and theta0)."""
    v = df[c].to_numpy(dtype=float).copy()
    if c in ("phi0", "theta0"):
        v[df["phi0"].to_numpy(dtype=float) > np.pi / 2] = np.nan
    return v


def inputs(df):
    return [df[c].to_numpy() for c in ["R1", "R2", "G", "nu", "mu", "P", "phi"]]


def test_scene_rows_every_column():
    df = pd.read_csv(DATA / "vectors_scene.csv")
    r = misalign.estimate(*inputs(df), details=True)
    for c in ["s", "F", "phi0"]:
        assert rel(r[c], want(df, c)).max() <= MAIN, c
    for c in ["theta", "kprime", "m", "n", "a", "b", "p0", "d", "Pstar", "P0star", "theta0"]:
        assert rel(r[c], want(df, c)).max() <= REST, c
    assert (r["regime"] == df["regime"].to_numpy()).all()
    assert (r["model"] == "elliptic").all()
    assert (r["error"] == "").all()
    assert np.isnan(r["R"]).all()
    # The flags as the reference raises them: a/b = 1/k' below 10 is a round ellipse.
    round_ = np.array(["round_ellipse" in f for f in r["flags"]])
    assert (round_ == (df["kprime"].to_numpy() * 10 > 1)).all()


def test_line_rows_every_column():
    df = pd.read_csv(DATA / "vectors_line.csv")
    r = misalign.estimate(*inputs(df), contact="line", details=True)
    for c in ["s", "F", "phi0"]:
        assert rel(r[c], df[c]).max() <= MAIN, c
    for c in ["R", "b", "p0", "d", "Pstar", "P0star"]:
        assert rel(r[c], df[c]).max() <= REST, c
    assert (r["regime"] == df["regime"].to_numpy()).all()
    assert (r["model"] == "line").all()
    assert (r["error"] == "").all()


@pytest.mark.parametrize("threads", [True, False])
def test_f32_core_to_its_bound(threads):
    df = pd.read_csv(DATA / "vectors_scene.csv")
    r = misalign.estimate(*inputs(df), model="f32", threads=threads)
    for c in ["s", "F", "phi0"]:
        assert rel(r[c], want(df, c)).max() <= F32, c
    near_one = np.abs(df["s"].to_numpy() - 1) <= 1e-6
    assert (r["regime"][~near_one] == df["regime"].to_numpy()[~near_one]).all()


def test_one_scene_broadcasts_as_a_scene_per_row():
    df = pd.read_csv(DATA / "vectors_scene.csv").iloc[:50]
    row = df.iloc[0]
    P, phi = df["P"].to_numpy(), df["phi"].to_numpy()
    scalars = [row[c] for c in ["R1", "R2", "G", "nu", "mu"]]
    for model in ["reference", "f32", "fixed"]:
        a = misalign.estimate(*scalars, P, phi, model=model)
        b = misalign.estimate(*[np.full(50, x) for x in scalars], P, phi, model=model)
        for c in ["s", "F", "phi0"]:
            np.testing.assert_array_equal(a[c], b[c])


def test_fixed_core_near_the_reference():
    # Loads that are whole counts of 10 mN, angles whole counts of 0.1 nrad.
    P = np.round(np.geomspace(100.0, 2e4, 40), 2)[:, None]
    phi = (np.round(np.geomspace(2e-5, 2e-3, 30) / 1e-10) * 1e-10)[None, :]
    ref = misalign.estimate(0.05, 0.05, 79.3e9, 0.3, 0.3, P, phi)
    fix = misalign.estimate(0.05, 0.05, 79.3e9, 0.3, 0.3, P, phi, model="fixed",
                            counts="adc", angle_lsb=1e-10)
    assert fix["s"].shape == (40, 30)
    for c in ["s", "F", "phi0"]:
        assert rel(fix[c], ref[c]).max() <= 1e-4, c
    # The default, exact counts: any load and angle, the core's own error.
    P = np.geomspace(0.1037, 2e4, 40)[:, None]
    phi = np.geomspace(1.13e-7, 2e-3, 30)[None, :]
    ref = misalign.estimate(0.05, 0.05, 79.3e9, 0.3, 0.3, P, phi)
    fix = misalign.estimate(0.05, 0.05, 79.3e9, 0.3, 0.3, P, phi, model="fixed")
    for c in ["s", "F", "phi0"]:
        assert rel(fix[c], ref[c]).max() <= 1e-5, c


def test_threads_give_the_numbers_of_one_thread():
    # More rows than one chunk (8192), so that the rows are split over threads.
    rng = np.random.default_rng(5)
    n = 50_000
    P = np.exp(rng.uniform(np.log(100.0), np.log(5e4), n))
    phi = np.exp(rng.uniform(np.log(1e-6), np.log(3e-3), n)) * rng.choice([-1.0, 1.0], n)
    P[::997] = np.nan  # bad rows among them
    for model in ["reference", "f32", "fixed"]:
        a = misalign.estimate(0.05, 0.05, 79.3e9, 0.3, 0.3, P, phi, length=0.3, model=model,
                              details=True)
        b = misalign.estimate(0.05, 0.05, 79.3e9, 0.3, 0.3, P, phi, length=0.3, model=model,
                              details=True, threads=False)
        for k in a:
            np.testing.assert_array_equal(a[k], b[k], err_msg=f"{model} {k}")
        assert (a["model"] == "line").any() and (a["error"] != "").sum() == len(P[::997])
