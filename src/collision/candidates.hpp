// Broad phase: the primitive pairs (vertex-face, edge-edge, and optionally in-plane boundary vertex-edge)
// whose bounding boxes overlap, from per-mesh BVHs over faces. Self pairs of each deformable mesh, pairs
// between deformable meshes, and deformable-immovable pairs are found; immovable meshes are never tested
// against each other. Pairs sharing a node are dropped.
#pragma once

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

// One BVH per mesh of the geometry, kept across steps: rebuilt when the mesh's topology changes, refitted
// otherwise.
class BvhCache {
 public:
  void update(const ContactGeometry& g, const std::vector<Aabb>& face_boxes);
  const Bvh& tree(int mesh) const { return trees_[mesh]; }
  int builds() const { return builds_; }

 private:
  std::vector<Bvh> trees_;
  std::vector<uint64_t> topology_;
  int builds_ = 0;
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
