#!/usr/bin/env python3
"""Commissions a misalign node over Modbus RTU (docs/modbus.md, "Commissioning from the
PC"): from what a reliability engineer planned (a scene file, a configuration file, the
monitor example's `--thresholds` table) it prepares the scene's bytes, unlocks the node
with the site's code, writes the configuration and the scene to its staged copy, reads
them back, commits, checks that the node runs them, and prints the node's status.

    python3 tools/commission.py --tcp 127.0.0.1:5020 --code 1234 \\
        --scene scene.csv --config config.csv --thresholds thresholds.csv

- `--tcp HOST:PORT`: a TCP bridge carrying RTU frames (or QEMU's serial port on a
  loopback socket); `--serial /dev/ttyUSB0 --baud 19200`: a serial line (8E1;
  `--parity N`: 8N2, `--parity O`: 8O1). Needs pyserial (3.5) beside pymodbus.
- `--scene S.csv`: the monitor example's scene file (`R1,R2,G,nu,mu[,length]`),
  prepared for the node's core (`--core f32`: `float::Auto`, `--core fixed`:
  `fixed::FixedAuto`) by `cargo run --release --example prepare`; or `--prepared B`:
  bytes that `examples/prepare.rs --out` wrote.
- `--config C.csv`: `name,value` lines, a `config_*` register of the map (the prefix may
  be left out, here and in `--set`), `new_code`, or one of the switches `latching` (the
  alarms that latch, bits 0-3) and `external_mode` (1: samples from the bus), which
  the node applies as they are written and keeps with the commit; `--set NAME=VALUE`
  adds or overrides one.
  `cargo xtask modbus --default-config C.csv` writes the defaults.
- `--thresholds T.csv`: the planner's table (`P,phi0,phi_warning,...`). It holds no
  register (its angles follow from the scene and the configuration's thresholds): it is
  checked against the configuration the node will run, its loads within the stop load
  and the highest accepted load, and its alarm angles summed up on the way.
- `--events OUT.csv`: the events the node holds, in the monitor example's `--events`
  format (decoded as `misalign::modbus::event_from_registers` does), from its
  `event_from` or `--events-from SEQ`; read through the window, `event_from` put back,
  nothing acknowledged.
- `--reset-statistics`: the node's statistics (counts, time and energy per state,
  extremes) start afresh, after a roller change say (the command 4, before anything
  is written); alone, nothing is committed.
- Without `--code`, nothing is written: the node's status and events only.

Register names and types come from the register map (`--registers`, default
docs/modbus/registers.csv); 32-bit values high word first. Exit status 0 when the node
runs what was written; otherwise the reason (a wrong code, a lock-out, the commit's
`commit_error`) on stderr and status 1, and whatever was staged is reverted.
Needs pymodbus (3.16).
"""

import argparse
import csv
import math
import os
import subprocess
import tempfile
import struct
import sys

REASONS = {
    1: "nothing staged",
    0x10: "a threshold is not finite (or a d/b threshold not positive)",
    0x11: "the warning is not before the alarm",
    0x12: "the deadband is negative, not finite or too wide",
    0x13: "the stop load is not positive, or the stop speed negative",
    0x14: "the nominal speed is not positive",
    0x15: "an accepted range is empty or not finite",
    0x16: "the spike filter's window or values",
    0x17: "the smoothing time constant is negative",
    0x18: "the trend's points or horizon",
    0x19: "friction tracking's values are inconsistent",
    0x20: "scene: wrong length",
    0x21: "scene: not a prepared scene",
    0x22: "scene: another scene type than the node's",
    0x23: "scene: another format version",
    0x24: "scene: its CRC-32 does not match (damaged in transfer)",
    0x25: "scene: a constant outside what preparing a scene produces",
}


class Failed(Exception):
    pass


