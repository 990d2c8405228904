#!/usr/bin/env python3
"""Make a weaker copy of a complex int8 (ci8) recording: Gaussian noise added so that the noise
floor rises by DB decibels, i.e. every satellite's C/N0 falls by DB (the signal is buried in
the noise, so the recording's own power is its noise floor). Seeded, streamed in bounded
memory; the result stays ci8 (the added noise is rounded; values are clipped to +-127 and the
count of clipped values reported).

usage: weaken.py IN OUT --db DB [--seed N]
"""
import argparse
import sys

import numpy as np

CHUNK = 1 << 22  # bytes (2 per complex sample)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--db", type=float, required=True, help="noise floor rise, dB (> 0)")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    if not a.db > 0:
        sys.exit("weaken.py: --db must be above 0")
    rng = np.random.default_rng(a.seed)
    try:
        with open(a.inp, "rb") as src:
            head = np.frombuffer(src.read(CHUNK), dtype=np.int8).astype(np.float64)
    except OSError as e:
        sys.exit(f"weaken.py: cannot read {a.inp}: {e.strerror}")
    if head.size == 0 or head.std() == 0:
        sys.exit("weaken.py: the input is empty or all zeros")
    sigma = head.std() * np.sqrt(10 ** (a.db / 10) - 1)
    clipped = total = 0
    if head.size % 2:
        sys.exit("weaken.py: the input is not ci8 (an odd number of bytes in its first block)")
    try:
        dst = open(a.out, "wb")
    except OSError as e:
        sys.exit(f"weaken.py: cannot write {a.out}: {e.strerror}")
    with open(a.inp, "rb") as src, dst:
        while True:
            b = src.read(CHUNK)
            if not b:
                break
            x = np.frombuffer(b, dtype=np.int8).astype(np.float64)
            y = np.rint(x + rng.normal(0.0, sigma, x.size))
            clipped += int(np.count_nonzero(np.abs(y) > 127))
            total += y.size
            dst.write(np.clip(y, -127, 127).astype(np.int8).tobytes())
    print(f"noise floor +{a.db} dB: added noise sigma {sigma:.2f} LSB per component "
          f"(input {head.std():.2f}); {clipped} of {total} values clipped")


if __name__ == "__main__":
    main()
