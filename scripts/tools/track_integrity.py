#!/usr/bin/env python3
"""Integrity of a run's valid fixes against a moving truth (issue 26's criterion).

    track_integrity.py OUT_DIR TRUTH.csv [--from S --to S]

Counts the valid fixes of OUT_DIR/pvt.csv (quality gnss or fused) whose 3D error against the
truth (interpolated at the fix's GPS time of week) exceeds 5 m and their stated 3-sigma plus
5 m (sigma = the norm of sigma_e/n/u), and lists the first of them. `--from/--to` are seconds
from the truth's first row. For a static antenna see fault_recovery.py.
"""
import argparse
import csv
import math

from truth_track import TruthTrack


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("truth")
    ap.add_argument("--from", dest="t_from", type=float, default=-1e18)
    ap.add_argument("--to", dest="t_to", type=float, default=1e18)
    a = ap.parse_args()
    track = TruthTrack(a.truth)
    truth_at = track.at

    n, bad, worst = 0, [], 0.0
    for r in csv.DictReader(open(f"{a.out}/pvt.csv")):
        if r["quality"] not in ("gnss", "fused"):
            continue
        t = float(r["tow_s"]) - track.start_tow
        p = truth_at(float(r["tow_s"]))
        if p is None or not (a.t_from <= t <= a.t_to):
            continue
        e = math.dist(p, [float(r["x_m"]), float(r["y_m"]), float(r["z_m"])])
        s = (math.sqrt(sum(float(r[k]) ** 2 for k in ("sigma_e_m", "sigma_n_m", "sigma_u_m")))
             if r["sigma_e_m"] else float("nan"))
        n += 1
        worst = max(worst, e)
        if e > 5 and not e <= 3 * s + 5:
            bad.append((t, e, 3 * s, r["n_sv"]))
    for t, e, s3, nsv in bad[:10]:
        print(f"  {t:.2f} s: error {e:.1f} m, 3-sigma {s3:.1f} m, {nsv} satellites")
    print(f"{n} valid fixes, worst 3D error {worst:.1f} m; {len(bad)} more than 5 m beyond their 3-sigma")


if __name__ == "__main__":
    main()
