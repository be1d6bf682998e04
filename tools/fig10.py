#!/usr/bin/python3
"""Fig. 10's claim, measured over several seeds and mesh sizes: does the adaptive ornament break into more, and
less uniform, shards than a static mesh of the same face count (the paper: the static mesh gives "fewer, bigger
and more uniform" shards)?

    tools/fig10.py [--binary bin/arcsim] [--out DIR] [--seeds N] [--jobs J] [--variants a,b,...]
                   [--markdown FILE] [--plot FILE] [--reuse]

One drop of the glass ball is chaotic: which mesh edge meets the floor first decides where the first cracks
run, so one run per variant says little (two single runs of the same build have given opposite answers). Each
seed therefore turns the ball's mesh about a random axis by a random angle (seed 0: the scene as written) and
drops it again. The ball is a sphere, so the physics is the same and only the mesh's placement changes.

Variants (each from conf/paper-ornament*.json; the ball's rest shape is its sphere in every one):
  adaptive   conf/paper-ornament.json as it is (remeshing with fracture sizing);
  static14, static15, static16, static20
             conf/paper-ornament-static.json on the geodesic mesh of that frequency (20 f^2 faces before cracking;
             cracks add faces). The static family brackets the adaptive run's mean face count, so its figures are
             interpolated to the adaptive runs' mean count and to their mean CPU time.

Per run: faces (mean over frames), CPU seconds of the simulator (user + system, so that two runs side by side do
not distort each other), the pieces of the last frame (tools/pieces.py): pieces, shards of at least 1/4096 of the
ball's area (a count that does not depend on the face size, unlike "at least 3 faces"), largest piece, and the
spread of the shard areas (coefficient of variation and Gini index over those shards), and `arcsim inspect` of
the last frame (valid mesh, no intersections). Writes DIR/fig10.md (or --markdown) and a plot of shards and their
spread against faces and against CPU seconds (--plot, PNG; needs python3-matplotlib). --reuse takes each run's
figures from DIR/<run>/result.json where present.
"""
import argparse
import concurrent.futures
import copy
import json
import math
import os
import random
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import bench_fracture  # noqa: E402  (strip_comments)
import pieces  # noqa: E402
import report  # noqa: E402  (read_log, measure)

VARIANTS = {
    "adaptive": ("paper-ornament", None),
    "static12": ("paper-ornament-static", "meshes/geosphere12.obj"),
    "static14": ("paper-ornament-static", "meshes/geosphere14.obj"),
    "static15": ("paper-ornament-static", "meshes/geosphere15.obj"),
    "static16": ("paper-ornament-static", "meshes/geosphere16.obj"),
    "static20": ("paper-ornament-static", "meshes/geosphere20.obj"),
}
DEFAULT_VARIANTS = ["adaptive", "static14", "static15", "static16", "static20"]
SHARD_FRACTION = 1.0 / 4096  # a shard: a piece of at least this fraction of the ball's area


def read_scene(name):
    with open(os.path.join(ROOT, "conf", name + ".json")) as f:
        return json.loads(bench_fracture.strip_comments(f.read()))


def absolute(path, base):
    return path if os.path.isabs(path) else os.path.normpath(os.path.join(base, path))


def seed_rotation(seed):
    """(degrees, axis): none for seed 0, else a uniformly random axis and angle."""
    if seed == 0:
        return None
    rng = random.Random(1000 + seed)
    z = rng.uniform(-1.0, 1.0)
    phi = rng.uniform(0.0, 2.0 * math.pi)
    r = math.sqrt(max(0.0, 1.0 - z * z))
    return rng.uniform(0.0, 360.0), [r * math.cos(phi), r * math.sin(phi), z]


def variant_scene(variant, seed):
    """The scene of one run, with every file path made absolute (the scene is written elsewhere)."""
    conf, mesh = VARIANTS[variant]
    scene = copy.deepcopy(read_scene(conf))
    base = ROOT  # conf/ files name meshes and materials from the repository's root
    for cloth in scene["cloths"]:
        if mesh:
            cloth["mesh"] = mesh
        cloth["mesh"] = absolute(cloth["mesh"], base)
        for material in cloth.get("materials", []):
            if isinstance(material.get("data"), str):
                material["data"] = absolute(material["data"], base)
        rotation = seed_rotation(seed)
        if rotation:
            # The ball is centred at the origin of its mesh, so turning it before the translation keeps it in place.
            cloth.setdefault("transform", {})["rotate"] = [rotation[0]] + rotation[1]
    for obstacle in scene.get("obstacles", []):
        obstacle["mesh"] = absolute(obstacle["mesh"], base)
    return scene


