#!/usr/bin/env python3
"""One row of the gaps-under-dynamics table: how a run came back from a fault, against a
moving truth.

    gap_recovery.py OUT_DIR TRUTH.csv --at S --len S [--label TEXT]

`--at` is the truth time (s from the truth's first row) where the fault starts and `--len` its
length: the signal returns at `at + len` of true time, for a cut (samples removed) as for
zeros. Prints: the label, when valid fixes are back after the return (s after it: the end of
the last stretch of more than 0.3 s without a valid fix that ends after the return and begins
within 10 s of it; else the first valid fix after the return; `never`), the
worst 3D error of the valid fixes from the fault to 10 s after the return, how many of those
are over 5 m, and how many are over 5 m and beyond their 3-sigma (the integrity failures).
"""
import argparse
import csv
import math

from truth_track import TruthTrack


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("truth")
    ap.add_argument("--at", type=float, required=True)
    ap.add_argument("--len", type=float, required=True)
    ap.add_argument("--label", default="")
    a = ap.parse_args()
    track = TruthTrack(a.truth)
    truth_at = track.at

    back, worst, over5, beyond = None, 0.0, 0, 0
    ret = a.at + a.len
    prev = a.at
    for r in csv.DictReader(open(f"{a.out}/pvt.csv")):
        if r["quality"] not in ("gnss", "fused"):
            continue
        t = float(r["tow_s"]) - track.start_tow
        if t < a.at:
            continue
        if prev <= ret + 10.0 and t - prev > 0.3 and t > ret:
            back = t - ret
        if t >= ret and back is None:
            back = t - ret
        prev = t
        if t > ret + 10.0:
            continue
        p = truth_at(float(r["tow_s"]))
        if p is None:
            continue
        e = math.dist(p, [float(r["x_m"]), float(r["y_m"]), float(r["z_m"])])
        s = math.sqrt(sum(float(r[k] or "nan") ** 2 for k in ("sigma_e_m", "sigma_n_m", "sigma_u_m")))
        worst = max(worst, e)
        over5 += e > 5
        beyond += e > 5 and not e <= 3 * s + 5
    back_s = "never" if back is None else f"{back:.1f} s"
    print(f"| {a.label} | {back_s} | {worst:.1f} m | {over5} | {beyond} |")


if __name__ == "__main__":
    main()
