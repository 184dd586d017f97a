"""The Raspberry Pi Pico node in its emulator (`cargo xtask pico` runs these against
lab/pico's harness): commissioning over the bus surviving a reset; each sensor
unplugged and stuck giving the sensor fault that names it; power cuts at sampled
points of a checkpoint, a commit and an acknowledgement (what the node answered is on
flash after the restart, nothing half-applied); the driver-enable pin right throughout.

The environment adds to conftest's: PICO_CONTROL (the harness's control port: one
command a line, one JSON answer), MODBUS_SCENE (a prepared scene for the node's core)
and PICO_CONFIG (tools/commission.py's --config file of the default configuration).
"""

import json
import os
import socket
import time

from conftest import UNIT, read_table, register_map
from master import Map, Master, u32_words
from test_config import code, commission, f32, get, write
from test_reset import ack_address, wait_serving

NONE = 0xFFFFFFFF
SENSOR_FAULT = 4


def harness(line):
    """One command to the harness; its JSON answer."""
    with socket.create_connection(("127.0.0.1", int(os.environ["PICO_CONTROL"])), timeout=30) as s:
        s.sendall((line + "\n").encode())
        answer = b""
        while not answer.endswith(b"\n"):
            chunk = s.recv(4096)
            if not chunk:
                break
            answer += chunk
    return json.loads(answer)


def inputs():
    return {r["name"]: r for r in register_map() if r["table"] == "input"}


def get_input(client, name):
    r = inputs()[name]
    n = 2 if r["type"] in ("u32", "f32") else 1
    w = read_table(client, "input", r["address"], n)
    return w[0] << 16 | w[1] if n == 2 else w[0]


def state(client):
    return get_input(client, "status") & 0xFF


FUNCTION_CHECK = 3


def category(client):
    """`status`'s NAMUR NE 107 category."""
    return get_input(client, "status") >> 8 & 0xF


def scene_commissioned(client):
    r = next(r for r in register_map() if r["table"] == "discrete" and r["name"] == "scene_commissioned")
    return read_table(client, "discrete", r["address"], 1)[0]


def wait_until(what, timeout_s=120):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            value = what()
        except Exception:  # noqa: BLE001 (a request lost: asked again)
            value = None
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError(f"not within {timeout_s} s: {what.__doc__}")


def boots():
    return harness("status")["boots"]


def restarted(client, before):
    """Waits until the node has restarted (the harness counts its boots) and serves."""
    wait_until(lambda: boots() > before)
    wait_serving(client)


def commissioned(client):
    scene = open(os.environ["MODBUS_SCENE"], "rb").read()
    status, out = commission(client, "--code", str(code()), "--prepared", os.environ["MODBUS_SCENE"],
                             "--config", os.environ["PICO_CONFIG"])
    assert status == 0, out
    assert get(client, "config_source") == 1
    assert get(client, "scene_active_crc") == int.from_bytes(scene[-4:], "little")
    return scene


def test_commissioning_over_the_bus_survives_a_reset(client):
    assert get(client, "config_source") == 0, "a fresh node runs the build's defaults"
    assert get_input(client, "samples") == 0, "an uncommissioned node monitors nothing"
    assert (category(client), scene_commissioned(client)) == (FUNCTION_CHECK, 0), "not commissioned"
    # The configuration alone does not commission it: the build's scene is no site's.
    status, out = commission(client, "--code", str(code()), "--config", os.environ["PICO_CONFIG"])
    assert status == 0, out
    assert get(client, "config_source") == 1
    at = harness("status")["ns"]
    wait_until(lambda: harness("status")["ns"] > at + 2e9)
    assert get_input(client, "samples") == 0, "no site's scene: nothing monitored"
    assert (category(client), scene_commissioned(client)) == (FUNCTION_CHECK, 0)
    scene = commissioned(client)
    assert scene_commissioned(client) == 1
    wait_until(lambda: get_input(client, "samples") > 20)
    assert category(client) != FUNCTION_CHECK, "commissioned and settled"
    before = boots()
    harness("reset")
    restarted(client, before)
    assert get(client, "config_source") == 1
    assert get(client, "scene_active_crc") == int.from_bytes(scene[-4:], "little")
    assert scene_commissioned(client) == 1, "kept through the reset"
    samples = get_input(client, "samples")
    assert samples > 0, "the monitor's checkpoint restored"
    wait_until(lambda: get_input(client, "samples") > samples + 10)


