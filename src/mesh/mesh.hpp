// The sheet mesh: world-space nodes, rest-space vertices, edges and faces, with all per-element state stored
// inside the elements so that it follows them through topology edits.
//
// Conventions
//  - Node: a world-space point (position x, velocity v). Its degrees of freedom are 3*index .. 3*index+2.
//  - Vert: a rest-space (material) point u in 3D. Every Vert belongs to one Node; a Node has several Verts only
//    on a seam of the rest parameterisation (OBJ `f i/k` with different k for the same i).
//  - Face: corners v[0..2] (Vert indices) counter-clockwise around the rest normal (u1-u0)x(u2-u0);
//    e[i] is the edge joining corners i and (i+1)%3.
//  - Edge: joins nodes n[0], n[1]. f[0] is the face in which the edge runs n[0] -> n[1] counter-clockwise,
//    f[1] the face in which it runs n[1] -> n[0]. A boundary edge (sheet border or crack lip) has exactly one
//    face; that face may be on either side (f[0] or f[1] is kNone).
//  - Elements live in vectors and are named by index. Removing an element unlinks it and marks it dead
//    (a tombstone), so every other index stays valid through any number of edits (remeshing and fracture keep
//    queues of indices). compact() then drops the dead elements, keeping order, and returns the old->new maps;
//    the simulation step compacts after each topology phase, so physics always sees a dense mesh.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "math/types.hpp"

namespace arcsim {

constexpr int kNone = -1;

struct Node {
  bool dead = false;        // removed (tombstone) until the next compact()
  Vec3 x = Vec3::Zero();   // world position (m)
  Vec3 x0 = Vec3::Zero();  // world position at the start of the current step (m)
  Vec3 v = Vec3::Zero();   // velocity (m/s)
  Vec3 a = Vec3::Zero();   // acceleration of the last physics step (m/s^2), used by reprojection
  int label = 0;           // OBJ `nl` label (0 = none), used by handles
  bool preserve = false;   // never removed by remeshing (handles, corners, crack tips)
  double mass = 0;         // lumped mass (kg), derived: see update_masses()
  std::vector<int> verts;  // rest-space vertices of this node
  std::vector<int> edges;  // incident edges
};

struct Vert {
  bool dead = false;        // removed (tombstone) until the next compact()
  Vec3 u = Vec3::Zero();    // rest-space position (m)
  int node = kNone;
  std::vector<int> faces;   // incident faces
  Mat3 sizing = Mat3::Zero();  // remeshing metric (1/m^2), rest space
};

struct Edge {
  bool dead = false;        // removed (tombstone) until the next compact()
  std::array<int, 2> n{kNone, kNone};  // nodes
  std::array<int, 2> f{kNone, kNone};  // faces (see orientation convention above)
  double rest_theta = 0;   // rest (plus plastic) dihedral angle (rad), signed, 0 = flat
  double damage = 0;       // bending-plasticity damage (dimensionless)
  bool preserve = false;   // never flipped or collapsed (defect lines, preserved creases)
  bool is_boundary() const { return f[0] == kNone || f[1] == kNone; }
};

struct Face {
  bool dead = false;        // removed (tombstone) until the next compact()
  std::array<int, 3> v{kNone, kNone, kNone};  // vertices, CCW
  std::array<int, 3> e{kNone, kNone, kNone};  // e[i] joins corners i and i+1
  int material = 0;        // index into the cloth's materials
  double thickness = 0;    // current thickness h (m); starts at the material's thickness, plasticity thins it
  Mat3 Fp = Mat3::Identity();  // stretching plasticity (rest space, 3D): F_el = F * Fp
  Mat3 Sp = Mat3::Zero();      // bending plasticity (plastic curvature tensor, rest space, 1/m)
  double damage = 0;           // plastic damage, weakens stiffness by 1/(1 + weakening*damage)
  // Derived rest-space data (update_rest_data): area (m^2), unit normal, an orthonormal in-plane frame
  // (columns t1, t2) and the inverse of the 2x2 rest edge matrix expressed in that frame.
  double rest_area = 0;
  Vec3 rest_normal = Vec3::UnitZ();
  Mat32 rest_frame = Mat32::Zero();
  Mat2 Dm_inv = Mat2::Identity();
};

class Mesh {
 public:
  std::vector<Node> nodes;
  std::vector<Vert> verts;
  std::vector<Edge> edges;
  std::vector<Face> faces;

