"""The node with flash (feature `modbus-flash`) across a reset: commissioned with a
configuration and a scene it was not built with, fed samples until events happen, some
of them acknowledged, then reset through QEMU's monitor (`system_reset`: the CPU and
every device reset, the image restarted from its reset vector, the `.uninit` RAM that
stands for flash kept), as a power cycle does without the node's cooperation. After
it the node runs the committed configuration (`config_source` 1, the active values
the committed ones) and offers exactly the events not acknowledged, in order, with
their own numbers and contents; no acknowledged one comes back. Then a reset of the
statistics (command 4), answered once it is checkpointed, holds across a second reset.

MODBUS_QEMU_MONITOR: the monitor's loopback port. MODBUS_SCENE: a prepared scene the
node was not built with. MODBUS_SAMPLES: the samples (master.py's format).
"""

import math
import os
import socket
import subprocess
import sys
import time

from conftest import HOST, UNIT, read_table, register_map
from master import Map, Master, f32_of, read_samples, u32_words
from test_config import code, get, write

ON_DELAY_MS = 4000
# The alarms that latch, committed with the configuration: warning and sensor fault.
LATCHING = 0b0101


def input_address(name):
    return next(r["address"] for r in register_map() if r["table"] == "input" and r["name"] == name)


# The input registers of the monitor's own state: from `status` up to the server's
# (`last_sample_time` on: what the bus offered, counted since the boot); of them the
# alarms' acknowledgement is the server's too (`alarms`, the top bits of `status`).
MONITORED_WORDS = input_address("last_sample_time")
ALARMS = input_address("alarms")
STATUS = input_address("status")


def monitor_state(words):
    return [w & 0x0FFF if k == STATUS else w for k, w in enumerate(words) if k != ALARMS]


def checkpoint_is_now_with_a_trend(client):
    age = read_table(client, "input", input_address("checkpoint_age"), 2)
    ttc = read_table(client, "input", input_address("time_to_critical"), 2)
    finite = not math.isnan(f32_of(*ttc))
    return (age[0] << 16 | age[1]) == 0 and finite


def ack_address():
    return next(r["address"] for r in register_map()
                if r["table"] == "holding" and r["name"] == "event_ack")


def reset_node():
    """`system_reset` on QEMU's human monitor."""
    with socket.create_connection((HOST, int(os.environ["MODBUS_QEMU_MONITOR"])), timeout=5) as s:
        s.recv(4096)  # the banner and prompt
        s.sendall(b"system_reset\n")
        time.sleep(0.5)


def wait_serving(client, timeout_s=300):
    """Reconnects and waits until the node answers again (it runs its self-test
    first)."""
    client.close()
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        time.sleep(0.5)
        if not client.connect():
            continue
        try:
            r = client.read_holding_registers(0, count=1, device_id=UNIT)
            if not r.isError():
                return
        except Exception:  # noqa: BLE001 (a half frame while the node restarts)
            pass
        client.close()
    raise AssertionError("the node did not answer after the reset")


def test_configuration_and_unacknowledged_events_survive_a_reset(client):
    assert get(client, "config_source") == 0, "a cold node runs the build-time defaults"
    # Commission: the other scene and an on-delay, through the commissioning tool.
    client.close()
    time.sleep(0.1)
    done = subprocess.run(
        [sys.executable, "tools/commission.py", "--tcp", f"127.0.0.1:{os.environ['MODBUS_PORT']}",
         "--registers", os.environ["MODBUS_REGISTERS"], "--code", str(code()),
         "--prepared", os.environ["MODBUS_SCENE"], "--set", f"config_on_delay={ON_DELAY_MS}",
         "--set", f"latching={LATCHING}"],
        capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    time.sleep(0.1)
    assert client.connect()
    assert get(client, "config_source") == 1
    with open(os.environ["MODBUS_SCENE"], "rb") as f:
        scene_crc = int.from_bytes(f.read()[-4:], "little")
    assert get(client, "scene_active_crc") == scene_crc
    active = get(client, "active_on_delay")
    assert active == ON_DELAY_MS

    # Samples until a dozen events, each read as it comes.
    regmap = Map(os.environ["MODBUS_REGISTERS"])
    master = Master(client, regmap)
    samples = read_samples(os.environ["MODBUS_SAMPLES"])
    i = 0
    while len(master.events) < 12:
        assert i < len(samples), f"{len(master.events)} events from every sample"
        chunk = samples[i:i + regmap.full]
        master.feed(chunk)
        i += len(chunk)
        master.read_events()
    # On, a sample a write, until a checkpoint (one a minute of monitored time, and at
    # each event) is of the last sample while the trend gives a time to critical: the
    # state at the reset is then the checkpoint's, conditioning and trend included.
    while not checkpoint_is_now_with_a_trend(client):
        assert i < len(samples), "no checkpoint with a time to critical"
        master.feed(samples[i:i + 1])
        i += 1
        master.read_events()
    monitored = read_table(client, "input", 0, MONITORED_WORDS)
    assert master.missed == 0
    events = master.events
    seqs = [e[0] << 16 | e[1] for e in events]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))
    # The master acknowledges the first five.
    acked = seqs[4]
    master.write(ack_address(), u32_words(acked))
    assert get(client, "event_ack") == acked

    reset_node()
    wait_serving(client)

    assert get(client, "config_source") == 1, "the committed configuration runs"
    assert get(client, "active_on_delay") == ON_DELAY_MS
    assert get(client, "latching") == LATCHING
    assert get(client, "scene_active_crc") == scene_crc
    # The monitor went on from its checkpoint under the committed configuration: every
    # value it shows is the one before the reset (the trend's time to critical too,
    # which a checkpoint restored before the committed configuration loses), but for
    # the alarms' acknowledgement, which is the bus's, not the monitor's state.
    again = read_table(client, "input", 0, MONITORED_WORDS)
    assert monitor_state(again) == monitor_state(monitored), \
        f"before the reset: {monitored}, after: {again}"
    after = Master(client, regmap)
    after.read_events()
    kept = [e[0] << 16 | e[1] for e in after.events]
    assert kept == seqs[5:], f"after the reset: {kept}, expected {seqs[5:]}"
    assert after.events == events[5:], "the events' contents changed"
    assert after.missed == 0

    # A reset of the statistics is answered once it is checkpointed: it holds across
    # a reset at once, before any event or periodic checkpoint.
    samples = input_address("samples")
    assert read_table(client, "input", samples, 2) != [0, 0]
    seq_next = read_table(client, "input", input_address("event_seq_next"), 2)
    assert not write(client, "unlock", code()).isError()
    assert not write(client, "command", 4).isError()
    assert read_table(client, "input", samples, 2) == [0, 0]
    reset_node()
    wait_serving(client)
    assert read_table(client, "input", samples, 2) == [0, 0], "the statistics came back"
    assert read_table(client, "input", input_address("event_seq_next"), 2) == seq_next
