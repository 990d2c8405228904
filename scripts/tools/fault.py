#!/usr/bin/env python3
"""Make a faulty copy of a recording: samples cut out (a front end dropping them) or zeroed
(an ADC dropout), streamed in bounded memory.

usage: fault.py IN OUT --bytes-per-sample B --fs HZ (--cut AT_S LEN_S | --zero AT_S LEN_S)

AT_S is the stream time of the fault in the input; LEN_S is rounded to whole samples.
"""
import argparse
import sys

CHUNK = 1 << 22


def copy(src, dst, n):
    while n > 0:
        b = src.read(min(CHUNK, n))
        if not b:
            sys.exit("fault.py: the input ends before the fault")
        dst.write(b)
        n -= len(b)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--bytes-per-sample", type=int, required=True)
    ap.add_argument("--fs", type=float, required=True)
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--cut", nargs=2, type=float, metavar=("AT_S", "LEN_S"))
    g.add_argument("--zero", nargs=2, type=float, metavar=("AT_S", "LEN_S"))
    a = ap.parse_args()
    at_s, len_s = a.cut or a.zero
    bps = a.bytes_per_sample
    start = round(at_s * a.fs) * bps
    length = round(len_s * a.fs) * bps
    with open(a.inp, "rb") as src, open(a.out, "wb") as dst:
        copy(src, dst, start)
        if a.cut:
            src.seek(length, 1)
        else:
            src.seek(length, 1)
            zeros = bytes(min(CHUNK, length))
            left = length
            while left > 0:
                dst.write(zeros[: min(len(zeros), left)])
                left -= min(len(zeros), left)
        while True:
            b = src.read(CHUNK)
            if not b:
                break
            dst.write(b)


if __name__ == "__main__":
    main()
