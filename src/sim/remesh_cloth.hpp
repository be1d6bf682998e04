// Remeshing of a simulation cloth: options from the scene, the per-cloth entry point used at frame ends and by
// fracture (whole mesh or a face subset), ARCSim's fixed high-resolution refinement, and mesh-size statistics
// for the per-frame log.
#pragma once

#include <vector>

#include "edit/edit_session.hpp"
#include "mesh/mesh_stats.hpp"
#include "remesh/remesh.hpp"
#include "scene/scene.hpp"
#include "sim/simulation.hpp"

namespace arcsim {

// Options from the scene: magic rib_stiffening, combine_tensors and edge_flip_threshold, gravity for the
// reprojection, the projection thickness as the world-space guard's clearance (the caller lists the obstacles). The per-cloth fields (remeshing parameters, reference) are filled in by remesh().
// The obstacle-proximity sizing term stays off: the collision module provides no nearest obstacle planes yet.
RemeshOptions remesh_options(const Scene& scene);

// Remeshes one cloth (see remesh_mesh) with its own remeshing parameters and reference surface (those fields of
// `options` are overridden). The caller follows up with Simulation::topology_changed(c, edited(stats)) (masses,
// element cache, compaction, handles).
RemeshStats remesh(Cloth& cloth, const std::vector<int>* face_subset, const RemeshOptions& options);

// Whether the pass changed the topology (a split, flip or collapse succeeded).
bool edited(const RemeshStats& stats);

// ARCSim's `fixed_high_res_mesh`: one isotropic remesh of the whole cloth to its size_min (nothing else enters
// the sizing). Does nothing if size_min is not finite and positive.
RemeshStats refine_to_size_min(Cloth& cloth, const RemeshOptions& options);

// Maps the node indices of the handles of cloth `cloth` through a compaction. Handle nodes are preserved by
// remeshing, so none of them disappears; a handle node that did (fracture may remove nothing either) is
// dropped with its anchor.
void remap_handles(std::vector<Handle>& handles, int cloth, const Mesh::Compaction& compaction);

// Keeps the line a handle holds whole through edge splits: the node a split adds between two nodes of one
// line-holding handle (Handle::holds_line: chosen by label) joins that handle, preserved, with its anchor
// interpolated as its position is. Registered as an observer of every remeshing pass (frame ends, fracture's
// zones, the fixed high-resolution refinement).
// WHY: a handle holds the nodes it was given; a split of a clamped border left the new middle node free, each
// held node then pulled on the sheet like a point load, and a notched sheet pulled apart by clamps along two
// borders tore along those borders before it tore at its notch.
class HandleLineKeeper : public EditObserver {
 public:
  HandleLineKeeper(std::vector<Handle>& handles, int cloth, Mesh& mesh)
      : handles_(handles), cloth_(cloth), mesh_(mesh) {}
  void stage_done(EditKind kind, EditStage stage, const EditResult& result) override;

 private:
  std::vector<Handle>& handles_;
  int cloth_;
  Mesh& mesh_;
};

}  // namespace arcsim
