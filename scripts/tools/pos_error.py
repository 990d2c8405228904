#!/usr/bin/env python3
"""Errors of an RTKLIB .pos file (lat/lon/height output) against a static truth position.

usage: pos_error.py POS LAT LON H [--max-mean-m M]
Prints the number of epochs, the distance of the mean position from the truth, and the
horizontal and vertical RMS of the epochs; exits 1 when the mean is more than M from the truth.
"""
import argparse
import math
import sys

ap = argparse.ArgumentParser()
ap.add_argument("pos")
ap.add_argument("lat", type=float)
ap.add_argument("lon", type=float)
ap.add_argument("h", type=float)
ap.add_argument("--max-mean-m", type=float)
a = ap.parse_args()
lat0, lon0, h0 = a.lat, a.lon, a.h
rows = [l.split() for l in open(a.pos) if l.strip() and not l.startswith("%")]
if not rows:
    sys.exit("no solution in " + a.pos)
R = 6378137.0
en = []
for r in rows:
    lat, lon, h = float(r[2]), float(r[3]), float(r[4])
    dn = math.radians(lat - lat0) * R
    de = math.radians(lon - lon0) * R * math.cos(math.radians(lat0))
    en.append((de, dn, h - h0))
n = len(en)
me, mn, mu = (sum(v[i] for v in en) / n for i in range(3))
h_rms = math.sqrt(sum(e * e + nn * nn for e, nn, _ in en) / n)
v_rms = math.sqrt(sum(u * u for _, _, u in en) / n)
mean_err = math.sqrt(me * me + mn * mn + mu * mu)
print(f"{n} epochs: mean position {mean_err:.2f} m from the truth; "
      f"horizontal RMS {h_rms:.2f} m, vertical RMS {v_rms:.2f} m")
if a.max_mean_m is not None and mean_err > a.max_mean_m:
    print(f"the mean position is more than {a.max_mean_m} m from the truth")
    sys.exit(1)
