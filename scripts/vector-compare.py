#!/usr/bin/env python3
"""Scalar vs vector tracking (issue 29) on simulated scenarios, scored against the simulator's truth.

Usage: simulate first (VEC_WORK defaults to /tmp/vec):
  gpsrx simulate samples/scenarios/vector-weak-26-32dbhz.toml -o $VEC_WORK/sim-vector-weak-26-32dbhz
  gpsrx simulate samples/scenarios/vector-blockage-3s.toml   -o $VEC_WORK/sim-vector-blockage-3s
  gpsrx simulate samples/scenarios/turn-10g-ins-perfect.toml -o $VEC_WORK/sim-turn
  gpsrx simulate samples/scenarios/turn-10g-ins-1mg.toml    -o $VEC_WORK/sim-turn-ins-1mg
then `scripts/vector-compare.py weak|block|turn|turn-ins`. Prints, per mode: valid fixes, mean
satellites in the fixes, the PRNs used, horizontal RMS against truth.csv, the time back to a valid
fix after the blockage and the largest 3-D error in the 3 s after it, and the share of 20-27 s
each satellite's channel was in carrier lock in the turn. `block SIM` scores another simulation
of the blockage (the scenario with another seed); `turn-ins` runs scalar with the INS, vector,
and vector with the INS on the turn with a 1 mg INS; `turn-ins-wrong` runs scalar and vector with
that INS log altered three ways (50 ms late, 10 mg more bias, 5 % scale factor on its velocity
change) and prints the satellites held and the 3-D RMS over 19-30 s; `turn-ins-cut` cuts 31 ms
of samples at 22 s (inside the turn) and scores scalar and vector with the INS;
`gpssim-weak [DB]` weakens the GPS-SDR-SIM recording of ../shared/data by DB (default 12) with
scripts/tools/weaken.py and scores scalar and vector (with --nav) against its truth position:
valid fixes, mean satellites in them, horizontal RMS, over all fixes and from 15 s.
VEC_EXTRA adds arguments to every `gpsrx run` (e.g. `--config my.toml`).
"""
import csv, json, math, subprocess, sys, os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GPSRX = os.environ.get("GPSRX", os.path.join(ROOT, "target/ci/gpsrx"))
NAV = os.environ.get("NAV", os.path.join(ROOT, "../shared/data/brdc0010.22n"))
EXTRA = os.environ.get("VEC_EXTRA", "").split()  # added to every `gpsrx run`

def ecef_to_enu_err(x, y, z, tx, ty, tz, lat, lon):
    la, lo = math.radians(lat), math.radians(lon)
    dx, dy, dz = x - tx, y - ty, z - tz
    e = -math.sin(lo) * dx + math.cos(lo) * dy
    n = -math.sin(la) * math.cos(lo) * dx - math.sin(la) * math.sin(lo) * dy + math.cos(la) * dz
    u = math.cos(la) * math.cos(lo) * dx + math.cos(la) * math.sin(lo) * dy + math.sin(la) * dz
    return e, n, u

def truth(sim):
    rows = list(csv.DictReader(open(f"{sim}/truth.csv")))
    return [(float(r["tow_s"]), float(r["x_m"]), float(r["y_m"]), float(r["z_m"]), float(r["lat_deg"]), float(r["lon_deg"]), float(r["t_s"])) for r in rows]

def truth_at(tr, tow):
    # linear interpolation in tow
    lo, hi = 0, len(tr) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if tr[mid][0] <= tow: lo = mid
        else: hi = mid
    a, b = tr[lo], tr[hi]
    w = 0.0 if b[0] == a[0] else (tow - a[0]) / (b[0] - a[0])
    return tuple(a[i] + w * (b[i] - a[i]) for i in range(7))

def run(sim, mode, out, extra=()):
    cmd = [GPSRX, "run", f"{sim}/signal.sigmf-meta", "--nav", NAV, "--allow-unhealthy",
           "--tracking", mode, "--out", out, "--json", "--no-plots", *extra,
           *EXTRA]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stderr[-2000:]); sys.exit(1)
    open(out + ".err", "w").write(r.stderr)
    return json.loads(r.stdout)

