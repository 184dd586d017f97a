"""A fleet of rollers: the condition monitor over each roller's recorded history, as a
function of one pandas DataFrame that Dask (``map_partitions``) or Spark
(``mapInPandas``, ``applyInPandas``) calls per partition, and a synthetic fleet to
try it on.

A history is a table with the columns ``roller`` (its name), ``t`` (s), ``P`` (N),
``phi`` (rad) and optionally ``V`` (m/s) and ``F`` (N), NaN meaning "not measured";
each roller's rows in time order, all in one partition (one Parquet file per roller
does it).
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from . import STATES, replay

#: The columns of :func:`roller_summary`'s answer, in order.
COLUMNS = (
    ["roller", "samples"]
    + [f"time_{s}_s" for s in STATES]
    + [f"energy_{s}_J" for s in STATES]
    + ["warnings", "alarms", "faults", "worst_margin_rad", "max_slip_ratio", "final_state"]
)


def meta():
    """An empty DataFrame with :func:`roller_summary`'s columns and dtypes (Dask's
    ``meta``)."""
    import pandas as pd

    dtypes = {"roller": "object", "samples": "int64", "warnings": "int64", "alarms": "int64",
              "faults": "int64", "final_state": "object"}
    return pd.DataFrame({c: pd.Series(dtype=dtypes.get(c, "float64")) for c in COLUMNS})


def roller_summary(pdf, *, scene=None, length=None, model: str = "f32",
                   config: Optional[dict] = None):
    """Per roller of ``pdf``: samples, time (s) and energy (J, the microslip's F phi V
    of section 7) in each monitor state, the number of warnings (entries into
    microslip), alarms (entries into gross slip) and sensor faults, the worst (least)
    margin to the critical angle (rad; NaN if never computed), the largest d/b and the
    final state. Scene, length, model and config as :func:`misalign.replay`."""
    import pandas as pd

    rows = []
    names = pdf["roller"].to_numpy()
    # One roller per partition (one Parquet file per roller): no grouping needed.
    one = len(names) > 0 and bool((names == names[0]).all())
    groups = [(names[0], pdf)] if one else pdf.groupby("roller", sort=False)
    for roller, g in groups:
        get = lambda c: g[c].to_numpy() if c in g else None  # noqa: E731
        r = replay(get("t"), get("P"), get("phi"), V=get("V"), F=get("F"), scene=scene,
                   length=length, model=model, config=config)
        ev = r.events
        entered = ev["state"][ev["kind"] == "state"] if len(ev) else pd.Series(dtype=object)
        margin = r.summary["min_margin_rad"]
        rows.append(
            [roller, int(r.summary["samples"])]
            + list(r.states["time_s"])
            + list(r.states["energy_J"])
            + [int((entered == "microslip").sum()), int((entered == "gross_slip").sum()),
               int((entered == "sensor_fault").sum()),
               np.nan if margin is None else float(margin),
               float(r.summary["max_slip_ratio"]), r.summary["final_state"]]
        )
    if not rows:
        return meta()
    return pd.DataFrame(rows, columns=COLUMNS).astype(meta().dtypes.to_dict())


def synthetic(rollers: int, hours: float, *, seed: int = 1, period_s: float = 1.0):
    """A synthetic fleet: ``rollers`` roller pairs of the built-in scenario's steel
    rollers, ``hours`` of samples every ``period_s`` s each, as a dict roller name ->
    DataFrame (t, P, phi, V). Each roller has its own load cycle and noise; every third
    one drifts through its critical angle (about 0.4 mrad at 2.5 kN), the others stay
    aligned; some have a dropout and a stop."""
    import pandas as pd

    rng = np.random.default_rng(seed)
    n = int(hours * 3600 / period_s)
    t = np.arange(n) * period_s
    fleet = {}
    for k in range(rollers):
        name = f"R{k:04d}"
        base = rng.uniform(1500.0, 3500.0)
        cycle = rng.uniform(300.0, 3000.0)
        load = base * (1 + 0.25 * np.sin(2 * np.pi * t / cycle)) * (1 + 0.01 * rng.standard_normal(n))
        start = rng.uniform(0.5e-4, 2e-4)
        end = rng.uniform(6e-4, 9e-4) if k % 3 == 0 else start * rng.uniform(1.0, 1.5)
        phi = start + (end - start) * t / max(t[-1], 1.0) + 3e-6 * rng.standard_normal(n)
        speed = 2.0 * (1 + 0.01 * rng.standard_normal(n))
        if k % 4 == 1 and n > 100:  # a stop of 1/20 of the history
            a = n // 2
            stop = slice(a, a + n // 20)
            load[stop] = 20.0 * rng.standard_normal(len(load[stop]))
            speed[stop] = 0.0
        frame = pd.DataFrame({"roller": name, "t": t, "P": load, "phi": phi, "V": speed})
        if k % 5 == 2 and n > 100:  # a dropout of 3 minutes
            frame = frame.drop(frame.index[n // 3: n // 3 + int(180 / period_s)])
        fleet[name] = frame.reset_index(drop=True)
    return fleet


def write_parquet(fleet: dict, directory) -> int:
    """Writes each roller of ``fleet`` as one Parquet file (one row group) under
    ``directory``; returns the number of samples."""
    import pathlib

    d = pathlib.Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    total = 0
    for name, frame in fleet.items():
        frame.to_parquet(d / f"{name}.parquet", index=False, row_group_size=max(len(frame), 1))
        total += len(frame)
    return total


def run_dask(directory, client=None, **kwargs):
    """The per-roller summary of the Parquet fleet under ``directory`` on Dask: one
    partition per file (one roller), :func:`roller_summary` per partition. Uses the
    given ``distributed.Client`` (or Dask's default scheduler). Keyword arguments go to
    :func:`roller_summary`."""
    import dask.dataframe as dd

    df = dd.read_parquet(str(directory), split_row_groups=False)
    out = df.map_partitions(roller_summary, meta=meta(), **kwargs)
    result = client.compute(out).result() if client is not None else out.compute()
    return result.sort_values("roller").reset_index(drop=True)