  // Builds a mesh from rest positions, world positions and triangles given as (vert, vert, vert) with
  // vert_node[k] the node of vert k. Creates edges and all adjacency. Does not validate: see mesh/validate.hpp.
  static Mesh from_triangles(const std::vector<Vec3>& node_x, const std::vector<Vec3>& vert_u,
                             const std::vector<int>& vert_node, const std::vector<std::array<int, 3>>& tris,
                             const std::vector<int>& tri_material = {});

  // --- element creation and removal (low level; keeps adjacency lists consistent) ---
  int add_node(const Node& n);
  int add_vert(const Vert& v, int node);
  // Adds an edge between two nodes if none exists, returns its index (existing or new).
  int get_or_add_edge(int n0, int n1);
  // Adds a face on three verts; creates missing edges and links faces/edges. Returns the face index.
  int add_face(const std::array<int, 3>& v, const Face& prototype);
  // Removes a face and unlinks it from its verts and edges (edges stay, possibly with no face at all).
  void remove_face(int f);
  // Removes an edge that has no faces.
  void remove_edge(int e);
  // Removes a vert that has no faces.
  void remove_vert(int v);
  // Removes a node that has no verts and no edges.
  void remove_node(int n);

  // Index maps returned by compact(): old index -> new index, kNone for removed elements.
  struct Compaction {
    std::vector<int> node, vert, edge, face;
  };
  // Drops dead elements (order of the live ones kept) and renumbers every reference.
  Compaction compact();
  bool is_compact() const;

  // --- queries ---
  int find_edge(int n0, int n1) const;        // kNone if absent
  int face_node(int f, int corner) const { return verts[faces[f].v[corner]].node; }
  int corner_of_node(int f, int node) const;  // kNone if absent
  // The faces around node n (over all its verts), sorted, each once.
  std::vector<int> node_faces(int n) const;
  int other_face(int e, int f) const { return edges[e].f[0] == f ? edges[e].f[1] : edges[e].f[0]; }
  // The node of face f opposite to edge e (kNone if f is kNone).
  int opposite_node(int e, int f) const;
  bool is_boundary_node(int n) const;

  // --- derived data ---
  void update_rest_data(int f);  // rest area, normal, frame, Dm_inv of one face
  void update_rest_data();       // all faces
  // Signed dihedral angle of edge e in rest space (0 for boundary edges and across rest-space seams).
  double rest_dihedral(int e) const;
  double world_dihedral(int e) const;
  Vec3 world_normal(int f) const;  // unit normal of face f in world space
  double world_area(int f) const;

 private:
  size_t dead_count_ = 0;
};

// Signed dihedral angle (rad) of the hinge x0-x1 with wing x2 in face A = (x0, x1, x2) and wing x3 in face
// B = (x1, x0, x3): theta = atan2((nA x nB) . e, nA . nB) with e = (x1 - x0)/|x1 - x0| and nA, nB the unit
// normals. 0 when flat; the sign says which way the sheet folds, consistently in rest and world space.
double dihedral_angle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);

// World vertex normals of every node (area-weighted unit face normals; zero for dead nodes), and the same for
// rest space per vert (indexed like mesh.verts).
std::vector<Vec3> world_node_normals(const Mesh& mesh);
std::vector<Vec3> rest_vert_normals(const Mesh& mesh);
// The same normals for the listed nodes / verts only, written into `normals` (indexed like mesh.nodes /
// mesh.verts; resized to it, other entries left as they are). Bit-identical to the whole-mesh functions (the
// faces are summed in the same order); the cost is the listed elements' fans.
void update_world_node_normals(const Mesh& mesh, const std::vector<int>& nodes, std::vector<Vec3>& normals);
void update_rest_vert_normals(const Mesh& mesh, const std::vector<int>& verts, std::vector<Vec3>& normals);

}  // namespace arcsim
