#!/usr/bin/env python3
"""Carrier lock per satellite from a `gpsrx run` output directory (channels.csv, pvt.csv).

usage: lock_report.py OUT_DIR [--from S] [--to S] [--held 0.97]

The window is in seconds of stream time (`t_stream_s`, from the first sample). Prints, per PRN,
the fraction of its channel rows in the window that are in state `track` with carrier lock;
how many PRNs are "held" (at least --held of their rows); the longest stretch any channel
spent in state `track` without carrier lock over the whole run (a lost lock that nothing
recovers shows here); how many channel rows were in state `recover`; and the fewest satellites
in a valid fix of the window.
"""
import argparse
import csv
from collections import defaultdict


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--from", dest="t_from", type=float, default=0.0)
    ap.add_argument("--to", dest="t_to", type=float, default=1e18)
    ap.add_argument("--held", type=float, default=0.97)
    a = ap.parse_args()
    rows = defaultdict(lambda: [0, 0])
    unlocked_since = {}
    longest = (0.0, None)
    recover_rows = 0
    for r in csv.DictReader(open(f"{a.out}/channels.csv")):
        t = float(r["t_stream_s"])
        key = (r["channel"], r["prn"])
        locked = r["carrier_lock"] in ("1", "true")
        recover_rows += r["state"] == "recover"
        if r["state"] == "track" and not locked:
            start = unlocked_since.setdefault(key, t)
            if t - start > longest[0]:
                longest = (t - start, r["prn"])
        else:
            unlocked_since.pop(key, None)
        if a.t_from <= t <= a.t_to:
            rows[r["prn"]][0] += 1
            rows[r["prn"]][1] += r["state"] == "track" and locked
    fractions = {p: locked / n for p, (n, locked) in rows.items() if n}
    held = [p for p, f in fractions.items() if f >= a.held]
    per = ", ".join(f"G{int(p):02d} {100 * f:.1f} %" for p, f in sorted(fractions.items(), key=lambda x: int(x[0])))
    # pvt.csv has no stream time: a channel row with both times gives the offset.
    offset = None
    for r in csv.DictReader(open(f"{a.out}/channels.csv")):
        if r["tow_s"]:
            offset = float(r["tow_s"]) - float(r["t_stream_s"])
            break
    n_sv = []
    if offset is not None:
        for r in csv.DictReader(open(f"{a.out}/pvt.csv")):
            if r["quality"] == "none" or not r["tow_s"]:
                continue
            if a.t_from <= float(r["tow_s"]) - offset <= a.t_to:
                n_sv.append(int(r["n_sv"]))
    print(f"phase-locked in the window: {per}")
    print(f"held (>= {100 * a.held:.0f} % of the window): {len(held)} of {len(fractions)}; "
          f"longest in track without carrier lock: {longest[0]:.2f} s"
          + (f" (G{int(longest[1]):02d})" if longest[1] else "")
          + f"; channel rows in recover: {recover_rows}")
    if n_sv:
        print(f"valid fixes in the window: {len(n_sv)}, satellites {min(n_sv)}-{max(n_sv)}")
    else:
        print("valid fixes in the window: 0")


if __name__ == "__main__":
    main()
