// Broad phase: the primitive pairs (vertex-face, edge-edge, and optionally in-plane boundary vertex-edge)
// whose bounding boxes overlap, from per-mesh BVHs over faces. Self pairs of each deformable mesh, pairs
// between deformable meshes, and deformable-immovable pairs are found; immovable meshes are never tested
// against each other. Pairs sharing a node are dropped.
#pragma once

#include <array>
#include <cstdint>
#include <tuple>
#include <vector>

#include "collision/bvh.hpp"
#include "collision/contact_geometry.hpp"

namespace arcsim {

enum class PairKind : uint8_t { kVertexFace, kEdgeEdge, kVertexEdge };

struct PrimitivePair {
  PairKind kind;
  int a, b;  // VF: node, face; EE: edge, edge; VE: node, edge (global indices)
  bool operator<(const PrimitivePair& o) const { return std::tie(kind, a, b) < std::tie(o.kind, o.a, o.b); }
  bool operator==(const PrimitivePair& o) const { return kind == o.kind && a == o.a && b == o.b; }
};

// The global node indices and the four positions of a VF or EE pair, in the order of the narrow phase
// (vertex, face corners) or (edge a nodes, edge b nodes); VE uses (vertex, edge nodes, kNone).
std::array<int, 4> pair_nodes(const ContactGeometry& g, const PrimitivePair& p);

// The candidates that pass every test of topology alone (pairs sharing a node dropped, vertex-edge pairs only
// of boundary primitives), listed from the face pairs whose boxes overlap once every node's box is grown by a
// slack, and kept across searches (a Verlet list) while every node's box stays inside its grown box: any pair
// whose boxes overlap then is on the list, so a search only filters the list by boxes and moved flags. WHY:
// a sheet's nodes move little from one step to the next, and on small sheets finding the face pairs again
// (a traversal that reports every neighbouring face) cost more than all the tests they lead to.
// The parts of a ContactGeometry a candidate list depends on besides positions: kept with the list, and compared
// with the geometry of each later search (all of it, bit for bit: the meshes' topology hashes could collide).
struct CandidateConnectivity {
  std::vector<ContactGeometry::Range> meshes;
  std::vector<std::array<int, 3>> faces;
  std::vector<std::array<int, 2>> edges, edge_faces;
  std::vector<int> owned_node_begin, owned_nodes, owned_edge_begin, owned_edges;

  void capture(const ContactGeometry& g);
  bool matches(const ContactGeometry& g) const;
};

struct CandidateList {
  bool ready = false;
  // What the list was made for: the geometry's connectivity and the search's options.
  CandidateConnectivity connectivity;
  double margin = 0;
  bool vertex_edge = false;
  std::vector<Aabb> grown;  // per node: the box its search box must stay inside
  std::array<std::vector<PrimitivePair>, 3> by_kind;  // the candidates, by PairKind, in no particular order
  int served = 0;   // searches the list has served
  int backoff = 1;  // searches to go without a list after the next list that does not pay
  int skip = 0;     // searches left to go without a list
};

// One BVH per mesh of the geometry, kept across steps: rebuilt when the mesh's topology changes, refitted
// otherwise. Also the candidate lists of the swept and the static searches.
class BvhCache {
 public:
  void update(const ContactGeometry& g, const std::vector<Aabb>& face_boxes);
  const Bvh& tree(int mesh) const { return trees_[mesh]; }
  int builds() const { return builds_; }
  // How many times a candidate list was made (each search that could not reuse one).
  int list_builds() const { return list_builds_; }
  CandidateList& list(bool swept) { return lists_[swept ? 1 : 0]; }
  void count_list_build() { ++list_builds_; }

 private:
  std::vector<Bvh> trees_;
  std::vector<uint64_t> topology_;
  std::array<CandidateList, 2> lists_;
  int builds_ = 0;
  int list_builds_ = 0;
};

struct CandidateOptions {
  double margin = 0;         // pairs closer than this (m) are found (boxes grow by margin / 2)
  bool swept = false;        // boxes cover the motion x0 -> x1 (else the positions x0 only)
  bool vertex_edge = false;  // also boundary vertex vs boundary edge of deformable meshes
  // Optional flag per node: only pairs with at least one flagged node are wanted (e.g. the nodes an impact
  // zone moved since the last search); the traversal then skips subtrees without flagged nodes.
  const std::vector<char>* moved = nullptr;
};

// Candidate pairs, sorted (deterministic whatever the thread count).
std::vector<PrimitivePair> find_candidates(const ContactGeometry& g, BvhCache& cache,
                                           const CandidateOptions& options);

}  // namespace arcsim
