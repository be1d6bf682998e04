#!/usr/bin/python3
"""The paper's scenes, measured: a Table 1 of ours, a contact sheet of rendered frames per scene, and the run
checked frame by frame. One command (`make report` runs it with the defaults):

    tools/report.py [--binary bin/arcsim] [--threads N] [--out DIR] [--img docs/img] [--markdown FILE]
                    [--update-benchmarks docs/benchmarks.md] [--arcsim PATH] [--shared ../shared] [scene ...]

Runs every scene of SCENES below whose file exists in conf/ (or only the names given), one after the other, each
to its end at its default resolution: `arcsim simulate conf/X.json DIR/X --quiet [--threads N]`. Then per scene:

  table     faces (mean and max over frames), and wall seconds per frame at 25 frames per simulated second, as
            the paper's Table 1 counts them: "dynamics" = physics + collision + plasticity, "geometry" =
            remeshing + fracture (log.jsonl's `wall`), summed over the run and divided by 25 x the simulated
            time; writing the frames is not counted (the paper's figures do not say they include it). The
            paper's own figures (2011 Intel Xeon X5675, 6 cores) are printed beside ours.
  checks    `arcsim inspect DIR/X --every K` on about 20 frames and the last: every one a valid mesh with no
            intersecting triangles (cloth-cloth and cloth-obstacle); the pieces at the end (count, largest).
  pictures  `arcsim replay DIR/X --every K --size 480x270` and six of those frames, evenly spread, as one
            1440x540 PNG (3 x 2) in --img (`<scene>.png`), for docs/benchmarks.md to show.

With --arcsim, also ARCSim 0.3.1's two fracture scenes from --shared/arcsim-0.3-scenes (paper-tearing to
0.466 s, sphere-break to 0.01 s) with both engines, through tools/bench_fracture.py's runners (one engine at a
time), and their seconds per simulated second side by side.

Writes the table as markdown (--markdown, default DIR/report.md); with --update-benchmarks, replaces the part of
that file between the lines `<!-- report:begin -->` and `<!-- report:end -->` with it (added at the end the
first time). --reuse takes each scene's figures from an earlier invocation (DIR/<scene>.result.json) where
present, so a report can be completed scene by scene. Exit code 1 when a scene fails (non-zero exit of the simulator or of inspect).
"""
import argparse
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# name -> (paper figure, the paper's Table 1 row: faces, dynamics, geometry, total s per frame at 25 fps, or None)
SCENES = [
    ("demo", "default scene (tearing gel)", None),
    ("paper-metal-glass", "Fig. 2 metal frame, glass panes", (5720, 28.6, 25.8, 54.4)),
    ("paper-metal-rubber", "Fig. 2 variant: rubber panes", None),
    ("paper-ornament", "Fig. 10 ornament drop, adaptive", (4520, 23.2, 22.5, 45.7)),
    ("paper-ornament-static", "Fig. 10 ornament drop, static mesh", None),
    ("paper-dome", "Fig. 11 dome hit by a sphere", (17120, 34.2, 53.5, 87.7)),
    ("paper-tearing", "Fig. 8a paper tearing", (3010, 16.7, 21.8, 38.5)),
    ("paper-rubber-tear", "Fig. 3 rubber tearing", (2690, 11.3, 12.7, 24.0)),
    ("paper-rubber-tear-elastic", "Fig. 3 variant: no plasticity", None),
    ("paper-cylinder", "Fig. 9 left, buckling cylinder", (3800, 30.3, 44.7, 75.0)),
    ("paper-variety", "Fig. 1 material variety", (4220, 20.6, 43.7, 64.3)),
    ("paper-window", "Fig. 9 right, glass window", None),
]
DYNAMICS = ("physics", "collision", "plasticity")
GEOMETRY = ("remeshing", "fracture")


def machine():
    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return "%s, %d cores" % (cpu, os.cpu_count() or 0)


def commit():
    try:
        return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def read_log(path):
    frames = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line:
                frames.append(json.loads(line))
    return frames


