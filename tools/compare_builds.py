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
  shape      where frames differ: at the last common frame, the largest distance from a node of either run to
             the other run's surface (a symmetric Hausdorff distance, so runs that remeshed differently
             compare), and the same relative to the sheet's bounding-box diagonal;
  exit       each run's exit code.

--reuse compares the folders of an earlier invocation (same --out) without running the scenes again.

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
    with open(os.path.join(os.path.dirname(out), os.path.basename(out) + ".exit"), "w") as f:
        f.write("%d\n%s" % (r.returncode, r.stderr))
    return summarise(out, r.returncode, r.stderr.strip().splitlines()[-2:])


def summarise(out, code, stderr):
    exit_file = out + ".exit"
    if os.path.exists(exit_file) and not stderr:
        with open(exit_file) as f:
            text = f.read().split("\n", 1)
        code, stderr = int(text[0]), text[1].strip().splitlines()[-2:] if len(text) > 1 else []
    frames = []
    log = os.path.join(out, "log.jsonl")
    if os.path.exists(log):
        with open(log) as f:
            frames = [json.loads(l) for l in f if l.strip()]
    stepped = [fr for fr in frames if fr.get("frame", 0) >= 1]
    return {
        "exit": code, "stderr": stderr,
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
            "first_diff": first_diff, "last_common": common[-1] if common else None, "hausdorff": None,
            "diagonal": None}


def read_mesh(path):
    """World node positions and triangles (0-based node indices, polygons fanned) of an OBJ frame."""
    import numpy
    nodes, tris = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                nodes.append([float(v) for v in line.split()[1:4]])
            elif line.startswith("f "):
                corners = [int(c.split("/")[0]) - 1 for c in line.split()[1:]]
                tris += [(corners[0], corners[k], corners[k + 1]) for k in range(1, len(corners) - 1)]
    return numpy.array(nodes), numpy.array(tris, dtype=int)


def surface_samples(x, tris, spacing):
    """Points on every triangle no farther than `spacing` from each other along its edges."""
    import numpy
    out = [x]
    for t in tris:
        a, b, c = x[t[0]], x[t[1]], x[t[2]]
        longest = max(numpy.linalg.norm(b - a), numpy.linalg.norm(c - b), numpy.linalg.norm(a - c))
        n = int(numpy.ceil(longest / spacing))
        if n <= 1:
            continue
        i, j = numpy.meshgrid(numpy.arange(n + 1), numpy.arange(n + 1))
        keep = (i + j) <= n
        u, v = i[keep] / n, j[keep] / n
        out.append(a + numpy.outer(u, b - a) + numpy.outer(v, c - a))
    return numpy.vstack(out)


def shape_difference(a, b, name):
    """How far apart the two runs' sheets are in frame file `name`: the largest distance from a node of either run
    to the other run's surface (sampled every 0.1% of the size, which bounds the error), i.e. a symmetric
    Hausdorff distance that does not depend on how each run meshed the sheet; and the sheet's bounding-box
    diagonal in run a (m)."""
    from scipy.spatial import cKDTree  # python3-scipy (dependencies/install.sh)
    xa, ta = read_mesh(os.path.join(a, name))
    xb, tb = read_mesh(os.path.join(b, name))
    if len(xa) == 0 or len(xb) == 0:
        return None, None
    diagonal = float(((xa.max(axis=0) - xa.min(axis=0)) ** 2).sum() ** 0.5)
    spacing = 1e-3 * diagonal
    d_ab = cKDTree(surface_samples(xb, tb, spacing)).query(xa)[0].max()
    d_ba = cKDTree(surface_samples(xa, ta, spacing)).query(xb)[0].max()
    return float(max(d_ab, d_ba)), diagonal


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
    p.add_argument("--reuse", action="store_true", help="compare the folders of an earlier run, do not simulate")
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
        if args.reuse:
            ro, rn = summarise(base + "-old", 0, []), summarise(base + "-new", 0, [])
        else:
            ro = run(old, spec, base + "-old", args.threads)
            rn = run(new, spec, base + "-new", args.threads)
        fr = compare_frames(base + "-old", base + "-new")
        if fr["last_common"] and fr["first_diff"]:
            fr["hausdorff"], fr["diagonal"] = shape_difference(base + "-old", base + "-new", fr["last_common"])
        io, inn = inspect(inspector, base + "-old"), inspect(inspector, base + "-new")
        rows.append((spec, ro, rn, fr, io, inn))
        print("compare: %s: %d/%d frames identical" % (spec["label"], fr["identical"], fr["common"]),
              file=sys.stderr, flush=True)

    lines = ["| scene | to | frames identical | first differing | faces old / new | intersecting frames old / new "
             "(checked) | invalid old / new | sheets apart at the last common frame | plastic work old / new (J) | cracks old / new | stepping wall old / "
             "new (s) | exit old / new |",
             "|---|---:|---:|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for spec, ro, rn, fr, io, inn in rows:
        plastic = ("%.4g / %.4g" % (ro["plastic_work"], rn["plastic_work"])) if (ro["has_plastic"] or
                                                                                rn["has_plastic"]) else "-"
        apart = "-"
        if fr["hausdorff"] is not None:
            apart = "%s: %.3g m (%.2g of the size)" % (fr["last_common"][:5], fr["hausdorff"],
                                                      fr["hausdorff"] / fr["diagonal"] if fr["diagonal"] else 0)
        lines.append("| `%s` | %s | %d of %d%s | %s | %d / %d | %d / %d (%d, %d) | %d / %d | %s | %s | %d / %d | "
                     "%.2f / %.2f | %d / %d |" % (
                         spec["label"], "end" if spec["seconds"] is None else "%g s" % spec["seconds"],
                         fr["identical"], fr["common"], " (+%d in one run only)" % fr["only_one"] if fr["only_one"]
                         else "", fr["first_diff"] or "-", ro["faces"], rn["faces"], io["crossing"],
                         inn["crossing"], io["checked"], inn["checked"], io["invalid"], inn["invalid"], apart, plastic,
                         ro["cracks"], rn["cracks"], ro["wall"], rn["wall"], ro["exit"], rn["exit"]))
    text = "\n".join(lines) + "\n"
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(text)
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
