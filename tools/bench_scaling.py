#!/usr/bin/env python3
"""Scaling of the implicit step from the physics benchmark.

Usage: OMP_NUM_THREADS=2 bin/arcsim-bench --benchmark_filter=BM_ImplicitStep \
           --benchmark_format=json > step.json && tools/bench_scaling.py step.json

Prints per size the milliseconds per step of assembly, factorisation and solve, then the growth exponents
between 4k and 64k faces (time ~ faces^p) and the assembly share of the step at 16k faces.
"""
import json
import math
import sys


def main(path):
    with open(path) as f:
        data = json.load(f)
    rows = {}
    for b in data["benchmarks"]:
        if not b["name"].startswith("BM_ImplicitStep"):
            continue
        rows[int(b["faces"])] = b
    sizes = sorted(rows)
    print(f"{'faces':>8} {'assembly ms':>12} {'factor ms':>10} {'solve ms':>9} {'assembly share':>15}")
    for n in sizes:
        b = rows[n]
        print(f"{n:>8} {b['assembly_ms']:>12.2f} {b['factor_ms']:>10.2f} {b['solve_ms']:>9.2f} "
              f"{b['assembly_share']:>15.3f}")
    small = min((n for n in sizes if n >= 3000), default=None)
    large = max(sizes)
    if small and large > small:
        for key in ("assembly_ms", "factor_ms", "solve_ms"):
            p = math.log(rows[large][key] / rows[small][key]) / math.log(large / small)
            print(f"{key[:-3]:>13} grows as faces^{p:.2f} from {small} to {large} faces")
    mid = min(sizes, key=lambda n: abs(n - 16000))
    print(f"assembly share of the step at {mid} faces: {rows[mid]['assembly_share']:.3f}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/dev/stdin")