class Node:
    def __init__(self, client, registers, unit):
        self.c = client
        self.unit = unit
        with open(registers, newline="") as f:
            self.rows = {(r["table"], r["name"]): r for r in csv.DictReader(f)}

    def row(self, name, table="holding"):
        try:
            return self.rows[(table, name)]
        except KeyError:
            raise Failed(f"the register map has no {table} register {name}") from None

    def words(self, name, value):
        ty = self.row(name)["type"]
        if ty == "f32":
            return list(struct.unpack(">HH", struct.pack(">f", float(value))))
        v = int(value, 0) if isinstance(value, str) else int(value)
        if ty in ("u32", "i32"):
            v &= 0xFFFFFFFF
            return [v >> 16, v & 0xFFFF]
        return [v & 0xFFFF]

    def read(self, name, table="holding"):
        r = self.row(name, table)
        n = 2 if r["type"] in ("u32", "i32", "f32") else 1
        read = self.c.read_input_registers if table == "input" else self.c.read_holding_registers
        answer = read(int(r["address"]), count=n, device_id=self.unit)
        if answer.isError():
            raise Failed(f"read {name}: {answer}")
        return answer.registers

    def write(self, name, words):
        """The exception code, or None."""
        answer = self.c.write_registers(int(self.row(name)["address"]), words, device_id=self.unit)
        return answer.exception_code if answer.isError() else None

    def write_plain(self, name, words):
        """A holding register that needs no unlock (`event_from`)."""
        answer = self.c.write_registers(int(self.row(name)["address"]), words, device_id=self.unit)
        if answer.isError():
            raise Failed(f"write {name}: {answer}")

    def write_words(self, address, words):
        for i in range(0, len(words), 120):
            answer = self.c.write_registers(address + i, words[i:i + 120], device_id=self.unit)
            if answer.isError():
                raise Failed(f"scene block at {address + i}: exception {answer.exception_code}")


def u32(words):
    return words[0] << 16 | words[1]


# Switches the node applies as written (behind the unlock) and keeps with the
# committed configuration.
SWITCHES = ("latching", "external_mode")


def commission(node, code, settings, scene, reset_statistics=False):
    if scene is not None:
        want = node.read("scene_bytes")[0]
        if want == 0:
            raise Failed("this node takes no scene over the bus")
        if len(scene) != want:
            raise Failed(f"the node takes {want} bytes of prepared scene, the file has {len(scene)}")
    x = node.write("unlock", [code])
    if x == 3:
        raise Failed("wrong code (counted by the node; a few in a row lock it out)")
    if x == 1:
        raise Failed(f"locked out for {node.read('lockout')[0]} s after wrong codes")
    if x is not None:
        raise Failed(f"unlock: exception {x}")
    if reset_statistics:
        x = node.write("command", [4])
        if x is not None:
            node.write("command", [3])  # lock
            raise Failed(f"reset of the statistics: exception {x}")
        if not settings and scene is None:
            node.write("command", [3])  # lock
            return node.read("config_source")[0]
    # The switches as they were, put back if the commit fails.
    switched = {name: node.read(name) for name, _ in settings if name in SWITCHES}
    try:
        for name, value in settings:
            if not (name.startswith("config_") or name in ("new_code",) + SWITCHES):
                raise Failed(f"{name} is not a configuration register "
                             f"(config_*, new_code, {', '.join(SWITCHES)})")
            words = node.words(name, value)
            x = node.write(name, words)
            if x is not None:
                raise Failed(f"{name} = {value}: exception {x}")
            if name != "new_code" and node.read(name) != words:
                raise Failed(f"{name} reads back {node.read(name)}, not {words}")
        if scene is not None:
            padded = scene + b"\0" * (len(scene) % 2)
            words = [int.from_bytes(padded[i:i + 2], "big") for i in range(0, len(padded), 2)]
            node.write_words(int(node.row("scene_0_word")["address"]), words)
            crc = int.from_bytes(scene[-4:], "little")
            if u32(node.read("scene_staged_crc")) != crc:
                raise Failed("the staged scene's CRC differs from the file's: bytes lost on the way")
        x = node.write("command", [1])
        if x is not None:
            why = node.read("commit_error")[0]
            raise Failed(f"commit refused: {REASONS.get(why, why)} (commit_error {why:#x})")
    except Failed:
        for name, words in switched.items():
            node.write(name, words)
        node.write("command", [2])  # revert
        node.write("command", [3])  # lock
        raise
    # What the node runs now.
    for name, value in settings:
        if name in SWITCHES and node.read(name) != node.words(name, value):
            raise Failed(f"{name} reads {node.read(name)} after the commit")
        if name.startswith("config_"):
            active = "active_" + name[len("config_"):]
            if node.read(active) != node.words(name, value):
                raise Failed(f"{active} reads {node.read(active)} after the commit")
    if scene is not None and u32(node.read("scene_active_crc")) != int.from_bytes(scene[-4:], "little"):
        raise Failed("the node does not run the scene after the commit")
    return node.read("config_source")[0]