def shard_figures(summary):
    areas = summary["piece_areas"]
    total = sum(areas)
    shards = [a for a in areas if a >= SHARD_FRACTION * total]
    mean = sum(shards) / len(shards) if shards else 0.0
    cv = math.sqrt(sum((a - mean) ** 2 for a in shards) / len(shards)) / mean if shards else 0.0
    s = sorted(shards)
    gini = (sum((2 * (i + 1) - len(s) - 1) * a for i, a in enumerate(s)) / (len(s) * sum(s))) if s else 0.0
    return {"shards": len(shards), "cv": cv, "gini": gini}


def run_one(binary, out_root, variant, seed, reuse):
    name = "%s-s%d" % (variant, seed)
    folder = os.path.join(out_root, name)
    record = os.path.join(folder, "result.json")
    if reuse and os.path.exists(record):
        with open(record) as f:
            return json.load(f)
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    scene_path = os.path.join(folder, "scene.json")
    with open(scene_path, "w") as f:
        json.dump(variant_scene(variant, seed), f, indent=1)
    out = os.path.join(folder, "out")
    cmd = [binary, "simulate", scene_path, out, "--threads", "1", "--quiet"]
    start = time.perf_counter()
    with open(os.path.join(folder, "stderr.txt"), "w") as err:
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    result = {"name": name, "variant": variant, "seed": seed, "rotation": seed_rotation(seed),
              "exit": proc.returncode, "wall": time.perf_counter() - start,
              "cpu": usage.ru_utime + usage.ru_stime}
    with open(os.path.join(folder, "stderr.txt")) as f:
        errors = [line.strip() for line in f if line.strip()]
    result["error"] = errors[-1] if errors and proc.returncode != 0 else ""
    log = os.path.join(out, "log.jsonl")
    if os.path.exists(log):
        frames = report.read_log(log)
        m = report.measure(frames)
        result.update(faces_mean=m["faces_mean"], faces_max=m["faces_max"], sim_time=m["sim_time"],
                      cracks=m["cracks"])
        summary = pieces.summarise(pieces.newest_frame(out))
        result.update(pieces=summary["pieces"], largest=summary["largest_fraction"],
                      histogram=summary["histogram"], histogram_bins=summary["histogram_bins"],
                      **shard_figures(summary))
        check = subprocess.run([binary, "inspect", out, "--last", "--quiet"], capture_output=True, text=True)
        result["clean"] = check.returncode == 0
        result["inspect"] = (check.stderr.strip().splitlines() or [""])[-1]
    with open(record, "w") as f:
        json.dump(result, f)
    return result


def mean_sd(xs):
    if not xs:
        return float("nan"), float("nan")
    m = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
    return m, sd


def mean_se(xs):
    m, sd = mean_sd(xs)
    return m, (sd / math.sqrt(len(xs)) if len(xs) > 1 else float("nan"))


def family_at(ok, statics, key, x_key, x):
    """The static variants' mean `key` (over seeds) at x in `x_key`, linearly between the two variants whose mean
    x brackets it, with the standard error carried through; (None, None) outside their range."""
    means = []
    for v in statics:
        rs = [r for r in ok if r["variant"] == v]
        means.append((mean_sd([r[x_key] for r in rs])[0],) + mean_se([r[key] for r in rs]))
    means.sort()
    for (x0, y0, e0), (x1, y1, e1) in zip(means, means[1:]):
        if x0 <= x <= x1:
            w = 0.0 if x1 == x0 else (x - x0) / (x1 - x0)
            return (1 - w) * y0 + w * y1, math.hypot((1 - w) * e0, w * e1)
    return None, None


