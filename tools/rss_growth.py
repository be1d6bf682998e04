#!/usr/bin/env python3
"""Memory growth of a long run (issue 14): runs `arcsim simulate` on a scene for a given number of simulated
seconds, samples the process's resident set size (VmRSS) from /proc every --interval seconds, and prints the RSS
after warm-up (the first sample past --warmup of the run's wall time), the largest RSS after that and the growth
between them, in percent. Exit status 1 if the growth exceeds --limit percent.

  tools/rss_growth.py conf/swing.json --end-time 100      # 10 000 steps of the swinging sheet
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time


def rss_kib(pid):
    try:
        with open(f"/proc/{pid}/status") as status:
            for line in status:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene")
    parser.add_argument("--end-time", type=float, required=True, help="simulated seconds")
    parser.add_argument("--binary", default=os.path.join(os.path.dirname(__file__), "..", "bin", "arcsim"))
    parser.add_argument("--interval", type=float, default=0.25, help="seconds between samples")
    parser.add_argument("--warmup", type=float, default=0.2, help="fraction of the run's wall time to skip")
    parser.add_argument("--limit", type=float, default=5.0, help="largest allowed growth after warm-up, percent")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory(prefix="arcsim-rss-") as out:
        start = time.monotonic()
        process = subprocess.Popen([args.binary, "simulate", args.scene, out, "--quiet", "--end-time",
                                    str(args.end_time)])
        samples = []  # (seconds since start, KiB)
        while process.poll() is None:
            kib = rss_kib(process.pid)
            if kib is not None:
                samples.append((time.monotonic() - start, kib))
            time.sleep(args.interval)
        wall = time.monotonic() - start
        if process.returncode != 0:
            print(f"rss_growth: the run failed with exit code {process.returncode}", file=sys.stderr)
            return 2
        with open(os.path.join(out, "log.jsonl")) as log:
            frames = sum(1 for _ in log) - 1
    after = [kib for t, kib in samples if t >= args.warmup * wall]
    if len(after) < 2:
        print("rss_growth: too few samples after warm-up; run longer or sample more often", file=sys.stderr)
        return 2
    growth = 100.0 * (max(after) - after[0]) / after[0]
    print(f"{args.scene}: {frames} frames, {wall:.1f} s wall, {len(samples)} samples; RSS after warm-up "
          f"{after[0] / 1024:.1f} MiB, largest later {max(after) / 1024:.1f} MiB, at the end {after[-1] / 1024:.1f} "
          f"MiB; growth {growth:.2f}% (limit {args.limit}%)")
    return 0 if growth <= args.limit else 1


if __name__ == "__main__":
    sys.exit(main())
