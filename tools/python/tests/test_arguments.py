"""Arguments: a bad option or setting is a ValueError naming it, never a row blamed
for it, another exception type, or a value changed without a word; one rule for
every container of numbers; one meaning of model="fixed" across the tools."""

import subprocess
import warnings

import numpy as np
import pandas as pd
import pytest

import misalign
from conftest import ROOT

SCENE = (0.05, 0.05, 79.3e9, 0.3, 0.3)
T, P, PHI = [0.0, 1.0, 2.0], [2e3] * 3, [2e-4] * 3


@pytest.mark.parametrize("name", ["load_lsb", "angle_lsb"])
@pytest.mark.parametrize("bad", [0, 0.0, -1, -1e-3, np.nan, np.inf, -np.inf, 1e-300, 1e300,
                                 "0.01", None.__class__, True, [0.01], 1j])
def test_an_adcs_bad_lsb_is_a_value_error_naming_it(name, bad):
    with pytest.raises(ValueError, match=name):
        misalign.estimate(*SCENE, [1e3, 2e3], 2e-4, model="fixed", counts="adc", **{name: bad})


def test_an_angle_lsb_finer_than_the_tables_is_named_for_its_scene():
    with pytest.raises(ValueError, match=r"angle_lsb = 1e-14 rad.*at least"):
        misalign.estimate(*SCENE, [1e3, 2e3], 2e-4, model="fixed", counts="adc",
                          angle_lsb=1e-14)
    # A scene per row: the row whose scene refuses it is named.
    R1 = np.array([0.05, 0.05, 1e-9])
    with pytest.raises(ValueError, match=r"angle_lsb .* row 2"):
        misalign.estimate(R1, 0.05, 79.3e9, 0.3, 0.3, 1e3, 2e-4, model="fixed", counts="adc",
                          angle_lsb=1e-12)
    # Fine LSBs: a bad row is still that row's error.
    r = misalign.estimate(*SCENE, [1e3, -1.0], 2e-4, model="fixed", counts="adc",
                          angle_lsb=1e-8, load_lsb=0.5)
    assert r["error"][0] == "" and "load" in r["error"][1]


def test_lsbs_belong_to_the_adc():
    for kwargs in [{"load_lsb": 0.01}, {"angle_lsb": 1e-8}, {"load_lsb": 0.01, "model": "f32"}]:
        kwargs = {"model": "fixed", **kwargs}
        with pytest.raises(ValueError, match="lsb.*counts='adc'"):
            misalign.estimate(*SCENE, 1e3, 2e-4, **kwargs)
    with pytest.raises(ValueError, match="counts"):
        misalign.estimate(*SCENE, 1e3, 2e-4, model="fixed", counts="node")


@pytest.mark.parametrize("bad", [
    np.array(["1"] * 7, dtype=object), np.array(["1"] * 7), np.array([b"1"] * 7),
    np.array([1.0, "2"], dtype=object), np.array([1.0, None], dtype=object),
    np.array([True, False]), np.array([1.0, True], dtype=object),
    np.array([1.0, np.True_], dtype=object), np.array([1 + 0j], dtype=object),
    ["1", "2"], [1.0, "2"], pd.Series(["1", "2"], dtype=object), pd.Series(["1", "2"]),
    np.array([1.0, [2.0]], dtype=object), np.array([1.0, {}], dtype=object),
])
def test_strings_bools_and_objects_are_refused_in_any_container(bad):
    with pytest.raises(ValueError, match="P"):
        misalign.estimate(*SCENE, bad, 2e-4)
    with pytest.raises(ValueError, match="P"):
        misalign.replay(np.arange(float(len(bad))), bad, 2e-4)


