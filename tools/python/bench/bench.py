"""The package against its numpy + scipy peer, in one run on the same rows, and the
fleet on Dask from Parquet; writes docs/measurements-python.md (between its markers).

    python tools/python/bench/bench.py                 # 1e6 rows, the fleet; writes the page
    python tools/python/bench/bench.py --check --rows 200000 --fleet-rollers 4 --fleet-hours 6
                                                 # a short pass: accuracy asserted, no page

Speeds are the best of ``--repeat`` runs (wall clock; the package on both cores, the
peer on one, as numpy runs it). Accuracy: each implementation against the 50-digit
values of tests/data/vectors_scene.csv (every row), and, on the benchmark's rows, the
peer and the cores against the package's reference.
"""

import argparse
import datetime
import os
import pathlib
import platform
import sys
import tempfile
import time

import numpy as np
import pandas as pd

import misalign
from misalign import fleet

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import peer  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[3]
PAGE = ROOT / "docs" / "measurements-python.md"
BEGIN, END = "<!-- python-bench:begin -->", "<!-- python-bench:end -->"
SCENE = (0.05, 0.05, 79.3e9, 0.3, 0.3)
#: Targets: rows/s as a multiple of the peer's, and the fleet's samples/s.
TARGETS = {"reference": 20.0, "f32": 50.0}
FLEET_TARGET = 2e6
#: Accuracy the page states and --check asserts (max relative error, 50-digit data).
BOUNDS = {"reference": 4e-15, "f32": 2e-6, "peer": 2e-14}


def rows(n, seed=1):
    """n samples of the demo scene's operating range: P log-uniform in [200, 2e4] N,
    phi log-uniform in [2e-5, 2e-3] rad, signed at random."""
    rng = np.random.default_rng(seed)
    P = np.exp(rng.uniform(np.log(200.0), np.log(2e4), n))
    phi = np.exp(rng.uniform(np.log(2e-5), np.log(2e-3), n)) * rng.choice([-1.0, 1.0], n)
    return P, phi


