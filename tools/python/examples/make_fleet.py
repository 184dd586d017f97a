"""Writes a synthetic fleet as Parquet, one file per roller (misalign.fleet.synthetic):

    python tools/python/examples/make_fleet.py --rollers 24 --hours 72 --out fleet-data
"""

import argparse

from misalign import fleet


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rollers", type=int, default=24)
    ap.add_argument("--hours", type=float, default=72.0, help="history per roller (h)")
    ap.add_argument("--period", type=float, default=1.0, help="sample period (s)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="fleet-data")
    args = ap.parse_args()
    rollers = fleet.synthetic(args.rollers, args.hours, seed=args.seed, period_s=args.period)
    n = fleet.write_parquet(rollers, args.out)
    print(f"wrote {len(rollers)} rollers, {n} samples under {args.out}/")


if __name__ == "__main__":
    main()
