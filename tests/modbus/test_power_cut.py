"""Power cuts of the node with flash in QEMU, at points of a commit, of an event push
and of an acknowledgement. The node is a test build (feature `_power-cut`,
nodes/firmware/cut.rs): the test writes a plan (`commit N`, `push N` or `ack N`)
to MODBUS_POWER_CUT_PLAN, and the node resets itself after N points (bytes written,
words erased) of its next such operation, as a power cut there would. The master
then reconnects and checks: the old configuration or the new one, whole; no event
back that was acknowledged on flash (`event_acked`); no stored event lost or changed;
and a commit or an acknowledgement the node answered is in force (it answers a write
once it is on flash).

Points: 0, 1, 3, 7, 15, ... (2^k - 1) until the operation completes before its point;
with MODBUS_POWER_CUT_ALL=1 every point, 0, 1, 2, ...
"""

import itertools
import os
import time

import pytest

from conftest import read_table, register_map
from master import Map, Master, read_samples, u32_words
from test_config import code, get, view, write
from test_reset import ack_address, wait_serving

NONE = 0xFFFFFFFF


def points():
    if os.environ.get("MODBUS_POWER_CUT_ALL"):
        return itertools.count()
    return (2 ** k - 1 for k in itertools.count())


def plan(op, n):
    with open(os.environ["MODBUS_POWER_CUT_PLAN"], "w") as f:
        f.write(f"{op} {n}\n")


def inputs():
    return {r["name"]: r for r in register_map() if r["table"] == "input"}


def get_input(client, name):
    r = inputs()[name]
    n = 2 if r["type"] in ("u32", "f32") else 1
    w = read_table(client, "input", r["address"], n)
    return w[0] << 16 | w[1] if n == 2 else w[0]


def frames_now(client):
    """The node's count of frames since its boot, read until it is at least 40: a node
    reset after this counts fewer when `settled` asks (its few reads, and a request QEMU
    held back for the restarted UART)."""
    while True:
        frames = get_input(client, "bus_frames")
        if frames >= 40:
            return frames


def settled(client, frames):
    """After an operation planned to be cut: reconnected once the node answers;
    whether it was reset (its count of frames begun again), or None when the node has
    not taken the plan (the operation did not run: a request lost on its way)."""
    time.sleep(0.3)
    wait_serving(client)
    if os.path.exists(os.environ["MODBUS_POWER_CUT_PLAN"]):
        return None
    return get_input(client, "bus_frames") <= frames


def seq(event):
    return event[0] << 16 | event[1]


def stored_events(client, regmap):
    """Every event the node holds on flash, from the oldest not acknowledged."""
    acked = get_input(client, "event_acked")
    m = Master(client, regmap)
    m.write(regmap.event_from, u32_words(0 if acked == NONE else acked + 1))
    m.read_events()
    assert m.missed == 0, f"{m.missed} events lost"
    seqs = [seq(e) for e in m.events]
    if seqs:
        assert seqs == list(range(seqs[0], seqs[0] + len(seqs))), seqs
        if acked != NONE:
            assert seqs[0] == acked + 1, f"acknowledged through {acked}, yet {seqs[0]} offered"
    return m.events


