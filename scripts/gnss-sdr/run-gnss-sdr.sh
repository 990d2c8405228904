#!/usr/bin/env bash
# Process a raw GPS L1 C/A I/Q recording with GNSS-SDR (an independent
# receiver) and score its position fixes against the known truth.
#
#   run-gnss-sdr.sh FILE FORMAT FS_HZ TRUTH_LAT_DEG TRUTH_LON_DEG TRUTH_H_M [OUTDIR]
#   run-gnss-sdr.sh --self-test
#
# FORMAT: ci8 | ci16_le | cf32_le (SigMF names; ibyte/ishort/gr_complex also accepted)
# Exit: 0 pass, 1 error >= MAX_ERR_M (m, default 10), 2 no fix, 3 GNSS-SDR failed,
#       4 missing tool, 64 usage error. See README.md for the environment knobs.
set -euo pipefail

SCRIPT_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
TEMPLATE="$SCRIPT_DIR/gps_l1_ca_file.conf.in"
HELPER="$SCRIPT_DIR/gnss_sdr_report.py"

usage() {
    sed -n '2,10p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
    exit 64
}
die() { echo "run-gnss-sdr: $*" >&2; exit "${2:-64}"; }

command -v python3 >/dev/null || die "python3 is required" 4

if [[ ${1:-} == "--self-test" ]]; then
    exec python3 "$HELPER" selftest --template "$TEMPLATE"
fi
[[ ${1:-} == "-h" || ${1:-} == "--help" ]] && usage
[[ $# -eq 6 || $# -eq 7 ]] || usage

FILE_ARG=$1 FORMAT=$2 FS_ARG=$3 LAT=$4 LON=$5 HGT=$6 OUTDIR_ARG=${7:-}

command -v gnss-sdr >/dev/null || die "gnss-sdr not found (Debian: apt-get install gnss-sdr)" 4
[[ -f $FILE_ARG && -r $FILE_ARG ]] || die "cannot read sample file '$FILE_ARG'"
FILE=$(realpath -e -- "$FILE_ARG")

case ${FORMAT,,} in
    ci8 | ibyte | int8 | sc8) FORMAT=ci8 ITEM_TYPE=ibyte ADAPTER=Ibyte_To_Complex BYTES_PER_SAMPLE=2 ;;
    ci16_le | ci16 | ishort | int16 | sc16) FORMAT=ci16_le ITEM_TYPE=ishort ADAPTER=Ishort_To_Complex BYTES_PER_SAMPLE=4 ;;
    cf32_le | cf32 | gr_complex | fc32) FORMAT=cf32_le ITEM_TYPE=gr_complex ADAPTER=Pass_Through BYTES_PER_SAMPLE=8 ;;
    *) die "unknown FORMAT '$FORMAT' (use ci8, ci16_le or cf32_le)" ;;
esac

num_re='^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$'
for v in "$FS_ARG" "$LAT" "$LON" "$HGT" "${IF_HZ:-0}" "${MAX_ERR_M:-10}"; do
    [[ $v =~ $num_re ]] || die "not a number: '$v'"
done
# GNSS-SDR wants integer rates; accept 2.6e6 as well as 2600000
FS=$(python3 -c 'import sys; v=float(sys.argv[1]); r=round(v); sys.exit(1) if r<=0 or abs(v-r)>1e-6 else print(r)' "$FS_ARG") ||
    die "bad FS_HZ '$FS_ARG': must be a positive integer number of Hz"
IF_HZ=$(python3 -c 'import sys; print(repr(float(sys.argv[1])).rstrip("0").rstrip("."))' "${IF_HZ:-0}")

# ---------------------------------------------------------------- knobs
MAX_ERR_M=${MAX_ERR_M:-10}
TROP_MODEL=${TROP_MODEL:-Saastamoinen} # OFF for recordings simulated without troposphere
IONO_MODEL=${IONO_MODEL:-Broadcast}    # Klobuchar from the navigation message
CHANNELS=${CHANNELS:-12}
ACQ_PFA=${ACQ_PFA:-0.0000001}
ACQ_COH_MS=${ACQ_COH_MS:-4}
ACQ_DOPPLER_MAX=${ACQ_DOPPLER_MAX:-6000}
ACQ_DOPPLER_STEP=${ACQ_DOPPLER_STEP:-$((500 / ACQ_COH_MS))}
CN0_MIN=${CN0_MIN:-30}
ELEV_MASK=${ELEV_MASK:-5}
SKIP_FIXES=${SKIP_FIXES:-0}
PASS_METRIC=${PASS_METRIC:-fixes}      # fixes: mean of per-fix 3D errors; position: error of the mean position
[[ $PASS_METRIC == fixes || $PASS_METRIC == position ]] || die "PASS_METRIC must be 'fixes' or 'position'"
FILE_START=${FILE_START:-}             # optional: GPS 'WEEK:TOW' or UTC 'HH:MM:SS' of the first sample
LEAP_SECONDS=${LEAP_SECONDS:-18}
case ${TROP_MODEL,,} in off | none | 0 | false) TROP_MODEL=OFF ;; saastamoinen) TROP_MODEL=Saastamoinen ;; esac
case ${IONO_MODEL,,} in off | none | 0 | false) IONO_MODEL=OFF ;; broadcast | klobuchar) IONO_MODEL=Broadcast ;; esac
if python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) == 0 else 1)' "$IF_HZ"; then
    INPUT_FILTER=${INPUT_FILTER:-Pass_Through}
else
    INPUT_FILTER=${INPUT_FILTER:-Freq_Xlating_Fir_Filter}
fi

