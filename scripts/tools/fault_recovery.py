#!/usr/bin/env python3
"""How a run came back from a fault, from its pvt.csv and a static truth position.

usage: fault_recovery.py PVT_CSV LAT LON H --start-tow S --at S --len S --kind cut|zero
                         [--max-back S] [--max-err M]

The signal comes back at true GPS time start + at + len (for a cut the samples of that span
are gone, for zeros they are empty). Prints the first valid fix after it ("back", seconds after
the return), the number of valid fixes after the fault, the largest 3D error of any valid fix
after the fault (a fix from the wrong time would show here), how many of the valid fixes after
it are more than 5 m off beyond their stated 3-sigma (3 x the root sum of squares of
sigma_e_m, sigma_n_m, sigma_u_m: issue 26's integrity bound), and how many were written flagged
invalid. With --max-back / --max-err it exits 1 when the first valid fix comes later or a valid
fix after the fault is further off (issue 26's acceptance: 1.5 s, 5 m).
"""
import argparse
import csv
import math

A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)


def ecef(lat, lon, h):
    lat, lon = math.radians(lat), math.radians(lon)
    n = A / math.sqrt(1 - E2 * math.sin(lat) ** 2)
    return ((n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1 - E2) + h) * math.sin(lat))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("pvt")
    ap.add_argument("lat", type=float)
    ap.add_argument("lon", type=float)
    ap.add_argument("h", type=float)
    ap.add_argument("--start-tow", type=float, required=True)
    ap.add_argument("--at", type=float, required=True)
    ap.add_argument("--len", type=float, required=True)
    ap.add_argument("--kind", choices=["cut", "zero"], required=True)
    ap.add_argument("--max-back", type=float, help="fail when the first valid fix comes later, s")
    ap.add_argument("--max-err", type=float, help="fail when a valid fix after it is further off, m")
    a = ap.parse_args()
    x0 = ecef(a.lat, a.lon, a.h)
    t_fault = a.start_tow + a.at
    t_back = t_fault + a.len
    first, worst, valid, flagged, uncovered = None, 0.0, 0, 0, 0
    for r in csv.DictReader(open(a.pvt)):
        if not r["tow_s"] or float(r["tow_s"]) <= t_fault:
            continue
        if r["quality"] == "none":
            flagged += 1
            continue
        t = float(r["tow_s"])
        err = math.dist(x0, [float(r[k]) for k in ("x_m", "y_m", "z_m")])
        worst = max(worst, err)
        valid += 1
        sig = [r.get(k) or "" for k in ("sigma_e_m", "sigma_n_m", "sigma_u_m")]
        s3 = 3 * math.sqrt(sum(float(x) ** 2 for x in sig)) if all(sig) else 0.0
        if err > 5.0 and err > s3:
            uncovered += 1
        if first is None:
            first = t
    back = f"{first - t_back:.1f} s" if first is not None else "never"
    print(f"   back {back} after the signal returns; {valid} valid fixes after the fault, "
          f"worst 3D error {worst:.1f} m ({uncovered} over 5 m beyond their 3-sigma); "
          f"{flagged} written flagged invalid")
    late = a.max_back is not None and (first is None or first - t_back > a.max_back)
    off = a.max_err is not None and worst > a.max_err
    return 1 if late or off else 0


if __name__ == "__main__":
    raise SystemExit(main())
