#!/usr/bin/env python3
"""Time whole processes side by side: wall time, CPU time (user + sys) and peak memory.

    time_commands.py --runs N --json OUT.json NAME=COMMAND [NAME=COMMAND ...]

Each COMMAND is a shell command line. The commands run in interleaved rounds (A, B, C, A, B,
C, ...) so that slow drifts of the machine (another job, thermal state) touch every command
alike; each keeps the median of its N runs. The CPU time and peak resident memory are those of
the command's whole process tree as the kernel reports them to the waiting parent (wait4's
rusage: the process and every descendant it waited for). A command that exits non-zero stops
the script with its name and exit status.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time


def run_once(command: str) -> dict:
    """One run of `command` under /bin/sh: wall s, CPU s, peak RSS MB."""
    t0 = time.monotonic()
    proc = subprocess.Popen(["/bin/sh", "-c", command], stdin=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.monotonic() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    return {
        "rc": proc.returncode,
        "wall_s": wall,
        "cpu_s": usage.ru_utime + usage.ru_stime,
        # Linux reports ru_maxrss in KiB.
        "peak_mb": usage.ru_maxrss * 1024 / 1e6,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--json", required=True, help="where the per-command medians are written")
    ap.add_argument("commands", nargs="+", metavar="NAME=COMMAND")
    args = ap.parse_args()
    named = []
    for item in args.commands:
        name, sep, command = item.partition("=")
        if not sep or not name or not command:
            ap.error(f"expected NAME=COMMAND, got {item!r}")
        named.append((name, command))
    if args.runs < 1:
        ap.error("--runs must be at least 1")

    samples = {name: [] for name, _ in named}
    for r in range(args.runs):
        for name, command in named:
            s = run_once(command)
            if s["rc"] != 0:
                print(f"time_commands: {name} exited with status {s['rc']} (run {r + 1}): {command}",
                      file=sys.stderr)
                return 1
            print(f"  run {r + 1}/{args.runs} {name}: wall {s['wall_s']:.2f} s, CPU {s['cpu_s']:.2f} s, "
                  f"peak {s['peak_mb']:.0f} MB", file=sys.stderr)
            samples[name].append(s)

    out = {}
    for name, runs in samples.items():
        out[name] = {
            key: statistics.median(s[key] for s in runs) for key in ("wall_s", "cpu_s", "peak_mb")
        }
        out[name]["runs"] = len(runs)
        out[name]["wall_all_s"] = [round(s["wall_s"], 3) for s in runs]
    with open(args.json, "w") as f:
        json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
