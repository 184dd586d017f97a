#!/usr/bin/env python3
"""One half-duplex RS-485 line joining the byte streams of many parties (README.md).

    python3 lab/bus/bus.py --master 5020 --control 5021 \\
        --node a=127.0.0.1:6001 --node b=127.0.0.1:6002 [--babbler noise]

Every byte a party sends occupies the line for one character time at that party's
baud rate (11 bits: start, 8 data, parity or a second stop bit, stop), from when it
arrived or the party's previous character ended. It reaches every other party when
its sender's transmission (its characters back to back) ends: as sent, if no other
party's character overlapped it and the receiver runs at the sender's baud rate and
parity; otherwise as garbage.
Standard library only.
"""

import argparse
import asyncio
import json
import random
import sys
import time

BITS_PER_CHAR = 11  # start, 8 data, parity (or a second stop bit with none), stop
PARITIES = ("none", "odd", "even")


class Party:
    def __init__(self, name, baud, parity):
        self.name = name
        self.baud = baud
        self.parity = parity
        self.writers = []  # connections this party receives on
        self.free_at = 0.0  # when its last character leaves the line
        self.wired = True  # on the line: off it, it neither sends nor hears anything
        self.sent = 0  # characters it put on the line
        self.collided = 0  # of which overlapped by another party's
        self.received_garbage = 0  # characters it received as garbage

    def char_s(self):
        return BITS_PER_CHAR / self.baud

    def settings(self):
        return (self.baud, self.parity)


class Line:
    def __init__(self, seed):
        self.parties = {}
        self.pending = []  # characters on the line, not yet delivered: [party, start, end, byte]
        self.history = []  # characters that left the line in the last second
        self.rng = random.Random(seed)
        self.wake = asyncio.Event()
        self.t0 = time.monotonic()

    def now(self):
        return time.monotonic() - self.t0

    def transmit(self, party, data):
        """`data` from `party`, just arrived: each byte a character on the line."""
        if not party.wired:
            return
        t = self.now()
        for b in data:
            start = max(t, party.free_at)
            end = start + party.char_s()
            party.free_at = end
            self.pending.append([party, start, end, b])
            party.sent += 1
        self.wake.set()

    def garbage(self, n):
        return bytes(self.rng.randrange(256) for _ in range(n))

    def deliver(self, now):
        """Every character of each transmission that has ended, to every other party:
        a sender's characters back to back go out together once its last has ended,
        so that a receiver sees no gap in a frame that the sender made none in (the
        bus's own timing jitter would split frames at their silences otherwise)."""
        ended = {id(c[0]) for c in self.pending if c[0].free_at <= now}
        done = [c for c in self.pending if id(c[0]) in ended]
        if not done:
            return
        self.pending = [c for c in self.pending if id(c[0]) not in ended]
        on_line = self.history + done + self.pending
        out = {}
        for party, start, end, b in done:
            collided = any(o[0] is not party and o[1] < end and start < o[2] for o in on_line)
            if collided:
                party.collided += 1
            for q in self.parties.values():
                if q is party or not q.wired:
                    continue
                if collided:
                    data = self.garbage(1)
                    q.received_garbage += 1
                elif q.settings() != party.settings():
                    # Sampled at the wrong rate: about one character per character
                    # time of the receiver's that the sender's spans, none right.
                    n = max(0, round(party.char_s() / q.char_s())) if q.baud != party.baud else 1
                    if q.baud < party.baud and self.rng.random() < q.baud / party.baud:
                        n = 1
                    data = self.garbage(n)
                    q.received_garbage += n
                else:
                    data = bytes([b])
                out.setdefault(q.name, bytearray()).extend(data)
        self.history = [c for c in self.history + done if c[2] > now - 1.0]
        for name, data in out.items():
            for w in list(self.parties[name].writers):
                try:
                    w.write(bytes(data))
                except (ConnectionError, RuntimeError):
                    pass

    async def run(self):
        while True:
            if not self.pending:
                self.wake.clear()
                await self.wake.wait()
                continue
            wait = min(c[0].free_at for c in self.pending) - self.now()
            if wait > 0:
                await asyncio.sleep(wait)
            self.deliver(self.now())

    def stats(self):
        return {
            n: {"baud": p.baud, "parity": p.parity, "sent": p.sent, "collided": p.collided,
                "received_garbage": p.received_garbage, "wired": p.wired,
                "connected": len(p.writers)}
            for n, p in self.parties.items()
        }


