#!/usr/bin/env python3
"""Commissions a misalign node over Modbus RTU (docs/modbus.md, "Commissioning from the
PC"): from what a reliability engineer planned (a scene file, a configuration file, the
monitor example's `--thresholds` table) it prepares the scene's bytes, checks every
value, unlocks the node with the site's code, writes the configuration and the scene to
its staged copy, reads them back, commits, checks that the node runs them, and prints
the node's status.

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
  the node applies as they are written and keeps with the commit (written alone, they
  need no commit); `--set NAME=VALUE` adds or overrides one.
  `cargo xtask modbus --default-config C.csv` writes the defaults.
- `--thresholds T.csv` (with `--scene`): the planner's table (`P,phi0,phi_warning,...`).
  It holds no register: it is checked against the scene and the configuration the node
  will run (its loads within the stop load and the highest accepted load; at each load
  the scene's critical angle, and d/b, or the margin, at the configuration's
  thresholds by the f64 reference, `examples/estimate --model reference`), and its
  alarm angles summed up on the way.
- `--events OUT.csv`: the events the node holds, in the monitor example's `--events`
  format (decoded as `misalign::modbus::event_from_registers` does), from its
  `event_from` or `--events-from SEQ`; read through the window, `event_from` put back,
  nothing acknowledged.
- `--reset-statistics`: the node's statistics (counts, time and energy per state,
  extremes, events dropped) start afresh, after a roller change say (the command 4),
  once everything else is in force: a refused run resets nothing.
- Line settings (`config_unit_id`, `config_baud`, `config_parity`,
  `config_answer_delay`, `config_bus_timeout`) are committed like the rest; the node
  answers the commit at its old settings and keeps the new ones only when a request
  reaches it at them within its `line_confirm_window`: the tool asks it at its new unit
  id (and, on `--serial`, at the new baud rate and parity) at once, and says whether
  it was confirmed. A node it cannot reach there goes back to its old settings by
  itself.
- `--scan`: every unit id from 1 to 247 (`--units FIRST-LAST` narrows it) asked once,
  with `--scan-timeout` seconds (default 0.1) for each answer: one line per node found
  (unit id, model name, map version, status, line settings in force); an answer that
  is not the node asked (another unit id in `unit_id`, or bytes that fail their CRC,
  as two nodes at one unit id make) is reported as a clash, not taken as a node.
- Without `--code`, nothing is written: the node's status and events only.

Register names, types and domains come from the register map (`--registers`, default
docs/modbus/registers.csv beside this tool, so that it runs from any folder); 32-bit
values high word first. Every value is checked against its register's type and domain
(the map's `min` and `max`) before the node is touched. Exit status 0 when the node
runs what was written; otherwise the reason (a value outside its register, a wrong
code, a lock-out, the commit's `commit_error`, any failure once unlocked) on stderr
and status 1, the switches put back, whatever was staged reverted, the node locked.
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


# The repository this tool sits in: the register map and `cargo run --example ...`.
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
REGISTERS = os.path.join(ROOT, "docs", "modbus", "registers.csv")


def f32_bits(x):
    """`x` rounded to the nearest f32, as its bits; OverflowError beyond the largest."""
    return struct.unpack(">I", struct.pack(">f", x))[0]


def f32(words):
    return struct.unpack(">f", struct.pack(">HH", *words))[0]


class Map:
    """The register map (docs/modbus/registers.csv's columns): each row by table and
    name, and each value a master writes checked against its register's type and
    domain (the columns `min` and `max`)."""

    def __init__(self, path):
        try:
            with open(path, newline="") as f:
                self.rows = {(r["table"], r["name"]): r for r in csv.DictReader(f)}
        except OSError as e:
            raise Failed(f"the register map {path}: {e.strerror}") from None

    def row(self, name, table="holding"):
        try:
            return self.rows[(table, name)]
        except KeyError:
            raise Failed(f"the register map has no {table} register {name}") from None

    def words(self, name, value):
        """`value` (text or a number) as the holding register's words, high word first;
        Failed, naming the register, for a value its type or domain does not hold."""
        r = self.row(name)
        if r["access"] != "rw":
            raise Failed(f"{name} is read only")
        ty, lo, hi, unit = r["type"], r.get("min", ""), r.get("max", ""), r["unit"]
        text = str(value).strip()
        within = f"from {lo} to {hi}{' ' + unit if unit else ''}"
        if ty == "f32":
            try:
                x = float(text)
                bits = f32_bits(x)
            except ValueError:
                raise Failed(f"{name} = {text}: not a number") from None
            except OverflowError:
                raise Failed(f"{name} = {text}: beyond the largest f32 ({within})") from None
            x = f32([bits >> 16, bits & 0xFFFF])
            if lo != "" and not math.isfinite(x):
                raise Failed(f"{name} = {text}: not a finite number ({within})")
            if lo != "" and not float(lo) <= x <= float(hi):
                raise Failed(f"{name} = {text}: outside its domain, {within}")
            return [bits >> 16, bits & 0xFFFF]
        if ty in ("u16", "u32"):
            try:
                v = int(text, 16) if text.lower().startswith("0x") else int(text)
            except ValueError:
                raise Failed(f"{name} = {text}: not a whole number ({within})") from None
            if not int(lo) <= v <= int(hi):
                raise Failed(f"{name} = {text}: outside its domain, a whole number {within}")
            return [v >> 16, v & 0xFFFF] if ty == "u32" else [v]
        raise Failed(f"{name}: a {ty} register, which this tool does not write")


class Node:
    def __init__(self, client, regs, unit, reconnect=None):
        self.c = client
        self.unit = unit
        self.map = regs
        self.rows = regs.rows
        self.row = regs.row
        # A new client at (baud, parity) on a serial line; None over TCP, where the
        # bridge carries the bytes whatever the node's UART runs.
        self.reconnect = reconnect

    def move(self, unit, baud, parity):
        """The node answers at these settings now: ask it there."""
        self.unit = unit
        if self.reconnect is not None:
            self.c.close()
            self.c = self.reconnect(baud, parity)

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
# committed configuration: nothing to commit for them.
SWITCHES = ("latching", "external_mode")
# The register `command`'s values.
COMMIT, REVERT, LOCK, RESET_STATISTICS = 1, 2, 3, 4
# The line settings a master must follow to reach the node after their commit.
MOVES = ("config_unit_id", "config_baud", "config_parity")
BAUD_RATES = (9600, 19200, 38400, 57600, 115200)
PARITY = {0: "N", 1: "O", 2: "E"}


def line_in_force(node, staged):
    """Before a commit that moves the node (a new unit id, baud rate or parity): its
    unit id, baud rate and parity in force, read while it answers there; None when the
    commit moves nothing."""
    if not any(n in MOVES for n, _, _ in staged):
        return None
    return {n: node.read("active_" + n[len("config_"):]) for n in MOVES}


def confirm_line(node, staged, was):
    """After a commit that moved the node from `was` (`line_in_force`): asks it at its
    new settings, which confirms them (`line_status` bit 1 clears)."""
    if was is None:
        return
    moved = {n: w for n, w, _ in staged if n in MOVES}
    now = {**was, **moved}
    unit, baud, parity = now["config_unit_id"][0], u32(now["config_baud"]), now["config_parity"][0]
    node.move(unit, baud, PARITY[parity])
    for _ in range(3):
        try:
            status = node.read("line_status", "input")[0]
        except Exception:  # noqa: BLE001 (no answer yet: asked again)
            continue
        if status & 2 == 0:
            return
    raise Failed(f"the node did not confirm its new line settings (unit {unit}, {baud} baud, "
                 f"parity {PARITY[parity]}): it goes back to the old ones within "
                 f"line_confirm_window")


def unlock(node, code):
    x = node.write("unlock", [code])
    if x == 3:
        raise Failed("wrong code (counted by the node; a few in a row lock it out)")
    if x == 1:
        raise Failed(f"locked out for {node.read('lockout')[0]} s after wrong codes")
    if x is not None:
        raise Failed(f"unlock: exception {x}")


def put_back(node, switched):
    """After a failure: the switches as they were, the staged copy reverted, the node
    locked; every step tried, whatever the others did. What failed, as text."""
    failed = []
    steps = [(name, words) for name, words in switched.items()]
    steps += [("command", [REVERT]), ("command", [LOCK])]
    for name, words in steps:
        try:
            x = node.write(name, words)
            if x is not None:
                failed.append(f"{name} {words}: exception {x}")
        except Exception as e:  # noqa: BLE001 (the line may be gone: say so, go on)
            failed.append(f"{name} {words}: {e}")
    return failed


def commission(node, code, settings, scene, reset_statistics=False):
    """Puts `settings` (name, words, text; every value checked against the map) and
    `scene` (prepared bytes) on the node with the site's `code`: unlocked, written,
    read back, committed (the switches alone need no commit), the active values read
    back, then the statistics reset if asked; the node locked. On any failure after
    the unlock, of any kind, the switches are put back, the staged copy reverted and
    the node locked before the failure goes on up, unless the commit was applied
    (then only the lock). Returns `config_source`."""
    if scene is not None:
        want = node.read("scene_bytes")[0]
        if want == 0:
            raise Failed("this node takes no scene over the bus")
        if len(scene) != want:
            raise Failed(f"the node takes {want} bytes of prepared scene, the file has {len(scene)}")
    staged = [s for s in settings if s[0] not in SWITCHES]
    # The switches as they were, put back if the run fails.
    switched = {name: node.read(name) for name, _, _ in settings if name in SWITCHES}
    unlock(node, code)
    # Once a commit applied the staged copy (and ended the unlock), a failure has
    # nothing to put back; after it the node is unlocked again only to reset.
    committed, unlocked = False, True
    try:
        for name, words, text in settings:
            x = node.write(name, words)
            if x is not None:
                raise Failed(f"{name} = {text}: exception {x}")
            if name != "new_code" and node.read(name) != words:
                raise Failed(f"{name} reads back {node.read(name)}, not {words}")
        if scene is not None:
            padded = scene + b"\0" * (len(scene) % 2)
            words = [int.from_bytes(padded[i:i + 2], "big") for i in range(0, len(padded), 2)]
            node.write_words(int(node.row("scene_0_word")["address"]), words)
            crc = int.from_bytes(scene[-4:], "little")
            if u32(node.read("scene_staged_crc")) != crc:
                raise Failed("the staged scene's CRC differs from the file's: bytes lost on the way")
        if staged or scene is not None:
            line_was = line_in_force(node, staged)
            x = node.write("command", [COMMIT])
            if x is not None:
                why = node.read("commit_error")[0]
                raise Failed(f"commit refused: {REASONS.get(why, why)} (commit_error {why:#x})")
            committed, unlocked = True, False
            # Line settings: the node answers at the new ones now; asked there, it
            # keeps them.
            was = node.unit
            try:
                confirm_line(node, staged, line_was)
            except Failed as e:
                node.unit = was
                raise e
            # What the node runs now.
            for name, words, _ in staged:
                active = "active_" + name[len("config_"):]
                if name.startswith("config_") and node.read(active) != words:
                    raise Failed(f"{active} reads {node.read(active)} after the commit")
            if scene is not None and u32(node.read("scene_active_crc")) != crc:
                raise Failed("the node does not run the scene after the commit")
        if reset_statistics:
            if committed:
                # The commit ended the unlock; the code may be the one it committed.
                new = [w[0] for n, w, _ in settings if n == "new_code"]
                unlock(node, new[-1] if new else code)
                unlocked = True
            x = node.write("command", [RESET_STATISTICS])
            if x is not None:
                raise Failed(f"reset of the statistics: exception {x}")
        if unlocked:
            node.write("command", [LOCK])
    except BaseException as e:
        failed = []
        if not committed:
            failed = put_back(node, switched)
        else:
            e.add_note("the configuration was committed")
            if unlocked:
                failed = put_back(node, {})  # nothing staged to revert: the lock
        if failed:
            e.add_note("putting the node back failed (" + "; ".join(failed) + "): it locks "
                       "itself when the unlock times out")
        raise
    return node.read("config_source")[0]


STATES = {0: "stopped", 1: "normal", 2: "microslip", 3: "gross slip", 4: "sensor fault"}


def settings_words(regs, settings):
    """Each (name, text) as (register, words, text): the name a configuration register
    (`config_` may be left out), the value within its register's type and domain;
    Failed naming the first that is not, before anything is written."""
    out = []
    for name, text in settings:
        if not (name.startswith("config_") or name in ("new_code",) + SWITCHES):
            if ("holding", "config_" + name) in regs.rows:
                name = "config_" + name
            elif ("holding", name) in regs.rows and regs.row(name)["access"] != "rw":
                raise Failed(f"{name} is read only")
            else:
                raise Failed(f"{name} is not a configuration register "
                             f"(config_*, new_code, {', '.join(SWITCHES)})")
        out.append((name, regs.words(name, text), text))
    return out


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
            out.append((row[0].strip(), row[1].strip()))
    return out


def read_scene(path):
    """The monitor example's scene file: a header, then R1,R2,G,nu,mu[,length]."""
    with open(path, newline="") as f:
        text = f.read()
    rows = [r for r in csv.reader(text.splitlines(), delimiter=";" if ";" in text else ",") if r]
    if len(rows) != 2 or len(rows[1]) not in (5, 6):
        raise Failed(f"{path}: a header and one row R1,R2,G,nu,mu[,length]")
    return [c.strip() for c in rows[1]]


def cargo_example(name, args, stdin=None):
    """`cargo run --release --example NAME -- ARGS` in this repository; its stdout."""
    done = subprocess.run(["cargo", "run", "--quiet", "--release", "--example", name, "--", *args],
                          input=stdin, capture_output=True, text=True, cwd=ROOT)
    if done.returncode != 0:
        raise Failed(f"examples/{name}: {done.stderr.strip()}")
    return done.stdout


def prepare(scene, core):
    """The scene's prepared bytes for the node's core, from examples/prepare.rs."""
    r1, r2, g, nu, mu, *length = scene
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "scene.bin")
        args = ["--type", "auto" if core == "f32" else "fixed-auto", "--out", out]
        args += ["--length", length[0]] if length else []
        cargo_example("prepare", args + ["--", r1, r2, g, nu, mu])
        with open(out, "rb") as f:
            return f.read()


