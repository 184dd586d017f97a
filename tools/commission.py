#!/usr/bin/env python3
"""Commissions a misalign node over Modbus RTU (docs/modbus.md, Commissioning): unlocks it
with the site's code, writes configuration registers and a prepared scene (the bytes
`cargo run --example prepare -- --out scene.bin` writes for the node's scene type) to its
staged copy, reads them back, commits, and checks that the node runs them.

    python3 tools/commission.py --port 5020 --code 1234 \\
        --scene scene.bin --set config_warning=0.7 --set config_on_delay=5000

Over a TCP bridge (or QEMU's serial port on a loopback socket) with `--port`, or a serial
line with `--serial /dev/ttyUSB0 --baud 19200`. Register names and types come from the
register map (`--registers`, default docs/modbus/registers.csv). Exit status 0 when the
node runs what was written; otherwise the reason (a wrong code, a lock-out, the commit's
`commit_error`) on stderr and status 1, and whatever was staged is reverted.
Needs pymodbus (3.16).
"""

import argparse
import csv
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

    def write_words(self, address, words):
        for i in range(0, len(words), 120):
            answer = self.c.write_registers(address + i, words[i:i + 120], device_id=self.unit)
            if answer.isError():
                raise Failed(f"scene block at {address + i}: exception {answer.exception_code}")


def u32(words):
    return words[0] << 16 | words[1]


def commission(node, code, settings, scene):
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
    try:
        for name, value in settings:
            if not (name.startswith("config_") or name == "new_code"):
                raise Failed(f"{name} is not a configuration register (config_*, new_code)")
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
        node.write("command", [2])  # revert
        node.write("command", [3])  # lock
        raise
    # What the node runs now.
    for name, value in settings:
        if name.startswith("config_"):
            active = "active_" + name[len("config_"):]
            if node.read(active) != node.words(name, value):
                raise Failed(f"{active} reads {node.read(active)} after the commit")
    if scene is not None and u32(node.read("scene_active_crc")) != int.from_bytes(scene[-4:], "little"):
        raise Failed("the node does not run the scene after the commit")
    return node.read("config_source")[0]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--port", type=int, help="a TCP bridge's port (RTU frames over TCP)")
    p.add_argument("--serial", help="a serial device instead of --port")
    p.add_argument("--baud", type=int, default=19200)
    p.add_argument("--unit", type=int, default=1)
    p.add_argument("--registers", default="docs/modbus/registers.csv")
    p.add_argument("--code", type=int, required=True, help="the site's code")
    p.add_argument("--scene", help="prepared scene bytes (examples/prepare.rs --out)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a configuration register (config_*, new_code) and its value")
    args = p.parse_args()
    from pymodbus import FramerType
    if args.serial:
        from pymodbus.client import ModbusSerialClient
        client = ModbusSerialClient(args.serial, framer=FramerType.RTU, baudrate=args.baud,
                                    parity="E", timeout=2)
    elif args.port:
        from pymodbus.client import ModbusTcpClient
        client = ModbusTcpClient(args.host, port=args.port, framer=FramerType.RTU, timeout=2, retries=0)
    else:
        p.error("--port or --serial")
    settings = []
    for s in args.set:
        name, eq, value = s.partition("=")
        if not eq:
            p.error(f"--set {s}: NAME=VALUE")
        settings.append((name, value))
    scene = open(args.scene, "rb").read() if args.scene else None
    if not client.connect():
        print("commission: cannot connect", file=sys.stderr)
        return 1
    try:
        source = commission(Node(client, args.registers, args.unit), args.code, settings, scene)
    except Failed as e:
        print(f"commission: {e}", file=sys.stderr)
        return 1
    finally:
        client.close()
    print(f"commissioned: {len(settings)} registers{' and the scene' if scene else ''} committed, "
          f"config_source {source}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
