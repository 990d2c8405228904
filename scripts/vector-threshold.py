#!/usr/bin/env python3
"""Tracking threshold per mode (issue 29) on a fading simulation: each satellite's threshold is
its true C/N0 (truth_sv.csv) at its last observables (observables.rnx: phase-locked, above the
loss threshold), once it has left them for good; scalar against vector, run on the same
recording.

Usage: gpsrx simulate samples/scenarios/vector-threshold-fade.toml -o SIM
       scripts/vector-threshold.py SIM [OUT_DIR] [-- extra gpsrx run arguments]
GPSRX (default target/ci/gpsrx) and NAV (default ../shared/data/brdc0010.22n, else the copy in
samples/data) name the binary and the navigation file. Prints, per mode, every satellite's
threshold, their median and how many were used until the end, and the median gain of vector
over scalar; exits 1 if a run fails.
"""
import csv
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GPSRX = os.environ.get("GPSRX", os.path.join(ROOT, "target/ci/gpsrx"))
NAV = os.environ.get("NAV", os.path.join(ROOT, "../shared/data/brdc0010.22n"))
if not os.path.exists(NAV):
    NAV = os.path.join(ROOT, "samples/data/brdc0010.22n")


def truth_cn0(sim):
    """Per PRN: sorted (t_s, C/N0) from truth_sv.csv."""
    per = {}
    for r in csv.DictReader(open(f"{sim}/truth_sv.csv")):
        per.setdefault(int(r["prn"]), []).append((float(r["t_s"]), float(r["cn0_dbhz"])))
    return per


def cn0_at(series, t):
    best = min(series, key=lambda p: abs(p[0] - t))
    return best[1]


def last_observed(rinex):
    """Per PRN: the GPS time of week of its last epoch in a RINEX 3 observation file."""
    import datetime
    gps0 = datetime.datetime(1980, 1, 6)
    last, tow = {}, None
    header = True
    for line in open(rinex):
        if header:
            header = "END OF HEADER" not in line
            continue
        if line.startswith(">"):
            f = line[1:].split()
            sec = float(f[5])
            dt = datetime.datetime(int(f[0]), int(f[1]), int(f[2]), int(f[3]), int(f[4]))
            tow = ((dt - gps0).total_seconds() + sec) % 604800.0
        elif line.startswith("G") and tow is not None:
            last[int(line[1:3])] = tow
    return last


def thresholds(sim, out, extra, mode):
    """Per PRN the stream time of its last observables (None: to the end of the recording),
    and the recording's length."""
    cmd = [GPSRX, "run", f"{sim}/signal.sigmf-meta", "--nav", NAV, "--allow-unhealthy",
           "--tracking", mode, "--no-plots", "--out", out, *extra]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stderr[-2000:])
        sys.exit(1)
    rows = list(csv.DictReader(open(f"{sim}/truth.csv")))
    t0 = float(rows[0]["tow_s"]) - float(rows[0]["t_s"])  # GPS time of stream time 0
    end_t = float(rows[-1]["t_s"])
    last = {p: tow - t0 for p, tow in last_observed(f"{out}/observables.rnx").items()}
    return last, end_t


def main():
    args = sys.argv[1:]
    extra = []
    if "--" in args:
        i = args.index("--")
        args, extra = args[:i], args[i + 1:]
    if not args:
        sys.exit(__doc__)
    sim = args[0]
    out_dir = args[1] if len(args) > 1 else "/tmp/vector-threshold"
    os.makedirs(out_dir, exist_ok=True)
    truth = truth_cn0(sim)
    medians = {}
    for mode in ("scalar", "vector"):
        last, end_t = thresholds(sim, f"{out_dir}/{mode}", extra, mode)
        per = {}
        to_end = []
        for prn, t in sorted(last.items()):
            if t >= end_t - 1.0:
                to_end.append(prn)
            else:
                per[prn] = cn0_at(truth[prn], t)
        cells = " ".join(f"G{p:02} {c:.1f}" for p, c in per.items())
        med = statistics.median(per.values()) if per else float("nan")
        medians[mode] = med
        print(f"{mode}: thresholds (true C/N0 at each satellite's last observables, dB-Hz): {cells}; "
              f"median {med:.1f} dB-Hz; used to the end: {to_end}")
    print(f"median threshold gain of vector over scalar: {medians['scalar'] - medians['vector']:.1f} dB")


if __name__ == "__main__":
    main()
