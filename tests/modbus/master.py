"""A Modbus master for the node's external samples and event window, on pymodbus:
writes samples (function 16), reads every event back (function 4 on the window,
function 16 on `event_from`). The tests use it (`test_external.py`), and so does
`cargo xtask modbus --trace`, through its command line:

    python tests/modbus/master.py --port PORT --registers registers.csv \
        --samples samples.csv --events events.csv

Addresses come from the register map (`docs/modbus/registers.csv`'s columns), by
name. Samples in (`time_ms,load,phi,speed,axial_force`: the u32 timestamp, then each
f32 as its bit pattern in decimal, an empty cell for a value not measured); events
out (`event,w0,...,w24`: each event's registers, raw, in the window's order).
"""

import argparse
import csv
import struct
import sys

from pymodbus import FramerType
from pymodbus.client import ModbusTcpClient

UNIT = 1


class Map:
    """The addresses the master needs, by name."""

    def __init__(self, path):
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        at = {(r["table"], r["name"]): int(r["address"]) for r in rows}
        self.event_from = at[("holding", "event_from")]
        self.event_first = at[("input", "event_first")]
        self.event_count = at[("input", "event_count")]
        self.events_missed = at[("input", "events_missed")]
        self.slots = sum(1 for r in rows if r["table"] == "input" and r["name"].endswith("_seq")
                         and r["name"].startswith("event_"))
        self.slot0 = at[("input", "event_0_seq")]
        self.stride = at[("input", "event_1_seq")] - self.slot0
        self.samples = sum(1 for r in rows if r["name"].startswith("sample_") and r["name"].endswith("_time_ms")
                           and not r["name"].startswith("sample_full_"))
        self.sample0 = at[("holding", "sample_0_time_ms")]
        self.sample_stride = at[("holding", "sample_1_time_ms")] - self.sample0
        self.full = sum(1 for r in rows if r["name"].startswith("sample_full_") and r["name"].endswith("_flags"))
        self.full0 = at[("holding", "sample_full_0_flags")]
        self.full_stride = at[("holding", "sample_full_1_flags")] - self.full0


def u32_words(x):
    """A u32 as two registers, high word first."""
    return [(x >> 16) & 0xFFFF, x & 0xFFFF]


def f32_of(hi, lo):
    return struct.unpack(">f", struct.pack(">HH", hi, lo))[0]


def read_samples(path):
    """(time_ms, load bits, phi bits, speed bits or None, force bits or None)."""
    out = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            opt = lambda k: int(r[k]) if r[k] != "" else None  # noqa: E731
            out.append((int(r["time_ms"]), int(r["load"]), int(r["phi"]), opt("speed"), opt("axial_force")))
    return out


class Master:
    def __init__(self, client, regmap, unit=UNIT):
        self.c = client
        self.unit = unit
        self.m = regmap
        self.next_seq = None
        self.events = []
        self.missed = 0

    def write(self, address, values):
        r = self.c.write_registers(address, values, device_id=self.unit)
        assert not r.isError(), f"write {address}+{len(values)}: {r}"

    def feed(self, chunk):
        """One function-16 write of `chunk`'s samples: the basic block when none
        carries a speed or a force, else the full block."""
        if all(s[3] is None and s[4] is None for s in chunk):
            assert len(chunk) <= self.m.samples
            words = []
            for t, p, phi, _, _ in chunk:
                words += u32_words(t) + u32_words(p) + u32_words(phi)
            self.write(self.m.sample0, words)
        else:
            assert len(chunk) <= self.m.full
            words = []
            for t, p, phi, v, f in chunk:
                flags = (v is not None) | (f is not None) << 1
                words += [flags] + u32_words(t) + u32_words(p) + u32_words(phi)
                words += u32_words(v or 0) + u32_words(f or 0)
            self.write(self.m.full0, words)

    def read_events(self):
        """Reads the window until it holds nothing new; every event once, in order."""
        m = self.m
        while True:
            n = m.slot0 + m.slots * m.stride - m.event_first
            r = self.c.read_input_registers(m.event_first, count=n, device_id=self.unit)
            assert not r.isError(), f"event window: {r}"
            w = r.registers
            first = w[0] << 16 | w[1]
            count = w[m.event_count - m.event_first]
            i = m.events_missed - m.event_first
            self.missed += w[i] << 16 | w[i + 1]
            if self.next_seq is not None and count:
                assert first == self.next_seq, f"event {self.next_seq} expected, window starts at {first}"
            for k in range(count):
                at = m.slot0 - m.event_first + k * m.stride
                self.events.append(w[at:at + m.stride])
            if count == 0:
                return
            self.next_seq = (first + count) & 0xFFFFFFFF
            self.write(m.event_from, u32_words(self.next_seq))

    def run(self, samples):
        """Every sample fed, the events read after each write."""
        i = 0
        while i < len(samples):
            basic = all(s[3] is None and s[4] is None for s in samples[i:i + self.m.samples])
            n = self.m.samples if basic else self.m.full
            chunk = samples[i:i + n]
            self.feed(chunk)
            i += len(chunk)
            self.read_events()
        return self.events


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--port", type=int, required=True)
    ap.add_argument("--registers", required=True)
    ap.add_argument("--samples", required=True)
    ap.add_argument("--events", required=True)
    a = ap.parse_args()
    client = ModbusTcpClient("127.0.0.1", port=a.port, framer=FramerType.RTU, timeout=5, retries=0)
    if not client.connect():
        sys.exit("cannot connect to the node")
    master = Master(client, Map(a.registers))
    events = master.run(read_samples(a.samples))
    client.close()
    with open(a.events, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["event"] + [f"w{k}" for k in range(master.m.stride)])
        for k, e in enumerate(events):
            w.writerow([k] + list(e))
    print(f"{len(events)} events read, {master.missed} missed", file=sys.stderr)
    if master.missed:
        sys.exit(f"{master.missed} events were lost before they were read")


if __name__ == "__main__":
    main()