PLANNED = ("phi_warning", "phi_warning_clear", "phi_alarm", "phi_alarm_clear")
# What the planner's angles are planned for, and how closely it finds them: the angle
# where the slip ratio d/b (or the margin) reaches the threshold, to within 1e-4 of d/b
# (1e-4 phi0 of the margin); the planner's bisection with either core is within 1e-5.
PLANNED_WITHIN = 1e-4


def read_thresholds(path, scene):
    """The planner's table, and the reference model's answer at each of its angles
    (examples/estimate --model reference: phi0, d/b, whether near the switch of
    contact models, where the planner's model for the whole range may be the other)."""
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        raise Failed(f"{path}: {e.strerror}") from None
    if not rows or not {"P", "phi0", *PLANNED} <= set(rows[0]):
        raise Failed(f"{path}: not the planner's table (P,phi0,{','.join(PLANNED)})")
    if scene is None:
        raise Failed("--thresholds needs the scene file (--scene) the table was planned for")
    r1, r2, g, nu, mu, *length = scene
    points = [(r["P"], r[c] or "0") for r in rows for c in ("phi0",) + PLANNED]
    lines = ["R1,R2,G,nu,mu,P,phi" + (",length" if length else "")]
    lines += [",".join([r1, r2, g, nu, mu, P, phi] + length) for P, phi in points]
    answers = list(csv.DictReader(cargo_example("estimate", ["--model", "reference"],
                                                "\n".join(lines) + "\n").splitlines()))
    if len(answers) != len(points):
        raise Failed(f"{path}: the reference model answered {len(answers)} rows of {len(points)}")
    return rows, answers