def score(sim, out, t_start_tow, window=None):
    tr = truth(sim)
    fixes = [r for r in csv.DictReader(open(f"{out}/pvt.csv")) if r["quality"] != "none"]
    res = []
    for f in fixes:
        tow = float(f["tow_s"])
        t = truth_at(tr, tow - float(f["clock_bias_m"]) / 299792458.0)
        e, n, u = ecef_to_enu_err(float(f["x_m"]), float(f["y_m"]), float(f["z_m"]), t[1], t[2], t[3], t[4], t[5])
        res.append((tow - t_start_tow, math.hypot(e, n), abs(u), int(f["n_sv"]), f["used_prns"].split(), float(f["sigma_e_m"]), float(f["sigma_n_m"]), math.sqrt(e * e + n * n + u * u)))
    return res

def summary(name, summ, res, sel=lambda r: True):
    rs = [r for r in res if sel(r)]
    if not rs:
        print(f"{name}: no valid fixes"); return
    h = math.sqrt(sum(r[1] ** 2 for r in rs) / len(rs))
    used = sorted({p for r in rs for p in r[4]}, key=int)
    mean_n = sum(r[3] for r in rs) / len(rs)
    print(f"{name}: first fix {summ.get('first_fix_s')}, valid fixes {len(rs)}, mean n_sv {mean_n:.2f}, PRNs used {len(used)} {used}, "
          f"H RMS {h:.2f} m, H max {max(r[1] for r in rs):.2f} m, vector {summ.get('vector')}")
    return rs

def locks(out, t0, t1):
    rows = [r for r in csv.DictReader(open(f"{out}/channels.csv")) if r["t_stream_s"] and t0 <= float(r["t_stream_s"]) <= t1]
    per = {}
    for r in rows:
        per.setdefault(r["prn"], []).append(r["carrier_lock"] == "1" and r["state"] == "track")
    return {p: sum(v) / len(v) for p, v in per.items()}

if __name__ == "__main__":
    which = sys.argv[1]
    base = os.environ.get("VEC_WORK", "/tmp/vec")
    if which == "weak":
        sim = f"{base}/sim-vector-weak-26-32dbhz"
        for mode in ("scalar", "vector"):
            out = f"{base}/weak-{mode}"
            s = run(sim, mode, out)
            res = score(sim, out, 538194.0)
            summary(f"weak {mode} (all)", s, res)
            summary(f"weak {mode} (t>=20s)", s, res, lambda r: r[0] >= 20)
            print("  lock share 20-40 s:", {p: round(v, 2) for p, v in sorted(locks(out, 20, 40).items(), key=lambda x: int(x[0]))})
    if which == "block":
        sim = sys.argv[2] if len(sys.argv) > 2 else f"{base}/sim-vector-blockage-3s"
        tag = os.path.basename(sim.rstrip("/"))
        for mode in ("scalar", "vector"):
            out = f"{base}/block-{tag}-{mode}"
            s = run(sim, mode, out)
            res = score(sim, out, 538194.0)
            summary(f"block {mode} (before)", s, res, lambda r: r[0] < 20)
            after = [r for r in res if r[0] >= 23]
            if after:
                first3 = [r for r in after if r[0] <= after[0][0] + 3.0]
                print(f"  first valid fix after the blockage: {after[0][0] - 23:.2f} s after it ended, "
                      f"errors of the first 10: {[round(r[1], 1) for r in after[:10]]}, n_sv {[r[3] for r in after[:10]]}; "
                      f"in the 3 s after it: 3-D max {max(r[7] for r in first3):.1f} m, horizontal max {max(r[1] for r in first3):.1f} m")
                summary(f"block {mode} (after)", s, res, lambda r: r[0] >= 23)
    if which == "turn-ins":
        sim = f"{base}/sim-turn-ins-1mg"
        ins = ["--ins", f"{sim}/ins.csv"]
        for mode, extra in (("scalar", ins), ("vector", []), ("vector", ins)):
            out = f"{base}/turn-ins-{mode}-{len(extra)}"
            s = run(sim, mode, out, extra)
            res = score(sim, out, 538194.0)
            name = f"turn {mode}{' + INS' if extra else ''}"
            summary(f"{name} (20-27 s)", s, res, lambda r: 20 <= r[0] <= 27)
            lk = locks(out, 20, 27)
            held = [p for p, v in lk.items() if v >= 0.95]
            print(f"  satellites held through the turn (carrier lock >= 95% of 20-27 s): {len(held)} of {len(lk)}: {sorted(lk.items(), key=lambda x: int(x[0]))}")
    if which == "turn":
        PSD1000 = f"{base}/psd1000.toml"
        with open(PSD1000, "w") as f:
            f.write("[vector]\naccel_psd_m2_s3 = 1000.0\n")
        sim = f"{base}/sim-turn"
        cfgs = [("scalar", []), ("vector", []), ("vector", ["--config", PSD1000])]
        for i, (mode, extra) in enumerate(cfgs):
            out = f"{base}/turn-{mode}-{i}"
            s = run(sim, mode, out, extra)
            res = score(sim, out, 538194.0)
            summary(f"turn {mode} {extra} (all)", s, res)
            summary(f"turn {mode} (20-27 s)", s, res, lambda r: 20 <= r[0] <= 27)
            lk = locks(out, 20, 27)
            held = [p for p, v in lk.items() if v >= 0.95]
            print(f"  satellites held through the turn (carrier lock >= 95% of 20-27 s): {len(held)} of {len(lk)}: {sorted(lk.items(), key=lambda x: int(x[0]))}")

