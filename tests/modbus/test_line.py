"""The node with flash across resets, addressed on site: `tools/commission.py --scan`
finds it at the defaults, the tool gives it another unit id with the confirmation done
for it, and the node answers there after a reset (QEMU's `system_reset`, as
test_reset.py); a change that no request confirms is not kept through a reset, so a
wrong setting cannot lock the node out. Over the TCP bridge, as on a serial line:
the commit answered at the old unit id, the new one in force after it.

The answer delay in force holds each answer, as the node's own clock measures it
(its log, MODBUS_NODE_LOG).

MODBUS_QEMU_MONITOR: the monitor's loopback port.
"""

import os
import subprocess
import sys
import time

from pymodbus import FramerType
from pymodbus.client import ModbusTcpClient

from conftest import HOST, port, register_map
from test_config import code
from test_reset import reset_node

NEW_UNIT = 7


def commission(*args):
    return subprocess.run(
        [sys.executable, "tools/commission.py", "--tcp", f"{HOST}:{port()}",
         "--registers", os.environ["MODBUS_REGISTERS"], *args],
        capture_output=True, text=True, timeout=120)


def holding(name):
    return next(r["address"] for r in register_map()
                if r["table"] == "holding" and r["name"] == name)


def answering(unit, timeout_s=300):
    """A client once the node answers `unit` (it runs its self-test after a reset)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        c = ModbusTcpClient(HOST, port=port(), framer=FramerType.RTU, timeout=1, retries=0)
        if c.connect():
            try:
                r = c.read_holding_registers(holding("unit_id"), count=1, device_id=unit)
                if not r.isError():
                    assert r.registers[0] == unit
                    return c
            except Exception:  # noqa: BLE001 (a half frame while the node restarts)
                pass
        c.close()
        time.sleep(0.5)
    raise AssertionError(f"the node does not answer unit {unit}")


def silent(c, unit):
    try:
        r = c.read_holding_registers(holding("unit_id"), count=1, device_id=unit)
    except Exception:  # noqa: BLE001 (no answer: pymodbus raises or returns an error)
        return True
    return r.isError() and not getattr(r, "exception_code", None)


def test_scan_address_reset_and_an_unconfirmed_change(client):
    # The scan must report the map version the node's own register holds.
    version = client.read_holding_registers(holding("map_version"), count=1, device_id=1)
    assert not version.isError(), version
    client.close()
    scan = commission("--scan", "--units", "1-9", "--scan-timeout", "0.3")
    assert scan.returncode == 0, scan.stdout + scan.stderr
    assert "unit 1: " in scan.stdout, scan.stdout
    assert f"map_version {version.registers[0]}," in scan.stdout, scan.stdout
    assert "19200 baud 8E1" in scan.stdout, scan.stdout
    assert "1 nodes found, 0 clashes" in scan.stdout, scan.stdout

    done = commission("--code", str(code()), "--set", f"config_unit_id={NEW_UNIT}")
    assert done.returncode == 0, done.stderr
    c = answering(NEW_UNIT, 10)
    assert silent(c, 1), "the old unit id is not this node any more"
    lr = c.read_input_registers(next(r["address"] for r in register_map()
                                     if r["name"] == "line_status"), count=1, device_id=NEW_UNIT)
    assert lr.registers[0] & 2 == 0, "confirmed by the tool"
    c.close()
    scan = commission("--scan", "--units", "1-9", "--scan-timeout", "0.3")
    assert f"unit {NEW_UNIT}: " in scan.stdout and "1 nodes found" in scan.stdout, scan.stdout

    # Kept through a reset.
    reset_node()
    c = answering(NEW_UNIT)
    # A change no request confirms: committed by hand, never asked at its unit id,
    # then a reset within its window: the node starts at the confirmed one.
    assert not c.write_register(holding("unlock"), code(), device_id=NEW_UNIT).isError()
    assert not c.write_register(holding("config_unit_id"), 9, device_id=NEW_UNIT).isError()
    assert not c.write_register(holding("command"), 1, device_id=NEW_UNIT).isError()
    assert silent(c, NEW_UNIT), "unit 9 in force now"
    c.close()
    time.sleep(0.5)
    reset_node()
    c = answering(NEW_UNIT)
    c.close()

    # Back to the defaults for whatever runs after.
    done = commission("--unit", str(NEW_UNIT), "--code", str(code()), "--set", "config_unit_id=1")
    assert done.returncode == 0, done.stderr
    answering(1, 10).close()
    assert client.connect()


def answered_after(log, start):
    """The node's `answered N ms after the request` lines in its log (MODBUS_NODE_LOG)
    after its first `start` lines: N, measured by the node's own clock (SysTick, in
    QEMU's virtual time, which a master's wall clock does not follow)."""
    with open(log, errors="replace") as f:
        lines = f.read().splitlines()[start:]
    marker = "modbus: answered "
    return [int(l.split(marker)[1].split()[0]) for l in lines if marker in l]


def test_the_answer_delay_holds_each_answer(client):
    log = os.environ["MODBUS_NODE_LOG"]
    client.close()
    delay = 250
    done = commission("--code", str(code()), "--set", f"config_answer_delay={delay}")
    assert done.returncode == 0, done.stdout + done.stderr
    c = answering(1, 10)
    with open(log, errors="replace") as f:
        start = len(f.read().splitlines())
    for _ in range(3):
        r = c.read_holding_registers(holding("active_answer_delay"), count=1, device_id=1)
        assert not r.isError() and r.registers[0] == delay
    time.sleep(0.5)
    waited = answered_after(log, start)
    assert len(waited) >= 3, waited
    assert all(ms >= delay for ms in waited), waited
    assert all(ms < delay + 100 for ms in waited), waited
    c.close()
    # Back to none, which holds no answer.
    done = commission("--code", str(code()), "--set", "config_answer_delay=0")
    assert done.returncode == 0, done.stdout + done.stderr
    c = answering(1, 10)
    with open(log, errors="replace") as f:
        start = len(f.read().splitlines())
    assert not c.read_holding_registers(holding("unit_id"), count=1, device_id=1).isError()
    time.sleep(0.5)
    assert answered_after(log, start) == []
    c.close()