def latest_event(client):
    """The newest event's registers (the window read from it)."""
    regmap = Map(os.environ["MODBUS_REGISTERS"])
    nxt = get_input(client, "event_seq_next")
    m = Master(client, regmap)
    m.write(regmap.event_from, u32_words((nxt - 1) & NONE))
    w = read_table(client, "input", regmap.slot0, regmap.stride)
    return w


# (harness sensor, the state set, the fault's sensor index, its kind's index): sensors
# 0 load, 1 probe 1, 2 probe 2, 3 speed; kinds 0 disconnected, 1 bus, 3 stuck, 5 out
# of range (docs/modbus.md, the event's `fault`).
FAULTS = [
    ("load", "unplugged", 0, 0),
    ("load", "stuck", 0, 3),
    ("probe1", "unplugged", 1, 5),
    ("probe1", "stuck", 1, 3),
    ("probe2", "unplugged", 2, 5),
    ("probe2", "stuck", 2, 3),
    ("ads", "unplugged", 1, 1),
    ("tach", "unplugged", 3, 0),
    ("tach", "stuck", 3, 3),
]


def test_each_sensor_unplugged_and_stuck_gives_the_fault_naming_it(client):
    for sensor, how, index, kind in FAULTS:
        wait_until(lambda: state(client) not in (0, SENSOR_FAULT))
        harness(f"sensor {sensor} {how}")
        wait_until(lambda: state(client) == SENSOR_FAULT)
        event = latest_event(client)
        fault = event[10]
        assert event[7] == 1 and event[9] == SENSOR_FAULT, f"{sensor} {how}: {event}"
        assert fault >> 8 == 8, f"{sensor} {how}: cause {fault >> 8}, not the sensors' own"
        assert (fault >> 4) & 0xF == index and fault & 0xF == kind, \
            f"{sensor} {how}: fault {fault:#06x}, expected sensor {index} kind {kind}"
        harness(f"sensor {sensor} ok")
    wait_until(lambda: state(client) not in (0, SENSOR_FAULT))


def active_pair(client):
    return get(client, "active_warning"), get(client, "active_alarm")


def commit_pair(client, warning, alarm):
    """Unlocks, stages the warning and the alarm and commits them: whether the node
    answered every write (a power cut planned for the next flash operation may come
    in any of them: a write waits for the checkpoint the node takes meanwhile)."""
    writes = [("unlock", code()), ("config_warning", f32(warning)),
              ("config_alarm", f32(alarm)), ("command", 1)]
    try:
        return all(not write(client, name, value).isError() for name, value in writes)
    except Exception:  # noqa: BLE001 (no answer: the power went)
        return False


def flash_ops():
    return harness("status")["flash_ops"]


# Points of an operation where the power goes: the first, within, past the end (the
# operation completes; the next one is cut).
POINTS = [0, 5, 100, 100000]


def test_power_cut_in_a_commit_keeps_the_old_or_the_new_configuration_whole(client):
    before = flash_ops()
    assert commit_pair(client, 0.30, 0.60)
    ops = flash_ops() - before
    assert ops >= 1, "a commit writes the flash"
    pairs = [(0.31, 0.61), (0.32, 0.62), (0.33, 0.63), (0.34, 0.64)]
    for i, (warning, alarm) in enumerate(pairs):
        old = active_pair(client)
        nth = 1 + (i * ops) // len(pairs)
        booted = boots()
        harness(f"cut {nth} {POINTS[i % len(POINTS)]}")
        answered = commit_pair(client, warning, alarm)
        harness("cut 0 0")
        time.sleep(0.5)
        if boots() > booted:
            wait_serving(client)
        new = (f32(warning), f32(alarm))
        got = active_pair(client)
        assert got in (old, new), f"half a commit: {got}, old {old}, new {new}"
        if answered:
            assert got == new, "a commit the node answered is on flash"


