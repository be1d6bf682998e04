#!/usr/bin/python3
"""Two builds of arcsim on the same scenes: are their frames byte-identical, and where not, how do their figures of
merit compare? (The edit-session issue's "nothing changes for the user" check, usable for any change.)

Usage: tools/compare_builds.py --old BIN --new BIN [--inspect BIN] [--threads N] [--out DIR] [--markdown FILE]
                               [--shared DIR] [spec ...]

A spec is `conf/NAME.json` (a scene of this repository, run to its end), `arcsim:NAME[:SECONDS]` (a scene of
DIR/arcsim-0.3-scenes/conf, run from that folder to SECONDS, default 2), or either with `:SECONDS`. Without specs:
every scene of conf/ to its end and ARCSim's nine scenes to 2 s (flag.json to 1 s).

Each scene runs with the old build, then with the new one (never both at once), with `--threads N` (default 1:
the frames then do not depend on the machine's load), into DIR/NAME-old and DIR/NAME-new. Then per scene:

  frames     saved frames of both runs compared byte for byte (every NNNNN_CC.obj): how many are identical, and
             the first that differs;
  merit      from each run: faces at the end, stepping wall (sum of wall.total - wall.output over log.jsonl,
             frames >= 1), the plastic work (log.jsonl's plastic_work.total, summed), crack openings, and the
             frame checks of `arcsim inspect --every K` (about 25 frames and the last; --inspect names the binary
             with the inspect command, default the new one): frames with intersecting triangles, invalid frames;
  exit       each run's exit code.

Prints a markdown table (also to --markdown). Exit code 0 always when both builds ran; the table is the result.
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
ARCSIM_DEFAULT = ["crumple", "flag:1", "fold", "paper-tearing", "sphere", "sphere-break", "square", "square-pop",
                  "tshirt"]


def parse_spec(spec, shared):
    seconds = None
    if spec.startswith("arcsim:"):
        rest = spec[len("arcsim:"):]
        name, _, t = rest.partition(":")
        seconds = float(t) if t else 2.0
        return {"label": name, "scene": os.path.join("conf", name + ".json"),
                "cwd": os.path.join(shared, "arcsim-0.3-scenes"), "seconds": seconds}
    path, _, t = spec.partition(".json")
    t = t.lstrip(":")
    if t:
        seconds = float(t)
    return {"label": os.path.basename(path), "scene": os.path.abspath(path + ".json"), "cwd": ROOT,
            "seconds": seconds}


def run(binary, spec, out, threads):
    shutil.rmtree(out, ignore_errors=True)
    cmd = [binary, "simulate", spec["scene"], out, "--quiet", "--threads", str(threads)]
    if spec["seconds"] is not None:
        cmd += ["--end-time", repr(spec["seconds"])]
    r = subprocess.run(cmd, cwd=spec["cwd"], capture_output=True, text=True)
    frames = []
    log = os.path.join(out, "log.jsonl")
    if os.path.exists(log):
        with open(log) as f:
            frames = [json.loads(l) for l in f if l.strip()]
    stepped = [fr for fr in frames if fr.get("frame", 0) >= 1]
    return {
        "exit": r.returncode, "stderr": r.stderr.strip().splitlines()[-2:],
        "faces": frames[-1]["faces"] if frames else 0, "frames": len(stepped),
        "wall": sum(fr["wall"]["total"] - fr["wall"].get("output", 0.0) for fr in stepped),
        "plastic_work": sum(fr.get("plastic_work", {}).get("total", 0.0) for fr in frames),
        "has_plastic": any("plastic_work" in fr for fr in frames),
        "cracks": sum(fr.get("fracture", {}).get("cracks", 0) for fr in frames),
    }


def frame_files(out):
    return sorted(os.path.basename(p) for p in glob.glob(os.path.join(out, "[0-9]" * 5 + "_[0-9][0-9].obj")))


def compare_frames(a, b):
    fa, fb = frame_files(a), frame_files(b)
    common = sorted(set(fa) & set(fb))
    identical, first_diff = 0, None
    for name in common:
        with open(os.path.join(a, name), "rb") as x, open(os.path.join(b, name), "rb") as y:
            if x.read() == y.read():
                identical += 1
            elif first_diff is None:
                first_diff = name
    return {"common": len(common), "only_one": len(set(fa) ^ set(fb)), "identical": identical,
            "first_diff": first_diff}


def inspect(binary, out):
    names = frame_files(out)
    frames = sorted({n[:5] for n in names})
    every = max(1, len(frames) // 25)
    lines = []
    for extra in (["--every", str(every)], ["--last"]):
        r = subprocess.run([binary, "inspect", out, "--quiet"] + extra, capture_output=True, text=True)
        lines += [json.loads(l) for l in r.stdout.splitlines() if l.strip()]
    return {"checked": len(lines), "crossing": sum(1 for l in lines if l["intersections"] > 0),
            "invalid": sum(1 for l in lines if not all(s["valid"] for s in l["sheets"]))}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("specs", nargs="*")
    p.add_argument("--old", required=True)
    p.add_argument("--new", required=True)
    p.add_argument("--inspect", default=None)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--out", default="/tmp/compare-builds")
    p.add_argument("--markdown", default=None)
    p.add_argument("--shared", default=os.path.join(ROOT, "..", "shared"))
    args = p.parse_args()
    old, new = os.path.abspath(args.old), os.path.abspath(args.new)
    inspector = os.path.abspath(args.inspect or args.new)
    specs = args.specs
    if not specs:
        specs = sorted(glob.glob(os.path.join(ROOT, "conf", "*.json")))
        if os.path.isdir(os.path.join(args.shared, "arcsim-0.3-scenes")):
            specs += ["arcsim:" + s for s in ARCSIM_DEFAULT]
    rows = []
    for s in specs:
        spec = parse_spec(s, os.path.abspath(args.shared))
        base = os.path.join(args.out, spec["label"])
        print("compare: %s ..." % spec["label"], file=sys.stderr, flush=True)
        ro = run(old, spec, base + "-old", args.threads)
        rn = run(new, spec, base + "-new", args.threads)
        fr = compare_frames(base + "-old", base + "-new")
        io, inn = inspect(inspector, base + "-old"), inspect(inspector, base + "-new")
        rows.append((spec, ro, rn, fr, io, inn))
        print("compare: %s: %d/%d frames identical" % (spec["label"], fr["identical"], fr["common"]),
              file=sys.stderr, flush=True)

    lines = ["| scene | to | frames identical | first differing | faces old / new | intersecting frames old / new "
             "(checked) | invalid old / new | plastic work old / new (J) | cracks old / new | stepping wall old / "
             "new (s) | exit old / new |",
             "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|"]
    for spec, ro, rn, fr, io, inn in rows:
        plastic = ("%.4g / %.4g" % (ro["plastic_work"], rn["plastic_work"])) if (ro["has_plastic"] or
                                                                                rn["has_plastic"]) else "-"
        lines.append("| `%s` | %s | %d of %d%s | %s | %d / %d | %d / %d (%d, %d) | %d / %d | %s | %d / %d | "
                     "%.2f / %.2f | %d / %d |" % (
                         spec["label"], "end" if spec["seconds"] is None else "%g s" % spec["seconds"],
                         fr["identical"], fr["common"], " (+%d in one run only)" % fr["only_one"] if fr["only_one"]
                         else "", fr["first_diff"] or "-", ro["faces"], rn["faces"], io["crossing"],
                         inn["crossing"], io["checked"], inn["checked"], io["invalid"], inn["invalid"], plastic,
                         ro["cracks"], rn["cracks"], ro["wall"], rn["wall"], ro["exit"], rn["exit"]))
    text = "\n".join(lines) + "\n"
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(text)
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
