// ARCSim's extended OBJ format, read and written.
//
// Read tags: v (node world position), vt (rest vertex, 2 or 3 numbers), ms (3D rest vertex, preferred over vt
// when both are present), ny/nv/nl (plastic position, velocity, label of the preceding node), e/ea/ed/ep
// (explicit edge with rest angle, damage, preserve), f (i, i/k or i/k/n; polygons are fan-triangulated),
// tm/tp/ts/td (material, Sp, Fp, damage of the preceding face), th (thickness of the preceding face, ours).
// Unknown tags are ignored and counted. Faces without /k use a rest vertex at the node's position.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"

namespace arcsim {

struct ObjData {
  std::vector<Vec3> node_x;           // v
  std::vector<Vec3> node_v;           // nv (zero if absent)
  std::vector<int> node_label;        // nl (0 if absent)
  std::vector<Vec3> vert_u;           // rest vertices (ms / vt, or created from node positions)
  std::vector<int> vert_node;         // node of each rest vertex
  std::vector<std::array<int, 3>> tris;  // rest-vertex indices, after triangulation
  std::vector<int> tri_line;          // source line of each triangle
  std::vector<int> tri_material;      // tm (0 if absent)
  std::vector<double> tri_thickness;  // th (0 = material default)
  std::vector<Mat3> tri_Sp, tri_Fp;   // tp, ts (zero / identity if absent)
  std::vector<double> tri_damage;     // td
  struct EdgeRecord {
    int n0, n1;                       // 0-based nodes
    double rest_theta = 0, damage = 0;
    bool preserve = false;
    bool has_rest_theta = false;
  };
  std::vector<EdgeRecord> edges;      // e / ea / ed / ep
  bool has_rest_coords = false;       // any vt or ms present
  int unknown_tag_lines = 0;
};

// Parses an OBJ file. Throws InputError "<path>:<line>: <problem>" on malformed lines (bad numbers, indices out
// of range, faces with fewer than 3 corners) and "<path>: cannot open" for a missing file.
ObjData read_obj(const std::string& path);

// Validates the triangles (mesh/validate.hpp) and builds a Mesh: node positions, velocities and labels, rest
// vertices, per-face material/thickness/plastic state, and edge records (rest angles; edges without a record get
// the rest-space dihedral angle). Throws InputError naming the file and element.
Mesh build_mesh(const ObjData& obj, const std::string& path);

// Convenience: read_obj + build_mesh.
Mesh load_obj_mesh(const std::string& path);

// Writes world positions (v), rest coordinates (ms, plus vt = rest x, y for texture mapping in other tools),
// velocities (nv), labels (nl), faces (f i/k), per-face tm/th/tp/ts/td where not default, and edges whose rest
// angle or preserve flag is not the default (e/ea/ep). Doubles are written with 17 significant digits, so a
// written mesh reads back identically. The file is written to a temporary name and renamed: a reader never sees
// a half-written file. Throws InputError if the file cannot be written.
void write_obj(const Mesh& mesh, const std::string& path);

// Plain OBJ of world positions and faces (obstacles).
void write_plain_obj(const Mesh& mesh, const std::string& path);

}  // namespace arcsim
