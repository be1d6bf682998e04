#include "sim/remesh_cloth.hpp"

#include <algorithm>
#include <cmath>

namespace arcsim {

RemeshOptions remesh_options(const Scene& scene) {
  RemeshOptions o;
  o.sizing.rib_stiffening = scene.magic.rib_stiffening;
  o.sizing.combine_tensors = scene.magic.combine_tensors;
  o.edge_flip_threshold = scene.magic.edge_flip_threshold;
  o.reprojection.gravity = scene.gravity;
  o.reprojection.max_displacement = 0.5 * scene.magic.repulsion_thickness;
  // Edits keep the gap the impact-zone projection enforces (collision_settings in sim/simulation.cpp).
  o.world_clearance = scene.magic.projection_thickness >= 0 ? scene.magic.projection_thickness
                                                            : 0.1 * scene.magic.repulsion_thickness;
  return o;
}

RemeshStats remesh(Cloth& cloth, const std::vector<int>* face_subset, const RemeshOptions& options) {
  RemeshOptions o = options;
  o.sizing.remeshing = cloth.remeshing;
  o.reference = cloth.reference.get();
  return remesh_mesh(cloth.mesh, cloth.materials, o, face_subset);
}

bool edited(const RemeshStats& stats) { return stats.splits + stats.flips + stats.collapses > 0; }

RemeshStats refine_to_size_min(Cloth& cloth, const RemeshOptions& options) {
  const double size = cloth.remeshing.size_min;
  if (!(std::isfinite(size) && size > 0)) return {};
  RemeshOptions o = options;
  o.extras.uniform_size = size;
  return remesh(cloth, nullptr, o);
}

void remap_handles(std::vector<Handle>& handles, int cloth, const Mesh::Compaction& compaction) {
  for (Handle& h : handles) {
    if (h.cloth != cloth) continue;
    std::vector<int> nodes;
    std::vector<Vec3> anchors;
    for (size_t i = 0; i < h.nodes.size(); ++i) {
      const int n = h.nodes[i];
      const int mapped = n >= 0 && n < static_cast<int>(compaction.node.size()) ? compaction.node[n] : kNone;
      if (mapped == kNone) continue;
      nodes.push_back(mapped);
      if (i < h.anchors.size()) anchors.push_back(h.anchors[i]);
    }
    h.nodes = std::move(nodes);
    h.anchors = std::move(anchors);
  }
}

void HandleLineKeeper::stage_done(EditKind kind, EditStage stage, const EditResult& result) {
  // At kTopology the new node sits on the chord of the split edge, before any later stage moves it; marking it
  // preserved there also keeps the reprojection stage from moving it.
  if (kind != EditKind::kSplitEdge || stage != EditStage::kTopology || !result.ok) return;
  if (result.added_nodes.size() != 1 || result.removed_edges.empty()) return;
  const int added = result.added_nodes[0];
  const std::array<int, 2> ends = mesh_.edges[result.removed_edges[0]].n;
  for (Handle& h : handles_) {
    if (!h.holds_line || h.cloth != cloth_ || h.nodes.size() != h.anchors.size()) continue;
    const auto a = std::find(h.nodes.begin(), h.nodes.end(), ends[0]);
    const auto b = std::find(h.nodes.begin(), h.nodes.end(), ends[1]);
    if (a == h.nodes.end() || b == h.nodes.end()) continue;
    const Vec3 &xa = mesh_.nodes[ends[0]].x, &xb = mesh_.nodes[ends[1]].x;
    const double length2 = (xb - xa).squaredNorm();
    const double t = length2 > 0 ? std::clamp((mesh_.nodes[added].x - xa).dot(xb - xa) / length2, 0.0, 1.0) : 0.5;
    const Vec3 anchor = (1 - t) * h.anchors[a - h.nodes.begin()] + t * h.anchors[b - h.nodes.begin()];
    h.nodes.push_back(added);
    h.anchors.push_back(anchor);
    mesh_.nodes[added].preserve = true;
    return;
  }
}

}  // namespace arcsim