async def connected(line, party, reader, writer):
    """One connection of `party`: what it sends goes on the line, what the line
    carries to it goes out on it, until it closes."""
    party.writers.append(writer)
    try:
        while data := await reader.read(4096):
            line.transmit(party, data)
    except ConnectionError:
        pass
    finally:
        party.writers.remove(writer)
        writer.close()


async def node(line, party, host, port):
    """The bus is the client of a node's serial server; reconnects if it goes."""
    while True:
        try:
            reader, writer = await asyncio.open_connection(host, port)
        except OSError:
            await asyncio.sleep(0.2)
            continue
        await connected(line, party, reader, writer)
        await asyncio.sleep(0.2)


async def babble(line, party, duty, seed):
    """Garbage with no regard for the line: bursts of 1-64 characters, the silences
    between them drawn so that it holds the line `duty` of the time."""
    rng = random.Random(seed)
    while True:
        n = rng.randint(1, 64)
        line.transmit(party, bytes(rng.randrange(256) for _ in range(n)))
        busy = n * party.char_s()
        await asyncio.sleep(busy + rng.uniform(0, 2) * busy * (1 - duty) / duty)


def command(line, text):
    """One control command; its answer (a dict)."""
    f = text.split()
    if not f:
        return {"error": "empty"}
    if f[0] == "stats":
        return line.stats()
    if f[0] == "set" and len(f) == 4 and f[1] in line.parties and f[3] in PARITIES:
        p = line.parties[f[1]]
        p.baud, p.parity = int(f[2]), f[3]
        return {"ok": f[1], "baud": p.baud, "parity": p.parity}
    if f[0] == "wire" and len(f) == 3 and f[1] in line.parties and f[2] in ("on", "off"):
        line.parties[f[1]].wired = f[2] == "on"
        return {"ok": f[1], "wired": line.parties[f[1]].wired}
    return {"error": f"not a command: {text.strip()} (stats; set NAME BAUD none|odd|even; wire NAME on|off)"}


async def control(line, reader, writer):
    while True:
        text = await reader.readline()
        if not text:
            break
        writer.write((json.dumps(command(line, text.decode())) + "\n").encode())
        await writer.drain()
    writer.close()


async def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--master", type=int, required=True, metavar="PORT",
                    help="the master's port on 127.0.0.1 (every connection is the master)")
    ap.add_argument("--control", type=int, metavar="PORT", help="the control port on 127.0.0.1")
    ap.add_argument("--node", action="append", default=[], metavar="NAME=HOST:PORT",
                    help="a node's serial server, as QEMU's -serial tcp or the Pico harness's --port")
    ap.add_argument("--babbler", action="append", default=[], metavar="NAME",
                    help="a party of the bus's own that sends garbage regardless of the line")
    ap.add_argument("--duty", type=float, default=0.25, help="the share of time a babbler holds the line")
    ap.add_argument("--off", action="append", default=[], metavar="NAME",
                    help="a party off the line at the start (`wire NAME on` puts it on)")
    ap.add_argument("--baud", type=int, default=19200, help="every party's baud rate at the start")
    ap.add_argument("--parity", default="even", choices=PARITIES, help="every party's parity at the start")
    ap.add_argument("--seed", type=int, default=20261129, help="the garbage's and babblers' seed")
    a = ap.parse_args()
    line = Line(a.seed)
    master = line.parties["master"] = Party("master", a.baud, a.parity)
    tasks = [asyncio.create_task(line.run())]
    for spec in a.node:
        name, _, addr = spec.partition("=")
        host, _, port = addr.rpartition(":")
        if not name or name in line.parties or not port.isdigit():
            sys.exit(f"bus: --node {spec}: NAME=HOST:PORT, each name once")
        p = line.parties[name] = Party(name, a.baud, a.parity)
        tasks.append(asyncio.create_task(node(line, p, host, int(port))))
    for k, name in enumerate(a.babbler):
        p = line.parties[name] = Party(name, a.baud, a.parity)
        tasks.append(asyncio.create_task(babble(line, p, a.duty, a.seed + k)))

    for name in a.off:
        if name not in line.parties:
            sys.exit(f"bus: --off {name}: no such party")
        line.parties[name].wired = False
    servers = [await asyncio.start_server(lambda r, w: connected(line, master, r, w), "127.0.0.1", a.master)]
    if a.control:
        servers.append(await asyncio.start_server(lambda r, w: control(line, r, w), "127.0.0.1", a.control))
    print(f"bus: master on 127.0.0.1:{a.master}, {len(line.parties) - 1} other parties, "
          f"{a.baud} baud {a.parity}", flush=True)
    await asyncio.gather(*tasks)


if __name__ == "__main__":
    try:
        asyncio.run(main())
    except KeyboardInterrupt:
        pass