STATES = {0: "stopped", 1: "normal", 2: "microslip", 3: "gross slip", 4: "sensor fault"}


def register(name):
    """A configuration register's name: `config_` added to a field's name."""
    if name in ("new_code",) + SWITCHES or name.startswith("config_"):
        return name
    return "config_" + name


def read_config(path):
    """`name,value` lines (a header `name,value`, blank lines and `#` comments allowed)."""
    out = []
    with open(path, newline="") as f:
        for n, row in enumerate(csv.reader(f), 1):
            if not row or not row[0].strip() or row[0].startswith("#"):
                continue
            if n == 1 and [c.strip() for c in row] == ["name", "value"]:
                continue
            if len(row) != 2:
                raise Failed(f"{path}:{n}: name,value")
            out.append((register(row[0].strip()), row[1].strip()))
    return out


def read_scene(path):
    """The monitor example's scene file: a header, then R1,R2,G,nu,mu[,length]."""
    with open(path, newline="") as f:
        text = f.read()
    rows = [r for r in csv.reader(text.splitlines(), delimiter=";" if ";" in text else ",") if r]
    if len(rows) != 2 or len(rows[1]) not in (5, 6):
        raise Failed(f"{path}: a header and one row R1,R2,G,nu,mu[,length]")
    return [c.strip() for c in rows[1]]