def check_thresholds(node, path, table, settings):
    """The planner's table against the configuration the node will run: its loads
    within (stop load, highest accepted load], its critical angles the scene's, and
    each angle where the configuration's d/b (or margin) thresholds are reached. A
    summary line."""
    rows, answers = table

    def value(name):
        for n, words, _ in reversed(settings):
            if n == name:
                break
        else:
            words = node.read(name)
        return f32(words) if len(words) == 2 else words[0]
    stop, top = value("config_stop_load"), value("config_load_max")
    loads = [float(r["P"]) for r in rows]
    if min(loads) <= stop or max(loads) > top * (1 + 1e-6):
        raise Failed(f"{path}: loads {min(loads)} to {max(loads)} N, outside the configuration's "
                     f"stop load {stop} N to highest load {top} N: planned with another configuration")
    margin = value("config_thresholds_on") == 1
    w, a, d = value("config_warning"), value("config_alarm"), value("config_deadband")
    sign = 1 if margin else -1
    targets = {"phi_warning": (w, "config_warning"),
               "phi_warning_clear": (w + sign * d, "config_warning " + "-+"[margin] + " config_deadband"),
               "phi_alarm": (a, "config_alarm"),
               "phi_alarm_clear": (a + sign * d, "config_alarm " + "-+"[margin] + " config_deadband")}
    per_row = 1 + len(PLANNED)
    for i, r in enumerate(rows):
        at = answers[i * per_row:(i + 1) * per_row]
        if any("near_model_switch" in x["flags"] or x["error"] for x in at):
            continue
        phi0 = float(at[0]["phi0"])
        if abs(float(r["phi0"]) - phi0) > PLANNED_WITHIN * phi0:
            raise Failed(f"{path}: at P = {r['P']} N phi0 is {r['phi0']} rad, the scene's is "
                         f"{phi0:.6g} rad: planned for another scene")
        for col, x in zip(PLANNED, at[1:]):
            if r[col] == "":
                continue
            target, what = targets[col]
            got = phi0 - float(r[col]) if margin else float(x["s"])
            if abs(got - target) > PLANNED_WITHIN * (phi0 if margin else 1):
                quantity = "the margin" if margin else "d/b"
                raise Failed(f"{path}: at P = {r['P']} N, {col} = {r[col]} rad gives {quantity} "
                             f"{got:.6g}, where the configuration's {what} is {target:.6g}: "
                             f"planned with another configuration")
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


