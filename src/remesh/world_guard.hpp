// Keeps remeshing from making the world surface cross itself, another cloth or an obstacle.
//
// WHY: remeshing runs between time steps and changes the world surface a little (a collapse replaces a fan of
// faces by a flatter one, a flip swaps a quad's diagonal, reprojection moves a node). Collision handling sees
// only the motion inside a step: an intersection an edit created is invisible to continuous collision
// detection and spreads from there (measured on ARCSim's sphere.json: 22 crossing triangle pairs after one
// remesh, 180 a step later). The guard lets an edit through only if its new triangles keep a clearance from
// every surface they do not touch, or at least come no closer than the triangles they replace were, and if
// the surface sweeps through nothing on its way from the old triangles to the new ones (a thin obstacle or a
// sheet's edge can lie between the two without touching either).
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim {

// A world triangle with the mesh nodes at its corners (kNone for corners not in the guarded mesh).
struct GuardTriangle {
  std::array<Vec3, 3> x;
  std::array<int, 3> nodes{kNone, kNone, kNone};
};

// A tetrahedron swept by the surface during an edit: a triangle whose corner x[0] moves to x[1] while the
// edge x[2] x[3] stays (a collapsing or moving node's face), or a flipped quad. nodes: mesh nodes of the
// corners (kNone where none).
struct GuardSweep {
  std::array<Vec3, 4> x;
  std::array<int, 4> nodes{kNone, kNone, kNone, kNone};
};

// Whether an edit that turns the triangles `before` into `after` (the same faces, index for index: corners moved,
// and node ids renamed as the edit renames them, e.g. a split node's copies given new ids) makes two of them
// cross: a pair that shares no node after the edit meets after it, and did not meet, sharing no node, before.
// kNone never counts as shared. Throws std::invalid_argument if `before` and `after` differ in size (a caller's
// mistake: they must be the same faces). WHY: WorldGuard checks an edit's triangles against the rest of the
// surface, not against each other; an edit that separates faces (a crack opening splits a node) can leave two of
// its own faces crossing (docs/stability.md, 2026-12-06 (h4)), which no contact normal can part afterwards.
bool edit_makes_crossing(const std::vector<GuardTriangle>& before, const std::vector<GuardTriangle>& after);

class WorldGuard {
 public:
  // Indexes the live faces of `mesh` (the mesh being edited: faces are looked up again at query time, so edits
  // only need to announce new or moved faces) and of `others` (fixed during the remesh). clearance in m.
  WorldGuard(const Mesh& mesh, const std::vector<const Mesh*>& others, double clearance);

  // Face f of the edited mesh is new or has moved: index it where it is now.
  void update_face(int f);
  // Every face around node n has moved.
  void update_node(int n);

  // Smallest distance (m) from the triangles to the faces they may not approach, capped at the clearance:
  // faces of the other meshes, and faces of the edited mesh that share no node with the triangle and are not
  // listed in `replaced` (the faces the edit removes).
  double separation(const std::vector<GuardTriangle>& triangles, const std::vector<int>& replaced) const;

  // True if no face the triangles may not approach (as for separation) meets one of the tetrahedra.
  bool sweep_is_clear(const std::vector<GuardSweep>& sweeps, const std::vector<int>& replaced) const;

  // True if one of the triangles folds through a face it touches at a single node: a face of the edited mesh
  // (not in `replaced`, sorted) or another of the triangles, sharing exactly one corner node with it, that it
  // meets anywhere else. WHY: separation and sweep_is_clear skip the faces a triangle touches, and a node
  // moved across its own fan (the reprojection after an edge split next to a crack tip, 2 mm through a 3 mm
  // fan) leaves two faces crossing that count as adjacent; the next edit that splits one of them makes the
  // crossing visible to collision handling, which cannot undo it (docs/repro/glass-plate-shards-coincident-lips.json:
  // one such move, 146 crossing pairs after the local remesh refined around it).
  bool folds_through_neighbours(const std::vector<GuardTriangle>& triangles, const std::vector<int>& replaced) const;

  // True if an edit replacing the triangles `before` by `after` through `sweeps` keeps the surface clear: it
  // sweeps through nothing, and `after` keeps the clearance or comes no closer to anything than `before` was.
  bool allows(const std::vector<GuardTriangle>& before, const std::vector<GuardTriangle>& after,
              const std::vector<GuardSweep>& sweeps, const std::vector<int>& replaced) const;

  // A node's move: false if `after` folds through a neighbour (folds_through_neighbours with `fold_replaced`,
  // unless nullptr), else allows(before, after, sweeps, replaced); the same answers from one walk of the grid.
  bool allows_move(const std::vector<GuardTriangle>& before, const std::vector<GuardTriangle>& after,
                   const std::vector<GuardSweep>& sweeps, const std::vector<int>* fold_replaced,
                   const std::vector<int>& replaced) const;

  // The world triangles of the live faces around node n of the edited mesh, where they are now.
  std::vector<GuardTriangle> fan(int n) const;
  // The tetrahedra the faces around node n swept when n moved from `from` to where it is now.
  std::vector<GuardSweep> fan_sweep(int n, const Vec3& from) const;

  double clearance() const { return clearance_; }

 private:
  using Key = std::uint64_t;
  Key key(int i, int j, int k) const;
  std::array<int, 3> cell_of(const Vec3& p) const;
  void insert(int mesh, int face);
  // (Re)builds the grid from scratch: cell size from the edited mesh's median edge, every live face where it is.
  void build();
  GuardTriangle triangle(int mesh, int face) const;
  // Entries of the cells the box touches, plus the large faces, that meet the box where they are now (live
  // faces only); sorted, unique.
  std::vector<std::int64_t> candidates(const Eigen::AlignedBox3d& box) const;
  // separation and sweep_is_clear, testing only the candidates `found` (any superset of those whose boxes meet
  // the shapes' `boxes`, one per shape, finite).
  double separation_among(const std::vector<GuardTriangle>& triangles, const std::vector<Eigen::AlignedBox3d>& boxes,
                          const std::vector<int>& replaced, const std::vector<std::int64_t>& found) const;
  // folds_through_neighbours against the candidates `found` (nullptr: the triangles against each other only).
  bool folds_among(const std::vector<GuardTriangle>& triangles, const std::vector<int>& replaced,
                   const std::vector<std::int64_t>* found) const;
  bool sweep_is_clear_among(const std::vector<GuardSweep>& sweeps, const std::vector<Eigen::AlignedBox3d>& boxes,
                            const std::vector<int>& replaced, const std::vector<std::int64_t>& found) const;
  // Whether the candidate face takes part: it is another mesh's, or a live face of the edited mesh that the
  // edit does not replace.
  bool counts(std::int64_t entry, const std::vector<int>& replaced) const;
  // Whether the candidate face has one of these nodes (it touches the shape, and is not compared with it).
  bool touches(std::int64_t entry, const int* nodes, int count) const;

  const Mesh& mesh_;
  std::vector<const Mesh*> meshes_;  // [0] is the edited mesh
  double clearance_;
  double cell_ = 1;                  // m
  // Grid cell -> entries (mesh << 32 | face). A face whose box covers many cells is kept in large_ instead.
  std::unordered_map<Key, std::vector<std::int64_t>> cells_;
  std::vector<std::int64_t> large_;
  // Faces indexed by the last build, and faces indexed since (new or moved faces are added again, never
  // removed). WHY a rebuild once the latter clearly outnumber the former: the cell size follows the mesh the
  // guard was built on, and a remesh that refines 2 faces to 1000 (ARCSim's square.json, first frame) left every
  // face in one cell, and every query sorted thousands of entries.
  long built_faces_ = 0, added_faces_ = 0;
  // Per mesh and face: the last query (candidates) that looked at it. Queries are therefore not thread-safe.
  mutable std::vector<std::vector<std::uint32_t>> seen_;
  mutable std::uint32_t query_ = 0;
};

}  // namespace arcsim
