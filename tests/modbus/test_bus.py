"""Eight nodes on one RS-485 line (lab/bus/bus.py): seven QEMU nodes with flash (four
Cortex-M4F, three Cortex-M0 micro:bits) and a Pico in its emulator, all at the
defaults (unit id 1, 19200 baud, 8E1). `cargo xtask modbus --bus` builds the images and
runs this file; it then compares each QEMU node's events with the host's replay.

- Two new nodes wired at once answer unit 1 together: `--scan` reports the clash.
- The technician's walkthrough of docs/modbus.md: each node wired alone with those
  already addressed, found at unit 1 by `tools/commission.py --scan`, given 11, 12, ...
  by the tool; a last scan lists the eight. Then all polled together: the QEMU nodes
  fed the same samples, interleaved, every event read back (written for xtask).
- A node at the wrong baud rate, a babbler and a stopped node on the line: every other
  node answers every poll; the master's timeouts and retries are counted and printed.
- A baud-rate change never confirmed: the node goes back to 19200 within its window
  (line_reverts counts it); one confirmed at the new rate is kept through a reset.

QEMU's UART has no baud rate: the bus holds each party's (README.md); the test sets
it as the node's `active_baud` and `active_parity` say, after each change.

Environment: BUS_M4F_ELF, BUS_M0_ELF, PICO_ELF, PICO_DRIVE, MODBUS_REGISTERS,
MODBUS_SAMPLES, MODBUS_UNLOCK_CODE, BUS_OUT (a folder: events-NAME.csv per QEMU node).
"""

import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time

import pytest
from pymodbus import FramerType
from pymodbus.client import ModbusTcpClient

from conftest import register_map
from master import Map, Master, read_samples

HOST = "127.0.0.1"
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# name: (machine, ELF variable); the Pico last.
QEMU_NODES = [("m4f-1", "mps2-an386", "BUS_M4F_ELF"), ("m0-1", "microbit", "BUS_M0_ELF"),
              ("m4f-2", "mps2-an386", "BUS_M4F_ELF"), ("m0-2", "microbit", "BUS_M0_ELF"),
              ("m4f-3", "mps2-an386", "BUS_M4F_ELF"), ("m0-3", "microbit", "BUS_M0_ELF"),
              ("m4f-4", "mps2-an386", "BUS_M4F_ELF")]
NODES = [n for n, _, _ in QEMU_NODES] + ["pico"]
FIRST_UNIT = 11  # the walkthrough's: the nip's number plus 10
UNITS = {n: FIRST_UNIT + k for k, n in enumerate(NODES)}
# The share of the line's time the babbler holds with its garbage.
BABBLE_DUTY = 0.1


def free_port():
    with socket.socket() as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


def wait_for_log(path, what, timeout_s):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        with open(path, errors="replace") as f:
            if what in f.read():
                return
        time.sleep(0.5)
    raise AssertionError(f"{path}: no {what!r} within {timeout_s} s")


