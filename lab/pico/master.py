"""The master of `cargo xtask pico --trace`: while the harness plays the trace through
the node's sensors, reads every event from the node's event window (function 4) and
acknowledges it (`event_ack`, so that the node's flash never fills), until the harness
says the trace has played; then reads the rest. Writes each event's registers, raw, in
master.py's `--events` format (tests/modbus/master.py, whose reader it uses).

    python lab/pico/master.py --port PORT --control CONTROL --registers registers.csv \\
        --events events.csv
"""

import argparse
import csv
import json
import os
import socket
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tests", "modbus"))
from master import Map, Master, u32_words  # noqa: E402

from pymodbus import FramerType  # noqa: E402
from pymodbus.client import ModbusTcpClient  # noqa: E402


def control(port, line):
    """One command to the harness; its JSON answer."""
    with socket.create_connection(("127.0.0.1", port), timeout=30) as s:
        s.sendall((line + "\n").encode())
        answer = b""
        while not answer.endswith(b"\n"):
            chunk = s.recv(4096)
            if not chunk:
                break
            answer += chunk
    return json.loads(answer)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--port", type=int, required=True)
    ap.add_argument("--control", type=int, required=True)
    ap.add_argument("--registers", required=True)
    ap.add_argument("--events", required=True)
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds the trace may take")
    a = ap.parse_args()
    client = ModbusTcpClient("127.0.0.1", port=a.port, framer=FramerType.RTU, timeout=5, retries=3)
    if not client.connect():
        sys.exit("cannot connect to the node")
    regmap = Map(a.registers)
    with open(a.registers, newline="") as f:
        ack = next(int(r["address"]) for r in csv.DictReader(f)
                   if r["table"] == "holding" and r["name"] == "event_ack")
    master = Master(client, regmap)
    start = time.monotonic()
    while True:
        done = control(a.control, "status")["done"]
        master.read_events()
        if master.next_seq:
            master.write(ack, u32_words((master.next_seq - 1) & 0xFFFFFFFF))
        if done:
            break
        if time.monotonic() - start > a.timeout:
            sys.exit(f"the trace did not play within {a.timeout} s")
        time.sleep(1.0)
    client.close()
    with open(a.events, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["event"] + [f"w{k}" for k in range(regmap.stride)])
        for k, e in enumerate(master.events):
            w.writerow([k] + list(e))
    print(f"{len(master.events)} events read, {master.missed} missed", file=sys.stderr)
    if master.missed:
        sys.exit(f"{master.missed} events were lost before they were read")


if __name__ == "__main__":
    main()
