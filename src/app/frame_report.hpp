// What the simulate command reports about each frame: a line of out/log.jsonl and of `--progress json`.
#pragma once

#include <string>
#include <vector>

#include "collision/collision_step.hpp"  // ImpactZoneTotals
#include "fracture/fracture_step.hpp"      // FractureStats

namespace arcsim {

// Wall-clock seconds spent on one frame, by module (Simulation::times) plus writing the frame files.
struct FrameWallTimes {
  double physics = 0, collision = 0, remeshing = 0, plasticity = 0, fracture = 0, output = 0;
  double total = 0;  // the whole frame: stepping and output
};

// Mesh size of one cloth at the end of a frame (sim/remesh_cloth.hpp's mesh_size_stats).
struct ClothMeshReport {
  long long faces = 0;
  double edge_min = 0, edge_median = 0, edge_max = 0;  // world edge lengths (m)
  bool remeshed = false;  // the frame ended with a remeshing pass: the counts below are its edits
  int splits = 0, flips = 0, collapses = 0;
  int guarded = 0;        // edits and moves the world-space guard refused (remesh/world_guard.hpp)
};

struct FrameReport {
  int frame = 0;
  double time = 0;        // simulated time at the end of the frame (s)
  int steps = 0;          // time steps taken in this frame
  long long nodes = 0;    // over all cloths
  long long faces = 0;
  bool saved = false;     // frame files were written for it
  FrameWallTimes wall;
  std::vector<ClothMeshReport> meshes;  // per cloth, in scene order
  std::vector<double> plastic_work;  // J per cloth over the frame's steps; empty when plasticity is off
  bool has_impact_zones = false;     // the collision module ran: impact_zones below is meaningful
  ImpactZoneTotals impact_zones;     // summed over the frame's steps
  bool has_fracture = false;         // the fracture module ran in this frame: fracture below is meaningful
  FractureStats fracture;            // summed over the frame's steps and cloths
  // The implicit step's linear solves over the frame's steps and cloths (CholeskySolver::solve_system).
  int solves = 0, factorizations = 0, solver_iterations = 0;
  std::vector<double> residuals;     // per solve, in order: |A dv - b| / |b|
  bool has_time_step = false;        // adaptive time stepping is on: the fields below are meaningful
  int substeps = 0;                  // dynamics substeps taken in this frame
  int retries = 0;                   // failed attempts redone with a smaller step
  int held_steps = 0;                // steps taken with a persistent collision fallback held
  int substep_level = 0;             // the finest level used (substeps per step = 2^level)
  double smallest_step = 0;          // s
  std::string retry_cause;           // the last failure's cause ("" if none)
};

// {"frame":..,"time":..,"steps":..,"nodes":..,"faces":..,"saved":..,"wall":{"physics":..,...,"total":..}}, then
// "plastic_work":{"total":..,"cloth0":..,...} (J) when plastic_work is not empty, then
// "meshes":{"cloth0":{"faces":..,"edge_min":..,"edge_median":..,"edge_max":..[,"splits":..,"flips":..,
// "collapses":..,"guarded":..]},...} (m) when meshes is not empty (the edit counts when remeshed),
// then "impact_zones":{"steps":..,"impacts":..,"zones":..,"iterations":..,"largest_zone":..,"fallback_zones":..,
// "ill_conditioned_zones":..,"unresolved_steps":..} when has_impact_zones, then "fracture":{"cracks":..,
// "refused":..,"substeps":..,"candidates":..,"largest_zone":..,"remesh_edits":..,"max_ratio":..,"seconds":..}
// when has_fracture (max_ratio: the largest separation strength / toughness seen at a step's first evaluation),
// then "time_step":{"substeps":..,"retries":..,"level":..,"smallest":..[,"held":..][,"cause":".."]} when
// has_time_step (held when held_steps > 0), then
// "solver":{"solves":..,"factorizations":..,"iterations":..,"max_residual":..,"residuals":[..]} when solves > 0.
std::string frame_log_line(const FrameReport& report);

// {"frame":..,"total":..,"time":..,"faces":..,"nodes":..,"wall":..}; total is null when the run is unbounded,
// wall is the frame's total wall time (s).
std::string progress_json_line(const FrameReport& report, double total_frames);

}  // namespace arcsim