class Bench:
    """The bus, the nodes on it, their QEMU monitors and the Pico's control port."""

    def __init__(self, tmp):
        self.tmp = tmp
        self.procs = []
        self.serial = {n: free_port() for n in NODES}
        self.monitor = {n: free_port() for n, _, _ in QEMU_NODES}
        self.master, self.control = free_port(), free_port()
        for name, machine, elf in QEMU_NODES:
            env = dict(os.environ, MISALIGN_QEMU_MACHINE=machine, MISALIGN_QEMU_TIMEOUT="0",
                       MISALIGN_QEMU_SERIAL_PORT=str(self.serial[name]),
                       MISALIGN_QEMU_MONITOR_PORT=str(self.monitor[name]),
                       MISALIGN_QEMU_PARENT=str(os.getpid()))
            self.spawn(name, [os.path.join(ROOT, "lab/qemu-run"), machine, os.environ[elf]], env)
        pico_flash = os.path.join(tmp, "pico-flash.bin")
        self.pico_control = free_port()
        self.spawn("pico", ["node", os.path.join(ROOT, "lab/pico/harness.mjs"),
                            "--elf", os.environ["PICO_ELF"], "--flash", pico_flash,
                            "--drive", os.environ["PICO_DRIVE"], "--port", str(self.serial["pico"]),
                            "--control", str(self.pico_control), "--realtime",
                            "--parent", str(os.getpid())], dict(os.environ))
        for name in NODES:
            wait_for_log(self.log(name), "modbus: serving", 300)
        nodes = [a for n in NODES for a in ("--node", f"{n}={HOST}:{self.serial[n]}")]
        off = [a for n in NODES + ["noise"] for a in ("--off", n)]
        self.spawn("bus", [sys.executable, os.path.join(ROOT, "lab/bus/bus.py"),
                           "--master", str(self.master), "--control", str(self.control),
                           "--babbler", "noise", "--duty", str(BABBLE_DUTY), *nodes, *off], dict(os.environ))
        wait_for_log(self.log("bus"), "bus: master on", 30)

    def log(self, name):
        return os.path.join(self.tmp, f"{name}.log")

    def spawn(self, name, argv, env):
        with open(self.log(name), "w") as out:
            self.procs.append(subprocess.Popen(argv, env=env, stdout=out, stderr=subprocess.STDOUT,
                                               stdin=subprocess.DEVNULL, start_new_session=True))

    def close(self):
        for p in self.procs:
            try:
                os.killpg(p.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
            p.wait(timeout=30)

    def bus(self, line):
        """One command on the bus's control port; its JSON answer."""
        with socket.create_connection((HOST, self.control), timeout=10) as s:
            s.sendall((line + "\n").encode())
            answer = b""
            while not answer.endswith(b"\n"):
                answer += s.recv(65536)
        return json.loads(answer)

    def qemu(self, name, command):
        """One command to a QEMU node's monitor (stop, cont, system_reset)."""
        with socket.create_connection((HOST, self.monitor[name]), timeout=10) as s:
            s.sendall(f"{command}\n".encode())
            time.sleep(0.3)


@pytest.fixture(scope="module")
def bench():
    tmp = tempfile.mkdtemp(prefix="bus-")
    b = Bench(tmp)
    yield b
    print("\nthe line at the end:", json.dumps(b.bus("stats")))
    b.close()


def holding(name):
    return next(r["address"] for r in register_map() if r["table"] == "holding" and r["name"] == name)


def input_reg(name):
    return next(r["address"] for r in register_map() if r["table"] == "input" and r["name"] == name)


def client(bench, timeout=1.0):
    c = ModbusTcpClient(HOST, port=bench.master, framer=FramerType.RTU, timeout=timeout, retries=0)
    assert c.connect()
    return c


def commission(bench, *args):
    done = subprocess.run([sys.executable, os.path.join(ROOT, "tools/commission.py"), "--tcp",
                           f"{HOST}:{bench.master}", "--registers", os.environ["MODBUS_REGISTERS"], *args],
                          capture_output=True, text=True, timeout=300)
    print(f"$ commission.py {' '.join(args)}\n{done.stdout}{done.stderr}")
    return done


def scan(bench, last):
    return commission(bench, "--scan", "--units", f"1-{last}", "--scan-timeout", "1.0")


def code():
    return os.environ["MODBUS_UNLOCK_CODE"]


class Tally:
    """The master's polls: each a read with up to `tries` attempts; timeouts (no answer
    or a garbled one) and retries counted per unit."""

    def __init__(self, c, tries=4):
        self.c, self.tries = c, tries
        self.timeouts, self.retries, self.polls, self.failed = {}, {}, {}, {}

    def read(self, unit, address, count, table="holding"):
        self.polls[unit] = self.polls.get(unit, 0) + 1
        for attempt in range(self.tries):
            if attempt:
                self.retries[unit] = self.retries.get(unit, 0) + 1
            try:
                f = self.c.read_holding_registers if table == "holding" else self.c.read_input_registers
                r = f(address, count=count, device_id=unit)
                if not r.isError():
                    return r.registers
            except Exception:  # noqa: BLE001 (no answer, or one that failed its CRC)
                pass
            self.timeouts[unit] = self.timeouts.get(unit, 0) + 1
        self.failed[unit] = self.failed.get(unit, 0) + 1
        return None

    def report(self, title):
        print(f"\n{title}: unit polls timeouts retries failed")
        for u in sorted(self.polls):
            print(f"  {u:4} {self.polls[u]:5} {self.timeouts.get(u, 0):8} "
                  f"{self.retries.get(u, 0):7} {self.failed.get(u, 0):6}")


def test_two_new_nodes_at_unit_1_are_a_clash(bench):
    bench.bus(f"wire {NODES[0]} on")
    bench.bus(f"wire {NODES[1]} on")
    try:
        done = scan(bench, 3)
    finally:
        bench.bus(f"wire {NODES[1]} off")
    assert "unit 1: clash" in done.stdout and "0 nodes found, 1 clashes" in done.stdout, done.stdout
    assert done.returncode == 1


def test_eight_nodes_addressed_one_by_one_through_commission_py(bench):
    for k, name in enumerate(NODES):
        bench.bus(f"wire {name} on")
        done = scan(bench, FIRST_UNIT + k)
        assert "unit 1: " in done.stdout and f"{k + 1} nodes found, 0 clashes" in done.stdout, done.stdout
        done = commission(bench, "--code", code(), "--set", f"config_unit_id={UNITS[name]}")
        assert done.returncode == 0, done.stdout + done.stderr
    done = scan(bench, FIRST_UNIT + len(NODES))
    assert f"{len(NODES)} nodes found, 0 clashes" in done.stdout, done.stdout
    for name in NODES:
        assert f"unit {UNITS[name]}: " in done.stdout, (name, done.stdout)
    assert "unit 1: " not in done.stdout


def test_polled_together_each_node_gives_its_own_events(bench):
    # 5 s for an answer, as master.py's: a write is not repeated (a repeated batch of
    # samples would be refused as out of order, and the events would differ).
    c = client(bench, timeout=5.0)
    regmap = Map(os.environ["MODBUS_REGISTERS"])
    samples = read_samples(os.environ["MODBUS_SAMPLES"])
    masters = {n: Master(c, regmap, unit=UNITS[n]) for n, _, _ in QEMU_NODES}
    tally = Tally(c)
    start = time.monotonic()
    i = rounds = 0
    while i < len(samples):
        # As Master.run: the full block (fewer samples) once any carries a speed.
        basic = all(x[3] is None and x[4] is None for x in samples[i:i + regmap.samples])
        n = regmap.samples if basic else regmap.full
        for name, m in masters.items():
            m.feed(samples[i:i + n])
            # Events read every tenth round and at the end: the window holds more
            # than ten rounds' worth, and missed ones are counted below.
            if rounds % 10 == 9 or i + n >= len(samples):
                m.read_events()
        # The Pico runs on its own sensors: polled for its samples count meanwhile.
        assert tally.read(UNITS["pico"], input_reg("samples"), 2, "input") is not None
        i += n
        rounds += 1
    print(f"\n{len(samples)} samples fed to each of {len(masters)} QEMU nodes in "
          f"{time.monotonic() - start:.1f} s")
    for name, m in masters.items():
        assert m.missed == 0, f"{name}: {m.missed} events lost"
        with open(os.path.join(os.environ["BUS_OUT"], f"events-{name}.csv"), "w") as f:
            f.write(",".join(["event"] + [f"w{k}" for k in range(regmap.stride)]) + "\n")
            for k, e in enumerate(m.events):
                f.write(",".join(str(v) for v in [k] + list(e)) + "\n")
        print(f"  {name} (unit {UNITS[name]}): {len(m.events)} events")
    c.close()


def test_a_wrong_baud_rate_a_babbler_and_a_stopped_node_do_not_stop_the_others(bench):
    wrong, stopped = "m0-1", "m4f-2"
    bench.bus(f"set {wrong} 9600 even")
    bench.qemu(stopped, "stop")
    bench.bus("wire noise on")
    c = client(bench, timeout=1.0)
    tally = Tally(c, tries=5)
    rounds = 3
    wrong_answers = []
    try:
        for _ in range(rounds):
            for name in NODES:
                got = tally.read(UNITS[name], holding("unit_id"), 1)
                expected = None if name in (wrong, stopped) else [UNITS[name]]
                if got != expected:
                    wrong_answers.append(f"{name}: {got}")
    finally:
        c.close()
        bench.bus("wire noise off")
        bench.qemu(stopped, "cont")
        bench.bus(f"set {wrong} 19200 even")
    tally.report(f"{rounds} rounds, {wrong} at 9600 baud, {stopped} stopped, a babbler on "
                 f"{bench.bus('stats')['noise']['sent']} characters")
    assert not wrong_answers, wrong_answers
    stats = bench.bus("stats")
    assert stats["noise"]["collided"] > 0, "the babbler never met a frame: the test tested nothing"
    healthy = [UNITS[n] for n in NODES if n not in (wrong, stopped)]
    assert all(tally.failed.get(u, 0) == 0 for u in healthy)
    assert sum(tally.retries.get(u, 0) for u in healthy) > 0, "no retry counted: was the babbler on?"
    # Both back once the line is right again.
    c = client(bench)
    for name in (wrong, stopped):
        r = Tally(c).read(UNITS[name], holding("unit_id"), 1)
        assert r == [UNITS[name]], name
    c.close()


def read(c, unit, name, table="holding"):
    a = holding(name) if table == "holding" else input_reg(name)
    n = 2 if name in ("active_baud", "config_baud", "line_reverts") else 1
    f = c.read_holding_registers if table == "holding" else c.read_input_registers
    for _ in range(5):
        try:
            r = f(a, count=n, device_id=unit)
            if not r.isError():
                w = r.registers
                return w[0] << 16 | w[1] if n == 2 else w[0]
        except Exception:  # noqa: BLE001 (a frame lost: asked again)
            pass
        time.sleep(0.2)
    raise AssertionError(f"unit {unit}: {name} not read")


def commit_baud(c, unit, baud):
    """Unlocks, stages a baud rate, commits: answered at the old settings."""
    for name, value in (("unlock", int(code())), ("config_baud", None), ("command", 1)):
        if value is None:
            r = c.write_registers(holding(name), [baud >> 16, baud & 0xFFFF], device_id=unit)
        else:
            r = c.write_register(holding(name), value, device_id=unit)
        assert not r.isError(), (name, r)


def test_a_change_never_confirmed_reverts_and_a_confirmed_one_survives_a_reset(bench):
    never, kept = "m0-2", "m4f-3"
    # 5 s for an answer: a commit writes the node's flash first (the micro:bit's NVMC).
    c = client(bench, timeout=5.0)
    window = read(c, UNITS[never], "line_confirm_window")
    reverts = read(c, UNITS[never], "line_reverts", "input")
    start = time.monotonic()
    commit_baud(c, UNITS[never], 57600)
    bench.bus(f"set {never} 57600 even")  # its UART now runs at 57600; nobody asks it there
    commit_baud(c, UNITS[kept], 38400)
    bench.bus(f"set {kept} 38400 even")
    bench.bus("set master 38400 even")
    assert read(c, UNITS[kept], "active_baud") == 38400  # the request that confirms it
    assert read(c, UNITS[kept], "line_status", "input") & 2 == 0, "confirmed"
    bench.qemu(kept, "system_reset")
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline:
        with open(bench.log(kept), errors="replace") as f:
            if f.read().count("modbus: serving") >= 2:
                break
        time.sleep(0.5)
    assert read(c, UNITS[kept], "active_baud") == 38400, "kept through the reset"
    assert read(c, UNITS[kept], "active_unit_id") == UNITS[kept]
    # The master back at 19200 for the node that waits; this one stays at 38400.
    bench.bus("set master 19200 even")
    # The node never asked at 57600 goes back by itself within its window. The master,
    # at 19200, has no answer from it meanwhile.
    assert Tally(c, tries=1).read(UNITS[never], holding("unit_id"), 1) is None
    time.sleep(max(0.0, window + 2 - (time.monotonic() - start)))
    bench.bus(f"set {never} 19200 even")  # what its active_baud is about to say
    assert read(c, UNITS[never], "active_baud") == 19200
    assert read(c, UNITS[never], "line_reverts", "input") == reverts + 1
    print(f"\nunconfirmed change undone after its {window} s window; the confirmed one kept "
          f"through a reset ({time.monotonic() - start:.0f} s)")
    c.close()
