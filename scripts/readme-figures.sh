#!/usr/bin/env bash
# Every measured number in README.md, printed by the commands that produce it.
#
#   scripts/readme-figures.sh [SECTION ...]        (default: every section)
#   scripts/readme-figures.sh --list
#
# Sections (README heading in brackets; docs/readme-figures.md maps each number to one):
#   demo       `gpsrx demo`                                   [The two set-up commands]
#   seoul      the GPS-SDR-SIM recording of ../shared/data     [gpsrx run]
#   hard       the "Hard recordings" table                    [Hard recordings]
#   weak       the weak-mix recording, with and without --nav [Finding satellites]
#   faults     samples cut / zeroed in the GPS-SDR-SIM file    [Lost samples and outages]
#   long-gaps  5 s / 60 s cut from the simulated Seoul file    [Lost samples and outages]
#   dyn-gaps   cuts and zeros inside a 10 g turn and a 4.3 g climb [Lost samples and outages]
#   aided      the 5 g turn with an INS, aided and not         [INS aiding]
#   loops      narrow 0.4 Hz loops: 10 g turns, the C/N0 ladder [Loss of carrier lock]
#   dr         the drive with a 30 s outage, --dr --accel      [Dead reckoning]
#   acquire    the real PocketSDR capture                      [gpsrx acquire]
#   track      the demo recording through `gpsrx track`        [gpsrx track]
#   jitter     loop jitter against the thermal-noise formulas  [gpsrx track] (a test's table)
#   studies    every study, full grid                          [Studies]
#   bench      `gpsrx bench --correlator avx2`                 [Benchmarks]
#   vs-gnss-sdr  scripts/bench-vs-gnss-sdr.sh                  [Benchmarks]
#   scaling    scripts/scaling-table.sh                        [Benchmarks]
#
# The machine is printed first. Timings depend on it and on what else runs: the README gives
# the machine of every timing it quotes. Environment: GPSRX (the binary; default: build
# release), WORK (scratch, default mktemp -d), SHARED (default ../shared/data beside the clone).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
WORK=${WORK:-$(mktemp -d)}
SHARED=${SHARED:-$ROOT/../shared/data}
ALL=(demo seoul hard weak faults long-gaps dyn-gaps aided loops dr acquire track jitter studies bench vs-gnss-sdr scaling)
die() { echo "readme-figures: $*" >&2; exit 1; }