def prepare(scene, core):
    """The scene's prepared bytes for the node's core, from examples/prepare.rs."""
    r1, r2, g, nu, mu, *length = scene
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "scene.bin")
        cmd = ["cargo", "run", "--quiet", "--release", "--example", "prepare", "--",
               "--type", "auto" if core == "f32" else "fixed-auto", "--out", out]
        cmd += ["--length", length[0]] if length else []
        done = subprocess.run(cmd + ["--", r1, r2, g, nu, mu], capture_output=True, text=True,
                              cwd=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
        if done.returncode != 0:
            raise Failed(f"preparing the scene: {done.stderr.strip()}")
        return open(out, "rb").read()


def f32(words):
    return struct.unpack(">f", struct.pack(">HH", *words))[0]


def check_thresholds(node, path, settings):
    """The planner's table against the configuration the node will run: its loads
    within (stop load, highest accepted load]. A summary line."""
    def value(name):
        for n, v in reversed(settings):
            if n == name:
                return float(v)
        return f32(node.read(name))
    stop, top = value("config_stop_load"), value("config_load_max")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows or "P" not in rows[0] or "phi_alarm" not in rows[0]:
        raise Failed(f"{path}: not the planner's table (P,phi0,phi_warning,...)")
    loads = [float(r["P"]) for r in rows]
    if min(loads) <= stop or max(loads) > top * (1 + 1e-6):
        raise Failed(f"{path}: loads {min(loads)} to {max(loads)} N, outside the configuration's "
                     f"stop load {stop} N to highest load {top} N: planned with another configuration")
    alarms = [float(r["phi_alarm"]) for r in rows if r["phi_alarm"] != ""]
    at = f", alarm at {min(alarms):.4g} to {max(alarms):.4g} rad" if alarms else ""
    return f"thresholds planned for {min(loads):.4g} to {max(loads):.4g} N{at}"


RISK = ["stopped", "normal", "microslip", "gross_slip", "sensor_fault"]
KINDS = {1: "state", 2: "approaching", 3: "friction_changed", 4: "friction_cleared"}
CHANNELS = ["Load", "Angle", "Speed", "AxialForce"]
FAULTS = {1: "NonFinite", 2: "OutOfRange", 3: "Stuck", 6: "Driver"}
NONE = 0x7FC00000  # the map's sentinel of an absent value


def rust(x):
    """A number as Rust's Display prints it: the shortest digits that read back to
    the same value, without an exponent."""
    if x != x:
        return "NaN"
    if x in (float("inf"), float("-inf")):
        return "inf" if x > 0 else "-inf"
    from decimal import Decimal
    text = format(Decimal(repr(x)).normalize(), "f")
    return "-0" if text == "0" and math.copysign(1, x) < 0 else text


def rust_f32(bits):
    """An f32 (its bit pattern) as Rust's Display prints it."""
    x = struct.unpack(">f", struct.pack(">I", bits))[0]
    for digits in range(1, 10):
        short = float(f"{x:.{digits}g}")
        if x != x or struct.pack(">f", short) == struct.pack(">I", bits):
            return rust(short) if x == x else "NaN"
    return rust(x)


def fault(code):
    """A fault code as the monitor's Debug name (`misalign::modbus::fault_from_code`)."""
    kind, low = code >> 8, code & 0xFF
    if code == 0:
        return ""
    if kind in FAULTS and low < len(CHANNELS):
        return f"{FAULTS[kind]}({CHANNELS[low]})"
    return {0x400: "Gap", 0x500: "TimeBackwards", 0x700: "Estimator"}.get(code, f"code {code:#06x}")


def event_row(w):
    """One event slot's registers as a row of the monitor example's --events file."""
    u32_at = lambda i: w[i] << 16 | w[i + 1]  # noqa: E731
    opt = lambda i: "" if u32_at(i) == NONE else rust_f32(u32_at(i))  # noqa: E731
    kind = KINDS.get(w[7])
    if kind is None:
        raise Failed(f"event {u32_at(0)}: kind {w[7]}")
    state, frm, why, ttc = "", "", "", ""
    if w[7] == 1:
        state, frm, why = RISK[w[9]], RISK[w[8]], fault(w[10])
    elif w[7] == 2:
        ttc = rust_f32(u32_at(11))
    else:
        state = "mu=" + rust_f32(u32_at(11))
    reading = ["", "", "", "", "", ""] if w[7] >= 3 else [
        rust_f32(u32_at(13)), rust_f32(u32_at(15)), rust_f32(u32_at(17)), rust_f32(u32_at(19)),
        opt(21), opt(23)]
    t = rust((u32_at(4) * 1000 + w[6]) / 1e3)
    return [t, str(u32_at(0)), state, frm, kind, why, *reading, ttc, str(u32_at(2))]


EVENTS_HEADER = "t,seq,state,from,kind,fault,P,phi,s,F,phi0,margin,time_to_critical,time_ms"


def held_events(node, start):
    """Every event the node holds from sequence number `start` (None: from its own
    `event_from`), read through the window; `event_from` is put back as it was (reading
    acknowledges nothing)."""
    event_from = node.read("event_from")
    first_at = int(node.row("event_first", "input")["address"])
    slot0 = int(node.row("event_0_seq", "input")["address"])
    stride = int(node.row("event_1_seq", "input")["address"]) - slot0
    slots = sum(1 for (t, n) in node.rows if t == "input" and n.startswith("event_") and n.endswith("_seq"))
    if start is not None:
        node.write_plain("event_from", [start >> 16, start & 0xFFFF])
    held = []
    try:
        while True:
            answer = node.c.read_input_registers(first_at, count=slot0 + slots * stride - first_at,
                                                 device_id=node.unit)
            if answer.isError():
                raise Failed(f"the event window: {answer}")
            w = answer.registers
            count = w[int(node.row("event_count", "input")["address"]) - first_at]
            for k in range(count):
                at = slot0 - first_at + k * stride
                held.append(w[at:at + stride])
            if count < slots:
                return held
            nxt = (u32(w[0:2]) + count) & 0xFFFFFFFF
            node.write_plain("event_from", [nxt >> 16, nxt & 0xFFFF])
    finally:
        node.write_plain("event_from", event_from)


def status(node, events_out, events_from):
    """The node's status as lines; the events it holds into `events_out` (the monitor
    example's --events format)."""
    s = node.read("status", "input")[0]
    lines = [
        f"state {STATES.get(s & 0xFF, s & 0xFF)}, config_source {node.read('config_source')[0]}, "
        f"scene_active_crc {u32(node.read('scene_active_crc')):#010x}",
        f"samples {u32(node.read('samples', 'input'))}, "
        f"events_dropped {u32(node.read('events_dropped', 'input'))}, "
        f"event_seq_next {u32(node.read('event_seq_next', 'input'))}",
    ]
    held = held_events(node, events_from)
    first = f" from {u32(held[0][0:2])}" if held else ""
    lines.append(f"{len(held)} events held{first}")
    if events_out:
        with open(events_out, "w", newline="") as f:
            f.write(EVENTS_HEADER + "\n")
            for e in held:
                f.write(",".join(event_row(e)) + "\n")
    return lines


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--tcp", metavar="HOST:PORT", help="a TCP bridge (RTU frames over TCP)")
    p.add_argument("--serial", help="a serial device instead of --tcp")
    p.add_argument("--baud", type=int, default=19200)
    p.add_argument("--parity", choices=["E", "O", "N"], default="E",
                   help="the serial line's parity (default E: 8E1; N: 8N2, as Modbus asks)")
    p.add_argument("--unit", type=int, default=1)
    p.add_argument("--registers", default="docs/modbus/registers.csv")
    p.add_argument("--code", type=int, help="the site's code (without it: the status only)")
    p.add_argument("--scene", help="the monitor example's scene file (R1,R2,G,nu,mu[,length])")
    p.add_argument("--core", choices=["f32", "fixed"], default="f32",
                   help="the node's core, for --scene (default f32)")
    p.add_argument("--prepared", help="prepared scene bytes (examples/prepare.rs --out)")
    p.add_argument("--config", help="a configuration file: name,value lines")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a configuration register (config_*, new_code, latching, external_mode) "
                        "and its value")
    p.add_argument("--reset-statistics", action="store_true",
                   help="start the node's statistics afresh (needs --code)")
    p.add_argument("--thresholds", help="the monitor example's --thresholds table, checked")
    p.add_argument("--events", metavar="OUT.csv",
                   help="the events the node holds, as the monitor example's --events")
    p.add_argument("--events-from", type=int, metavar="SEQ",
                   help="read the events from this sequence number (default: event_from)")
    args = p.parse_args()
    if args.scene and args.prepared:
        p.error("--scene or --prepared, not both")
    from pymodbus import FramerType
    if args.serial:
        from pymodbus.client import ModbusSerialClient
        client = ModbusSerialClient(args.serial, framer=FramerType.RTU, baudrate=args.baud,
                                    parity=args.parity, stopbits=2 if args.parity == "N" else 1,
                                    timeout=2)
    elif args.tcp:
        from pymodbus.client import ModbusTcpClient
        host, _, port = args.tcp.rpartition(":")
        if not host or not port.isdigit():
            p.error(f"--tcp {args.tcp}: HOST:PORT")
        client = ModbusTcpClient(host, port=int(port), framer=FramerType.RTU, timeout=2, retries=0)
    else:
        p.error("--tcp HOST:PORT or --serial DEVICE")
    try:
        settings = read_config(args.config) if args.config else []
        for s in args.set:
            name, eq, value = s.partition("=")
            if not eq:
                p.error(f"--set {s}: NAME=VALUE")
            settings.append((register(name.strip()), value.strip()))
        if args.scene:
            scene = prepare(read_scene(args.scene), args.core)
        else:
            scene = open(args.prepared, "rb").read() if args.prepared else None
    except (Failed, OSError) as e:
        print(f"commission: {e}", file=sys.stderr)
        return 1
    if not client.connect():
        print("commission: cannot connect", file=sys.stderr)
        return 1
    try:
        node = Node(client, args.registers, args.unit)
        planned = check_thresholds(node, args.thresholds, settings) if args.thresholds else None
        if args.code is not None:
            source = commission(node, args.code, settings, scene, args.reset_statistics)
        elif settings or scene or args.reset_statistics:
            raise Failed("writing needs the site's code (--code)")
        lines = status(node, args.events, args.events_from)
    except Failed as e:
        print(f"commission: {e}", file=sys.stderr)
        return 1
    finally:
        client.close()
    if args.reset_statistics:
        print("statistics reset")
    if args.code is not None and (settings or scene):
        print(f"commissioned: {len(settings)} registers{' and the scene' if scene else ''} "
              f"committed, config_source {source}")
    if planned:
        print(planned)
    for line in lines:
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
