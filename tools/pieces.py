#!/usr/bin/env python3
"""Counts the pieces of a cracked sheet: the connected components of a cloth frame (extended OBJ), two faces
being connected when they share a node (a crack's two lips are different nodes, so they separate pieces).

    python3 tools/pieces.py <frame.obj | out-dir> [--json] [--min-faces N] [--bins B]

With an output folder, the newest NNNNN_00.obj in it is read. Prints the piece count, the faces and the
world-space area (m^2) of each piece, largest first, and a histogram of piece areas as fractions of the whole
sheet in logarithmic bins (1/2..1, 1/4..1/2, ..., below 1/2^B), so that a few big shards and many small ones
can be told from a uniform break. --min-faces N also reports the count of pieces of at least N faces ("shards",
leaving out crumbs of one or two faces). --json prints one JSON object instead of the text.
"""
import glob
import json
import math
import os
import re
import sys


def read_obj(path):
    """World node positions and faces (node indices, 0-based) of an extended OBJ."""
    nodes, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                nodes.append(tuple(float(x) for x in line.split()[1:4]))
            elif line.startswith("f "):
                faces.append(tuple(int(t.split("/")[0]) - 1 for t in line.split()[1:4]))
    return nodes, faces


def area(p, q, r):
    u = [q[i] - p[i] for i in range(3)]
    v = [r[i] - p[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return 0.5 * math.sqrt(sum(c * c for c in n))


def pieces(nodes, faces):
    """[(faces, area)] per connected piece, largest area first (union-find over the faces' nodes)."""
    parent = list(range(len(nodes)))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b, c in faces:
        ra, rb, rc = find(a), find(b), find(c)
        parent[rb] = ra
        parent[find(rc)] = ra
    count, size = {}, {}
    for a, b, c in faces:
        r = find(a)
        count[r] = count.get(r, 0) + 1
        size[r] = size.get(r, 0.0) + area(nodes[a], nodes[b], nodes[c])
    return sorted(((count[r], size[r]) for r in count), key=lambda p: -p[1])


def histogram(areas, bins):
    """Counts of pieces whose area fraction of the whole lies in (1/2^(k+1), 1/2^k], k = 0..bins-1, and a last
    bin for everything smaller."""
    total = sum(areas)
    counts = [0] * (bins + 1)
    for a in areas:
        k = int(math.floor(-math.log2(a / total))) if a > 0 else bins
        counts[min(max(k, 0), bins)] += 1
    return counts


def summarise(path, min_faces=3, bins=12):
    nodes, faces = read_obj(path)
    parts = pieces(nodes, faces)
    areas = [a for _, a in parts]
    total = sum(areas)
    face_counts = [n for n, _ in parts]
    shards = [a for n, a in parts if n >= min_faces]
    # Gini coefficient of the shard areas: 0 when every shard has the same size, towards 1 when one holds all.
    s = sorted(shards)
    gini = (sum((2 * (i + 1) - len(s) - 1) * a for i, a in enumerate(s)) / (len(s) * sum(s))) if s else 0.0
    mean = sum(shards) / len(shards) if shards else 0.0
    cv = (math.sqrt(sum((a - mean) ** 2 for a in shards) / len(shards)) / mean) if shards else 0.0
    return {
        "file": path, "faces": len(faces), "area": total, "pieces": len(parts),
        "shards": len(shards), "min_faces": min_faces,
        "largest_fraction": areas[0] / total if areas else 0.0,
        "shard_area_cv": cv, "shard_area_gini": gini,
        "histogram_bins": ["1/2^%d..1/2^%d" % (k + 1, k) for k in range(bins)] + ["<1/2^%d" % bins],
        "histogram": histogram(areas, bins),
        "piece_faces": face_counts, "piece_areas": areas,
    }


def newest_frame(folder):
    frames = sorted(glob.glob(os.path.join(folder, "[0-9]*_00.obj")),
                    key=lambda p: int(re.match(r"(\d+)_", os.path.basename(p)).group(1)))
    if not frames:
        sys.exit("pieces.py: no NNNNN_00.obj in " + folder)
    return frames[-1]


def main(argv):
    args, as_json, min_faces, bins = [], False, 3, 12
    i = 0
    while i < len(argv):
        if argv[i] == "--json":
            as_json = True
        elif argv[i] == "--min-faces":
            i += 1
            min_faces = int(argv[i])
        elif argv[i] == "--bins":
            i += 1
            bins = int(argv[i])
        else:
            args.append(argv[i])
        i += 1
    if len(args) != 1:
        sys.exit(__doc__)
    path = newest_frame(args[0]) if os.path.isdir(args[0]) else args[0]
    r = summarise(path, min_faces, bins)
    if as_json:
        print(json.dumps(r))
        return
    print("%s: %d faces, %d pieces, %d shards of >= %d faces; largest piece %.1f%% of the area; shard areas: "
          "CV %.2f, Gini %.2f" % (r["file"], r["faces"], r["pieces"], r["shards"], min_faces,
                                  100 * r["largest_fraction"], r["shard_area_cv"], r["shard_area_gini"]))
    print("area fraction histogram (pieces per bin):")
    for label, n in zip(r["histogram_bins"], r["histogram"]):
        print("  %-14s %d" % (label, n))
    print("pieces (faces, area m^2), largest first:",
          ", ".join("%d/%.3g" % p for p in zip(r["piece_faces"][:30], r["piece_areas"][:30])),
          "..." if len(r["piece_faces"]) > 30 else "")


if __name__ == "__main__":
    main(sys.argv[1:])