def crc16(data):
    """Modbus RTU's CRC-16 (0xA001 reflected, from 0xFFFF), low byte first on the wire."""
    crc = 0xFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return bytes([crc & 0xFF, crc >> 8])


def ask_raw(client, unit, at, timeout):
    """A read of two holding registers from `at`, sent on the client's own port as
    bytes; every byte that comes back within `timeout` s (less once a whole answer
    is in), so that garbled bytes are seen rather than taken for silence."""
    import time
    body = bytes([unit, 3, at >> 8, at & 0xFF, 0, 2])
    port = client.socket
    send = port.sendall if hasattr(port, "sendall") else port.write

    def recv():
        """Bytes now (b"" for none yet); None at the end of the connection."""
        if hasattr(port, "recv"):
            try:
                return port.recv(256) or None
            except TimeoutError:
                return b""
        return port.read(port.in_waiting or 1)

    got = b""
    kept = port.gettimeout() if hasattr(port, "recv") else None
    if hasattr(port, "recv"):
        port.settimeout(0.02)
    try:
        # A late answer to the unit asked before is not this one's.
        if hasattr(port, "recv"):
            while recv():
                pass
        else:
            port.reset_input_buffer()
        send(body + crc16(body))
        deadline = time.monotonic() + timeout
        extended = False
        while True:
            if time.monotonic() >= deadline:
                # The start of this unit's answer, late: the rest gets as long again.
                if extended or not (got[:3] == bytes([unit, 3, 4]) and len(got) < 9):
                    break
                deadline, extended = time.monotonic() + timeout, True
            chunk = recv()
            if chunk is None:
                break
            got += chunk
            if answer_of(got, unit) is not None:
                break
    finally:
        if hasattr(port, "recv"):
            port.settimeout(kept)
    return got