def markdown(results, args):
    ok = [r for r in results if "shards" in r and r["exit"] == 0]
    variants = [v for v in args.variants if any(r["variant"] == v for r in ok)]
    lines = ["### Fig. 10 over %d seeds (`tools/fig10.py --seeds %d`, %s)" % (args.seeds, args.seeds,
                                                                             time.strftime("%Y-%m-%d")),
             "",
             "Machine: %s; commit %s. CPU seconds of each run (user + system, `--threads 1`). A shard: a piece of "
             "at least 1/4096 of the ball's area; CV and Gini: the spread of the shards' areas (0 = all equal)."
             % (report.machine(), report.commit()),
             "",
             "| variant | runs | faces mean | CPU s | pieces | shards | largest piece | shard CV | shard Gini | clean |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for v in variants:
        rs = [r for r in ok if r["variant"] == v]

        def cell(key, spec, scale=1.0):
            m, sd = mean_sd([scale * r[key] for r in rs])
            return ("%s ± %s" % (format(m, spec), format(sd, spec))) if len(rs) > 1 else format(m, spec)
        lines.append("| %s | %d | %s | %s | %s | %s | %s%% | %s | %s | %d of %d |" % (
            v, len(rs), cell("faces_mean", ".0f"), cell("cpu", ".0f"), cell("pieces", ".0f"), cell("shards", ".1f"),
            cell("largest", ".1f", 100.0), cell("cv", ".2f"), cell("gini", ".2f"),
            sum(1 for r in rs if r.get("clean")), len(rs)))
    failed = [r for r in results if "shards" not in r or r["exit"] != 0]
    if failed:
        lines += ["", "Runs that stopped (left out of every figure above and below):", ""]
    for r in failed:
        lines.append("- %s exited %d: %s" % (r["name"], r["exit"], r.get("error") or "see its stderr.txt"))
    lines += ["", "Per run (seed: the mesh turned by the angle about the axis; seed 0 as the scene is written):", "",
              "| run | rotation | faces mean | CPU s | pieces | shards | largest | CV | Gini |",
              "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in sorted(ok, key=lambda r: (args.variants.index(r["variant"]), r["seed"])):
        rot = "-" if not r["rotation"] else "%.0f° about (%.2f, %.2f, %.2f)" % (r["rotation"][0], *r["rotation"][1])
        lines.append("| %s | %s | %.0f | %.0f | %d | %d | %.1f%% | %.2f | %.2f |" % (
            r["name"], rot, r["faces_mean"], r["cpu"], r["pieces"], r["shards"], 100 * r["largest"], r["cv"],
            r["gini"]))
    adaptive = [r for r in ok if r["variant"] == "adaptive"]
    statics = [v for v in variants if v.startswith("static")]
    if adaptive and len(statics) >= 2:
        lines += ["", "Adaptive against the static family at the adaptive runs' mean face count and mean CPU time: each "
                  "static variant's mean over its seeds, interpolated linearly between the two variants that bracket "
                  "the adaptive mean (standard errors of the means carried through the interpolation). A difference "
                  "counts as resolved when it exceeds twice its standard error.", "",
                  "| at | measure | adaptive mean ± se | static, interpolated ± se | difference ± se | verdict |",
                  "|---|---|---:|---:|---:|---|"]
        for x_key, label, spec in (("faces_mean", "faces", ".0f"), ("cpu", "CPU s", ".0f")):
            x = mean_sd([r[x_key] for r in adaptive])[0]
            for key, name in (("shards", "shards"), ("cv", "shard area CV"), ("gini", "shard area Gini")):
                a_mean, a_se = mean_se([r[key] for r in adaptive])
                s_mean, s_se = family_at(ok, statics, key, x_key, x)
                if s_mean is None:
                    lines.append("| %s %s | %s | outside the static variants' range | | | |" % (
                        format(x, spec), label, name))
                    continue
                diff, se = a_mean - s_mean, math.hypot(a_se, s_se)
                verdict = ("adaptive higher" if diff > 2 * se else "adaptive lower" if diff < -2 * se
                           else "not resolved")
                lines.append("| %s %s | %s | %.2f ± %.2f | %.2f ± %.2f | %+.2f ± %.2f | %s |" % (
                    format(x, spec), label, name, a_mean, a_se, s_mean, s_se, diff, se, verdict))
    return "\n".join(lines) + "\n"


def plot(results, args):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    ok = [r for r in results if "shards" in r and r["exit"] == 0]
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    colours = {"adaptive": "tab:red"}
    for (row, key, ylabel) in ((0, "shards", "shards (>= 1/4096 of the ball)"), (1, "cv", "shard area CV")):
        for col, (x_key, xlabel) in enumerate((("faces_mean", "faces, mean over frames"),
                                               ("cpu", "CPU seconds (one core)"))):
            ax = axes[row][col]
            static = [r for r in ok if r["variant"].startswith("static")]
            ax.plot([r[x_key] for r in static], [r[key] for r in static], "o", color="tab:blue", alpha=0.35,
                    markersize=4, label="static, one seed")
            for v in sorted({r["variant"] for r in static}):
                rs = [r for r in static if r["variant"] == v]
                ax.errorbar(mean_sd([r[x_key] for r in rs])[0], mean_sd([r[key] for r in rs])[0],
                            yerr=mean_sd([r[key] for r in rs])[1], fmt="s", color="tab:blue",
                            label="static, mean ± sd" if v == "static14" else None)
            rs = [r for r in ok if r["variant"] == "adaptive"]
            ax.plot([r[x_key] for r in rs], [r[key] for r in rs], "o", color=colours["adaptive"], alpha=0.5,
                    markersize=4, label="adaptive, one seed")
            if rs:
                ax.errorbar(mean_sd([r[x_key] for r in rs])[0], mean_sd([r[key] for r in rs])[0],
                            yerr=mean_sd([r[key] for r in rs])[1], fmt="D", color=colours["adaptive"],
                            label="adaptive, mean ± sd")
            ax.set_xlabel(xlabel)
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
            if row == 0 and col == 0:
                ax.legend(fontsize=8)
    fig.suptitle("Fig. 10: glass ornament, adaptive vs static meshes (%d seeds)" % args.seeds)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.plot)), exist_ok=True)
    fig.savefig(args.plot, dpi=80)
    return args.plot


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--binary", default=os.path.join(ROOT, "bin", "arcsim"))
    p.add_argument("--out", default="/tmp/arcsim-fig10")
    p.add_argument("--seeds", type=int, default=4)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--variants", default=",".join(DEFAULT_VARIANTS))
    p.add_argument("--markdown")
    p.add_argument("--plot")
    p.add_argument("--reuse", action="store_true")
    args = p.parse_args()
    args.variants = args.variants.split(",")
    unknown = [v for v in args.variants if v not in VARIANTS]
    if unknown:
        sys.exit("fig10.py: unknown variant %s (known: %s)" % (", ".join(unknown), ", ".join(VARIANTS)))
    binary = os.path.abspath(args.binary)
    os.makedirs(args.out, exist_ok=True)
    # Slowest first, so that the pool's last minutes are not one long run alone.
    order = ["adaptive", "static20", "static16", "static15", "static14", "static12"]
    jobs = [(v, s) for s in range(args.seeds) for v in sorted(args.variants, key=order.index)]
    results = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(run_one, binary, args.out, v, s, args.reuse): (v, s) for v, s in jobs}
        for future in concurrent.futures.as_completed(futures):
            r = future.result()
            results.append(r)
            print("%-12s exit %d, %.0f CPU s, %s faces mean, %s shards, CV %s" % (
                r["name"], r["exit"], r["cpu"], "%.0f" % r["faces_mean"] if "faces_mean" in r else "-",
                r.get("shards", "-"), "%.2f" % r["cv"] if "cv" in r else "-"), flush=True)
    text = markdown(results, args)
    if args.plot:
        made = plot(results, args)
        if made:
            text += "\n![Fig. 10 over seeds](%s)\n" % os.path.relpath(made, os.path.dirname(
                os.path.abspath(args.markdown or os.path.join(args.out, "fig10.md"))))
    with open(args.markdown or os.path.join(args.out, "fig10.md"), "w") as f:
        f.write(text)
    print(text)
    return 1 if any(r["exit"] != 0 or not r.get("clean", False) for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
