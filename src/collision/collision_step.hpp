// The two collision phases of a time step, over all cloths and obstacles:
//  - before the velocity solve, proximity (repulsion + friction) terms for each cloth's implicit system;
//  - after the position update, the impact-zone response that makes the step's motion collision free.
// A CollisionHandler keeps the per-mesh BVHs between steps (rebuilt only when a topology changes).
#pragma once

#include <string>
#include <vector>

#include "collision/candidates.hpp"
#include "collision/impact_zones.hpp"
#include "collision/proximity.hpp"
#include "mesh/mesh.hpp"
#include "physics/cloth_physics.hpp"

namespace arcsim {

struct CollisionSettings {
  double repulsion_thickness = 1e-3;   // m
  double projection_thickness = 1e-4;  // m
  double stiffness = 1e9;              // collision_stiffness (N/m^3, times element area)
  double friction = 0.6;               // cloth-cloth
  double obstacle_friction = 0.3;      // cloth-obstacle and floor
  bool floor = false;                  // floor proxy
  double floor_height = 0;             // m
  // Repulsion thickness between material neighbours (a crack's lips; collision/proximity.hpp), m: the lip
  // gap new cracks open with.
  double neighbour_thickness = 0;
  int step = 0;                        // for messages
  bool stacked_lips_keep_start_side = false;  // ImpactZoneParams::stacked_lips_keep_start_side
  // Work units (collision/impact_zones.hpp) the impact-zone response of one step may spend.
  double work_budget = kInfinity;
};

// Impact-zone work summed over the steps since the totals were last cleared (for the run's log), and the
// proximity contacts of the same steps (what each collision phase did, for tests that check a phase ran).
struct ImpactZoneTotals {
  long long proximities = 0; // proximity (repulsion + friction) contacts found before the velocity solves
  int steps = 0;             // steps with a collision response
  long long impacts = 0;     // impacts found in the steps' first detection rounds
  long long zones = 0;       // zones at the ends of the steps
  long long iterations = 0;  // detection rounds
  int largest_zone = 0;      // nodes, largest over the steps
  int fallback_zones = 0;    // zones moved rigidly or held at their start positions
  int ill_conditioned_zones = 0;  // of those, zones whose projection was refused as ill-conditioned
  int unresolved_steps = 0;  // steps whose motion could not be made collision free
  double work = 0;           // work units (collision/impact_zones.hpp) of the collision responses
  double largest_work = 0;   // ... of the costliest step
  // The steps' warnings (ImpactZoneStats::warnings), the first kMaxWarnings of them; warnings counts them all.
  static constexpr int kMaxWarnings = 10;
  std::vector<std::string> first_warnings;
  long long warnings = 0;
  void add(const ImpactZoneStats& s);
};

class CollisionHandler {
 public:
  // Contact terms for each cloth (in the order given) at the start of the step: cloths at x moving with v,
  // obstacles at x0 moving to x in dt (s).
  std::vector<std::vector<ContactTerm>> proximity_terms(const std::vector<const Mesh*>& cloths,
                                                        const std::vector<const Mesh*>& obstacles,
                                                        const CollisionSettings& settings, double dt);

  // After the position update (every node moved x0 -> x): moves cloth nodes so that the motion is collision
  // free and adds the position change / dt to their velocities. When the work budget runs out
  // (ImpactZoneStats::out_of_budget) the nodes are left as they were; the caller fails the step.
  ImpactZoneStats resolve_collisions(const std::vector<Mesh*>& cloths, const std::vector<const Mesh*>& obstacles,
                                     const CollisionSettings& settings, double dt);

  // Per cloth (in the order given, local node indices, sorted): the nodes the last resolve_collisions moved by a
  // fallback (rigid or held impact zones; ImpactZoneStats::fallback_nodes).
  const std::vector<std::vector<int>>& fallback_nodes() const { return fallback_nodes_; }

  const BvhCache& bvh_cache() const { return cache_; }
  const ImpactZoneTotals& totals() const { return totals_; }
  void clear_totals() { totals_ = ImpactZoneTotals(); }

 private:
  ImpactZoneTotals totals_;
  std::vector<std::vector<int>> fallback_nodes_;
  BvhCache cache_;
  ContactGeometry geometry_;
};

}  // namespace arcsim
