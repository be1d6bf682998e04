#!/usr/bin/env python3
"""Measures how straight a tear's lips are: the deviation of each crack lip from its chord.

    python3 tools/lip_deviation.py <final frame .obj> [--initial <frame 0 .obj>] [--json]

The OBJ files are arcsim's cloth frames (extended OBJ: `v` world positions, `ms` rest-space positions, faces
`f node/rest-vertex ...`; docs/file-formats.md). --initial defaults to 00000_<cloth>.obj beside the final frame
(frame 0 of the same run, before any crack).

Lips. A crack splits rest vertices, so in rest space a lip is a border edge of the rest-vertex topology (an edge
of one face only). The sheet's own border (its outline and any notch or slit cut into it) is made of the border
edges of frame 0; a border edge of the final frame is a lip edge when its midpoint lies farther than `--tol`
(default 1e-4 m) from every border edge of frame 0. Lip edges are chained into polylines (connected components;
at a junction the longest path between two ends is kept). A crack gives two lips (its two sides), which lie
within the lip gap of each other in rest space.

Deviation. For each lip: the chord is the straight line through the lip's two end vertices; the deviation of a
vertex is its distance from that line. Reported, per lip: its chord length, its length along the lip, max and
RMS deviation, in two spaces:
  - rest space (`ms`, 2D): the path the crack took through the material. Plasticity does not move rest
    positions (it lives in each face's plastic tensor), so this measures the crack path alone.
  - world space (`v`, 3D): the lip's final shape. A lip the crack tip stretched plastically is longer than its
    chord once the load is off it and so has to wave, in plane or out of it: the undulating edges of the
    paper's Fig. 3. An elastic lip springs back to its (straight) rest length.
The ratio length / chord (1 for a straight lip) is printed next to them for the same reason.
"""
import argparse
import json
import math
import os
import sys


def read_obj(path):
    world, rest, faces = [], [], []
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                world.append(tuple(float(x) for x in t[1:4]))
            elif t[0] == "ms":
                rest.append(tuple(float(x) for x in t[1:4]))
            elif t[0] == "f":
                nodes, verts = [], []
                for c in t[1:4]:
                    parts = c.split("/")
                    nodes.append(int(parts[0]) - 1)
                    verts.append(int(parts[1]) - 1 if len(parts) > 1 and parts[1] else int(parts[0]) - 1)
                faces.append((nodes, verts))
    if not rest:
        rest = list(world)
    return world, rest, faces


def border_edges(faces):
    """Rest-vertex edges with one face, each as (vert a, vert b, node a, node b)."""
    count = {}
    for nodes, verts in faces:
        for k in range(3):
            a, b = verts[k], verts[(k + 1) % 3]
            key = (min(a, b), max(a, b))
            entry = count.setdefault(key, [0, None])
            entry[0] += 1
            entry[1] = (a, b, nodes[k], nodes[(k + 1) % 3])
    return [e[1] for e in count.values() if e[0] == 1]


def point_segment_distance(p, a, b):
    ab = [b[i] - a[i] for i in range(3)]
    ap = [p[i] - a[i] for i in range(3)]
    den = sum(x * x for x in ab)
    s = 0.0 if den == 0 else max(0.0, min(1.0, sum(ap[i] * ab[i] for i in range(3)) / den))
    return math.dist(p, [a[i] + s * ab[i] for i in range(3)])


def point_line_distance(p, a, b):
    ab = [b[i] - a[i] for i in range(3)]
    ap = [p[i] - a[i] for i in range(3)]
    den = sum(x * x for x in ab)
    if den == 0:
        return math.dist(p, a)
    s = sum(ap[i] * ab[i] for i in range(3)) / den
    return math.dist(p, [a[i] + s * ab[i] for i in range(3)])


def chains(edges):
    """Connected components of the lip edges, each reduced to its longest path between two ends, as a list of
    (vert, node) pairs in order."""
    adjacent, node_of = {}, {}
    for a, b, na, nb in edges:
        adjacent.setdefault(a, set()).add(b)
        adjacent.setdefault(b, set()).add(a)
        node_of[a], node_of[b] = na, nb
    seen, result = set(), []
    for start in adjacent:
        if start in seen:
            continue
        component, stack = [], [start]
        seen.add(start)
        while stack:
            v = stack.pop()
            component.append(v)
            for w in adjacent[v]:
                if w not in seen:
                    seen.add(w)
                    stack.append(w)

        def farthest(source):
            parent, order = {source: None}, [source]
            for v in order:
                for w in adjacent[v]:
                    if w not in parent:
                        parent[w] = v
                        order.append(w)
            return order[-1], parent

        end, _ = farthest(component[0])
        other, parent = farthest(end)
        path = [other]
        while parent[path[-1]] is not None:
            path.append(parent[path[-1]])
        result.append([(v, node_of[v]) for v in path])
    return result


def deviation(points):
    a, b = points[0], points[-1]
    d = [point_line_distance(p, a, b) for p in points]
    length = sum(math.dist(points[i], points[i + 1]) for i in range(len(points) - 1))
    chord = math.dist(a, b)
    return {"chord": chord, "length": length, "length_over_chord": length / chord if chord > 0 else None,
            "max": max(d), "rms": math.sqrt(sum(x * x for x in d) / len(d))}


def measure(final_path, initial_path, tol=1e-4, min_chord=0.0):
    world, rest, faces = read_obj(final_path)
    _, rest0, faces0 = read_obj(initial_path)
    outline = [(rest0[a], rest0[b]) for a, b, _, _ in border_edges(faces0)]
    lips = []
    for a, b, na, nb in border_edges(faces):
        mid = [(rest[a][i] + rest[b][i]) / 2 for i in range(3)]
        if min(point_segment_distance(mid, p, q) for p, q in outline) > tol:
            lips.append((a, b, na, nb))
    out = []
    for chain in chains(lips):
        r = deviation([rest[v] for v, _ in chain])
        if r["chord"] < min_chord:
            continue
        w = deviation([world[n] for _, n in chain])
        out.append({"vertices": len(chain), "rest": r, "world": w})
    out.sort(key=lambda c: -c["rest"]["length"])
    return {"lip_edges": len(lips), "lips": out}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("final")
    parser.add_argument("--initial")
    parser.add_argument("--tol", type=float, default=1e-4, help="m: farther than this from frame 0's border")
    parser.add_argument("--min-chord", type=float, default=0.01, help="m: lips shorter than this are left out")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    initial = args.initial
    if initial is None:
        base = os.path.basename(args.final)
        initial = os.path.join(os.path.dirname(args.final), "00000_" + base.split("_", 1)[1])
    result = measure(args.final, initial, args.tol, args.min_chord)
    if args.json:
        print(json.dumps(result))
        return
    print("%d lip edges, %d lips with a chord >= %g m" % (result["lip_edges"], len(result["lips"]), args.min_chord))
    print("%4s %5s | %-40s | %-40s" % ("lip", "verts", "rest: chord length max rms (mm)  len/chord",
                                       "world: chord length max rms (mm)  len/chord"))
    for k, lip in enumerate(result["lips"]):
        cells = []
        for space in ("rest", "world"):
            d = lip[space]
            cells.append("%6.1f %6.1f %5.2f %5.2f  %6.4f" % (d["chord"] * 1e3, d["length"] * 1e3, d["max"] * 1e3,
                                                             d["rms"] * 1e3, d["length_over_chord"] or 0))
        print("%4d %5d | %-40s | %-40s" % (k, lip["vertices"], cells[0], cells[1]))


if __name__ == "__main__":
    sys.exit(main())
