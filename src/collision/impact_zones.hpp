// Collision response after the position update (Bridson et al. 2002, Harmon et al. 2008, as in ARCSim):
// continuous collision detection over x0 -> x1 finds impacts; impacts sharing movable nodes are grouped into
// impact zones, and each zone is projected so that every impact's gap is at least the projection thickness
// (zone_solver.hpp). Detection and projection repeat, zones growing and keeping their constraints, until the
// motion is collision free. A zone that does not resolve within the iteration limit falls back to rigid motion
// of its nodes with their mean displacement; if even that collides, to moving with the obstacles it touches (when
// they moved: held still, it would be run through), and last to staying at x0; each with a warning on stderr:
// never to silent interpenetration.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "collision/candidates.hpp"
#include "collision/ccd.hpp"
#include "collision/contact_geometry.hpp"
#include "collision/zone_solver.hpp"

namespace arcsim {

struct ImpactZoneParams {
  double thickness = 1e-4;         // projection thickness: required gap after the projection (m)
  double contact_distance = 1e-6;  // CCD contact distance (m)
  int max_iterations = 30;         // detect/project rounds before the rigid fallback
  int max_fallback_iterations = 20;
  bool floor = false;              // floor proxy: nodes may not cross the plane y = floor_height downwards
  double floor_height = 0;         // m
  ZoneMethod method = ZoneMethod::kAutomatic;
  int step = 0;                    // for messages
  // Crack lips that start stacked (overlapped across their edges, apart out of the surface) keep the side they
  // start on, instead of the facing lips' normal across their edges (impact_zones.cpp, near_parallel_edge_normal).
  // The simulation sets it at the adaptive step's finest substep only (docs/stability.md, 2026-12-06 (h2)).
  bool stacked_lips_keep_start_side = false;
  // Work budget of one resolve_impacts, in work units (zone_evaluation_work per evaluation of a zone's
  // projection, kCcdPairWork per candidate pair tested): once spent, the response stops unresolved with
  // ImpactZoneStats::out_of_budget. Counted, not timed, so that where it stops is the same on every machine and
  // with any number of threads.
  double work_budget = kInfinity;
};

// Work units of one candidate pair's continuous collision test (about its cost against one constraint term of a
// zone evaluation).
constexpr double kCcdPairWork = 100;

struct ImpactRecord {
  int kind = 0;                    // PairKind, or kFloorImpact
  int a = 0, b = 0;                // the primitives (for PairKind) / the node (floor)
  std::array<int, 4> nodes{kNone, kNone, kNone, kNone};  // global node indices
  std::array<double, 4> weights{0, 0, 0, 0};
  Vec3 normal = Vec3::UnitY();
  double offset = 0;               // constant part of the gap (floor: -floor_height) (m)
  double time = 0;                 // normalised time of contact
};
constexpr int kFloorImpact = 3;

// Every impact of the motion x0 -> x1 of the geometry (at most one per primitive pair: the first), in a
// deterministic order. With `moved` (a flag per node), only impacts involving a flagged node.
// With `work`, adds the detection's work units (kCcdPairWork per candidate pair).
std::vector<ImpactRecord> detect_impacts(const ContactGeometry& g, BvhCache& cache, const ImpactZoneParams& params,
                                         const std::vector<char>* moved = nullptr, double* work = nullptr);

struct ImpactZoneStats {
  int iterations = 0;        // detection rounds
  int impacts = 0;           // impacts found in the first round
  int zones = 0;             // zones at the end
  int largest_zone = 0;      // nodes
  int fallback_zones = 0;    // zones moved rigidly, carried with obstacles or held at x0
  int ill_conditioned_zones = 0;  // projections refused as ill-conditioned (those zones also count as fallback)
  bool resolved = true;      // the final motion is collision free
  double work = 0;           // work units spent (ImpactZoneParams::work_budget)
  bool out_of_budget = false;  // stopped, unresolved, when the work budget ran out (the positions are then
                               // part-way and must not be kept)
  // Nodes (geometry indices, sorted) of the zones on a fallback: their end positions are not the
  // physics' outcome, and the strain between them and their neighbours is not the material's.
  std::vector<int> fallback_nodes;
  // What went wrong, one line each ("collision: step N: ..."): fallbacks, ill-conditioned zones, unresolved.
  std::vector<std::string> warnings;
};

// Moves the movable nodes' end positions g.x1 so that the motion is collision free.
ImpactZoneStats resolve_impacts(ContactGeometry& g, BvhCache& cache, const ImpactZoneParams& params);

}  // namespace arcsim