def altered_ins(src, dst_dir):
    """The INS log `src` altered three ways; returns {name: path}."""
    rows = list(csv.DictReader(open(src)))
    cols = list(rows[0].keys())
    pos, vel = ["x_m", "y_m", "z_m"], ["vx_mps", "vy_mps", "vz_mps"]
    out = {}
    def write(name, rs):
        path = f"{dst_dir}/ins-{name}.csv"
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=cols); w.writeheader(); w.writerows(rs)
        out[name] = path
    # 50 ms late (5 samples at 100 Hz): the content of 50 ms before, same time stamps.
    write("late-50ms", [dict(r, **{c: rows[max(k - 5, 0)][c] for c in pos + vel}) for k, r in enumerate(rows)])
    b = 0.0980665
    def biased(r):
        t = float(r["t_s"])
        return dict(r, **{c: "%.9f" % (float(r[c]) + b * t) for c in vel}, **{c: "%.6f" % (float(r[c]) + 0.5 * b * t * t) for c in pos})
    write("bias-10mg", [biased(r) for r in rows])
    v0 = [float(rows[0][c]) for c in vel]; p0 = [float(rows[0][c]) for c in pos]
    def scaled(r):
        t = float(r["t_s"])
        d = {c: "%.9f" % (float(r[c]) + 0.05 * (float(r[c]) - v0[i])) for i, c in enumerate(vel)}
        d.update({c: "%.6f" % (float(r[c]) + 0.05 * (float(r[c]) - p0[i] - v0[i] * t)) for i, c in enumerate(pos)})
        return dict(r, **d)
    write("scale-5pc", [scaled(r) for r in rows])
    return out

def rms_3d(res, t0, t1):
    rs = [r[7] for r in res if t0 <= r[0] <= t1]
    return math.sqrt(sum(x * x for x in rs) / len(rs)) if rs else float("nan")

if __name__ == "__main__" and sys.argv[1] == "turn-ins-wrong":
    base = os.environ.get("VEC_WORK", "/tmp/vec")
    sim = f"{base}/sim-turn-ins-1mg"
    for name, path in altered_ins(f"{sim}/ins.csv", base).items():
        for mode in ("scalar", "vector"):
            out = f"{base}/wrong-{name}-{mode}"
            s = run(sim, mode, out, ["--ins", path])
            res = score(sim, out, 538194.0)
            lk = locks(out, 20, 27)
            held = sum(1 for v in lk.values() if v >= 0.95)
            v = s.get("vector") or {}
            print(f"INS {name}, {mode}: held {held} of {len(lk)}, 3-D RMS 19-30 s {rms_3d(res, 19, 30):.2f} m, handed back {v.get('disengagements', '-')} times")

