#!/usr/bin/env python3
"""Generates the project's own small test and demo meshes (extended OBJ, flat sheets in the xy plane, CCW).

    python3 tools/make_meshes.py [output_dir]     (default: meshes/ next to tools/)

meshes/square.obj       1 m x 1 m, 10 x 10 cells, 121 nodes, 200 faces; the two top corners have label 1.
meshes/strip.obj        1 m x 0.1 m, 20 x 2 cells, 63 nodes, 80 faces; left end label 1, right end label 2.
meshes/square_notch.obj the square with a 90-degree V notch (0.1 m deep, 0.2 m wide) cut into the middle of the
                        left side, tip at (0.1, 0.5); 120 nodes, 198 faces; bottom side label 1, top side label 2
                        (for pulling the sheet apart across the notch).
meshes/square_slit.obj  1 m x 1 m, 20 x 20 cells, a slit 0.2 deep into the middle of the left side (a thin V, 0.02
                        wide at the edge, tip at (0.2, 0.5)); 445 nodes, 800 faces; bottom side label 1, top side
                        label 2 (rubber tearing, conf/paper-rubber-tear.json).
meshes/square_top_notch.obj  1 m x 1 m, 20 x 20 cells, a V notch 0.05 deep (0.01 wide at the edge) cut down
                        from the middle of the top side, tip at (0.5, 0.95); 442 nodes, 800 faces; four 3 x 3-node
                        corner grips centred 0.1 in from the corners, left label 1, right label 2 (paper tearing,
                        conf/paper-tearing.json).
meshes/square_clamped.obj  the square (10 x 10 cells, 121 nodes, 200 faces) with its 40 border nodes labelled 1
                        (clamped all round: conf/paper-variety.json).
meshes/ground.obj       1 m x 1 m, one cell (2 faces, 4 nodes): a floor obstacle, scaled up by the scenes.
meshes/sphere.obj       unit sphere (radius 1 m, centre 0) as an icosahedron subdivided twice: 162 nodes,
                        320 faces, outward (CCW seen from outside). An obstacle, scaled by the scenes.
meshes/geosphereF.obj   unit geodesic sphere (icosahedron faces cut F x F), 20 F^2 faces, F in
                        ORNAMENT_FREQUENCIES (6: the adaptive ornament's start; 12, 14, 15, 16, 20: static meshes to
                        match an adaptive run's mean face count, conf/paper-ornament*.json).
meshes/hemisphere.obj   unit hemisphere z >= 0 (octahedron's upper faces cut 8 x 8), 256 faces; rim label 1
                        (conf/paper-dome.json).
meshes/pane.obj         1 m x 1 m, 16 x 16 cells, 512 faces; every border node label 1 (conf/paper-window.json).
meshes/box_frame.obj     a square tube 20 cm wide and 20 cm high (z up, open at top and bottom, centred on the z
                        axis, bottom at z = 0): the box frame of the metal-and-glass scene. 1 cm cells, 80 around
                        x 20 up, 1680 nodes, 3200 faces. Its front (y = -0.1) and back (y = 0.1) walls are window
                        frames: a 2 cm aluminium border (face material 0) around a 16 x 16 cm glass pane (`tm 1`);
                        its two side walls (x = +-0.1) are plain aluminium. Bottom two node rows (z = 0, 0.01) label 1,
                        top two rows label 2 (a handle on them clamps the rim's position and slope).
                        The four corner lines and the pane outlines are edge records marked `ep` (preserved:
                        never flipped or collapsed), so remeshing keeps the folds and the material borders.
                        No `vt`/`ms` lines: the rest shape is this folded 3D shape.
meshes/cylinder.obj     an open tube (polycarbonate cylinder scene): radius 5 cm, height 12 cm, axis z, bottom at
                        z = 0; 48 around x 18 up (6.5 x 6.7 mm cells), 912 nodes, 1728 faces. Bottom rim label 1,
                        top rim label 2. The faces of the two cell rows at each rim (1.3 cm) have `tm 1`, the
                        end collars. The radius carries a deterministic imperfection of +-0.1 mm (0.1 h):
                        a mode of 5 waves around x 1 half-wave up plus a 3-wave tilt, so that the buckles do
                        not have to wait for round-off. Rest shape = this shape.
No `vt` lines: a flat sheet's rest shape is its initial world shape. Coordinates are in metres.
"""
import os
import sys


