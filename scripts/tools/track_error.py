#!/usr/bin/env python3
"""Errors of a `gpsrx run` against the simulator's truth, for a moving receiver.

usage: track_error.py OUT_DIR TRUTH_CSV [--from S] [--to S]

OUT_DIR is a `gpsrx run --out` directory (pvt.csv, channels.csv); TRUTH_CSV the simulator's
truth.csv. --from/--to select a window in seconds from the truth file's first epoch. Prints the
number of valid fixes (and of those written flagged invalid, left out), horizontal/vertical/3D RMS and maximum position error (truth interpolated
linearly at each fix's GPS time), the 3D velocity RMS error, and the fraction of channel
reports in the window that were tracking with phase lock.
"""
import argparse
import csv
import math
import sys


def enu_rotation(x, y, z):
    lon = math.atan2(y, x)
    p = math.hypot(x, y)
    # geodetic latitude (Bowring, one iteration is plenty for a rotation)
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    lat = math.atan2(z, p * (1 - e2))
    for _ in range(5):
        n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
        h = p / math.cos(lat) - n
        lat = math.atan2(z, p * (1 - e2 * n / (n + h)))
    sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
    return [[-so, co, 0.0], [-sl * co, -sl * so, cl], [cl * co, cl * so, sl]]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("truth")
    ap.add_argument("--from", dest="t_from", type=float, default=-1e18)
    ap.add_argument("--to", dest="t_to", type=float, default=1e18)
    a = ap.parse_args()
    truth = [
        (float(r["tow_s"]), [float(r[k]) for k in ("x_m", "y_m", "z_m")],
         [float(r[k]) for k in ("vx_mps", "vy_mps", "vz_mps")])
        for r in csv.DictReader(open(a.truth))
    ]
    if len(truth) < 2:
        sys.exit("truth file has fewer than 2 rows")
    t0 = truth[0][0]
    lo, hi = t0 + a.t_from, t0 + a.t_to
    h2 = v2 = d2 = vel2 = 0.0
    n = nv = 0
    worst = 0.0
    j = 1
    flagged = 0
    for r in csv.DictReader(open(f"{a.out}/pvt.csv")):
        if not r["tow_s"]:
            continue
        t = float(r["tow_s"])
        if not (lo <= t <= hi) or t < truth[0][0] or t > truth[-1][0]:
            continue
        if r.get("quality", "gnss") == "none":
            # Written but flagged invalid (RAIM, PDOP): not a fix a user would take.
            flagged += 1
            continue
        while j < len(truth) - 1 and truth[j][0] < t:
            j += 1
        (ta, pa, va), (tb, pb, vb) = truth[j - 1], truth[j]
        u = (t - ta) / (tb - ta)
        p = [pa[k] + u * (pb[k] - pa[k]) for k in range(3)]
        v = [va[k] + u * (vb[k] - va[k]) for k in range(3)]
        d = [float(r[k]) - p[i] for i, k in enumerate(("x_m", "y_m", "z_m"))]
        rot = enu_rotation(*p)
        e, nn, up = (sum(rot[i][k] * d[k] for k in range(3)) for i in range(3))
        h2 += e * e + nn * nn
        v2 += up * up
        d3 = e * e + nn * nn + up * up
        d2 += d3
        worst = max(worst, math.sqrt(d3))
        n += 1
        if r.get("vx_mps"):
            fv = [float(r[k]) for k in ("vx_mps", "vy_mps", "vz_mps")]
            vel2 += sum((fv[k] - v[k]) ** 2 for k in range(3))
            nv += 1
    rows = locked = 0
    for r in csv.DictReader(open(f"{a.out}/channels.csv")):
        if not r["tow_s"] or not r["gps_week"]:
            continue
        t = float(r["tow_s"])
        if lo <= t <= hi and int(r["gps_week"]) > 0:
            rows += 1
            locked += r["state"] == "track" and r["carrier_lock"] in ("1", "true")
    if n == 0:
        print(f"fixes 0 in the window ({flagged} flagged invalid); phase-locked channel reports {locked}/{rows}")
        return
    print(
        f"fixes {n} ({flagged} more flagged invalid): RMS horizontal {math.sqrt(h2 / n):.2f} m, vertical {math.sqrt(v2 / n):.2f} m, "
        f"3D {math.sqrt(d2 / n):.2f} m (max {worst:.2f} m); velocity RMS "
        f"{math.sqrt(vel2 / max(nv, 1)):.3f} m/s; phase-locked channel reports "
        f"{locked}/{rows} ({100.0 * locked / max(rows, 1):.1f} %)"
    )


if __name__ == "__main__":
    main()
