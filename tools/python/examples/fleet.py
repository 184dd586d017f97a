"""The condition monitor over a fleet's histories on Dask: a Parquet dataset with one
file per roller (columns roller, t in s, P in N, phi in rad, optional V in m/s and F
in N), one partition per roller, misalign.fleet.roller_summary per partition, on a
distributed.LocalCluster with both cores. Prints per roller the time and energy per
state, the warnings and alarms and the worst margin.

    python tools/python/examples/make_fleet.py --rollers 24 --hours 72 --out fleet-data
    python tools/python/examples/fleet.py fleet-data

The same function runs as a Spark UDF (docs/python.md, "Fleet").
"""

import argparse
import time

import distributed
import pandas as pd

from misalign import fleet


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("data", help="directory of Parquet files, one per roller")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--model", choices=["f32", "fixed"], default="f32")
    args = ap.parse_args()
    with distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1,
                                  processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        t0 = time.perf_counter()
        summary = fleet.run_dask(args.data, client=client, model=args.model)
        seconds = time.perf_counter() - t0
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        hours = summary[[f"time_{s}_s" for s in ("normal", "microslip", "gross_slip")]] / 3600
        hours.columns = ["normal h", "microslip h", "gross slip h"]
        table = pd.concat([summary[["roller"]], hours.round(2),
                           summary[["energy_microslip_J", "energy_gross_slip_J", "warnings",
                                    "alarms", "faults", "worst_margin_rad", "final_state"]]],
                          axis=1)
        print(table.to_string(index=False))
    samples = int(summary["samples"].sum())
    print(f"\n{len(summary)} rollers, {samples} samples in {seconds:.2f} s: "
          f"{samples / seconds:,.0f} samples/s (cluster start not included)")


if __name__ == "__main__":
    main()