def number(x):
    """Shortest text for a grid coordinate (rounded so that 0.1 * 3 prints as 0.3)."""
    text = repr(round(x, 12))
    return text[:-2] if text.endswith(".0") else text


def grid(width, height, cells_x, cells_y):
    """Node positions and CCW triangles of a regular grid. Diagonals alternate like a chequerboard, so that no
    direction is favoured; cell (i, j) is cut along '/' when i + j is even."""
    nodes = [(width * i / cells_x, height * j / cells_y) for j in range(cells_y + 1) for i in range(cells_x + 1)]

    def node(i, j):
        return j * (cells_x + 1) + i

    faces = []
    for j in range(cells_y):
        for i in range(cells_x):
            a, b, c, d = node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)
            if (i + j) % 2 == 0:
                faces += [(a, b, c), (a, c, d)]
            else:
                faces += [(a, b, d), (b, c, d)]
    return nodes, faces, node


def drop_node(nodes, faces, labels, removed):
    """Removes one node that no face uses any more and renumbers the others."""
    assert all(removed not in f for f in faces)
    renumber = lambda n: n - 1 if n > removed else n
    nodes = nodes[:removed] + nodes[removed + 1:]
    faces = [tuple(renumber(n) for n in f) for f in faces]
    labels = {renumber(n): value for n, value in labels.items()}
    return nodes, faces, labels


def write_obj(path, comment, nodes, faces, labels):
    lines = ["# " + line for line in comment.splitlines()]
    for n, (x, y) in enumerate(nodes):
        lines.append("v %s %s 0" % (number(x), number(y)))
        if n in labels:
            lines.append("nl %d" % labels[n])
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
    with open(path, "w") as out:
        out.write("\n".join(lines) + "\n")


def square():
    nodes, faces, node = grid(1.0, 1.0, 10, 10)
    labels = {node(0, 10): 1, node(10, 10): 1}
    return nodes, faces, labels


def strip():
    nodes, faces, node = grid(1.0, 0.1, 20, 2)
    labels = {}
    for j in range(3):
        labels[node(0, j)] = 1
        labels[node(20, j)] = 2
    return nodes, faces, labels


def square_notch():
    nodes, faces, node = grid(1.0, 1.0, 10, 10)
    # Cells (0, 4) and (0, 5) are cut along '/' and '\' respectively, so both triangles touching the left-side
    # node (0, 0.5) also touch (0.1, 0.5): removing them leaves a V notch whose tip is (0.1, 0.5).
    cut_node = node(0, 5)
    faces = [f for f in faces if cut_node not in f]
    labels = {}
    for i in range(11):
        labels[node(i, 0)] = 1
        labels[node(i, 10)] = 2
    return drop_node(nodes, faces, labels, cut_node)


def slit_sheet(cells, slit_cells, half_width):
    """A unit square of cells x cells grid cells with a slit cut into the middle of its left side: the nodes of the
    middle row (j = cells / 2) left of column slit_cells are doubled, the copy used by the faces above the slit
    moved up and the other moved down by half_width * (1 - x / depth), so the slit is a thin V (opening
    2 half_width at the edge) whose tip is the single node (slit_cells / cells, 0.5). Returns nodes, faces,
    node(i, j) and top(i) (the node above the slit in column i, the copy for i < slit_cells)."""
    nodes, faces, node = grid(1.0, 1.0, cells, cells)
    mid = cells // 2
    depth = slit_cells / cells
    nodes = list(nodes)
    copy = {}
    for i in range(slit_cells):
        x, y = nodes[node(i, mid)]
        w = half_width * (1 - x / depth)
        nodes[node(i, mid)] = (x, y - w)
        copy[node(i, mid)] = len(nodes)
        nodes.append((x, y + w))
    # a face lies above the slit when its centroid does
    split = []
    for f in faces:
        if sum(nodes[n][1] for n in f) / 3 > 0.5 and any(n in copy for n in f):
            f = tuple(copy.get(n, n) for n in f)
        split.append(f)
    top = lambda i: copy.get(node(i, mid), node(i, mid))
    return nodes, split, node, top


