#!/usr/bin/env python3
"""Compares two dumps of drawn points (psysc run --dump, tests/aot/aot_dump.c) bit for bit:
the same frames, types and ids in the same order, and every float the same float32.
    compare_dumps.py EXPECTED.csv ACTUAL.csv"""
import csv
import struct
import sys

FIELDS = ["frame", "type", "id", "x", "y", "z", "r", "g", "b", "a", "size"]


def rows(path):
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            yield [row[k] for k in FIELDS]


def bits(text):
    return struct.pack("<f", float(text))


def main():
    expected, actual = list(rows(sys.argv[1])), list(rows(sys.argv[2]))
    if len(expected) != len(actual):
        sys.exit(f"{len(expected)} points expected, {len(actual)} drawn")
    for n, (e, a) in enumerate(zip(expected, actual)):
        if e[:3] != a[:3]:
            sys.exit(f"point {n}: frame, type, id {e[:3]} expected, {a[:3]} drawn")
        for k, (x, y) in enumerate(zip(e[3:], a[3:])):
            if bits(x) != bits(y):
                sys.exit(f"point {n} (frame {e[0]}, {e[1]} {e[2]}): {FIELDS[3 + k]} {x} expected, {y} drawn")
    print(f"{len(expected)} points, every value the same bits")


if __name__ == "__main__":
    main()