if [[ ${1:-} == --list ]]; then printf '%s\n' "${ALL[@]}"; exit 0; fi
SECTIONS=("$@")
[[ ${#SECTIONS[@]} -gt 0 ]] || SECTIONS=("${ALL[@]}")
for s in "${SECTIONS[@]}"; do
    [[ " ${ALL[*]} " == *" $s "* ]] || die "unknown section '$s' (--list lists them)"
done

if [[ -z ${GPSRX:-} ]]; then
    (cd "$ROOT" && cargo build --release -p gpsrx-cli >&2)
    GPSRX=${CARGO_TARGET_DIR:-$ROOT/target}/release/gpsrx
fi
[[ -x $GPSRX ]] || die "no binary at $GPSRX"
GPSRX=$(realpath "$GPSRX")
mkdir -p "$WORK"
NAV=$ROOT/samples/data/brdc0010.22n
TOOLS=$ROOT/scripts/tools

echo "machine: $(sed -n 's/^model name[[:space:]]*:[[:space:]]*//p' /proc/cpuinfo | head -1), $(nproc) cores; $(git -C "$ROOT" describe --always --dirty)"

# `run CMD...`: print the command (paths shortened to the work directory) and run it.
run() {
    echo "\$ ${*//$WORK\//}"
    "$@"
}
# The shared GPS-SDR-SIM recording, decompressed once into WORK (2.6 MHz ci8, 40 s).
seoul_file() {
    [[ -f $SHARED/gpssim-static-seoul-2p6msps.ci8.zst ]] || die "the shared recording is missing: $SHARED"
    [[ -f $WORK/seoul.ci8 ]] || zstd -q -d -o "$WORK/seoul.ci8" "$SHARED/gpssim-static-seoul-2p6msps.ci8.zst"
    echo "$WORK/seoul.ci8"
}
SEOUL_LLH=(37.5665 126.9780 40.0)

section_demo() {
    run "$GPSRX" demo
}

section_seoul() {
    local f
    f=$(seoul_file)
    run "$GPSRX" run "$f" --format ci8 --fs 2.6e6 --tropo none --allow-unhealthy --out "$WORK/seoul" --no-plots
    run python3 "$TOOLS/pvt_error.py" "$WORK/seoul/pvt.csv" "${SEOUL_LLH[@]}"
    echo "-- RTKLIB single point (rnx2rtkp) on our observables.rnx with the IGS navigation file:"
    printf 'pos1-posmode=single\npos1-ionoopt=brdc\npos1-tropopt=off\npos1-elmask=5\n' >"$WORK/spp.conf"
    run rnx2rtkp -k "$WORK/spp.conf" -o "$WORK/rtk.pos" "$WORK/seoul/observables.rnx" "$SHARED/brdc0010.22n" 2>/dev/null
    run python3 "$TOOLS/pos_error.py" "$WORK/rtk.pos" "${SEOUL_LLH[@]}"
    echo "-- with --nav: the first fix once a TLM/HOW is decoded"
    run "$GPSRX" run "$f" --format ci8 --fs 2.6e6 --tropo none --allow-unhealthy --nav "$NAV" --out "$WORK/seoul-nav" --no-plots
    echo "-- with --nav, --time and --approx-llh (10 km off): coarse-time fix from the code phases"
    run "$GPSRX" run "$f" --format ci8 --fs 2.6e6 --tropo none --allow-unhealthy --nav "$NAV" \
        --time 2190:538200 --approx-llh 37.65,127.05,0 --out "$WORK/seoul-coarse" --no-plots
    if command -v gnss-sdr >/dev/null; then
        echo "-- GNSS-SDR on the same recording (scripts/gnss-sdr/run-gnss-sdr.sh):"
        TROP_MODEL=OFF FILE_START=2190:538200 MAX_ERR_M=1000 bash "$ROOT/scripts/gnss-sdr/run-gnss-sdr.sh" \
            "$f" ci8 2600000 "${SEOUL_LLH[@]}" "$WORK/gnss-sdr-seoul" 2>&1 |
            grep -E "tracked PRNs|fixes|first fix|mean pos err|per-fix err|RESULT" || true
    else
        echo "-- GNSS-SDR: not installed (apt-get install gnss-sdr)"
    fi
}

# Simulate a scenario of samples/scenarios, run `gpsrx run` on it with any extra options, and
# score it against its truth.
sim_run() {
    local name=$1 scenario=$2
    shift 2
    run "$GPSRX" simulate "$ROOT/samples/scenarios/$scenario" -o "$WORK/$name" >"$WORK/$name.sim.log"
    local data
    data=$(ls "$WORK/$name"/signal.* | grep -v sigmf-meta | head -1)
    run "$GPSRX" run "$data" --out "$WORK/$name/run" --no-plots "$@" 2>"$WORK/$name.run.log"
    run python3 "$TOOLS/track_error.py" "$WORK/$name/run" "$WORK/$name/truth.csv"
}

section_hard() {
    sim_run turns hard-two-10g-turns.toml
    sim_run s31 hard-static-31dbhz.toml
    sim_run s28 hard-static-28dbhz.toml
    sim_run demo-sc default.toml
    sim_run sydney hard-real-if-16mhz-sydney.toml
    sim_run reykjavik hard-2bit-5mhz-reykjavik.toml
    sim_run tunnel drive-dr-outage.toml --nav "$NAV"
    echo "-- the tunnel (70-100 s): fixes inside it"
    run python3 "$TOOLS/track_error.py" "$WORK/tunnel/run" "$WORK/tunnel/truth.csv" --from 70 --to 100
}

section_weak() {
    run "$GPSRX" simulate "$ROOT/samples/scenarios/weak-mix-2p6msps.toml" -o "$WORK/weak" >/dev/null
    for nav in "" "--nav $NAV"; do
        # shellcheck disable=SC2086
        run "$GPSRX" run "$WORK/weak/signal.ci8" --out "$WORK/weak/run" --no-plots $nav 2>"$WORK/weak.log"
        grep -E "acquired" "$WORK/weak.log" | sed 's/^.*INFO //' | head -12
        run python3 "$TOOLS/track_error.py" "$WORK/weak/run" "$WORK/weak/truth.csv"
    done
}

section_faults() {
    local f
    f=$(seoul_file)
    for fault in "cut 20 0.001" "cut 20 0.00125" "cut 20 0.020" "cut 20 0.031" "cut 20 0.5" "zero 20 1" "zero 20 2" \
        "cut 20 5" "cut 10 20"; do
        read -r kind at len <<<"$fault"
        python3 "$TOOLS/fault.py" "$f" "$WORK/fault.ci8" --bytes-per-sample 2 --fs 2.6e6 --"$kind" "$at" "$len"
        "$GPSRX" run "$WORK/fault.ci8" --format ci8 --fs 2.6e6 --tropo none --allow-unhealthy --nav "$NAV" \
            --out "$WORK/fault" --no-plots 2>"$WORK/fault.log" >/dev/null || true
        echo "-- $kind $len s at $at s: $(grep -E "samples lost|were .* ms of signal" "$WORK/fault.log" | sed 's/^.*\(WARN\|INFO\) //' | tail -1)"
        python3 "$TOOLS/fault_recovery.py" "$WORK/fault/pvt.csv" "${SEOUL_LLH[@]}" --start-tow 538200 --at "$at" \
            --len "$len" --kind "$kind"
    done
    rm -f "$WORK/fault.ci8"
}

# Long gaps (issue 26) on the simulator's static Seoul scenario (12 satellites; 2.048 MHz ci8,
# 110 s): 5 s and 60 s cut at 35 s (the ephemerides are decoded by then), with and without --nav.
section_long-gaps() {
    run "$GPSRX" simulate "$ROOT/samples/scenarios/static-seoul-4msps.toml" -o "$WORK/lg" \
        --duration 110 --fs 2.048e6 >/dev/null
    local llh
    llh=$(awk -F, 'NR == 2 { print $13, $14, $15 }' "$WORK/lg/truth.csv")
    for len in 5 60; do
        python3 "$TOOLS/fault.py" "$WORK/lg/signal.ci8" "$WORK/lg-cut.ci8" --bytes-per-sample 2 \
            --fs 2.048e6 --cut 35 "$len"
        for nav in "" "--nav $NAV"; do
            # shellcheck disable=SC2086
            "$GPSRX" run "$WORK/lg-cut.ci8" --format ci8 --fs 2.048e6 $nav --out "$WORK/lg-run" \
                --no-plots 2>"$WORK/lg.log" >/dev/null || true
            echo "-- cut $len s at 35 s $([[ -n $nav ]] && echo with || echo without) --nav: $(grep -E "coarse-time fix at|time re-established" "$WORK/lg.log" | sed 's/^.*\(WARN\|INFO\) //' | head -1)"
            # shellcheck disable=SC2086
            python3 "$TOOLS/fault_recovery.py" "$WORK/lg-run/pvt.csv" $llh --start-tow 563388 \
                --at 35 --len "$len" --kind cut
        done
    done
    rm -f "$WORK/lg-cut.ci8"
}

# Gaps inside dynamics (issue 26): the simulator's 10 g turn (45-51 s) and 4.3 g climbing
# acceleration (40-60 s), 65 s of ci8 at 2.6 MHz with a 1 mg INS; no fault, a 31 ms and a
# 1.25 ms cut and 1 s of zeros in the middle of the manoeuvre, with and without --nav and --ins.
# Columns: valid fixes back after the return, worst valid fix from the fault to 10 s after,
# valid fixes over 5 m, and over 5 m beyond their stated 3-sigma (scripts/tools/gap_recovery.py).
section_dyn-gaps() {
    local sc at fault kind len opts args
    for sc in turn rocket; do
        case $sc in
            turn) run "$GPSRX" simulate "$ROOT/samples/scenarios/gaps-turn-10g.toml" -o "$WORK/dg" >/dev/null; at=48.0 ;;
            rocket) run "$GPSRX" simulate "$ROOT/samples/scenarios/gaps-rocket-4g.toml" -o "$WORK/dg" >/dev/null; at=50.0 ;;
        esac
        for fault in "cut 0" "cut 0.031" "cut 0.00125" "zero 1.0"; do
            read -r kind len <<<"$fault"
            python3 "$TOOLS/fault.py" "$WORK/dg/signal.ci8" "$WORK/dg-fault.ci8" --bytes-per-sample 2 \
                --fs 2.6e6 --"$kind" "$at" "$len"
            for opts in nav nav+ins none ins; do
                args=(--format ci8 --fs 2.6e6 --allow-unhealthy --no-plots)
                [[ $opts == nav* ]] && args+=(--nav "$NAV")
                [[ $opts == *ins ]] && args+=(--ins "$WORK/dg/ins.csv")
                "$GPSRX" run "$WORK/dg-fault.ci8" "${args[@]}" --out "$WORK/dg-run" 2>/dev/null >/dev/null || true
                python3 "$TOOLS/gap_recovery.py" "$WORK/dg-run" "$WORK/dg/truth.csv" --at "$at" \
                    --len "$len" --label "$sc | $kind $len s at $at s | $opts"
            done
        done
        rm -f "$WORK/dg-fault.ci8"
    done
}

section_aided() {
    run "$GPSRX" simulate "$ROOT/samples/scenarios/turn-5g-ins.toml" -o "$WORK/t5" >/dev/null
    for mode in aided unaided; do
        local extra=()
        [[ $mode == unaided ]] && extra=(--no-aiding)
        run "$GPSRX" run "$WORK/t5/signal.ci16_le" --out "$WORK/t5-$mode" --nav "$NAV" --pll-bw 3 \
            --ins "$WORK/t5/ins.csv" --no-plots "${extra[@]}" 2>/dev/null | grep -E "first fix|INS aiding"
        echo "-- the turn (40-50 s):"
        run python3 "$TOOLS/track_error.py" "$WORK/t5-$mode" "$WORK/t5/truth.csv" --from 40 --to 50
    done
}

section_loops() {
    for ins in perfect 1mg 2mg; do
        run "$GPSRX" simulate "$ROOT/samples/scenarios/turn-10g-ins-$ins.toml" -o "$WORK/t10-$ins" >/dev/null
    done
    for case in "perfect 3" "1mg 3" "2mg 3" "1mg 2" "2mg 2"; do
        read -r ins order <<<"$case"
        echo "-- 10 g turn (19-28 s), INS $ins, aided order $order at 0.4 Hz"
        run "$GPSRX" run "$WORK/t10-$ins/signal.ci8" --nav "$NAV" --ins "$WORK/t10-$ins/ins.csv" --allow-unhealthy \
            --aided-pll-order "$order" --aided-pll-bw 0.4 --out "$WORK/t10-$ins-$order" --no-plots >/dev/null 2>&1
        run python3 "$TOOLS/lock_report.py" "$WORK/t10-$ins-$order" --from 19 --to 28
        run python3 "$TOOLS/track_error.py" "$WORK/t10-$ins-$order" "$WORK/t10-$ins/truth.csv"
    done
    echo "-- static, 33-40 dB-Hz (issue 25), unaided 3rd order at 0.4 Hz, 10-60 s"
    run "$GPSRX" simulate "$ROOT/samples/scenarios/static-cn0-ladder-4msps.toml" -o "$WORK/ladder" >/dev/null
    run "$GPSRX" run "$WORK/ladder/signal.ci8" --nav "$NAV" --allow-unhealthy --pll-order 3 --pll-bw 0.4 \
        --out "$WORK/ladder/run" --no-plots >/dev/null 2>&1
    run python3 "$TOOLS/lock_report.py" "$WORK/ladder/run" --from 10 --to 60
    run python3 "$TOOLS/track_error.py" "$WORK/ladder/run" "$WORK/ladder/truth.csv"
}

section_dr() {
    run "$GPSRX" simulate "$ROOT/samples/scenarios/drive-dr-outage.toml" -o "$WORK/drive" | grep -E "^(dr|accel):"
    run "$GPSRX" run "$WORK/drive/signal.ci8" --nav "$NAV" --dr "$WORK/drive/dr.csv" --accel "$WORK/drive/accel.csv" \
        --out "$WORK/drive/run" --no-plots 2>/dev/null
    run python3 "$TOOLS/fused_error.py" "$WORK/drive/run/fused.csv" "$WORK/drive/truth.csv"
}

section_acquire() {
    local f=$SHARED/real/pocketsdr_L1_20211202_084700_4MHz_IQ.bin
    [[ -f $f ]] || die "missing $f"
    run "$GPSRX" acquire "$f" --format ci8 --fs 4e6 --invert-q
}

section_track() {
    run "$GPSRX" simulate "$ROOT/samples/scenarios/default.toml" -o "$WORK/demo-track" >/dev/null
    run "$GPSRX" track "$WORK/demo-track/signal.ci8" --out "$WORK/demo-track/track.csv"
}

section_jitter() {
    # The test asserts the loops' Doppler bias and jitter bounds and prints its table.
    (cd "$ROOT" && run cargo test -q --profile ci -p gpsrx-cli --test cli \
        pll_and_dll_jitter_match_the_thermal_noise_formulas_on_simulated_if -- --nocapture 2>&1 |
        grep -E "^G[0-9]+ |test result")
}

section_studies() {
    for s in steady-state bandwidth dynamics dr landmarks threshold vector; do
        if "$GPSRX" study --help 2>/dev/null | grep -q "$s"; then
            run "$GPSRX" study "$s" --out "$WORK/study-$s"
        fi
    done
}

section_bench() {
    run "$GPSRX" bench --correlator avx2
}

section_vs-gnss-sdr() {
    GPSRX=$GPSRX WORK=$WORK/vs bash "$ROOT/scripts/bench-vs-gnss-sdr.sh"
}

section_scaling() {
    GPSRX=$GPSRX WORK=$WORK/scaling RUN_ARGS="--correlator avx2 --no-plots" bash "$ROOT/scripts/scaling-table.sh"
}

for s in "${SECTIONS[@]}"; do
    echo
    echo "=================== $s"
    "section_$s"
done