def answer_of(got, unit):
    """The two registers of `got` if it is exactly one valid answer of `unit`."""
    if len(got) == 9 and got[:3] == bytes([unit, 3, 4]) and crc16(got[:7]) == got[7:]:
        return [got[3] << 8 | got[4], got[5] << 8 | got[6]]
    return None


def scan(client, regs, units, timeout):
    """Each unit id in `units` asked once (`unit_id` and `map_version`): the nodes
    found as lines, and the clashes (an answer that is not the node asked: bytes that
    are not one valid answer, as two nodes answering at once make, or another unit
    id in `unit_id`)."""
    found, clashes = [], []
    at = int(regs.row("unit_id")["address"])
    for unit in units:
        got = ask_raw(client, unit, at, timeout)
        if not got:
            continue
        registers = answer_of(got, unit)
        if registers is None:
            if len(got) == 5 and got[0] == unit and got[1] == 0x83 and crc16(got[:3]) == got[3:]:
                clashes.append(f"unit {unit}: exception {got[2]} to a read every node "
                               f"answers: not this map's node")
            else:
                clashes.append(f"unit {unit}: clash: {len(got)} bytes that are not one valid answer "
                               f"(two nodes at one unit id?): {got[:12].hex()}")
            continue
        if registers[0] != unit:
            clashes.append(f"unit {unit}: answered with unit_id {registers[0]} (a clash)")
            continue
        node = Node(client, regs, unit)
        try:
            found.append(describe(node, registers[1]))
        except Exception as e:  # noqa: BLE001 (garbled mid-way: a clash)
            clashes.append(f"unit {unit}: clash while reading it: {e}")
    return found, clashes


