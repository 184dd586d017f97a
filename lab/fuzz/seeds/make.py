#!/usr/bin/env python3
"""Writes the seed inputs of the fuzz targets (lab/fuzz/seeds/<target>/<name>) in the
layout of fuzz_targets/extreme.rs: each structured value is one selector byte and
eight payload bytes (little-endian); selector 0 takes the payload as raw bits. Run from
anywhere: python3 lab/fuzz/seeds/make.py"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
MAX = 1.7976931348623157e308
INF = float("inf")
TINY = 5e-324


def f64(x):
    """A structured f64 given by its exact value (selector 0: raw bits)."""
    return b"\x00" + struct.pack("<d", x)


def f32(x):
    """A structured f32 (selector 0: the payload's low 32 bits)."""
    return b"\x00" + struct.pack("<f", x) + b"\x00" * 4


def count(n):
    """A structured u32 count (selector 0: the payload's low 32 bits)."""
    return b"\x00" + struct.pack("<I", n) + b"\x00" * 4


def angle(n):
    """A structured angle count: the magnitude, bit 7 of the selector for the sign."""
    return (b"\x80" if n < 0 else b"\x00") + struct.pack("<I", abs(n)) + b"\x00" * 4


STEEL = [0.05, 0.05, 79.3e9, 0.3, 0.3]

SEEDS = {
    # r1 r2 g nu mu load phi length exact x y
    "reference": {
        "steel": STEEL + [1000.0, 2e-4, 0.02, False, 1e-4, 1e-5],
        "effective-radius-underflow": [TINY, TINY, 79.3e9, 0.3, 0.3, 1.0, 1e-3, 0.02, False, 0.0, 0.0],
        "strip-width-overflow": [1e308, INF, TINY, 0.3, 0.3, 1.0, 0.0, 0.02, False, 0.0, 0.0],
        "radius-sum-overflow": [MAX, MAX, TINY, 0.3, MAX, 0.0, 0.0, 0.02, False, 0.0, 0.0],
    },
    # r1 r2 g nu mu load(f32) phi(f32) risk(f32) length load_max angle_min
    "float_core": {
        "steel": STEEL + [1000.0, 2e-4, 0.8, 0.02, 5e3, 1e-6],
        "force-overflow": [1e15, 1e15, 79.3e9, 0.3, 1e10, 1e38, 1.0, 0.8, 1.0, 1e3, 1e-3],
        "line-critical-overflow": [1e-4, INF, 1e-38, 0.3, 0.3, 1e38, 1e-3, 0.8, 1.0, 1e3, 1e-3],
        "critical-underflow": [0.05, 0.05, 79.3e9, 0.3, 1e-30, 1.401298464324817e-45, 0.0, 0.8, 1.0, 1e3, 1e-3],
    },
    # r1 r2 g nu mu load_lsb angle_lsb load angle bits(u32) risk
    "fixed_core": {
        "steel": STEEL + [1e-3, 1e-11, 1_000_000, 20_000_000, 0, 0.8],
        "angle-lsb-above-right-angle": [1e10, 1e10, 1.0, 1e-300, 0.3, 1e-6, 1e30, 1000, 0, 0, 0.8],
        "force-beyond-2-to-127": [1e-30, 1e-30, 1e90, 0.3, 1e-10, 2.0**98 / 1e-10, 2.0**-40,
                                  2**32 - 1, 1, 0, 0.8],
        "gross-slip-force-above-mu-p": STEEL + [1000.0 / 2**30, 2.0**-30, 2**30, 2**30, 0, 0.8],
        "force-below-2-to-minus-128": [1e-30, 1e-30, 1e-38, 0.3, 1e-10, 2.0**-60, 2.0**-40, 1, 1, 0, 0.8],
    },
}


def encode(target, values):
    if target == "reference":
        *head, exact, x, y = values
        return b"".join(map(f64, head)) + bytes([int(exact)]) + f64(x) + f64(y)
    if target == "float_core":
        scene, sample, rest = values[:5], values[5:8], values[8:]
        return b"".join(map(f64, scene)) + b"".join(map(f32, sample)) + b"".join(map(f64, rest))
    scene, lsbs, (load, ang, bits, risk) = values[:5], values[5:7], values[7:]
    return (b"".join(map(f64, scene + lsbs)) + count(load) + angle(ang)
            + struct.pack("<I", bits) + f64(risk))


for target, seeds in SEEDS.items():
    os.makedirs(os.path.join(HERE, target), exist_ok=True)
    for name, values in seeds.items():
        with open(os.path.join(HERE, target, name), "wb") as f:
            f.write(encode(target, values))