def best(f, repeat):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def rel(got, want):
    got, want = np.asarray(got, float), np.asarray(want, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.abs(got / want - 1.0)
    e[(got == want) | (np.isnan(got) & np.isnan(want))] = 0.0
    return float(np.nan_to_num(e, nan=np.inf).max())


def accuracy_50_digit():
    df = pd.read_csv(ROOT / "tests" / "data" / "vectors_scene.csv")
    cols = [df[c].to_numpy() for c in ["R1", "R2", "G", "nu", "mu", "P", "phi"]]
    with np.errstate(all="ignore"):
        ps, pf, pp = peer.forward(*cols)
    out = {"peer": {"s": ps, "F": pf, "phi0": pp}}
    for model in ["reference", "f32"]:
        r = misalign.estimate(*cols, model=model)
        out[model] = {k: r[k] for k in ["s", "F", "phi0"]}
    # The package answers no critical angle (NaN) where the data's phi0 passes pi/2
    # (eq 4 with unequal radii); the peer, written without that rule, its number.
    none = df["phi0"].to_numpy(dtype=float) > np.pi / 2
    ours = df["phi0"].to_numpy(dtype=float).copy()
    ours[none] = np.nan

    def want(m, k):
        return ours if (k == "phi0" and m != "peer") else df[k]

    errors = {m: {k: rel(v[k], want(m, k)) for k in ["s", "F", "phi0"]} for m, v in out.items()}
    return errors, len(df)


def fleet_speed(rollers, hours, repeat):
    import distributed

    with tempfile.TemporaryDirectory() as d:
        samples = fleet.write_parquet(fleet.synthetic(rollers, hours, seed=2), d)
        t0 = time.perf_counter()
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, \
                distributed.Client(cluster) as client:
            startup = time.perf_counter() - t0
            fleet.run_dask(d, client=client)  # warm-up: the workers import the modules
            seconds, result = best(lambda: fleet.run_dask(d, client=client), repeat)
    assert int(result["samples"].sum()) == samples
    return samples, seconds, startup, result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--fleet-rollers", type=int, default=24)
    ap.add_argument("--fleet-hours", type=float, default=72.0)
    ap.add_argument("--check", action="store_true",
                    help="assert the accuracy bounds and print the figures; write no page")
    args = ap.parse_args()
    load = os.getloadavg()[0]

    P, phi = rows(args.rows)
    speed, err_rows = {}, {}
    with np.errstate(all="ignore"):
        t, (ps, pf, pp) = best(lambda: peer.forward(*SCENE, P, phi), args.repeat)
    speed["peer"] = args.rows / t
    results = {}
    for label, kwargs in [("reference", {}), ("reference, one thread", {"threads": False}),
                          ("f32", {"model": "f32"}), ("fixed", {"model": "fixed"})]:
        t, r = best(lambda: misalign.estimate(*SCENE, P, phi, **kwargs), args.repeat)
        speed[label] = args.rows / t
        results[label] = r
    ref = results["reference"]
    assert (ref["error"] == "").all()
    for label, got in [("peer", {"s": ps, "F": pf, "phi0": pp})] + [
            (m, results[m]) for m in ["f32", "fixed"]]:
        err_rows[label] = {k: rel(got[k], ref[k]) for k in ["s", "F", "phi0"]}
    err_digits, digit_rows = accuracy_50_digit()
    k = min(args.rows, 200_000)
    costs = [misalign._misalign.reference_cost(P[:k], phi[:k]) for _ in range(args.repeat)]
    cost = {key: min(c[key] for c in costs) for key in costs[0]}  # each the best of repeat
    samples, fleet_s, startup, summary = fleet_speed(args.fleet_rollers, args.fleet_hours,
                                                     max(1, args.repeat - 1))
    fleet_rate = samples / fleet_s

    failed = [f"{m}: {k} {e:.2e} > {BOUNDS[m]:.0e}" for m, errs in err_digits.items()
              for k, e in errs.items() if e > BOUNDS[m]]
    lines = page(args, load, speed, err_digits, digit_rows, err_rows, samples, fleet_s,
                 startup, fleet_rate, len(summary), cost, k)
    print("\n".join(lines))
    if failed:
        print("accuracy bound exceeded: " + "; ".join(failed), file=sys.stderr)
        return 1
    if not args.check:
        write(lines)
        print(f"wrote {PAGE.relative_to(ROOT)}", file=sys.stderr)
    return 0


def page(args, load, speed, err_digits, digit_rows, err_rows, samples, fleet_s, startup,
         fleet_rate, rollers, cost, cost_rows):
    e3 = lambda e: "{:.1e} / {:.1e} / {:.1e}".format(e["s"], e["F"], e["phi0"])  # noqa: E731
    cmd = "python tools/python/bench/bench.py" + (
        "" if args.rows == 1_000_000 else f" --rows {args.rows}")
    out = [
        BEGIN,
        f"Written by `{cmd}` on {datetime.date.today().isoformat()}: {os.cpu_count()} cores "
        f"({platform.machine()}), load average {load:.1f} at the start (other work on the "
        f"machine slows both sides alike; the ratios are from the same run), "
        f"numpy {np.__version__}, Python {platform.python_version()}.",
        "",
        f"**Forward model, {args.rows:,} rows** of one scene (steel rollers R1 = R2 = 50 mm, "
        "G = 79.3 GPa, nu = 0.3, mu = 0.3), P log-uniform in [200, 2e4] N, phi log-uniform in "
        "[2e-5, 2e-3] rad with random sign; best of "
        f"{args.repeat}, wall clock, from numpy arrays in to numpy arrays out. The peer "
        "(`tools/python/bench/peer.py`) is numpy + scipy on one core as numpy runs it; the package "
        "computes its rows over both cores unless said. Error: the largest relative error "
        f"of d/b / F / phi0 against the 50-digit values ({digit_rows} rows of "
        "tests/data/vectors_scene.csv), and on the benchmark's rows against the package's "
        "reference.",
        "",
        "| implementation | rows/s | x peer | target | error vs 50-digit (s / F / phi0) "
        "| error vs reference, bench rows |",
        "|---|---:|---:|---:|---|---|",
    ]
    for label in ["peer", "reference", "reference, one thread", "f32", "fixed"]:
        base = label.split(",")[0]
        target = TARGETS.get(label)
        ratio = speed[label] / speed["peer"]
        met = "" if target is None else (
            f"{target:.0f}x {'met' if ratio >= target else 'NOT met'}")
        digits = e3(err_digits[base]) if base in err_digits and label == base else ""
        vs_ref = e3(err_rows[label]) if label in err_rows else ("0 (itself)" if label == "reference" else "")
        out.append(f"| {label} | {speed[label]:,.0f} | {ratio:.1f} | {met} | {digits} | {vs_ref} |")
    out += [
        "",
        f"**Where the reference's time goes** (one thread, the first {cost_rows:,} of these "
        f"rows, ns per row, each the best of {args.repeat}, "
        "`misalign._misalign.reference_cost`): the ellipse's shape "
        f"(k', m, n from theta, eqs 4-6) {cost['ellipse_shape']:.0f}, the critical angle "
        f"(phi0 at the load, eqs 18, 30) {cost['critical_angle']:.0f}, the whole elliptic "
        f"solution {cost['elliptic']:.0f}; `reference::fast`, which answers the batch's rows "
        f"where it can to the same digits, {cost['fast_estimate']:.0f} a row called row by "
        f"row and {cost['batch']:.0f} in the batch with its columns, eight rows at a time; "
        f"the peer's whole row takes {1e9 / speed['peer']:.0f} ns on one core. The f32 "
        f"core: {cost['f32_core']:.0f} ns per row called row by row, {cost['f32_batch']:.0f} "
        "in the batch with its columns (one thread).",
        "",
        f"**Fleet**: {rollers} rollers, {samples:,} samples (`misalign.fleet.synthetic"
        f"({args.fleet_rollers}, {args.fleet_hours:g})`, one Parquet file per roller), "
        "`misalign.fleet.run_dask` on a `distributed.LocalCluster` of 2 worker processes "
        "with one thread each: read Parquet, the monitor (f32 core) over every sample, the "
        f"per-roller summary back in the client (best of {max(1, args.repeat - 1)} after a warm-up run in which the workers import the modules): {fleet_s:.2f} s, **{fleet_rate:,.0f} "
        f"samples/s** end to end (target {FLEET_TARGET:,.0f}: "
        f"{'met' if fleet_rate >= FLEET_TARGET else 'NOT met'}); the cluster's start, "
        f"{startup:.1f} s, is not in it.",
        END,
    ]
    return out


def write(lines):
    text = PAGE.read_text() if PAGE.exists() else ""
    block = "\n".join(lines)
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        text = head + block + rest.split(END, 1)[1]
    else:
        text = text + ("\n" if text else "") + block + "\n"
    PAGE.write_text(text)


if __name__ == "__main__":
    sys.exit(main())