def square_slit():
    """meshes/square_slit.obj: 20 x 20 cells, a slit 0.2 deep (4 cells) into the middle of the left side, 0.02
    wide at the edge; bottom side label 1, top side label 2 (pulled apart across the slit: rubber tearing)."""
    nodes, faces, node, _ = slit_sheet(20, 4, 0.01)
    labels = {}
    for i in range(21):
        labels[node(i, 0)] = 1
        labels[node(i, 20)] = 2
    return nodes, faces, labels


def square_top_notch():
    """meshes/square_top_notch.obj: 20 x 20 cells with a small V notch (one cell, 0.05 deep, 0.01 wide at the edge)
    cut down from the middle of the top side, tip at (0.5, 0.95): the slit sheet of square_slit with a one-cell
    slit, turned a quarter turn clockwise. The hands hold the sheet at four 0.1 x 0.1 corner patches (3 x 3 nodes)
    centred 0.1 in from each corner: label 1 the two on the left (x = 0.1), label 2 the two on the right
    (x = 0.9); turning the hands apart in the sheet's plane opens the notch (paper tearing by hand)."""
    nodes, faces, node, _ = slit_sheet(20, 1, 0.005)
    nodes = [(y, 1 - x) for x, y in nodes]   # rotation by -90 degrees plus a shift: keeps the faces CCW
    labels = {}
    for n, (x, y) in enumerate(nodes):
        near = lambda a, b: abs(a - b) < 0.051
        if near(y, 0.1) or near(y, 0.9):
            if near(x, 0.1):
                labels[n] = 1
            elif near(x, 0.9):
                labels[n] = 2
    return nodes, faces, labels


def square_clamped():
    """meshes/square_clamped.obj: the 10 x 10 square with every border node labelled 1 (a sheet clamped all round:
    the material-variety impacts, conf/paper-variety.json)."""
    nodes, faces, node = grid(1.0, 1.0, 10, 10)
    labels = {node(i, j): 1 for j in range(11) for i in range(11) if i in (0, 10) or j in (0, 10)}
    return nodes, faces, labels


def ground():
    nodes, faces, _ = grid(1.0, 1.0, 1, 1)
    return nodes, faces, {}


def icosphere(levels):
    """Unit icosphere: the icosahedron's faces split in four `levels` times, new nodes pushed onto the sphere.
    Returns 3D nodes and outward CCW faces."""
    g = (1 + 5 ** 0.5) / 2
    nodes = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g), (0, -1, -g), (0, 1, -g),
             (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]

    def unit(p):
        length = sum(c * c for c in p) ** 0.5
        return tuple(c / length for c in p)

    nodes = [unit(p) for p in nodes]
    for _ in range(levels):
        middle = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                nodes.append(unit(tuple((p + q) / 2 for p, q in zip(nodes[a], nodes[b]))))
                middle[key] = len(nodes) - 1
            return middle[key]

        split = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            split += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = split
    return nodes, faces


def write_obj_3d(path, comment, nodes, faces):
    lines = ["# " + line for line in comment.splitlines()]
    lines += ["v %.12g %.12g %.12g" % p for p in nodes]
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
    with open(path, "w") as out:
        out.write("\n".join(lines) + "\n")


# --- glass scenes (paper Fig. 9 right, 10, 11 left) ---------------------------------------------------------

