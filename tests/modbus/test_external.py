"""The node on a master's samples: the built-in scenario's samples written over the bus
(function 16, the full sample block: they carry a speed), every event read back from
the event window after each write.

MODBUS_SAMPLES: the samples (master.py's format). MODBUS_EVENTS_OUT: where the events
read go, raw; `cargo xtask modbus` then compares them with the host's replay of the
same samples, bit for bit. MODBUS_EVENT_WINDOW: the events the node's window holds.
"""

import csv
import os

from conftest import register_map, UNIT
from master import Map, Master, read_samples


def test_every_event_read_without_loss_across_the_window_wrap(client):
    master = Master(client, Map(os.environ["MODBUS_REGISTERS"]))
    events = master.run(read_samples(os.environ["MODBUS_SAMPLES"]))
    assert master.missed == 0, f"{master.missed} events lost"
    seqs = [e[0] << 16 | e[1] for e in events]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs))), "sequence numbers not contiguous"
    window = int(os.environ["MODBUS_EVENT_WINDOW"])
    assert len(events) > 2 * window, f"{len(events)} events do not wrap a window of {window} twice"
    with open(os.environ["MODBUS_EVENTS_OUT"], "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["event"] + [f"w{k}" for k in range(master.m.stride)])
        for k, e in enumerate(events):
            w.writerow([k] + list(e))


def test_the_samples_are_counted(client):
    rows = {r["name"]: r for r in register_map()}
    n = len(read_samples(os.environ["MODBUS_SAMPLES"]))
    accepted = rows["external_accepted"]
    r = client.read_input_registers(accepted["address"], count=2, device_id=UNIT)
    assert not r.isError(), r
    assert r.registers[0] << 16 | r.registers[1] == n
