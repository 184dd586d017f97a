"""The fleet on Dask: a small synthetic fleet as Parquet, one partition per roller,
the per-roller summary on a distributed.LocalCluster of two workers, the same as
the summary computed roller by roller in this process."""

import numpy as np
import pandas as pd
import pytest

import misalign
from misalign import fleet

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def small_fleet(tmp_path_factory):
    d = tmp_path_factory.mktemp("fleet")
    rollers = fleet.synthetic(6, 2.0, seed=3)
    samples = fleet.write_parquet(rollers, d)
    return d, rollers, samples


def test_fleet_on_a_local_cluster(small_fleet):
    directory, rollers, samples = small_fleet
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        got = fleet.run_dask(directory, client=client)
    assert list(got.columns) == fleet.COLUMNS
    assert list(got["roller"]) == sorted(rollers)
    assert got["samples"].sum() == samples
    want = pd.concat([fleet.roller_summary(f) for f in rollers.values()], ignore_index=True)
    pd.testing.assert_frame_equal(got, want.sort_values("roller").reset_index(drop=True))
    # Every third roller drifts through its critical angle: alarms and no margin left;
    # the aligned ones stay in normal with a positive margin.
    drifting = got["roller"].isin([f"R{k:04d}" for k in range(0, 6, 3)])
    assert (got.loc[drifting, "alarms"] >= 1).all()
    assert (got.loc[drifting, "worst_margin_rad"] <= 0).all()
    assert (got.loc[~drifting, "alarms"] == 0).all()
    assert (got.loc[~drifting, "worst_margin_rad"] > 0).all()
    # Time per state adds up to the history; energy only where the rollers run.
    times = got[[f"time_{s}_s" for s in misalign.STATES]].sum(axis=1)
    assert (times > 0.9 * 2 * 3600).all() and (times <= 2 * 3600).all()
    assert (got["energy_normal_J"] > 0).all() and (got["energy_stopped_J"] == 0).all()


def test_summary_of_a_partition_with_several_rollers(small_fleet):
    _, rollers, _ = small_fleet
    both = pd.concat([rollers["R0000"], rollers["R0001"]], ignore_index=True)
    got = fleet.roller_summary(both)
    want = pd.concat([fleet.roller_summary(rollers[r]) for r in ["R0000", "R0001"]],
                     ignore_index=True)
    pd.testing.assert_frame_equal(got, want)
    assert len(fleet.roller_summary(both.iloc[:0])) == 0
    assert np.isfinite(got["max_slip_ratio"]).all()
