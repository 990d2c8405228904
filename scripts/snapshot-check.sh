#!/usr/bin/env bash
# Scores `gpsrx snapshot` on the shared real snapshots (../shared/data/real/snapshots):
# the 60 SnapperGPS snapshots against their RTK truth with the a-priori 30 km off, and the
# 107 ms airborne capture against its reference position (a-priori 35 km and 3 s off).
# Prints the fix rate, the median and 95th percentile horizontal errors and the throughput;
# exits 1 when the data is missing or a check fails: each snapshot alone, fix rate < 90 %,
# median > 17 m or 95th percentile > 30 m (regression bounds: measured 14.7 and 25.0 m);
# smoothed across snapshots as a walker (--smooth-accel 0.5), median > 10 m or 95th
# percentile > 25 m (issue 27's acceptance); airborne error > 50 m.
set -euo pipefail
cd "$(dirname "$0")/.."
D=../shared/data/real/snapshots
BIN=${GPSRX:-target/ci/gpsrx}
[ -x "$BIN" ] || cargo build --profile ci -p gpsrx-cli
[ -f "$D/snappergps_w00_first60.json" ] || { echo "missing $D (shared data)"; exit 1; }
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
"$BIN" snapshot "$D/snappergps_w00_first60.json" --nav "$D/snappergps_w00.nav" \
  --approx-llh 52.03,-1.2574,112 --out "$OUT/snapper" \
  --truth "$D/snappergps_w00_first60_truth.json" --truth-h 112.4 2>/dev/null | tee "$OUT/snapper.txt"
"$BIN" snapshot "$D/snappergps_w00_first60.json" --nav "$D/snappergps_w00.nav" \
  --approx-llh 52.03,-1.2574,112 --smooth-accel 0.5 --out "$OUT/smooth" \
  --truth "$D/snappergps_w00_first60_truth.json" --truth-h 112.4 2>/dev/null | tee "$OUT/smooth.txt"
"$BIN" snapshot "$D/sxnsr_test_data_flight.stream" --nav "$D/sxnsr_test_data_flight.12n" \
  --format ri2_lsb --map 0.5,1.5,-1.5,-0.5 --fs 20.48e6 --if 5499998.474 \
  --time 1672:391561 --approx-llh 52.6,10.9,0 --height-sigma 0 --out "$OUT/air" \
  --truth-ecef 3839479.7,721777.3,5025349.9 2>/dev/null | tee "$OUT/air.txt"
awk '
  FNR == 1 && /snapshots:/ { n = $1; f = $3; if (f < 0.9 * n) { print "FAIL: fix rate"; bad = 1 } }
  /median/ {
    gsub(/,/, "");
    for (i = 1; i <= NF; i++) { if ($i == "median") med = $(i + 1); if ($i == "percentile") p95 = $(i + 1) }
    if (FILENAME ~ /snapper/ && (med > 17 || p95 > 30)) { print "FAIL: SnapperGPS errors"; bad = 1 }
    if (FILENAME ~ /smooth/ && (med > 10 || p95 > 25)) { print "FAIL: smoothed SnapperGPS errors"; bad = 1 }
    if (FILENAME ~ /air/ && med > 50) { print "FAIL: airborne error"; bad = 1 }
  }
  END { exit bad }' "$OUT/snapper.txt" "$OUT/smooth.txt" "$OUT/air.txt" && echo "snapshot check: ok"
