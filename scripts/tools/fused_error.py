#!/usr/bin/env python3
"""Horizontal errors of a `gpsrx run --dr` fused.csv against the simulator's truth.csv, by
source (fused: GNSS and DR; dr: dead reckoning alone).

usage: fused_error.py FUSED_CSV TRUTH_CSV
"""
import bisect
import csv
import math
import sys

truth = [(float(r["tow_s"]), float(r["lat_deg"]), float(r["lon_deg"])) for r in csv.DictReader(open(sys.argv[2]))]
ts = [t[0] for t in truth]
R = 6378137.0
by = {}
for r in csv.DictReader(open(sys.argv[1])):
    if not r["tow_s"]:
        continue
    t = float(r["tow_s"])
    j = bisect.bisect_left(ts, t)
    if j == 0 or j >= len(ts):
        continue
    (ta, la, oa), (tb, lb, ob) = truth[j - 1], truth[j]
    u = (t - ta) / (tb - ta)
    lat, lon = la + u * (lb - la), oa + u * (ob - oa)
    dn = math.radians(float(r["lat_deg"]) - lat) * R
    de = math.radians(float(r["lon_deg"]) - lon) * R * math.cos(math.radians(lat))
    by.setdefault(r["source"], []).append(math.hypot(de, dn))
for source, errs in sorted(by.items()):
    rms = math.sqrt(sum(e * e for e in errs) / len(errs))
    print(f"{source}: {len(errs)} rows, horizontal RMS {rms:.2f} m, max {max(errs):.2f} m")
