#!/usr/bin/env bash
# Scores `gpsrx snapshot` on the shared real snapshots (../shared/data/real/snapshots):
# the 60 SnapperGPS snapshots against their RTK truth with the a-priori 30 km off, and the
# 107 ms airborne capture against its reference position (a-priori 35 km and 3 s off).
# Prints the fix rate, the median and 95th percentile horizontal errors and the throughput;
# exits 1 when the data is missing or a check fails (fix rate < 90 %, median > 25 m,
# 95th percentile > 60 m, airborne error > 50 m: regression bounds, not the issue's 10 m goal).
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
"$BIN" snapshot "$D/sxnsr_test_data_flight.stream" --nav "$D/sxnsr_test_data_flight.12n" \
  --format ri2_lsb --map 0.5,1.5,-1.5,-0.5 --fs 20.48e6 --if 5499998.474 \
  --time 1672:391561 --approx-llh 52.6,10.9,0 --height-sigma 0 --out "$OUT/air" \
  --truth-ecef 3839479.7,721777.3,5025349.9 2>/dev/null | tee "$OUT/air.txt"
awk '
  FNR == 1 && /snapshots:/ { n = $1; f = $3; if (f < 0.9 * n) { print "FAIL: fix rate"; bad = 1 } }
  /median/ {
    gsub(/,/, "");
    for (i = 1; i <= NF; i++) { if ($i == "median") med = $(i + 1); if ($i == "percentile") p95 = $(i + 1) }
    if (FILENAME ~ /snapper/ && (med > 25 || p95 > 60)) { print "FAIL: SnapperGPS errors"; bad = 1 }
    if (FILENAME ~ /air/ && med > 50) { print "FAIL: airborne error"; bad = 1 }
  }
  END { exit bad }' "$OUT/snapper.txt" "$OUT/air.txt" && echo "snapshot check: ok"
