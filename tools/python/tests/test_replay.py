"""The replay against the Rust replay: the monitor example's --events and --thresholds
files for the built-in scenario (both cores) and for a recorded trace with faults,
time going backwards and unmeasured cells, compared bit for bit."""

import subprocess

import numpy as np
import pandas as pd
import pytest

import misalign
from conftest import ROOT

NUMBERS = ["P", "phi", "s", "F", "phi0", "margin", "time_to_critical"]
TEXT = ["state", "from", "kind", "fault"]


def rust_monitor(tmp_path, *args):
    """Runs `cargo run --release --example monitor` with --events, --plot and
    --thresholds into tmp_path; returns the events and thresholds tables as text."""
    events, thresholds = tmp_path / "events.csv", tmp_path / "thresholds.csv"
    subprocess.run(
        ["cargo", "run", "--quiet", "--release", "--example", "monitor", "--", *args,
         "--events", str(events), "--plot", str(tmp_path / "plot.svg"),
         "--thresholds", str(thresholds)],
        cwd=ROOT, check=True, stdout=subprocess.DEVNULL,
    )
    read = lambda p: pd.read_csv(p, dtype=str, keep_default_na=False)  # noqa: E731
    return read(events), read(thresholds)


def f32_bits(text_column):
    return np.array([np.float32(x) if x != "" else np.float32("nan") for x in text_column])


def assert_same_events(py: pd.DataFrame, rust: pd.DataFrame):
    assert len(py) == len(rust) > 0
    np.testing.assert_array_equal(py["seq"].to_numpy(), rust["seq"].astype(np.int64))
    np.testing.assert_array_equal(py["time_ms"].to_numpy(), rust["time_ms"].astype(np.int64))
    np.testing.assert_array_equal(py["t"].to_numpy(), rust["t"].astype(np.float64))
    for c in TEXT:
        assert list(py[c]) == list(rust[c]), c
    for c in NUMBERS:
        # The Rust file writes each f32 in its shortest round-trip form: equal as f32
        # bits (NaN where the cell is empty).
        np.testing.assert_array_equal(py[c].to_numpy().astype(np.float32), f32_bits(rust[c]),
                                      err_msg=c)


def assert_same_thresholds(py: pd.DataFrame, rust: pd.DataFrame):
    assert list(py.columns) == list(rust.columns)
    assert len(py) == len(rust) > 0
    for c in rust.columns:
        want = np.array([float(x) if x != "" else np.nan for x in rust[c]])
        np.testing.assert_array_equal(py[c].to_numpy(), want, err_msg=c)


@pytest.mark.parametrize("model", ["f32", "fixed"])
def test_builtin_scenario_as_the_rust_replay(tmp_path, model):
    rust_events, rust_thresholds = rust_monitor(tmp_path, "--model", model)
    s = misalign.scenario()
    r = misalign.replay(s["t"], s["P"], s["phi"], V=s["V"], F=s["F"], model=model,
                        progress=True, chunk=5000)
    assert_same_events(r.events, rust_events)
    assert_same_thresholds(misalign.thresholds(s["P"], model=model), rust_thresholds)
    assert r.summary["samples"] == len(s)
    assert set(r.states["state"]) == set(misalign.STATES)
    assert r.states["time_s"].sum() > 0 and r.summary["final_state"] in misalign.STATES


def test_recorded_trace_as_the_rust_replay(tmp_path):
    n = 4000
    t = np.arange(n, dtype=float)
    t[1500] = t[1499]          # a repeated timestamp
    t[2500:] -= 30.0           # time goes backwards once
    rng = np.random.default_rng(7)
    P = 2500 + 800 * np.sin(t / 300) + 20 * rng.standard_normal(n)
    phi = 1e-4 + 6e-4 * np.arange(n) / n + 3e-6 * rng.standard_normal(n)
    P[100] = np.nan            # a non-finite load: a counted fault
    V = np.where(np.arange(n) % 50 == 0, np.nan, 2.0)   # not measured there
    F = np.where(np.arange(n) % 3 == 0, 0.3 * P * 0.5, np.nan)
    trace = pd.DataFrame({"t": t, "P": P, "phi": phi, "V": V, "F": F})
    path = tmp_path / "trace.csv"
    # Empty cells for "not measured"; Rust reads NaN in P as a number that is not finite.
    trace.to_csv(path, index=False, na_rep="", float_format="%.17g")
    text = path.read_text().splitlines()
    head, rows = text[0], text[1:]
    rows[100] = rows[100].replace(",,", ",NaN,", 1)
    path.write_text("\n".join([head] + rows) + "\n")
    rust_events, rust_thresholds = rust_monitor(tmp_path, "--trace", str(path))
    back = pd.read_csv(path)
    r = misalign.replay(back["t"], back["P"], back["phi"], V=back["V"], F=back["F"])
    assert_same_events(r.events, rust_events)
    assert_same_thresholds(misalign.thresholds(back["P"]), rust_thresholds)
    assert r.summary["faults"]["time_backwards"] >= 1
    assert r.summary["repeated_timestamps"] >= 1
    assert r.summary["friction"] is not None  # mu tracked from the measured F
