#!/usr/bin/env python3
"""CPU time of a `gpsrx run` by stage, from a sampled profile with call stacks.

    perf record --call-graph dwarf,32768 -F 499 -o run.data gpsrx run FILE --out DIR
    perf script -i run.data -F tid,ip,sym > run.txt
    scripts/tools/cpu_by_stage.py run.txt [--hz 499]

Each sample is put in the first stage whose marker appears in its call stack (the background
search before the channels: the search's refinement calls the tracking correlator), samples
whose stack was cut short in rustfft or the acquisition code count as search, and samples of
idle workers (rayon's spinning and sleeping, futex waits) as "rayon idle". The CPU seconds are
samples / Hz, so they include perf's own overhead (a few percent); the shares are what to read.
`gpsrx run --profile` gives the wall time of the same stages without perf.
"""
import argparse
import collections
import sys

# (stage, marker in a frame's symbol), first match wins.
RULES = [
    ("cold start search", "ChannelManager::cold_start"),
    ("background search", "AcquisitionEngine::search_slice"),
    ("setup (FFT plans, replicas)", "AcquisitionEngine::new"),
    ("navigation (reports, fixes, rows)", "ReportsOut"),
    ("navigation (reports, fixes, rows)", "Receiver::end_round"),
    ("navigation (reports, fixes, rows)", "Receiver::deliver"),
    ("reading the recording", "read_integer"),
    ("reading the recording", "SampleSource>::read"),
    ("outputs at the end (plots, files)", "Sink>::finish"),
    ("channels (correlators, loops)", "run_channel"),
    ("channels (correlators, loops)", "Channel::process_period"),
    ("channels (correlators, loops)", "gpsrx_dsp::correlator"),
    ("channels (correlators, loops)", "gpsrx_tracking"),
    ("background search", "rustfft"),
    ("background search", "gpsrx_dsp::acquisition"),
]
IDLE = ("sched_yield", "futex", "wait_until", "Sleep::", "sleep")


def samples(lines):
    """(tid, [symbols, leaf first]) per sample of `perf script -F tid,ip,sym` output."""
    cur = None
    for line in lines:
        s = line.strip()
        if not s:
            if cur:
                yield cur
            cur = None
            continue
        if cur is None:
            cur = (s.split()[0], [])
            continue
        parts = s.split(None, 1)
        cur[1].append(parts[1] if len(parts) > 1 else parts[0])
    if cur:
        yield cur


def stage(stack):
    for name, marker in RULES:
        if any(marker in f for f in stack):
            return name
    if any(k in f for f in stack[:12] for k in IDLE):
        return "rayon idle (spinning, waking)"
    return "other"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("script", help="perf script -F tid,ip,sym output ('-': standard input)")
    ap.add_argument("--hz", type=float, default=499.0, help="perf record's -F")
    a = ap.parse_args()
    src = sys.stdin if a.script == "-" else open(a.script)
    counts = collections.Counter(stage(st) for _, st in samples(src))
    total = sum(counts.values())
    if total == 0:
        print("no samples", file=sys.stderr)
        return 1
    print(f"{total} samples at {a.hz:g} Hz: {total / a.hz:.2f} s of CPU")
    for name, n in counts.most_common():
        print(f"  {name:<40} {n / a.hz:6.2f} s {100 * n / total:5.1f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
