#!/usr/bin/env python3
"""Wall time of ARCSim's own example scenes, for the speed comparison with ARCSim 0.3.1.

Usage: tools/bench_arcsim_scenes.py [--shared DIR] [--threads N] [--repeat K] [--arcsim PATH]
                                    [scene:seconds ...]

Runs `bin/arcsim simulate` on each scene of DIR/arcsim-0.3-scenes/conf (default ../shared) for the given
simulated seconds (default: sphere:2, flag:2, square:2), writing into a temporary folder, and prints per scene
the wall time (best of K runs), the steps and the per-module wall times read from log.jsonl.

With --arcsim PATH (an ARCSim 0.3.1 binary, e.g. /work/anchor/build/arcsim), each scene is then also run by
ARCSim in the same invocation, one engine after the other (never both at once), and a second table gives both
engines' stepping wall (start-up and ARCSim's initial relaxation excluded, measured as tools/bench_fracture.py
does: ours from log.jsonl, ARCSim from the arrival of its per-step "Sim frame" lines), best of K runs each, and
ARCSim's over ours: the figure of the 5x goal.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_fracture  # noqa: E402  (the two engines' runners, shared with the fracture benchmark)

MODULES = ["physics", "collision", "remeshing", "plasticity", "fracture", "output"]


def run(binary, scenes_dir, scene, seconds, threads):
    with tempfile.TemporaryDirectory() as out:
        cmd = [binary, "simulate", os.path.join("conf", scene + ".json"), out, "--end-time", str(seconds),
               "--quiet"]
        if threads:
            cmd += ["--threads", str(threads)]
        start = time.perf_counter()
        subprocess.run(cmd, cwd=scenes_dir, check=True)
        wall = time.perf_counter() - start
        with open(os.path.join(out, "log.jsonl")) as f:
            frames = [json.loads(line) for line in f if line.strip()]
    modules = {m: sum(fr["wall"].get(m, 0.0) for fr in frames) for m in MODULES}
    steps = sum(fr.get("steps", 0) for fr in frames)
    faces = frames[-1]["faces"] if frames else 0
    return wall, steps, faces, modules


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--shared", default=os.path.join(root, "..", "shared"))
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--binary", default=os.path.join(root, "bin", "arcsim"))
    parser.add_argument("--arcsim", help="ARCSim 0.3.1 binary: also run each scene with it and print the ratio")
    parser.add_argument("--timeout", type=float, default=3600.0, help="per run, with --arcsim (s)")
    parser.add_argument("scenes", nargs="*", default=["sphere:2", "flag:2", "square:2"])
    args = parser.parse_args()
    scenes_dir = os.path.join(args.shared, "arcsim-0.3-scenes")
    if not os.path.isdir(scenes_dir):
        sys.exit(f"{scenes_dir}: folder not found (ARCSim's scenes are needed for this benchmark)")
    print(f"{'scene':<14} {'sim s':>6} {'wall s':>8} {'steps':>6} {'ms/step':>8} {'faces':>6}  "
          + " ".join(f"{m:>9}" for m in MODULES))
    for item in args.scenes:
        scene, _, seconds = item.partition(":")
        seconds = float(seconds or 2)
        best = None
        for _ in range(max(1, args.repeat)):
            result = run(args.binary, scenes_dir, scene, seconds, args.threads)
            if best is None or result[0] < best[0]:
                best = result
        wall, steps, faces, modules = best
        per_step = 1000 * wall / steps if steps else float("nan")
        print(f"{scene:<14} {seconds:>6.2f} {wall:>8.2f} {steps:>6d} {per_step:>8.2f} {faces:>6d}  "
              + " ".join(f"{modules[m]:>9.2f}" for m in MODULES))
    if args.arcsim:
        side_by_side(args, scenes_dir)


def side_by_side(args, scenes_dir):
    """Both engines on each scene, one after the other; stepping walls (best of --repeat) and their ratio."""
    print()
    print(f"{'scene':<14} {'sim s':>6} {'ours s':>8} {'ARCSim s':>9} {'ARCSim/ours':>12}  status")
    for item in args.scenes:
        scene, _, seconds = item.partition(":")
        seconds = float(seconds or 2)
        best = {}
        for _ in range(max(1, args.repeat)):
            with tempfile.TemporaryDirectory() as tmp:
                runs = [bench_fracture.run_ours(args.binary, scenes_dir, scene, seconds, args.threads, args.timeout,
                                                os.path.join(tmp, "ours")),
                        bench_fracture.run_arcsim(args.arcsim, scenes_dir, scene, seconds, args.timeout,
                                                  os.path.join(tmp, "arcsim"))]
            for r in runs:
                if r["engine"] not in best or r["stepping_wall"] < best[r["engine"]]["stepping_wall"]:
                    best[r["engine"]] = r
        ours, arcsim = best["ours"], best["ARCSim"]
        ok = ours["status"] == "done" and arcsim["status"] == "done" and ours["stepping_wall"] > 0
        ratio = arcsim["stepping_wall"] / ours["stepping_wall"] if ok else float("nan")
        print(f"{scene:<14} {seconds:>6.2f} {ours['stepping_wall']:>8.2f} {arcsim['stepping_wall']:>9.2f} "
              f"{ratio:>11.2f}x  ours {ours['status']}, ARCSim {arcsim['status']}")


if __name__ == "__main__":
    main()