def measure(frames):
    """Table 1 figures from a run's log.jsonl lines."""
    stepped = [fr for fr in frames if fr.get("frame", 0) >= 1]
    faces = [fr["faces"] for fr in frames]
    sim_time = frames[-1].get("time", 0.0) - frames[0].get("time", 0.0) if frames else 0.0
    dyn = sum(fr["wall"].get(m, 0.0) for fr in stepped for m in DYNAMICS)
    geo = sum(fr["wall"].get(m, 0.0) for fr in stepped for m in GEOMETRY)
    total = sum(fr["wall"]["total"] - fr["wall"].get("output", 0.0) for fr in stepped)
    frames25 = 25.0 * sim_time if sim_time > 0 else float("nan")
    cracks = sum(fr.get("fracture", {}).get("cracks", 0) for fr in frames)
    return {
        "frames": len(stepped), "sim_time": sim_time, "faces_mean": sum(faces) / len(faces) if faces else 0,
        "faces_max": max(faces) if faces else 0, "dynamics": dyn / frames25, "geometry": geo / frames25,
        "total": total / frames25, "stepping_wall": total, "cracks": cracks,
    }


def inspect(binary, out, every):
    cmd = [binary, "inspect", out, "--every", str(every), "--quiet"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    lines = [json.loads(l) for l in r.stdout.splitlines() if l.strip()]
    last = subprocess.run([binary, "inspect", out, "--last", "--quiet"], capture_output=True, text=True)
    last_lines = [json.loads(l) for l in last.stdout.splitlines() if l.strip()]
    final = last_lines[-1] if last_lines else (lines[-1] if lines else None)
    pieces = []
    if final:
        for sheet in final["sheets"]:
            pieces += sheet.get("piece_faces", [])
    return {
        "checked": len(lines) + (1 if last_lines else 0),
        "clean": r.returncode == 0 and last.returncode == 0,
        "problem": (r.stderr.strip() or last.stderr.strip()).splitlines()[-1:] if (r.returncode or last.returncode)
        else [],
        "pieces": sorted(pieces, reverse=True),
    }


def contact_sheet(binary, out, every, image):
    """Six evenly spread rendered frames, 3 x 2, as one PNG."""
    from PIL import Image  # python3-pil (dependencies/install.sh)
    png_dir = os.path.join(out, "png")
    subprocess.run([binary, "replay", out, png_dir, "--every", str(every), "--size", "480x270", "--quiet"],
                   check=True)
    names = sorted(n for n in os.listdir(png_dir) if n.endswith(".png"))
    if not names:
        return None
    picks = [names[round(i * (len(names) - 1) / 5)] for i in range(6)] if len(names) >= 6 else names
    w, h = 480, 270
    sheet = Image.new("RGB", (3 * w, 2 * h), "white")
    for k, name in enumerate(picks):
        with Image.open(os.path.join(png_dir, name)) as im:
            sheet.paste(im.convert("RGB").resize((w, h)), ((k % 3) * w, (k // 3) * h))
    os.makedirs(os.path.dirname(image), exist_ok=True)
    sheet.save(image, optimize=True)
    return [int(n[:-4]) for n in picks]


def run_scene(args, name):
    conf = os.path.join(ROOT, "conf", name + ".json")
    out = os.path.join(args.out, name)
    record = out + ".result.json"
    if args.reuse and os.path.exists(record):
        with open(record) as f:
            return json.load(f)
    shutil.rmtree(out, ignore_errors=True)
    cmd = [args.binary, "simulate", conf, out, "--quiet"]
    if args.threads:
        cmd += ["--threads", str(args.threads)]
    start = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    result = {"name": name, "command": " ".join(cmd), "exit": r.returncode, "wall": wall,
              "stderr": r.stderr.strip().splitlines()[-3:]}
    log = os.path.join(out, "log.jsonl")
    if not os.path.exists(log):
        return result
    frames = read_log(log)
    result.update(measure(frames))
    saved = sum(1 for fr in frames if fr.get("saved", True))
    every = max(1, saved // 20)
    result["inspect"] = inspect(args.binary, out, every)
    try:
        result["sheet_frames"] = contact_sheet(args.binary, out, max(1, saved // 12),
                                               os.path.join(args.img, name + ".png"))
    except (subprocess.CalledProcessError, ImportError, OSError) as e:
        result["sheet_frames"] = None
        result["stderr"].append("contact sheet: %s" % e)
    with open(record, "w") as f:
        json.dump(result, f)
    return result


def arcsim_side_by_side(args):
    sys.path.insert(0, HERE)
    import bench_fracture  # the runners of both engines, one run at a time
    scenes_dir = os.path.join(args.shared, "arcsim-0.3-scenes")
    rows = []
    for scene, seconds in (("paper-tearing", 0.466), ("sphere-break", 0.01)):
        if not os.path.exists(os.path.join(scenes_dir, "conf", scene + ".json")):
            continue
        base = os.path.join(args.out, "arcsim-" + scene)
        shutil.rmtree(base + "-ours", ignore_errors=True)
        shutil.rmtree(base + "-arcsim", ignore_errors=True)
        ours = bench_fracture.run_ours(os.path.abspath(args.binary), scenes_dir, scene, seconds, args.threads,
                                       3600, base + "-ours")
        theirs = bench_fracture.run_arcsim(os.path.abspath(args.arcsim), scenes_dir, scene, seconds, 3600,
                                           base + "-arcsim")
        rows.append((scene, seconds, ours, theirs))
    return rows


def fmt(x, spec):
    return "-" if x is None or x != x else format(x, spec)


def shard_comparison(results, args):
    """Fig. 10's claim measured: the pieces of the adaptive and the static ornament's last frames (tools/pieces.py:
    count, shards of >= 3 faces, size spread, histogram of area fractions), when both ran."""
    runs = {r["name"]: r for r in results if "total" in r}
    pair = ("paper-ornament", "paper-ornament-static")
    if not all(name in runs for name in pair):
        return []
    sys.path.insert(0, HERE)
    import pieces
    summaries = [pieces.summarise(pieces.newest_frame(os.path.join(args.out, name))) for name in pair]
    lines = ["", "Fig. 10, adaptive against static (last frame of each, `tools/pieces.py`; the paper: the static "
             "mesh gives fewer, bigger and more uniform shards):", "",
             "| run | faces mean | pieces | shards (>= 3 faces) | largest piece | shard area CV | shard area Gini |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for name, s in zip(pair, summaries):
        lines.append("| `%s` | %.0f | %d | %d | %.1f%% | %.2f | %.2f |" % (
            name, runs[name]["faces_mean"], s["pieces"], s["shards"], 100 * s["largest_fraction"],
            s["shard_area_cv"], s["shard_area_gini"]))
    lines += ["", "Pieces per bin of area fraction of the whole ball:", "",
              "| bin | " + " | ".join("`%s`" % name for name in pair) + " |", "|---|---:|---:|"]
    for k, label in enumerate(summaries[0]["histogram_bins"]):
        lines.append("| %s | %d | %d |" % (label, summaries[0]["histogram"][k], summaries[1]["histogram"][k]))
    return lines


def markdown(results, arcsim_rows, args):
    today = datetime.date.today().isoformat()
    lines = [
        "### The paper's scenes, measured (`make report`, %s)" % today,
        "",
        "Machine: %s; commit %s; `%s`%s. Seconds are wall seconds per frame at 25 frames per simulated second "
        "(dynamics = physics + collision + plasticity; geometry = remeshing + fracture; writing frames not "
        "counted). The paper's Table 1 was measured on an Intel Xeon X5675 (2011, 6 cores)." % (
            machine(), commit(), "tools/report.py", " --threads %d" % args.threads if args.threads else ""),
        "",
        "| scene | shows | sim s | faces mean | faces max | dynamics | geometry | total | paper faces | paper total "
        "| paper / ours | cracks | pieces at end | frames checked |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|",
    ]
    for r in results:
        paper = r.get("paper")
        if "total" not in r:
            lines.append("| `%s` | %s | failed: exit %d, %s |  |  |  |  |  |  |  |  |  |  |  |" % (
                r["name"], r["shows"], r["exit"], " ".join(r["stderr"])[:200]))
            continue
        ins = r.get("inspect", {})
        pieces = ins.get("pieces", [])
        piece_text = "%d (largest %s)" % (len(pieces), ", ".join(str(p) for p in pieces[:3])) if pieces else "-"
        checked = "%d, %s" % (ins.get("checked", 0), "clean" if ins.get("clean") else
                              "**not clean**: " + " ".join(ins.get("problem", []))[:160])
        if r["exit"] != 0:
            checked += "; **exit %d**: %s" % (r["exit"], " ".join(r["stderr"])[:160])
        lines.append("| `%s` | %s | %s | %.0f | %d | %s | %s | %s | %s | %s | %s | %d | %s | %s |" % (
            r["name"], r["shows"], fmt(r["sim_time"], ".2f"), r["faces_mean"], r["faces_max"],
            fmt(r["dynamics"], ".2f"), fmt(r["geometry"], ".2f"), fmt(r["total"], ".2f"),
            "%d" % paper[0] if paper else "-", fmt(paper[3], ".1f") if paper else "-",
            fmt(paper[3] / r["total"], ".0f" if paper[3] / r["total"] >= 10 else ".2g") + "x"
            if paper and r["total"] > 0 else "-",
            r["cracks"], piece_text, checked))
    pictures = [r for r in results if r.get("sheet_frames")]
    if pictures:
        lines += ["", "Contact sheets (frames left to right, top to bottom):", ""]
        for r in pictures:
            rel = os.path.relpath(os.path.join(args.img, r["name"] + ".png"), os.path.join(ROOT, "docs"))
            lines.append("- `%s` (frames %s): ![%s](%s)" % (r["name"], ", ".join(map(str, r["sheet_frames"])),
                                                           r["name"], rel))
    lines += shard_comparison(results, args)
    if arcsim_rows:
        lines += ["", "ARCSim 0.3.1's fracture scenes, both engines in this run (wall s per simulated s):", "",
                  "| scene | to (s) | ours | ARCSim | ratio |", "|---|---:|---:|---:|---:|"]
        for scene, seconds, ours, theirs in arcsim_rows:
            a = ours["stepping_wall"] / ours["sim_time"] if ours.get("sim_time") else float("nan")
            b = theirs["stepping_wall"] / theirs["sim_time"] if theirs.get("sim_time") else float("nan")
            lines.append("| `%s` | %g | %s | %s | %s |" % (scene, seconds, fmt(a, ".1f"), fmt(b, ".1f"),
                                                          fmt(b / a, ".1f") + "x" if a == a and b == b else "-"))
    return "\n".join(lines) + "\n"


def update_benchmarks(path, text):
    begin, end = "<!-- report:begin -->", "<!-- report:end -->"
    old = open(path).read() if os.path.exists(path) else ""
    block = begin + "\n" + text + end
    if begin in old and end in old:
        new = old[:old.index(begin)] + block + old[old.index(end) + len(end):]
    else:
        new = old.rstrip("\n") + "\n\n" + block + "\n"
    with open(path, "w") as f:
        f.write(new)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenes", nargs="*", help="scene names (default: every scene of the list found in conf/)")
    p.add_argument("--binary", default=os.path.join(ROOT, "bin", "arcsim"))
    p.add_argument("--threads", type=int, default=0, help="--threads for the simulator (default: its own)")
    p.add_argument("--out", default=os.path.join(ROOT, "out", "report"))
    p.add_argument("--img", default=os.path.join(ROOT, "docs", "img"))
    p.add_argument("--markdown", default=None)
    p.add_argument("--update-benchmarks", default=None)
    p.add_argument("--arcsim", default=None, help="an ARCSim 0.3.1 binary: also run its fracture scenes")
    p.add_argument("--shared", default=os.path.join(ROOT, "..", "shared"))
    p.add_argument("--reuse", action="store_true",
                   help="take a scene's figures from an earlier invocation's DIR/<scene>.result.json if present")
    args = p.parse_args()
    args.out = os.path.abspath(args.out)
    args.img = os.path.abspath(args.img)
    known = {name: (shows, paper) for name, shows, paper in SCENES}
    names = args.scenes or [n for n, _, _ in SCENES if os.path.exists(os.path.join(ROOT, "conf", n + ".json"))]
    unknown = [n for n in names if not os.path.exists(os.path.join(ROOT, "conf", n + ".json"))]
    if unknown:
        sys.exit("report: no such scene in conf/: " + ", ".join(unknown))
    os.makedirs(args.out, exist_ok=True)
    results = []
    failed = False
    for name in names:
        print("report: %s ..." % name, file=sys.stderr, flush=True)
        r = run_scene(args, name)
        r["shows"], r["paper"] = known.get(name, ("", None))
        results.append(r)
        ok = r["exit"] == 0 and r.get("inspect", {}).get("clean", False)
        failed |= not ok
        print("report: %s: exit %d, %.1f s wall, %s" % (name, r["exit"], r["wall"],
                                                      "clean" if ok else "NOT CLEAN"), file=sys.stderr, flush=True)
    arcsim_rows = arcsim_side_by_side(args) if args.arcsim else []
    text = markdown(results, arcsim_rows, args)
    md = args.markdown or os.path.join(args.out, "report.md")
    with open(md, "w") as f:
        f.write(text)
    with open(os.path.join(args.out, "report.json"), "w") as f:
        json.dump(results, f, indent=1, default=str)
    if args.update_benchmarks:
        update_benchmarks(args.update_benchmarks, text)
    sys.stdout.write(text)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
