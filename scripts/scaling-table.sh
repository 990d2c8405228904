#!/usr/bin/env bash
# How the receiver's cost grows with the sampling rate and the number of channels, on this
# machine: the README's scaling table.
#
#   scripts/scaling-table.sh [DURATION_S]        (default 8)
#
# For each rate (2.6, 4, 16, 24 MHz; RATES="..." to change) and 4, 8 and 12 satellites
# (the first N of the 12 above 5 degrees in samples/scenarios/static-seoul-4msps.toml), it
# simulates DURATION_S of ci8 and times `gpsrx run --search-budget 0` (CPU time: user + sys,
# and wall). Per rate, a least-squares line CPU = a + b * channels gives the cost of one
# channel (b, as ns of CPU per sample and as the share of one core it keeps busy)
# and of everything else (a: reading, the cold search, navigation).
# Environment: GPSRX (the binary; default: build release), RUN_ARGS (extra `gpsrx run` options,
# e.g. "--correlator avx2"), WORK (scratch, default mktemp -d; recordings are deleted as they
# are used).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
DURATION=${1:-8}
RATES=${RATES:-"2.6e6 4e6 16e6 24e6"}
WORK=${WORK:-$(mktemp -d)}
RUN_ARGS=${RUN_ARGS:-}
mkdir -p "$WORK"
die() { echo "scaling-table: $*" >&2; exit 1; }
command -v python3 >/dev/null || die "python3 is required"
[[ -x /usr/bin/time ]] || die "/usr/bin/time is required (Debian package 'time')"
if [[ -z ${GPSRX:-} ]]; then
    (cd "$ROOT" && cargo build --release -p gpsrx-cli >&2)
    GPSRX=${CARGO_TARGET_DIR:-$ROOT/target}/release/gpsrx
fi
[[ -x $GPSRX ]] || die "no binary at $GPSRX"
PRNS=(1 3 7 8 10 14 17 21 22 27 28 30)
RESULTS=$WORK/results.csv
echo "fs_hz,satellites,tracked,cpu_s,wall_s,duration_s" >"$RESULTS"
for fs in $RATES; do
    for n in 4 8 12; do
        list=$(IFS=,; echo "${PRNS[*]:0:$n}")
        sed -e "s/^duration_s = .*/duration_s = $DURATION/" \
            -e 's|^nav = .*|nav = "builtin:brdc0010.22n"|' \
            "$ROOT/samples/scenarios/static-seoul-4msps.toml" >"$WORK/scenario.toml"
        printf '\n[satellites]\nprns = [%s]\n' "$list" >>"$WORK/scenario.toml"
        echo "simulating $DURATION s at $fs Hz with $n satellites..." >&2
        rm -rf "$WORK/sim"
        "$GPSRX" simulate "$WORK/scenario.toml" --fs "$fs" -o "$WORK/sim" >/dev/null
        rm -rf "$WORK/out"
        # Exit 2 (no fix: a short run without --nav) is a complete run.
        status=0
        # shellcheck disable=SC2086
        /usr/bin/time -f "%U %S %e" -o "$WORK/time.txt" \
            "$GPSRX" run "$WORK/sim/signal.ci8" --out "$WORK/out" --search-budget 0 --json $RUN_ARGS \
            >"$WORK/run.json" 2>"$WORK/run.log" || status=$?
        [[ $status -le 2 && $status -ne 1 ]] || die "gpsrx run failed (exit $status): see $WORK/run.log"
        python3 - "$fs" "$n" "$WORK/run.json" "$WORK/time.txt" "$DURATION" >>"$RESULTS" <<'PY'
import json, sys
fs, n, run, tm, dur = sys.argv[1:]
s = json.load(open(run))
u, sy, wall = map(float, open(tm).read().split()[-3:])
print(f"{float(fs):.0f},{n},{len(s['tracked_prns'])},{u + sy:.3f},{wall:.3f},{float(dur):g}")
PY
        rm -rf "$WORK/sim" "$WORK/out"
    done
done
CPU_MODEL=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
python3 - "$RESULTS" "$CPU_MODEL" "$RUN_ARGS" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print(f"\nscaling on {sys.argv[2]}, {len(rows)} runs of `gpsrx run --search-budget 0 {sys.argv[3]}`".rstrip())
print("\n| fs (MHz) | channels | CPU s | wall s | real time |")
print("|---|---|---|---|---|")
for r in rows:
    d, w = float(r["duration_s"]), float(r["wall_s"])
    print(f"| {float(r['fs_hz']) / 1e6:g} | {r['tracked']} | {float(r['cpu_s']):.2f} | {w:.2f} | {d / w:.1f}x |")
print("\nPer rate, CPU = a + b * channels (least squares over the runs above):\n")
print("| fs (MHz) | one channel: ns of CPU per sample | one channel: % of a core | the rest: % of a core |")
print("|---|---|---|---|")
by_fs = {}
for r in rows:
    by_fs.setdefault(float(r["fs_hz"]), []).append(r)
for fs, rs in sorted(by_fs.items()):
    xs = [float(r["tracked"]) for r in rs]
    ys = [float(r["cpu_s"]) / float(r["duration_s"]) for r in rs]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")
    a = my - b * mx
    print(f"| {fs / 1e6:g} | {b / fs * 1e9:.2f} | {100 * b:.2f} | {100 * a:.1f} |")
PY
echo
echo "raw results in $RESULTS"