# ---------------------------------------------------------------- output dir
if [[ -n $OUTDIR_ARG ]]; then
    mkdir -p -- "$OUTDIR_ARG"
    OUTDIR=$(cd -- "$OUTDIR_ARG" && pwd)
else
    OUTDIR=$(mktemp -d "${TMPDIR:-/tmp}/gnss-sdr-run.XXXXXX")
fi
# GNSS-SDR's INI parser cuts values at ';' / '#' and trims blanks
[[ $OUTDIR =~ [[:space:]\;\#] ]] && die "OUTDIR '$OUTDIR' must not contain blanks, ';' or '#'"
# stale outputs of an earlier run in the same directory would be scored too
rm -f -- "$OUTDIR"/*.nmea "$OUTDIR"/*.gpx "$OUTDIR"/*.kml "$OUTDIR"/gnss-sdr.*.log.* "$OUTDIR"/gnss-sdr.INFO \
    "$OUTDIR"/gnss-sdr.WARNING "$OUTDIR"/gnss-sdr.ERROR "$OUTDIR"/fixes.csv "$OUTDIR"/report.txt
SRC=$FILE
if [[ $FILE =~ [[:space:]\;\#] ]]; then
    SRC="$OUTDIR/input.$FORMAT"
    ln -sf -- "$FILE" "$SRC"
fi

SIZE=$(stat -Lc %s -- "$FILE")
((SIZE % BYTES_PER_SAMPLE == 0)) || echo "run-gnss-sdr: warning: file size $SIZE is not a multiple of $BYTES_PER_SAMPLE bytes ($FORMAT)" >&2
DURATION=$(python3 -c 'import sys; print("%.3f" % (int(sys.argv[1]) / int(sys.argv[2]) / int(sys.argv[3])))' "$SIZE" "$BYTES_PER_SAMPLE" "$FS")
TIMEOUT_S=${GNSS_SDR_TIMEOUT_S:-$(python3 -c 'import sys; print(int(3 * float(sys.argv[1]) + 60))' "$DURATION")}

CONF="$OUTDIR/gnss-sdr.conf"
python3 "$HELPER" fill "$TEMPLATE" "$CONF" \
    FILENAME="$SRC" ITEM_TYPE="$ITEM_TYPE" ADAPTER="$ADAPTER" FS="$FS" IF="$IF_HZ" \
    INPUT_FILTER="$INPUT_FILTER" CHANNELS="$CHANNELS" PFA="$ACQ_PFA" ACQ_COH_MS="$ACQ_COH_MS" \
    DOPPLER_MAX="$ACQ_DOPPLER_MAX" DOPPLER_STEP="$ACQ_DOPPLER_STEP" CN0_MIN="$CN0_MIN" \
    TROP_MODEL="$TROP_MODEL" IONO_MODEL="$IONO_MODEL" ELEV_MASK="$ELEV_MASK" OUTDIR="$OUTDIR" ||
    die "could not fill $TEMPLATE" 3

echo "run-gnss-sdr: $(gnss-sdr --version 2>&1 | head -n1) on $FILE ($FORMAT, $FS Hz, ${DURATION} s), trop $TROP_MODEL, iono $IONO_MODEL"
echo "run-gnss-sdr: outputs in $OUTDIR (timeout ${TIMEOUT_S} s)"

# ---------------------------------------------------------------- run
# Run inside OUTDIR (GNSS-SDR drops some files into its working directory),
# without keyboard listener or stdin, line-buffered so that a killed run
# still leaves its console lines; TERM at the timeout, KILL 20 s later.
RC=0
T0=$(date +%s.%N)
(
    cd -- "$OUTDIR"
    exec timeout --signal=TERM --kill-after=20 "$TIMEOUT_S" \
        stdbuf -oL -eL gnss-sdr --config_file="$CONF" --log_dir="$OUTDIR" --keyboard=false \
        </dev/null >"$OUTDIR/gnss-sdr.stdout" 2>"$OUTDIR/gnss-sdr.stderr"
) || RC=$?
T1=$(date +%s.%N)
WALL=$(python3 -c 'import sys; print("%.2f" % (float(sys.argv[2]) - float(sys.argv[1])))' "$T0" "$T1")
TIMED_OUT=()
if ((RC == 124 || RC == 137)); then
    TIMED_OUT=(--timed-out)
    echo "run-gnss-sdr: WARNING: gnss-sdr did not finish within ${TIMEOUT_S} s and was killed" >&2
elif ((RC != 0)); then
    echo "run-gnss-sdr: WARNING: gnss-sdr exited with status $RC; last lines of its stderr:" >&2
    tail -n 15 "$OUTDIR/gnss-sdr.stderr" >&2 || true
fi
[[ ${GNSS_SDR_VERBOSE:-0} != 0 ]] && cat "$OUTDIR/gnss-sdr.stdout"

set +e
python3 "$HELPER" report --file "$FILE" --format "$FORMAT" --fs "$FS" --if-hz "$IF_HZ" \
    --duration "$DURATION" --outdir "$OUTDIR" --console "$OUTDIR/gnss-sdr.stdout" --stderr "$OUTDIR/gnss-sdr.stderr" \
    --lat "$LAT" --lon "$LON" --h "$HGT" --max-err "$MAX_ERR_M" --skip "$SKIP_FIXES" --metric "$PASS_METRIC" \
    --rc "$RC" "${TIMED_OUT[@]}" --timeout "$TIMEOUT_S" --wall "$WALL" \
    --file-start "$FILE_START" --leap "$LEAP_SECONDS" \
    --csv "$OUTDIR/fixes.csv" --report-file "$OUTDIR/report.txt"
exit $?