def geodesic_sphere(frequency):
    """Unit sphere from the icosahedron with each face cut into frequency^2 triangles (class I geodesic grid,
    edges split into `frequency` parts, nodes pushed onto the sphere): 20 f^2 faces, 10 f^2 + 2 nodes. Unlike
    icosphere(), any frequency, so a static mesh can be matched to a face count. Outward CCW faces."""
    g = (1 + 5 ** 0.5) / 2
    corners = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g), (0, -1, -g), (0, 1, -g),
               (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
    ico = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
           (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
           (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    return subdivided_polyhedron(corners, ico, frequency)


def subdivided_polyhedron(corners, triangles, frequency):
    """Each triangle (a, b, c) of a polyhedron cut into frequency^2 triangles on the barycentric grid
    a + (i (b - a) + j (c - a)) / f, nodes shared along edges and corners (keyed by their exact rational
    barycentric position), then every node pushed onto the unit sphere."""
    f = frequency
    nodes, index = [], {}

    def node(a, b, c, i, j):
        # The grid point's weights over the corners, as integers out of f: unique for a shared point.
        weights = {}
        for corner, w in ((a, f - i - j), (b, i), (c, j)):
            if w:
                weights[corner] = weights.get(corner, 0) + w
        key = tuple(sorted(weights.items()))
        if key not in index:
            p = [sum(corners[k][d] * w for k, w in key) / f for d in range(3)]
            length = sum(x * x for x in p) ** 0.5
            nodes.append(tuple(x / length for x in p))
            index[key] = len(nodes) - 1
        return index[key]

    faces = []
    for a, b, c in triangles:
        for j in range(f):
            for i in range(f - j):
                p, q, r = node(a, b, c, i, j), node(a, b, c, i + 1, j), node(a, b, c, i, j + 1)
                faces.append((p, q, r))
                if i + j + 1 < f:
                    faces.append((q, node(a, b, c, i + 1, j + 1), r))
    return nodes, faces


def hemisphere(frequency):
    """Unit upper hemisphere (z >= 0) from the octahedron's four upper faces, each cut into frequency^2
    triangles and pushed onto the sphere: 4 f^2 faces; its rim is the octahedron's equator, so it lies exactly
    in the plane z = 0. Rim nodes carry label 1 (the held rim of the glass dome). Outward CCW faces."""
    corners = [(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0), (0, 0, 1)]
    upper = [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]
    nodes, faces = subdivided_polyhedron(corners, upper, frequency)
    labels = {n: 1 for n, p in enumerate(nodes) if abs(p[2]) < 1e-12}
    return nodes, faces, labels


def pane(cells):
    """1 m x 1 m flat sheet, cells x cells, with every border node labelled 1 (a window pane held in its
    frame). Chequerboard diagonals as grid()."""
    nodes, faces, node = grid(1.0, 1.0, cells, cells)
    labels = {}
    for k in range(cells + 1):
        for n in (node(k, 0), node(k, cells), node(0, k), node(cells, k)):
            labels[n] = 1
    return nodes, faces, labels


def write_obj_3d_labelled(path, comment, nodes, faces, labels):
    """write_obj_3d with `nl` node labels (for handles on curved meshes)."""
    lines = ["# " + line for line in comment.splitlines()]
    for n, p in enumerate(nodes):
        lines.append("v %.12g %.12g %.12g" % p)
        if n in labels:
            lines.append("nl %d" % labels[n])
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
    with open(path, "w") as out:
        out.write("\n".join(lines) + "\n")


def write_obj_general(path, comment, nodes, faces, labels=None, materials=None, preserved=None):
    """Extended OBJ of a 3D sheet: `v` (and `nl` labels), `f` with an optional `tm` material index per face
    (written only when not 0), and `e a b` + `ep` edge records for the preserved edges (node index pairs)."""
    labels = labels or {}
    lines = ["# " + line for line in comment.splitlines()]
    for n, p in enumerate(nodes):
        lines.append("v %s %s %s" % tuple(number(c) for c in p))
        if n in labels:
            lines.append("nl %d" % labels[n])
    for k, (a, b, c) in enumerate(faces):
        lines.append("f %d %d %d" % (a + 1, b + 1, c + 1))
        if materials and materials[k] != 0:
            lines.append("tm %d" % materials[k])
    for a, b in sorted(preserved or ()):
        lines += ["e %d %d" % (a + 1, b + 1), "ep"]
    with open(path, "w") as out:
        out.write("\n".join(lines) + "\n")


# Frequencies of the geodesic ornament meshes written by main(): 6 is the adaptive run's coarse start; the
# others are static meshes of 20 f^2 faces to match an adaptive run's mean face count (conf/paper-ornament*.json).
ORNAMENT_FREQUENCIES = (6, 12, 14, 15, 16, 20)
def periodic_tube(cells_around, cells_up, height, place):
    """A tube: a grid `cells_around` x `cells_up` whose last column is glued to the first. `place(s, z)` maps
    the unrolled coordinate s in [0, 1) and the height z to a 3D point. Diagonals alternate like a chequerboard
    (cells_around even keeps the pattern across the seam). Faces are CCW seen from outside when place() runs
    counter-clockwise about +z."""
    assert cells_around % 2 == 0
    def node(i, j):
        return j * cells_around + i % cells_around
    nodes = [place(i / cells_around, height * j / cells_up) for j in range(cells_up + 1) for i in range(cells_around)]
    faces, cells = [], []
    for j in range(cells_up):
        for i in range(cells_around):
            a, b, c, d = node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)
            if (i + j) % 2 == 0:
                faces += [(a, b, c), (a, c, d)]
            else:
                faces += [(a, b, d), (b, c, d)]
            cells += [(i, j), (i, j)]
    return nodes, faces, cells, node


def box_frame(width=0.2, height=0.2, border=0.02, cell=0.01, clamp_rows=2):
    per_wall = int(round(width / cell))
    around, up = 4 * per_wall, int(round(height / cell))
    h = width / 2
    corners = [(-h, -h), (h, -h), (h, h), (-h, h)]  # counter-clockwise about +z, wall k from corner k to k+1

    def place(s, z):
        k = min(int(s * 4 + 1e-9), 3)
        t = s * 4 - k
        (x0, y0), (x1, y1) = corners[k], corners[(k + 1) % 4]
        return (x0 + t * (x1 - x0), y0 + t * (y1 - y0), z)

    nodes, faces, cells, node = periodic_tube(around, up, height, place)
    b = int(round(border / cell))

    def in_pane(i, j):  # cell (i, j) lies in a glass pane: front (wall 0) or back (wall 2) wall, inside the border
        wall, local = divmod(i, per_wall)
        return wall in (0, 2) and b <= local < per_wall - b and b <= j < up - b

    materials = [1 if in_pane(i, j) else 0 for (i, j) in cells]
    preserved = set()
    for j in range(up):  # the corner lines
        for k in range(4):
            preserved.add(tuple(sorted((node(k * per_wall, j), node(k * per_wall, j + 1)))))
    for wall in (0, 2):  # the pane outlines
        i0, i1 = wall * per_wall + b, wall * per_wall + per_wall - b
        for i in range(i0, i1):
            for j in (b, up - b):
                preserved.add(tuple(sorted((node(i, j), node(i + 1, j)))))
        for j in range(b, up - b):
            for i in (i0, i1):
                preserved.add(tuple(sorted((node(i, j), node(i, j + 1)))))
    labels = {}
    for i in range(around):  # two rows at each rim, so that a rim handle clamps the walls' slope too
        for j in range(clamp_rows):
            labels[node(i, j)] = 1
            labels[node(i, up - j)] = 2
    return nodes, faces, labels, materials, preserved


def cylinder(radius=0.05, height=0.12, around=48, up=18, imperfection=1e-4, collar_rows=2):
    import math

    def place(s, z):
        phi = 2 * math.pi * s
        r = radius + imperfection * (0.7 * math.cos(5 * phi) * math.sin(math.pi * z / height) +
                                     0.3 * math.cos(3 * phi + 1.0) * (z / height))
        return (r * math.cos(phi), r * math.sin(phi), z)

    nodes, faces, cells, node = periodic_tube(around, up, height, place)
    labels = {}
    for i in range(around):
        labels[node(i, 0)] = 1
        labels[node(i, up)] = 2
    # The end collars: the faces of the two cell rows at each rim get material 1 (the scene makes it unbreakable,
    # as a tube glued into end caps; cracks then start in the buckles, not at the clamps).
    materials = [1 if j < collar_rows or j >= up - collar_rows else 0 for (i, j) in cells]
    return nodes, faces, labels, materials


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "meshes")
    os.makedirs(out_dir, exist_ok=True)
    generated = "generated by tools/make_meshes.py"
    write_obj(os.path.join(out_dir, "square.obj"),
              "1 m x 1 m flat sheet, 10 x 10 cells; top corners label 1\n" + generated, *square())
    write_obj(os.path.join(out_dir, "strip.obj"),
              "1 m x 0.1 m strip, 20 x 2 cells; left end label 1, right end label 2\n" + generated, *strip())
    write_obj(os.path.join(out_dir, "square_notch.obj"),
              "1 m x 1 m sheet with a V notch (tip at 0.1 0.5) in the left side; bottom label 1, top label 2\n" +
              generated, *square_notch())
    write_obj(os.path.join(out_dir, "square_slit.obj"),
              "1 m x 1 m sheet, 20 x 20 cells, with a slit 0.2 deep (tip at 0.2 0.5) into its left side; bottom "
              "label 1, top label 2\n" + generated, *square_slit())
    write_obj(os.path.join(out_dir, "square_top_notch.obj"),
              "1 m x 1 m sheet, 20 x 20 cells, with a V notch 0.05 deep (tip at 0.5 0.95) in its top side; corner "
              "grips left (label 1) and right (label 2)\n" + generated, *square_top_notch())
    write_obj(os.path.join(out_dir, "square_clamped.obj"),
              "1 m x 1 m flat sheet, 10 x 10 cells; every border node label 1\n" + generated, *square_clamped())
    write_obj(os.path.join(out_dir, "ground.obj"),
              "1 m x 1 m flat sheet, one cell (a floor obstacle)\n" + generated, *ground())
    write_obj_3d(os.path.join(out_dir, "sphere.obj"),
                 "unit sphere, icosahedron subdivided twice, outward faces\n" + generated, *icosphere(2))
    for f in ORNAMENT_FREQUENCIES:
        nodes, faces = geodesic_sphere(f)
        write_obj_3d(os.path.join(out_dir, "geosphere%d.obj" % f),
                     "unit geodesic sphere, icosahedron faces cut %dx%d (%d faces), outward\n" % (f, f, len(faces))
                     + generated, nodes, faces)
    write_obj_3d_labelled(os.path.join(out_dir, "hemisphere.obj"),
                          "unit hemisphere z >= 0, octahedron faces cut 8x8 (256 faces); rim label 1\n" + generated,
                          *hemisphere(8))
    write_obj(os.path.join(out_dir, "pane.obj"),
              "1 m x 1 m flat pane, 16 x 16 cells; border label 1\n" + generated, *pane(16))
    write_obj_general(os.path.join(out_dir, "box_frame.obj"),
                      "square tube 0.2 x 0.2 x 0.2 m: aluminium frame (tm 0), glass panes in the front and back "
                      "walls (tm 1);\nbottom two rows label 1, top two rows label 2; corner lines and pane outlines "
                      "preserved (ep)\n" + generated, *box_frame())
    write_obj_general(os.path.join(out_dir, "cylinder.obj"),
                      "open cylinder r = 0.05 m, h = 0.12 m, with a 0.1 mm imperfection; bottom rim label 1, top "
                      "rim label 2; the two cell rows at each rim tm 1 (collars)\n" + generated, *cylinder())


if __name__ == "__main__":
    main()