def test_numbers_are_taken_in_any_container():
    want = misalign.estimate(*SCENE, np.array([1e3, 2e3]), 2e-4)["s"]
    from fractions import Fraction
    for good in [np.array([1000, 2000.0], dtype=object), [1000, 2000.0],
                 np.array([np.float32(1000), np.int16(2000)], dtype=object),
                 np.array([Fraction(1000), 2000], dtype=object), pd.Series([1000, 2000]),
                 (1000, 2000)]:
        np.testing.assert_array_equal(misalign.estimate(*SCENE, good, 2e-4)["s"], want)


@pytest.mark.parametrize("field", ["on_delay_ms", "off_delay_ms", "fault_delay_ms",
                                   "inhibit_ms", "stuck_ms", "gap_ms"])
@pytest.mark.parametrize("bad", [-5, 2**40, 2**32, None, 1.5, 5.0, "5", True, np.nan, [5]])
def test_a_bad_time_setting_is_a_value_error_naming_it(field, bad):
    for call in (lambda c: misalign.replay(T, P, PHI, config=c),
                 lambda c: misalign.thresholds(load_max=3e3, config=c)):
        with pytest.raises(ValueError, match=field):
            call({field: bad})


@pytest.mark.parametrize("field", ["warning", "alarm", "deadband", "stop_load", "stop_speed",
                                   "nominal_speed", "load_min", "load_max", "angle_max",
                                   "speed_max", "force_max", "smoothing_tau_s"])
@pytest.mark.parametrize("bad", [None, "0.5", True, np.nan, np.inf, -np.inf, 1e300, 10**400,
                                 [0.5], 1j])
def test_a_bad_number_setting_is_a_value_error_naming_it(field, bad):
    with pytest.raises(ValueError, match=field):
        misalign.replay(T, P, PHI, config={field: bad})


@pytest.mark.parametrize("field", ["spikes", "trend", "friction"])
@pytest.mark.parametrize("bad", [0, 1, None, "False", 0.0, [False]])
def test_a_bad_switch_is_a_value_error_naming_it(field, bad):
    with pytest.raises(ValueError, match=field):
        misalign.replay(T, P, PHI, config={field: bad})


def test_good_settings_are_taken():
    r = misalign.replay(T, P, PHI, config={"on_delay_ms": np.uint32(5), "warning": np.float32(0.4),
                                           "spikes": np.False_, "trend": False,
                                           "thresholds": "slip_ratio", "gap_ms": 0})
    assert r.summary["samples"] == 3


@pytest.mark.parametrize("config", [5, "on_delay_ms=5", [("on_delay_ms", 5)], {1: 5},
                                    {"thresholds": 1}, {"thresholds": "slip"}])
def test_a_bad_config_is_a_value_error(config):
    with pytest.raises(ValueError, match="config"):
        misalign.replay(T, P, PHI, config=config)


@pytest.mark.parametrize("kwargs, name", [
    ({"scene": (0.05, 0.05, "x", 0.3, 0.3)}, "G"), ({"scene": 5}, "scene"),
    ({"scene": (0.05, 0.05)}, "scene"), ({"scene": "abcde"}, "scene"),
    ({"scene": (0.05, 0.05, 79.3e9, 0.3, None)}, "mu"), ({"length": "x"}, "length"),
    ({"length": [0.1]}, "length"), ({"chunk": 0}, "chunk"), ({"chunk": "5"}, "chunk"),
    ({"chunk": 2.5}, "chunk"), ({"chunk": True}, "chunk"), ({"progress": "yes"}, "progress"),
    ({"model": None}, "model"), ({"model": ["f32"]}, "model"),
])
def test_a_bad_replay_option_is_a_value_error_naming_it(kwargs, name):
    with pytest.raises(ValueError, match=name):
        misalign.replay(T, P, PHI, **kwargs)


@pytest.mark.parametrize("kwargs, name", [
    ({"details": "yes"}, "details"), ({"threads": 1}, "threads"), ({"model": 5}, "model"),
    ({"contact": None}, "contact"), ({"counts": 0}, "counts"),
])
def test_a_bad_estimate_option_is_a_value_error_naming_it(kwargs, name):
    with pytest.raises(ValueError, match=name):
        misalign.estimate(*SCENE, 1e3, 2e-4, **kwargs)


