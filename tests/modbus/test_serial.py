"""The commissioning tool over a serial line, for real: a second QEMU of the same node
image with its serial0 on a pseudo-terminal (`-serial pty`: lab/qemu-run with
MISALIGN_QEMU_SERIAL=pty; QEMU's monitor names the terminal, `info chardev`), and
`tools/commission.py --serial /dev/pts/N` (pymodbus's serial client over pyserial)
unlocking, writing, committing and reading back; then pymodbus's serial client reads
the node's active configuration. 8N2: Linux refuses to set parity on a
pseudo-terminal (EINVAL), which carries none; a real RS-485 line runs 8E1, the default.

The environment adds MODBUS_ELF and MODBUS_MACHINE: the node's image and its QEMU
machine.
"""

import os
import re
import subprocess
import sys
import socket
import threading
import time

import pytest
from pymodbus import FramerType
from pymodbus.client import ModbusSerialClient

from conftest import HOST, UNIT, register_map
from test_config import code

ON_DELAY_MS = 2500


def free_port():
    with socket.socket() as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


def pty_of(monitor_port, timeout_s=60):
    """The pseudo-terminal of serial0, from QEMU's monitor (`info chardev`)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            with socket.create_connection((HOST, monitor_port), timeout=5) as s:
                s.recv(4096)  # the banner and prompt
                s.sendall(b"info chardev\n")
                time.sleep(0.5)
                m = re.search(rb"serial0: filename=pty:(\S+)", s.recv(4096))
                if m:
                    return m.group(1).decode()
        except OSError:
            pass
        time.sleep(0.5)
    raise AssertionError("QEMU named no pseudo-terminal for serial0")


@pytest.fixture(scope="module")
def pty():
    """The node in QEMU on a pseudo-terminal: its path, once the node serves."""
    monitor = free_port()
    env = dict(os.environ, MISALIGN_QEMU_SERIAL="pty", MISALIGN_QEMU_TIMEOUT="0",
               MISALIGN_QEMU_MACHINE=os.environ["MODBUS_MACHINE"],
               MISALIGN_QEMU_MONITOR_PORT=str(monitor), MISALIGN_QEMU_PARENT=str(os.getpid()))
    env.pop("MISALIGN_QEMU_SERIAL_PORT", None)
    node = subprocess.Popen(["lab/qemu-run", os.environ["MODBUS_MACHINE"], os.environ["MODBUS_ELF"]],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            errors="replace", start_new_session=True)
    serving = threading.Event()

    def watch():
        for line in node.stdout:
            if "modbus: serving" in line:
                serving.set()

    threading.Thread(target=watch, daemon=True).start()
    try:
        path = pty_of(monitor)
        assert serving.wait(300), "the node on a pty did not serve"
        yield path
    finally:
        os.killpg(node.pid, 15)
        node.wait(timeout=30)


def commission(*args):
    return subprocess.run([sys.executable, "tools/commission.py", *args,
                           "--registers", os.environ["MODBUS_REGISTERS"]],
                          capture_output=True, text=True, timeout=120)


def test_the_commissioning_tool_commissions_over_a_serial_line(pty):
    assert pty.startswith("/dev/pts/"), pty
    done = commission("--serial", pty, "--parity", "N", "--code", str(code()),
                      "--set", f"config_on_delay={ON_DELAY_MS}")
    assert done.returncode == 0, done.stderr
    assert "config_source 1" in done.stdout, done.stdout
    # Read back by another master on the same line.
    address = next(r["address"] for r in register_map()
                   if r["table"] == "holding" and r["name"] == "active_on_delay")
    client = ModbusSerialClient(pty, framer=FramerType.RTU, baudrate=19200, parity="N", stopbits=2,
                                timeout=2)
    assert client.connect()
    try:
        r = client.read_holding_registers(address, count=2, device_id=UNIT)
        assert not r.isError(), r
        assert r.registers[0] << 16 | r.registers[1] == ON_DELAY_MS
    finally:
        client.close()
    # Status only, without the code: the node's state read over the line.
    status = commission("--serial", pty, "--parity", "N")
    assert status.returncode == 0, status.stderr
    assert "config_source 1" in status.stdout, status.stdout
