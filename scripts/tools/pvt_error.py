#!/usr/bin/env python3
"""Errors of a gpsrx pvt.csv against a static truth position.

usage: pvt_error.py PVT_CSV LAT_DEG LON_DEG H_M [--max-h M --max-v M --max-vel MPS --min-sv N]
Prints fixes, first fix time, horizontal / vertical RMS, velocity RMS, mean ENU error; exits 1
when a limit is exceeded.
"""
import argparse, csv, math, sys

p = argparse.ArgumentParser()
p.add_argument("pvt"); p.add_argument("lat", type=float); p.add_argument("lon", type=float); p.add_argument("h", type=float)
p.add_argument("--max-h", type=float); p.add_argument("--max-v", type=float); p.add_argument("--max-vel", type=float)
p.add_argument("--min-sv", type=int)
a = p.parse_args()
rows = list(csv.DictReader(open(a.pvt)))
if not rows:
    print("no fixes in", a.pvt); sys.exit(1)
A = 6378137.0; F = 1 / 298.257223563; E2 = F * (2 - F)
lat0, lon0 = math.radians(a.lat), math.radians(a.lon)
def ecef(lat, lon, h):
    n = A / math.sqrt(1 - E2 * math.sin(lat) ** 2)
    return ((n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon), (n * (1 - E2) + h) * math.sin(lat))
x0 = ecef(lat0, lon0, a.h)
sl, cl, so, co = math.sin(lat0), math.cos(lat0), math.sin(lon0), math.cos(lon0)
H, V, VEL, E, N, U = [], [], [], [], [], []
for r in rows:
    d = [float(r["x_m"]) - x0[0], float(r["y_m"]) - x0[1], float(r["z_m"]) - x0[2]]
    e = -so * d[0] + co * d[1]; n = -sl * co * d[0] - sl * so * d[1] + cl * d[2]; u = cl * co * d[0] + cl * so * d[1] + sl * d[2]
    H.append(e * e + n * n); V.append(u * u); E.append(e); N.append(n); U.append(u)
    if r["vx_mps"]:
        VEL.append(sum(float(r[k]) ** 2 for k in ("vx_mps", "vy_mps", "vz_mps")))
rms = lambda v: math.sqrt(sum(v) / len(v)) if v else float("nan")
mean = lambda v: sum(v) / len(v)
hr, vr, velr = rms(H), rms(V), rms(VEL)
nsv = min(int(r["n_sv"]) for r in rows)
print(f"fixes {len(rows)} from TOW {rows[0]['tow_s']}; satellites used >= {nsv}; horizontal RMS {hr:.3f} m, vertical RMS {vr:.3f} m, "
      f"velocity RMS {velr:.4f} m/s; mean error E {mean(E):+.2f} N {mean(N):+.2f} U {mean(U):+.2f} m")
ok = True
for name, val, lim in (("horizontal RMS", hr, a.max_h), ("vertical RMS", vr, a.max_v), ("velocity RMS", velr, a.max_vel)):
    if lim is not None and not (val <= lim):
        print(f"FAIL: {name} {val:.3f} > {lim}"); ok = False
if a.min_sv is not None and nsv < a.min_sv:
    print(f"FAIL: only {nsv} satellites used in some fix (want {a.min_sv})"); ok = False
sys.exit(0 if ok else 1)