def test_power_cut_in_an_acknowledgement_keeps_what_was_answered(client):
    regmap = Map(os.environ["MODBUS_REGISTERS"])
    for i, point in enumerate(POINTS):
        # An event to acknowledge: a sensor fault and its end.
        wait_until(lambda: state(client) not in (0, SENSOR_FAULT))
        harness("sensor load unplugged")
        wait_until(lambda: state(client) == SENSOR_FAULT)
        harness("sensor load ok")
        wait_until(lambda: state(client) not in (0, SENSOR_FAULT))
        newest = (get_input(client, "event_seq_next") - 1) & NONE
        acked = get_input(client, "event_acked")
        booted = boots()
        harness(f"cut 1 {point}")
        m = Master(client, regmap)
        try:
            m.write(ack_address(), u32_words(newest))
            answered = True
        except Exception:  # noqa: BLE001 (no answer: the power went)
            answered = False
        harness("cut 0 0")
        time.sleep(0.5)
        if boots() > booted:
            wait_serving(client)
        got = get_input(client, "event_acked")
        assert got in (acked, newest), f"acknowledged through {got}: neither {acked} nor {newest}"
        if answered:
            assert got == newest, "an acknowledgement the node answered is on flash"


def test_power_cut_in_a_checkpoint_restores_a_whole_one(client):
    for point in POINTS:
        checkpoints = get_input(client, "checkpoints")
        samples = get_input(client, "samples")
        booted = boots()
        # The next flash operation of a running node: its periodic checkpoint.
        harness(f"cut 1 {point}")
        restarted(client, booted)
        assert get(client, "config_source") == 1
        got = get_input(client, "checkpoints")
        assert got >= checkpoints, f"checkpoint {got} restored after {checkpoints} was stored"
        restored = get_input(client, "samples")
        assert 0 < restored <= samples + 600 * 10, "the monitor restored a checkpoint"
        harness("cut 0 0")


def test_the_driver_enable_pin_was_high_exactly_while_the_node_sent():
    status = harness("status")
    assert status["de_errors"] == 0, status


# A site's own calibration and sampling period, every value other than the build's
# (docs/modbus.md, Sensor settings).
SITE_SETTINGS = """name,value
config_sample_period,200
config_load_zero,-1500
config_load_scale,0.005
config_probe1_zero,5000
config_probe1_scale,1.1e-7
config_probe2_zero,4600
config_probe2_scale,9.5e-8
config_probe_span,0.35
config_probe_zero_offset,1e-6
config_tacho_pulses_per_rev,360
config_tacho_radius,0.06
config_tacho_max_speed,8
"""


def test_a_site_calibration_and_period_give_the_replays_events(tmp_path):
    """`cargo xtask pico --trace` on a node commissioned with a site's calibration and a
    200 ms period: the harness drives the sensors through the inverse of the committed
    calibration, the node samples at the committed period, and the events read over the
    bus equal, bit for bit, the monitor example's replay of the samples delivered."""
    import math
    import subprocess

    root = os.path.join(os.path.dirname(__file__), "..", "..")
    settings = tmp_path / "settings.csv"
    settings.write_text(SITE_SETTINGS)
    scene = tmp_path / "scene.csv"
    scene.write_text("R1,R2,G,nu,mu\n0.06,0.04,79.3e9,0.3,0.25\n")
    trace = tmp_path / "trace.csv"
    rows = ["t,P,phi,V"] + [
        f"{i / 10},{2500 + 40 * math.sin(i)},{1e-4 + 7e-4 * math.sin(math.pi * i / 300)},2.0"
        for i in range(600)]
    trace.write_text("\n".join(rows) + "\n")
    events, samples, replay = (tmp_path / n for n in ("events.csv", "samples.csv", "replay.csv"))
    subprocess.run(["cargo", "xtask", "pico", "--trace", trace, "--scene", scene, "--events", events,
                    "--samples", samples, "--settings", settings], cwd=root, check=True)
    subprocess.run(["cargo", "run", "-q", "--release", "--example", "monitor", "--", "--model", "fixed",
                    "--scene", scene, "--trace", samples, "--events", replay],
                   cwd=root, check=True, stdout=subprocess.DEVNULL)
    assert events.read_bytes() == replay.read_bytes()
    assert len(events.read_text().splitlines()) > 1, "an event was raised"
    # Sampled at the committed period: 200 ms between the delivered samples.
    times = [round(float(line.split(",")[0]) * 1000) for line in samples.read_text().splitlines()[1:]]
    steps = {b - a for a, b in zip(times, times[1:])}
    assert steps == {200}, steps