def describe(node, map_version):
    """One line of --scan: unit id, model name, map version, status, line settings."""
    model = "?"
    info = node.c.read_device_information(read_code=1, device_id=node.unit)
    if not info.isError():
        model = info.information.get(1, b"?").decode(errors="replace")
    s = node.read("status", "input")[0]
    line = ""
    if map_version >= 3 and ("holding", "active_baud") in node.rows:
        baud = u32(node.read("active_baud"))
        parity = PARITY.get(node.read("active_parity")[0], "?")
        delay = node.read("active_answer_delay")[0]
        timeout = node.read("active_bus_timeout")[0]
        line = (f", {baud} baud 8{parity}{2 if parity == 'N' else 1}, answer delay {delay} ms, "
                f"bus timeout {timeout} s")
    return (f"unit {node.unit}: {model}, map_version {map_version}, "
            f"state {STATES.get(s & 0xFF, s & 0xFF)}, NE 107 {s >> 8 & 15}{line}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--tcp", metavar="HOST:PORT", help="a TCP bridge (RTU frames over TCP)")
    p.add_argument("--serial", help="a serial device instead of --tcp")
    p.add_argument("--baud", type=int, default=19200)
    p.add_argument("--parity", choices=["E", "O", "N"], default="E",
                   help="the serial line's parity (default E: 8E1; N: 8N2, as Modbus asks)")
    p.add_argument("--unit", type=int, default=1)
    p.add_argument("--registers", default=REGISTERS,
                   help="the register map (default: this repository's docs/modbus/registers.csv)")
    p.add_argument("--code", help="the site's code (without it: the status only)")
    p.add_argument("--scene", help="the monitor example's scene file (R1,R2,G,nu,mu[,length])")
    p.add_argument("--core", choices=["f32", "fixed"], default="f32",
                   help="the node's core, for --scene (default f32)")
    p.add_argument("--prepared", help="prepared scene bytes (examples/prepare.rs --out)")
    p.add_argument("--config", help="a configuration file: name,value lines")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a configuration register (config_*, new_code, latching, external_mode) "
                        "and its value")
    p.add_argument("--reset-statistics", action="store_true",
                   help="start the node's statistics afresh (needs --code), once the rest is done")
    p.add_argument("--thresholds", help="the monitor example's --thresholds table, checked "
                                        "(needs --scene)")
    p.add_argument("--events", metavar="OUT.csv",
                   help="the events the node holds, as the monitor example's --events")
    p.add_argument("--events-from", type=int, metavar="SEQ",
                   help="read the events from this sequence number (default: event_from)")
    p.add_argument("--scan", action="store_true",
                   help="list every node on the line (unit id, model, map version, status, "
                        "line settings)")
    p.add_argument("--units", default="1-247", metavar="FIRST-LAST",
                   help="the unit ids --scan asks (default 1-247)")
    p.add_argument("--scan-timeout", type=float, default=0.1, metavar="S",
                   help="seconds --scan waits for each answer (default 0.1)")
    args = p.parse_args()
    if args.scene and args.prepared:
        p.error("--scene or --prepared, not both")
    if not (args.tcp or args.serial):
        p.error("--tcp HOST:PORT or --serial DEVICE")
    if args.tcp:
        host, _, port = args.tcp.rpartition(":")
        if not host or not port.isdigit():
            p.error(f"--tcp {args.tcp}: HOST:PORT")
    # Everything checked before the node is touched: the map, every value against its
    # register's type and domain, the code, the scene, the planner's table.
    try:
        regs = Map(args.registers)
        settings = read_config(args.config) if args.config else []
        for s in args.set:
            name, eq, value = s.partition("=")
            if not eq:
                p.error(f"--set {s}: NAME=VALUE")
            settings.append((name.strip(), value.strip()))
        settings = settings_words(regs, settings)
        code = None
        if args.code is not None:
            try:
                code = regs.words("unlock", args.code)[0]
            except Failed:
                r = regs.row("unlock")
                raise Failed(f"--code {args.code}: a site's code is a whole number from "
                             f"{r['min']} to {r['max']}") from None
        if code is None and (settings or args.scene or args.prepared or args.reset_statistics):
            raise Failed("writing needs the site's code (--code)")
        scene_row = read_scene(args.scene) if args.scene else None
        if args.scene:
            scene = prepare(scene_row, args.core)
        else:
            scene = open(args.prepared, "rb").read() if args.prepared else None
        table = read_thresholds(args.thresholds, scene_row) if args.thresholds else None
    except (Failed, OSError) as e:
        print(f"commission: {e}", file=sys.stderr)
        return 1
    for name, words, text in settings:
        if name == "config_baud" and u32(words) not in BAUD_RATES:
            print(f"commission: config_baud = {text}: one of {', '.join(map(str, BAUD_RATES))}",
                  file=sys.stderr)
            return 1
    from pymodbus import FramerType

    def connect(baud, parity, timeout=2):
        if args.serial:
            from pymodbus.client import ModbusSerialClient
            c = ModbusSerialClient(args.serial, framer=FramerType.RTU, baudrate=baud,
                                   parity=parity, stopbits=2 if parity == "N" else 1,
                                   timeout=timeout, retries=0)
        else:
            from pymodbus.client import ModbusTcpClient
            c = ModbusTcpClient(host, port=int(port), framer=FramerType.RTU, timeout=timeout,
                                retries=0)
        if not c.connect():
            raise Failed("cannot connect")
        return c

    if args.scan:
        try:
            first, _, last = args.units.partition("-")
            units = range(int(first), int(last or first) + 1)
            client = connect(args.baud, args.parity, args.scan_timeout)
        except (ValueError, Failed) as e:
            print(f"commission: --scan: {e}", file=sys.stderr)
            return 1
        try:
            found, clashes = scan(client, regs, units, args.scan_timeout)
        finally:
            client.close()
        for line in found:
            print(line)
        for line in clashes:
            print(line)
        print(f"{len(found)} nodes found, {len(clashes)} clashes, units {units.start}-{units.stop - 1}")
        return 1 if clashes else 0
    try:
        client = connect(args.baud, args.parity)
    except Failed:
        print("commission: cannot connect", file=sys.stderr)
        return 1
    try:
        node = Node(client, regs, args.unit,
                    (lambda b, par: connect(b, par)) if args.serial else None)
        planned = check_thresholds(node, args.thresholds, table, settings) if table else None
        if code is not None:
            source = commission(node, code, settings, scene, args.reset_statistics)
        lines = status(node, args.events, args.events_from)
    except Exception as e:  # noqa: BLE001 (any failure: said, never a traceback)
        why = str(e) if isinstance(e, Failed) else f"{type(e).__name__}: {e}"
        print("commission: " + "; ".join([why, *getattr(e, "__notes__", [])]), file=sys.stderr)
        return 1
    finally:
        node.c.close() if 'node' in locals() else client.close()
    if args.reset_statistics:
        print("statistics reset")
    switched = [n for n, _, _ in settings if n in SWITCHES]
    staged = len(settings) - len(switched)
    if code is not None and (staged or scene):
        print(f"commissioned: {staged} registers{' and the scene' if scene else ''} "
              f"committed, config_source {source}")
    if code is not None and switched:
        print(f"switched: {', '.join(switched)} (applied at once and kept), "
              f"config_source {source}")
    if planned:
        print(planned)
    for line in lines:
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
