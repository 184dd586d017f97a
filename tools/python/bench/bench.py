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
#: Targets: rows/s as a multiple of the peer's on the same workload, and the fleet's
#: samples/s.
TARGETS = {("one", "reference"): 20.0, ("one", "f32"): 50.0,
           ("rows", "reference"): 10.0, ("rows", "f32"): 10.0}
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


def installations(n, seed=4):
    """A table of installations, one a row: R1, R2 uniform in [20, 100] mm, G uniform
    in [70, 85] GPa (steels), mu uniform in [0.1, 0.5]; nu = 0.3."""
    rng = np.random.default_rng(seed)
    return (rng.uniform(0.02, 0.1, n), rng.uniform(0.02, 0.1, n),
            rng.uniform(70e9, 85e9, n), 0.3, rng.uniform(0.1, 0.5, n))


def peer_floor(P, phi, repeat):
    """What the peer cannot avoid: ns per row of one K, E pair of scipy
    (``ellipkm1`` and ``ellipe``) at the rows' k'^2, on one core; the peer takes two a
    row (one Newton step for k', one for theta0)."""
    from scipy.special import ellipe, ellipkm1

    theta = np.abs(phi)
    p = (theta / (2.0 * np.sqrt(np.log(8.0 / theta)))) ** 2
    t, _ = best(lambda: (ellipkm1(p), ellipe(1.0 - p)), repeat)
    return t * 1e9 / len(P)


