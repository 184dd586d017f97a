"""What the Modbus node's tests share (`cargo xtask modbus` runs them against the node
in QEMU, serial0 on a loopback port): a pymodbus client speaking RTU over the TCP
socket, the register map as the library exports it, and raw frames for what a well-
behaved client never sends.

The environment, set by xtask: MODBUS_PORT (the node's loopback port),
MODBUS_REGISTERS (the register map, `docs/modbus/registers.csv`'s columns),
MODBUS_CORE (`f32` or `fixed`), and per test file what the host's replay expects.
32-bit values are two registers, high word first (the map's convention; pymodbus's
default too).
"""

import csv
import os
import socket
import time

import pytest
from pymodbus import FramerType
from pymodbus.client import ModbusTcpClient

HOST = "127.0.0.1"
UNIT = 1


def port():
    return int(os.environ["MODBUS_PORT"])


@pytest.fixture(scope="module")
def client():
    c = ModbusTcpClient(HOST, port=port(), framer=FramerType.RTU, timeout=2, retries=0)
    assert c.connect(), "cannot connect to the node"
    yield c
    c.close()


def register_map():
    """The map's rows as dicts (table, address, name, type, scale, unit, access,
    description)."""
    with open(os.environ["MODBUS_REGISTERS"], newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r["address"] = int(r["address"])
    return rows


def words(row):
    """How many registers (or bits) a row of the map spans."""
    return 2 if row["type"] in ("u32", "i32", "f32") else 1


def read_table(client, table, start, count):
    """`count` registers or bits of `table` from `start`, as ints."""
    if table == "input":
        r = client.read_input_registers(start, count=count, device_id=UNIT)
    elif table == "holding":
        r = client.read_holding_registers(start, count=count, device_id=UNIT)
    elif table == "coil":
        r = client.read_coils(start, count=count, device_id=UNIT)
    elif table == "discrete":
        r = client.read_discrete_inputs(start, count=count, device_id=UNIT)
    else:
        raise ValueError(table)
    assert not r.isError(), f"{table} {start}+{count}: {r}"
    values = r.registers if table in ("input", "holding") else r.bits[:count]
    return [int(v) for v in values]


def crc16(frame):
    """Modbus RTU's CRC-16 (polynomial 0xA001 reflected, initial 0xFFFF), low byte
    first on the wire."""
    crc = 0xFFFF
    for b in frame:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return bytes([crc & 0xFF, crc >> 8])


def frame(pdu, unit=UNIT):
    body = bytes([unit]) + bytes(pdu)
    return body + crc16(body)


class Raw:
    """A bare socket to the node: frames as bytes, answers as bytes."""

    def __init__(self):
        self.sock = socket.create_connection((HOST, port()), timeout=2)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def send(self, data):
        self.sock.sendall(bytes(data))

    def answer(self, wait=1.0):
        """Every byte the node sends within `wait` seconds of silence."""
        got = b""
        self.sock.settimeout(wait)
        try:
            while True:
                chunk = self.sock.recv(512)
                if not chunk:
                    break
                got += chunk
                self.sock.settimeout(0.2)
        except socket.timeout:
            pass
        return got

    def close(self):
        self.sock.close()


@pytest.fixture
def raw(client):
    # QEMU's serial socket takes one client at a time: the pymodbus client steps
    # aside while the raw one talks.
    client.close()
    time.sleep(0.1)
    r = Raw()
    yield r
    r.close()
    time.sleep(0.1)
    assert client.connect()