@pytest.mark.parametrize("kwargs", [
    {"load_max": 50}, {"load_max": 1e-30}, {"load_max": 100}, {"load_max": -100},
    {"P": []}, {"P": [np.nan]}, {"P": [-100]}, {"P": [50.0] * 100}, {"load_max": 1e6},
    {"load_max": np.nan}, {"load_max": np.inf}, {"load_max": "3000"}, {"P": ["3000"]},
    {"P": [3e3], "load_max": 3e3},
])
def test_the_planner_refuses_a_range_it_cannot_honour(kwargs):
    with pytest.raises(ValueError, match="stop load|load_max|finite load|P"):
        misalign.thresholds(**kwargs)


def test_the_planner_says_what_it_changed():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table = misalign.thresholds(load_max=3e3)
    assert table.attrs == {"load_max": 3e3, "note": None}
    assert table["P"].iloc[0] > 100.0 and table["P"].iloc[-1] == 3e3
    with pytest.warns(UserWarning, match="load_max, 50000 N"):
        table = misalign.thresholds([4.9e4] * 100)
    assert table.attrs["load_max"] == 5e4 and table["P"].iloc[-1] == 5e4
    assert "50000 N" in table.attrs["note"]


def estimate_example(csv_text, *args):
    out = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "--example", "estimate", "--", *args],
        cwd=ROOT, input=csv_text, capture_output=True, text=True, check=True,
    ).stdout
    return pd.read_csv(__import__("io").StringIO(out))


def test_fixed_means_the_same_in_the_package_and_the_csv_tool():
    # Small loads and angles, where an ADC's counts are few.
    rng = np.random.default_rng(3)
    n = 60
    P = np.exp(rng.uniform(np.log(0.1), np.log(2e4), n))
    phi = np.exp(rng.uniform(np.log(1.1e-7), np.log(2e-3), n)) * rng.choice([-1.0, 1.0], n)
    R1 = rng.uniform(0.02, 0.1, n)
    P[:3], phi[:3] = [0.104, 0.1, 2e3], [3.3e-4, 1.1e-7, 1.13e-7]
    df = pd.DataFrame({"R1": R1, "R2": 0.05, "G": 79.3e9, "nu": 0.3, "mu": 0.3, "P": P,
                       "phi": phi})
    ref = misalign.estimate(R1, 0.05, 79.3e9, 0.3, 0.3, P, phi)
    for counts, args in [("exact", []), ("adc", ["--counts", "adc"]),
                         ("adc", ["--counts", "adc", "--load-lsb", "0.5",
                                  "--angle-lsb", "1e-8"])]:
        lsb = {"load_lsb": 0.5, "angle_lsb": 1e-8} if "--load-lsb" in args else {}
        kw = {} if counts == "exact" else {"counts": counts, **lsb}
        tool = estimate_example(df.to_csv(index=False), "--model", "fixed", *args)
        ours = misalign.estimate(R1, 0.05, 79.3e9, 0.3, 0.3, P, phi, model="fixed", **kw)
        ok = tool["error"].isna().to_numpy()
        assert ((ours["error"] == "") == ok).all(), (args, tool["error"][~ok])
        for c in ["s", "F", "phi0"]:
            np.testing.assert_array_equal(ours[c][ok], tool[c].to_numpy()[ok], err_msg=f"{args} {c}")
        if counts == "exact":
            for c in ["s", "F", "phi0"]:
                e = np.abs(ours[c] / ref[c] - 1.0)
                assert np.nanmax(e) < 1e-5, c
    # The ADC's rounding shows at 0.104 N (10 counts of 10 mN).
    adc = misalign.estimate(R1[:1], 0.05, 79.3e9, 0.3, 0.3, 0.104, 3.3e-4, model="fixed",
                            counts="adc")
    assert abs(adc["s"][0] / ref["s"][0] - 1.0) > 1e-2