def _cpu_flags():
    """The CPU's feature flags (Linux), empty elsewhere."""
    try:
        text = pathlib.Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    return {f for line in text.splitlines() if line.startswith("flags")
            for f in line.split(":", 1)[1].split()}


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
    scenes = {"one": SCENE, "rows": installations(args.rows)}
    models = {
        "one": [("reference", {}), ("reference, one thread", {"threads": False}),
                ("f32", {"model": "f32"}), ("fixed", {"model": "fixed"}),
                ("fixed, counts='adc'", {"model": "fixed", "counts": "adc"})],
        "rows": [("reference", {}), ("f32", {"model": "f32"}), ("fixed", {"model": "fixed"})],
    }
    speed, err_rows = {}, {}
    for work, scene in scenes.items():
        with np.errstate(all="ignore"):
            t, (ps, pf, pp) = best(lambda: peer.forward(*scene, P, phi), args.repeat)
        speed[work, "peer"] = args.rows / t
        results = {}
        for label, kwargs in models[work]:
            t, r = best(lambda: misalign.estimate(*scene, P, phi, **kwargs), args.repeat)
            speed[work, label] = args.rows / t
            results[label] = r
        ref = results["reference"]
        assert (ref["error"] == "").all()
        others = [("peer", {"s": ps, "F": pf, "phi0": pp})] + [
            (label, r) for label, r in results.items() if not label.startswith("reference")]
        for label, got in others:
            err_rows[work, label] = {k: rel(got[k], ref[k]) for k in ["s", "F", "phi0"]}
        del results, ref, others
    floor = peer_floor(P, phi, args.repeat)
    err_digits, digit_rows = accuracy_50_digit()
    k = min(args.rows, 200_000)
    costs = [misalign._misalign.reference_cost(P[:k], phi[:k]) for _ in range(args.repeat)]
    cost = {key: min(c[key] for c in costs) for key in costs[0]}  # each the best of repeat
    cost["peer_pair"] = floor
    cost["avx2"] = "avx2" in _cpu_flags()
    samples, fleet_s, startup, summary = fleet_speed(args.fleet_rollers, args.fleet_hours,
                                                     max(1, args.repeat - 1))
    fleet_rate = samples / fleet_s

    failed = [f"{m}: {k} {e:.2e} > {BOUNDS[m]:.0e}" for m, errs in err_digits.items()
              for k, e in errs.items() if e > BOUNDS[m]]
    failed += [f"peer on the {work} rows: {k} {e:.2e} > {BOUNDS['peer']:.0e}"
               for (work, label), errs in err_rows.items() if label == "peer"
               for k, e in errs.items() if e > BOUNDS["peer"]]
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
        f"machine slows both sides, the package's two threads the more; the ratios are "
        f"from the same run), numpy {np.__version__}, Python {platform.python_version()}.",
        "",
        f"**Forward model, {args.rows:,} rows**, P log-uniform in [200, 2e4] N, phi "
        "log-uniform in [2e-5, 2e-3] rad with random sign, in two workloads: *one scene* "
        "(steel rollers R1 = R2 = 50 mm, G = 79.3 GPa, nu = 0.3, mu = 0.3) and *a scene per "
        "row* (a table of installations: R1, R2 uniform in [20, 100] mm, G in [70, 85] GPa, "
        "mu in [0.1, 0.5], nu = 0.3, each row its own). Best of "
        f"{args.repeat}, wall clock, from numpy arrays in to numpy arrays out. The peer "
        "(`tools/python/bench/peer.py`) is numpy + scipy on one core as numpy runs it; the "
        "package computes its rows over both cores unless said. `fixed` is the fixed-point "
        "core with exact counts (the default), `counts='adc'` a node's ADC (10 mN, the "
        "finest angle). Error: the largest relative error of d/b / F / phi0 against the "
        f"50-digit values ({digit_rows} rows of tests/data/vectors_scene.csv), and on the "
        "benchmark's rows against the package's reference.",
        "",
        "| workload | implementation | rows/s | x peer | target | error vs 50-digit "
        "(s / F / phi0) | error vs reference, bench rows |",
        "|---|---|---:|---:|---:|---|---|",
    ]
    names = {"one": "one scene", "rows": "a scene per row"}
    for work, label in speed:
        base = label.split(",")[0]
        target = TARGETS.get((work, label))
        ratio = speed[work, label] / speed[work, "peer"]
        met = "" if target is None else (
            f"{target:.0f}x {'met' if ratio >= target else 'NOT met'}")
        digits = (e3(err_digits[base]) if work == "one" and base in err_digits
                  and label == base else "")
        vs_ref = (e3(err_rows[work, label]) if (work, label) in err_rows
                  else ("0 (itself)" if label == "reference" else ""))
        out.append(f"| {names[work]} | {label} | {speed[work, label]:,.0f} | {ratio:.1f} | "
                   f"{met} | {digits} | {vs_ref} |")
    peer_ns = 1e9 / speed["one", "peer"]
    out += [
        "",
        "**How the peer was checked.** Its error is in the table: within "
        f"{max(err_digits['peer'].values()):.0e} of the 50-digit values (asserted below "
        f"{BOUNDS['peer']:.0e}). Its speed: a row costs it {peer_ns:.0f} ns on one core, of "
        f"which the two pairs of scipy's `ellipkm1` and `ellipe` it needs (one Newton step "
        f"for k', one for theta0, each pair {cost['peer_pair']:.0f} ns a row here) take "
        f"{2 * cost['peer_pair']:.0f} ns: the rest (seeds, logarithms, the closed forms) "
        "cannot be made much cheaper in numpy. It is written for speed (its docstring: rows "
        "in cache-sized chunks, one K, E pair a step with their derivatives from them, seeds "
        "from the series of K and E to second order in k'^2, good to 1e-10, so that one step "
        "reaches rounding, the answer taken to first order in that step instead of another "
        "pair; tools/python/tests/test_peer.py holds its answers to Newton's method iterated "
        "to rounding over every angle); with first-order seeds it needed two pairs a solve, "
        "and the textbook form, a Newton loop to a tolerance then one more step and one "
        "more pair, takes six or more pairs a row.",
        "",
        f"**Where the package's time goes** (one thread, the first {cost_rows:,} of these "
        f"rows, ns per row, each the best of {args.repeat}, "
        "`misalign._misalign.reference_cost`): the reference's ellipse shape "
        f"(k', m, n from theta, eqs 4-6) {cost['ellipse_shape']:.0f}, its critical angle "
        f"(phi0 at the load, eqs 18, 30) {cost['critical_angle']:.0f}, its whole elliptic "
        f"solution {cost['elliptic']:.0f}; `reference::fast`, which answers the batch's rows "
        f"where it can to the same digits, {cost['fast_estimate']:.0f} a row called row by "
        f"row and {cost['batch']:.0f} in the batch with its columns, sixteen rows at a time "
        f"({'AVX2' if cost['avx2'] else 'SSE2'} lanes: the package takes its AVX2 build where "
        f"the CPU has it, the same bits); the f32 core {cost['f32_core']:.0f} called row by "
        f"row, {cost['f32_batch']:.0f} in the batch with its columns. A scene per row forms "
        "each row's constants in the same lanes instead of a preparation a row (which would "
        f"cost `reference::fast::Prepared::new` {cost['prepare_fast']:.0f}, the f32 core's "
        f"`Auto::new` {cost['prepare_f32']:.0f}): the batch with the scene given on every row "
        f"{cost['batch_rows']:.0f} (reference), {cost['f32_batch_rows']:.0f} (f32). "
        "A target of N x the peer on two cores asks for at most "
        f"2 x {peer_ns:.0f} / N ns a row on each: {2 * peer_ns / 20:.0f} ns for 20x, "
        f"{2 * peer_ns / 50:.0f} for 50x, {2 * peer_ns / 10:.0f} for 10x.",
        "",
        f"**Fleet**: {rollers} rollers, {samples:,} samples (`misalign.fleet.synthetic"
        f"({args.fleet_rollers}, {args.fleet_hours:g})`, one Parquet file per roller), "
        "`misalign.fleet.run_dask` on a `distributed.LocalCluster` of 2 worker processes "
        "with one thread each: read Parquet, the monitor (f32 core) over every sample, the "
        f"per-roller summary back in the client (best of {max(1, args.repeat - 1)} after a "
        f"warm-up run in which the workers import the modules): {fleet_s:.2f} s, "
        f"**{fleet_rate:,.0f} samples/s** end to end (target {FLEET_TARGET:,.0f}: "
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