if __name__ == "__main__" and sys.argv[1] == "turn-ins-cut":
    base = os.environ.get("VEC_WORK", "/tmp/vec")
    sim = f"{base}/sim-turn-ins-1mg"
    cut = f"{base}/turn-ins-cut22.ci8"
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts/tools/fault.py"), f"{sim}/signal.ci8", cut,
                    "--bytes-per-sample", "2", "--fs", "2.6e6", "--cut", "22", "0.031"], check=True, capture_output=True)
    for mode in ("scalar", "vector"):
        out = f"{base}/turn-ins-cut-{mode}"
        cmd = [GPSRX, "run", cut, "--format", "ci8", "--fs", "2.6e6", "--nav", NAV, "--allow-unhealthy",
               "--tracking", mode, "--ins", f"{sim}/ins.csv", "--out", out, "--json", "--no-plots"]
        r = subprocess.run(cmd, capture_output=True, text=True)
        res = score(sim, out, 538194.0)
        rs = [x for x in res if 19 <= x[0] <= 30]
        worst = max((x[7] for x in rs), default=float("nan"))
        print(f"31 ms cut at 22 s, {mode} + INS: {len(rs)} valid fixes over 19-30 s, 3-D RMS {rms_3d(res, 19, 30):.2f} m, max {worst:.1f} m")

def gpssim_score(out, t_from):
    """Valid fixes of `out` from `t_from` s (TOW 538200 + t_from) against the GPS-SDR-SIM
    recording's truth (37.5665, 126.9780, 40 m): count, mean satellites, horizontal RMS."""
    la, lo, h = math.radians(37.5665), math.radians(126.9780), 40.0
    a, e2 = 6378137.0, 6.69437999014e-3
    n = a / math.sqrt(1 - e2 * math.sin(la) ** 2)
    tx, ty = (n + h) * math.cos(la) * math.cos(lo), (n + h) * math.cos(la) * math.sin(lo)
    tz = (n * (1 - e2) + h) * math.sin(la)
    hs, ns = [], []
    for r in csv.DictReader(open(f"{out}/pvt.csv")):
        if r["quality"] == "none" or float(r["tow_s"]) - 538200.0 < t_from:
            continue
        e, nn, _ = ecef_to_enu_err(float(r["x_m"]), float(r["y_m"]), float(r["z_m"]), tx, ty, tz, 37.5665, 126.9780)
        hs.append(math.hypot(e, nn))
        ns.append(int(r["n_sv"]))
    if not hs:
        return "no valid fix"
    return f"{len(hs)} valid fixes, mean satellites {sum(ns) / len(ns):.2f} of 8, horizontal RMS {math.sqrt(sum(x * x for x in hs) / len(hs)):.2f} m"

if __name__ == "__main__" and sys.argv[1] == "gpssim-weak":
    # The GPS-SDR-SIM recording of ../shared/data weakened by DB (default 12) with
    # scripts/tools/weaken.py, scalar against vector with --nav (no troposphere in it).
    db = sys.argv[2] if len(sys.argv) > 2 else "12"
    base = os.environ.get("VEC_WORK", "/tmp/vec")
    src = os.path.join(ROOT, "../shared/data/gpssim-static-seoul-2p6msps.ci8.zst")
    raw, weak = f"{base}/gpssim.ci8", f"{base}/gpssim-weak-{db}.ci8"
    if not os.path.exists(src):
        sys.exit(f"vector-compare.py gpssim-weak: {src} not found (the shared GPS-SDR-SIM recording)")
    if not os.path.exists(raw):
        try:
            subprocess.run(["zstd", "-q", "-d", "-f", "-o", raw, src], check=True)
        except (OSError, subprocess.CalledProcessError) as e:
            sys.exit(f"vector-compare.py gpssim-weak: cannot decompress {src} with zstd ({e}): install zstd")
    if not os.path.exists(weak):
        subprocess.run([sys.executable, os.path.join(ROOT, "scripts/tools/weaken.py"), raw, weak, "--db", db], check=True, capture_output=True)
    for mode in ("scalar", "vector"):
        out = f"{base}/gpssim-weak-{db}-{mode}"
        cmd = [GPSRX, "run", weak, "--format", "ci8", "--fs", "2.6e6", "--tropo", "none", "--nav", NAV,
               "--allow-unhealthy", "--tracking", mode, "--out", out, "--json", "--no-plots",
               *EXTRA]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            print(r.stderr[-2000:]); sys.exit(1)
        print(f"-{db} dB, {mode}: all: {gpssim_score(out, 0.0)}; from 15 s: {gpssim_score(out, 15.0)}")
