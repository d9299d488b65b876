#!/usr/bin/env python3
"""Compares two visibility dumps (scripts/visibility-dump.sh) pixel by pixel.

For each `.npy` in BEFORE, reads the same name in AFTER and reports the share of
pixels whose visibility differs by more than 1e-3 (NaN background must match NaN).
Exits 1 if any pair has fewer than 99.99 % of its pixels within 1e-3, or if a render
exists on one side only. Standard library only: .npy float32 is parsed by hand.
"""
import os, struct, sys, ast

TOLERANCE = 1e-3
REQUIRED = 0.9999

def read_npy(path):
    with open(path, "rb") as f:
        data = f.read()
    assert data[:6] == b"\x93NUMPY", path
    major = data[6]
    if major == 1:
        hlen = struct.unpack("<H", data[8:10])[0]; start = 10
    else:
        hlen = struct.unpack("<I", data[8:12])[0]; start = 12
    header = ast.literal_eval(data[start:start + hlen].decode("latin1"))
    assert header["descr"] == "<f4", header
    body = data[start + hlen:]
    return struct.unpack("<%df" % (len(body) // 4), body)

def main(before, after):
    names = sorted(n for n in os.listdir(before) if n.endswith(".npy"))
    others = set(n for n in os.listdir(after) if n.endswith(".npy"))
    failed = False
    for name in sorted(set(names) ^ others):
        print(f"{name}: rendered on one side only"); failed = True
    worst = 1.0
    for name in names:
        if name not in others:
            continue
        a, b = read_npy(os.path.join(before, name)), read_npy(os.path.join(after, name))
        if len(a) != len(b):
            print(f"{name}: sizes differ"); failed = True; continue
        same = sum(1 for x, y in zip(a, b) if (x != x and y != y) or abs(x - y) <= TOLERANCE)
        share = same / len(a)
        worst = min(worst, share)
        flag = "" if share >= REQUIRED else "  FAIL"
        print(f"{name[:-4]:32s} {100 * share:9.4f} % within {TOLERANCE}{flag}")
        failed |= share < REQUIRED
    print(f"{len(names)} pairs; worst {100 * worst:.4f} % of pixels within {TOLERANCE}")
    return 1 if failed else 0

if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
