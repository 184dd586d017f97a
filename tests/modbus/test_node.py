"""The node on its own samples (the built-in scenario, then serving its final state),
through pymodbus and through raw frames.

MODBUS_EXPECTED: every register and bit of the map as this host's replay of the same
samples through `misalign::modbus::Server` reads it (`table,address,value`, raw
16-bit words and bits): the node's must be equal, word for word.
"""

import csv
import os
import random

from conftest import UNIT, frame, read_table, register_map, words


def expected():
    """The host's reads, in order: {read index: (table, start, [values])}."""
    reads = {}
    with open(os.environ["MODBUS_EXPECTED"], newline="") as f:
        for r in csv.DictReader(f):
            table, start, values = reads.setdefault(int(r["read"]), (r["table"], int(r["address"]), []))
            values.append(int(r["value"]))
    return reads


# First: the host replayed these very reads, and the node counts them (bus_*) as the
# host's server did; any request before them would move the counts.
def test_every_register_equals_the_host_replay(client):
    reads = expected()
    rows = register_map()
    covered = {(t, s + k) for t, s, v in reads.values() for k in range(len(v))}
    for r in rows:
        for k in range(words(r)):
            assert (r["table"], r["address"] + k) in covered, r["name"]
    names = {(r["table"], r["address"] + k): r["name"] for r in rows for k in range(words(r))}
    mismatches = []
    for i in sorted(reads):
        table, start, values = reads[i]
        got = read_table(client, table, start, len(values))
        for k, (g, v) in enumerate(zip(got, values)):
            if g != v:
                a = start + k
                mismatches.append(f"{table} {a} ({names.get((table, a), '?')}): node {g:#06x}, host {v:#06x}")
    assert not mismatches, "\n".join(mismatches)


def test_identification_basic_and_regular(client):
    basic = client.read_device_information(read_code=1, device_id=UNIT)
    assert not basic.isError(), basic
    for oid in (0, 1, 2):  # vendor, product code, revision
        assert basic.information.get(oid), f"basic object {oid} missing: {basic.information}"
    regular = client.read_device_information(read_code=2, device_id=UNIT)
    assert not regular.isError(), regular
    core = os.environ["MODBUS_CORE"]
    assert regular.information.get(4), "no product name"
    model = regular.information.get(5, b"")
    assert core.encode() in model, f"the model name does not name the core ({core}): {regular.information}"


def test_exceptions(client, raw):
    # 01: a function the node does not implement (8, diagnostics). Its length is
    # unknown, so the node answers at the silence after it (in QEMU a second of
    # virtual time, `nodes/firmware/uart.rs`): wait longer than for the others.
    raw.send(frame([0x08, 0x00, 0x00, 0x12, 0x34]))
    assert raw.answer(5.0) == frame([0x88, 0x01])
    # 02: registers beyond the map.
    raw.send(frame([0x04, 0xFF, 0x00, 0x00, 0x10]))
    assert raw.answer() == frame([0x84, 0x02])
    # 03: a read of no register, and of more than 125.
    raw.send(frame([0x04, 0x00, 0x00, 0x00, 0x00]))
    assert raw.answer() == frame([0x84, 0x03])
    raw.send(frame([0x03, 0x00, 0x00, 0x00, 0x7E]))
    assert raw.answer() == frame([0x83, 0x03])


def test_no_answer_to_bad_crc_other_units_or_broadcast_reads(client, raw):
    good = frame([0x04, 0x00, 0x00, 0x00, 0x01])
    bad = bytearray(good)
    bad[-1] ^= 0x5A
    raw.send(bad)
    assert raw.answer(0.5) == b""
    raw.send(frame([0x04, 0x00, 0x00, 0x00, 0x01], unit=UNIT + 1))
    assert raw.answer(0.5) == b""
    raw.send(frame([0x04, 0x00, 0x00, 0x00, 0x01], unit=0))
    assert raw.answer(0.5) == b""
    raw.send(good)
    answer = raw.answer()
    assert answer[:3] == bytes([UNIT, 0x04, 2]) and len(answer) == 7


def test_garbage_then_a_valid_frame_is_answered(client, raw):
    rng = random.Random(20261125)
    good = frame([0x04, 0x00, 0x00, 0x00, 0x02])
    for n in (1, 7, 64, 300):
        raw.send(bytes(rng.randrange(256) for _ in range(n)))
        # Whatever the garbage drew (an answer to a frame it happened to hold is
        # allowed), the node keeps listening: a valid frame after it is answered.
        raw.answer(0.5)
        raw.send(good)
        # Up to 5 s for its first byte: a loaded machine's QEMU may still be taking
        # the 300 bytes of garbage, one at a time, when the frame is sent.
        answer = raw.answer(5.0)
        assert len(answer) >= 9 and answer[-9:-6] == bytes([UNIT, 0x04, 4]), (n, answer.hex())


def test_still_answers_pymodbus_after_all_that(client):
    rows = register_map()
    status = next(r for r in rows if r["name"] == "status")
    assert len(read_table(client, status["table"], status["address"], 1)) == 1