class Feeder:
    """The scenario's samples, from where the monitor is (`samples`: after a cut, its
    checkpoint), again and again, times running on."""

    def __init__(self, client, regmap):
        self.c = client
        self.m = regmap
        self.samples = read_samples(os.environ["MODBUS_SAMPLES"])
        span = (self.samples[-1][0] - self.samples[0][0]) & NONE
        self.lap = span + 1000

    def sample(self, i):
        s = self.samples[i % len(self.samples)]
        return ((s[0] + (i // len(self.samples)) * self.lap) & NONE,) + s[1:]

    def until_event(self):
        """Samples, a block a write, until an event is raised; whether the node was cut
        (reset) on its way."""
        master = Master(self.c, self.m)
        frames = frames_now(self.c)
        seq_next = get_input(self.c, "event_seq_next")
        for _ in range(len(self.samples) // self.m.full + 1):
            try:
                i = get_input(self.c, "samples")
                master.feed([self.sample(i + k) for k in range(self.m.full)])
                if get_input(self.c, "event_seq_next") != seq_next:
                    break
            except Exception:  # noqa: BLE001 (an answer lost: a reset, or late)
                wait_serving(self.c)
                reset = get_input(self.c, "bus_frames") <= frames
                if reset or get_input(self.c, "event_seq_next") != seq_next:
                    break
        else:
            raise AssertionError("no event from a lap of the samples")
        return frames


def answered(request):
    """Whether a write planned to be cut was answered without an exception (not lost
    to the cut)."""
    try:
        r = request()
    except Exception:  # noqa: BLE001 (the answer lost to the cut)
        return False
    return r is None or not r.isError()


def unlock(client):
    assert not write(client, "unlock", code()).isError()


def commit(client, on_delay):
    unlock(client)
    assert not write(client, "config_on_delay", on_delay).isError()
    new = view(client, "config")
    return new


@pytest.fixture(autouse=True)
def no_plan_left():
    """No plan from an earlier run armed for this test's first operation."""
    path = os.environ["MODBUS_POWER_CUT_PLAN"]
    if os.path.exists(path):
        os.remove(path)


def sweep(op, cut_at):
    """`cut_at(n)` at each point until the operation completes before its point
    (`cut_at` returns whether the node was cut, after its checks; None if the
    operation did not run, which is tried again)."""
    cuts = 0
    for n in points():
        # Again while the operation did not run (None: a request lost on its way).
        for _ in range(3):
            cut = cut_at(n)
            if cut is not None:
                break
        else:
            raise AssertionError(f"{op}: the operation never ran at point {n}")
        if not cut:
            break
        cuts += 1
    print(f"{op}: cut at {cuts} points; complete before point {n}")
    assert cuts > 0


def test_a_commit_cut_anywhere_leaves_the_old_or_the_new_configuration(client):
    commit(client, 1000)
    assert not write(client, "command", 1).isError()
    rounds = itertools.count()

    def cut_at(n):
        old = view(client, "active")
        new = commit(client, 2000 + next(rounds))
        assert new != old
        plan("commit", n)
        frames = frames_now(client)
        answer = answered(lambda: write(client, "command", 1))
        cut = settled(client, frames)
        if cut is None:
            return None
        active = view(client, "active")
        assert active in (old, new), f"cut after {n} points: neither configuration"
        assert not answer or active == new, f"cut after {n} points: answered, yet not in force"
        assert get(client, "config_source") == 1
        assert cut or active == new, f"the commit completed before point {n}, yet is not in force"
        return cut

    sweep("commit", cut_at)


def test_an_event_push_cut_anywhere_loses_no_stored_event(client):
    regmap = Map(os.environ["MODBUS_REGISTERS"])
    feeder = Feeder(client, regmap)

    def cut_at(n):
        before = stored_events(client, regmap)
        if len(before) > 4:
            # Few held, so that the queue never fills and drops one.
            Master(client, regmap).write(ack_address(), u32_words(seq(before[-4])))
            before = stored_events(client, regmap)
        plan("push", n)
        frames = feeder.until_event()
        cut = settled(client, frames)
        if cut is None:
            return None
        after = stored_events(client, regmap)
        assert after[:len(before)] == before, f"cut after {n} points: stored events changed"
        assert cut or len(after) > len(before)
        return cut

    sweep("push", cut_at)


def test_an_acknowledgement_cut_anywhere_brings_back_no_acknowledged_event(client):
    regmap = Map(os.environ["MODBUS_REGISTERS"])
    feeder = Feeder(client, regmap)

    def cut_at(n):
        while len(stored_events(client, regmap)) < 2:
            feeder.until_event()
        before = stored_events(client, regmap)
        old = get_input(client, "event_acked")
        k = seq(before[0])
        plan("ack", n)
        frames = frames_now(client)
        answer = answered(lambda: Master(client, regmap).write(ack_address(), u32_words(k)))
        cut = settled(client, frames)
        if cut is None:
            return None
        durable = get_input(client, "event_acked")
        assert durable in (old, k), f"cut after {n} points: acknowledged through {durable}"
        assert not answer or durable == k, f"cut after {n} points: answered, yet not on flash"
        after = stored_events(client, regmap)
        kept = before if durable == NONE else [e for e in before if seq(e) > durable]
        assert after == kept, f"cut after {n} points"
        assert cut or durable == k
        return cut

    sweep("ack", cut_at)
