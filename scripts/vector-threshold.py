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
over scalar; then, so that a threshold counts only right observables, the errors of those taken
below 23 dB-Hz (true) against truth_sv.csv, their common part at each epoch removed (the
receiver clock): pseudorange RMS and largest, Doppler RMS, and carrier-phase slips (an
epoch-to-epoch phase change 0.35 cycle or more off the truth's). Exits 1 if a run fails.
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


def read_observables(rinex):
    """[(GPS time of week, {prn: (C1C, L1C, D1C)})] from a RINEX 3 observation file; event
    records (flags 2-5, e.g. where vector tracking takes the channels) and the lines they
    announce are skipped."""
    import datetime
    gps0 = datetime.datetime(1980, 1, 6)
    epochs, header, skip = [], True, 0
    for line in open(rinex):
        if header:
            header = "END OF HEADER" not in line
            continue
        if skip:
            skip -= 1
            continue
        if line.startswith(">"):
            if line[31:32] not in ("0", "1"):
                skip = int(line[32:35])
                continue
            f = line[1:].split()
            dt = datetime.datetime(int(f[0]), int(f[1]), int(f[2]), int(f[3]), int(f[4]))
            epochs.append((((dt - gps0).total_seconds() + float(f[5])) % 604800.0, {}))
        elif line.startswith("G") and epochs:
            cells = [line[3 + 16 * i: 3 + 16 * i + 14].strip() for i in range(3)]
            epochs[-1][1][int(line[1:3])] = tuple(float(c) if c else None for c in cells)
    return epochs


def last_observed(rinex):
    """Per PRN: the GPS time of week of its last epoch in a RINEX 3 observation file."""
    last = {}
    for tow, obs in read_observables(rinex):
        for prn in obs:
            last[prn] = tow
    return last


def weak_quality(sim, rinex, below_dbhz=23.0):
    """Errors of the observables taken below `below_dbhz` (true C/N0), the common part of
    each epoch removed: (count, pseudorange RMS m, pseudorange max m, Doppler RMS Hz, slips)."""
    truth = {}
    for r in csv.DictReader(open(f"{sim}/truth_sv.csv")):
        truth[(round(float(r["t_s"]), 1), int(r["prn"]))] = (
            float(r["pseudorange_m"]), float(r["carrier_phase_cycles"]), float(r["doppler_hz"]),
            float(r["cn0_dbhz"]))
    rows = list(csv.DictReader(open(f"{sim}/truth.csv")))
    t0 = float(rows[0]["tow_s"]) - float(rows[0]["t_s"])
    pr, dop, slips, prev = [], [], 0, {}
    for tow, obs in read_observables(rinex):
        t = round(tow - t0, 1)
        sats = {p: (o, truth[(t, p)]) for p, o in obs.items()
                if (t, p) in truth and None not in o}
        if len(sats) < 4:
            prev = {}
            continue
        e_pr = {p: o[0] - tr[0] for p, (o, tr) in sats.items()}
        e_dop = {p: o[2] - tr[2] for p, (o, tr) in sats.items()}
        m_pr, m_dop = statistics.median(e_pr.values()), statistics.median(e_dop.values())
        # Phase change against the truth's (the RINEX phase has the opposite sign of a
        # range-rate phase); its common part removed too.
        d_ph = {p: (o[1] - prev[p][0]) + (tr[1] - prev[p][1]) for p, (o, tr) in sats.items()
                if p in prev}
        m_ph = statistics.median(d_ph.values()) if len(d_ph) >= 4 else None
        for p, (o, tr) in sats.items():
            if tr[3] < below_dbhz:
                pr.append(e_pr[p] - m_pr)
                dop.append(e_dop[p] - m_dop)
                if m_ph is not None and p in d_ph and abs(d_ph[p] - m_ph) >= 0.35:
                    slips += 1
        prev = {p: (o[1], tr[1]) for p, (o, tr) in sats.items()}
    if not pr:
        return None
    rms = lambda v: (sum(x * x for x in v) / len(v)) ** 0.5
    return len(pr), rms(pr), max(map(abs, pr)), rms(dop), slips


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
    medians, modes_last = {}, {}
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
        q = weak_quality(sim, f"{out_dir}/{mode}/observables.rnx")
        if q:
            print(f"  {q[0]} observables below 23 dB-Hz: pseudorange error RMS {q[1]:.1f} m (max {q[2]:.1f}), "
                  f"Doppler error RMS {q[3]:.2f} Hz, carrier-phase slips {q[4]}")
        modes_last[mode] = per
    gains = [modes_last["scalar"][p] - modes_last["vector"][p]
             for p in modes_last["scalar"] if p in modes_last["vector"]]
    if gains:
        print(f"per satellite gain of vector over scalar: {min(gains):.1f} to {max(gains):.1f} dB, "
              f"{sum(g >= 3.0 for g in gains)} of {len(gains)} at least 3 dB")
    print(f"median threshold gain of vector over scalar: {medians['scalar'] - medians['vector']:.1f} dB")


if __name__ == "__main__":
    main()
