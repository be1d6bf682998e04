#pragma once
// Adaptive time stepping's test for a collision fallback that step refinement cannot remove.
//
// A step whose collision response needs a fallback (a rigid, carried or held impact zone) is redone in ever more
// substeps. That helps when the fallback comes from the step's length (nodes travelling too far per substep for
// the zone solve). It cannot help when the fallback comes from the state the step starts in (the lips of a fresh
// crack pressed together, shards already locked into each other): then the first substep needs it at every
// length. Refining anyway doubles the cost at every level down to the smallest substep, and the run then spends
// thousands of steps growing back (paper-ornament.json's landing on a 2-core AMD guest: 1024 substeps a step,
// ~16 000 substeps and 22 minutes for one such contact). The same holds for a fallback that comes at one moment
// of the step at every length (lips of a fresh crack that meet lying along each other). Such a step is retaken
// at the level where the streak began, as at the finest substep, where stacked crack lips keep the side they
// start on (Simulation::collision_step); that resolves most of these contacts (the ornament's landing: 66
// substeps and 37 s). A fallback that persists there too, on the streak's nodes, is held: the step is accepted
// with it if the response ends collision free (Simulation::adaptive_dynamics_step). WHY: stopping the run was
// the only other outcome (conf/paper-window.json stopped at step 39 with a 5-node zone where two lips' border
// edges lie along each other 1 um apart, after a change of rounding elsewhere), and refining to the end only
// made the same stop slower; a few nodes held for one substep of microseconds cost far less than the run.
#include <vector>

namespace arcsim {

class PersistentFallback {
 public:
  explicit PersistentFallback(int levels) : levels_(levels) {}
  // One failed attempt of the step, made as 2^level substeps: the index of the substep that failed and, per
  // cloth, the nodes its collision response had to fall back on (all empty if the failure had another cause).
  void record_failure(int failed_substep, const std::vector<std::vector<int>>& fallback_nodes, int level);
  // Whether the last `levels` attempts in a row, each one level finer or more, failed on fallbacks sharing a
  // node with the attempt before, in a substep lying within the one that failed before: the fallback comes at
  // the same moment of the step whatever the substep's length (in the first substep: from the start state).
  bool persistent() const { return streak_ >= levels_; }
  int streak() const { return streak_; }
  // The substep level of the streak's first attempt: refining past it did not help, so the step is taken there.
  int streak_level() const { return streak_level_; }
  // Per cloth, sorted: every node the streak's attempts fell back on.
  const std::vector<std::vector<int>>& streak_nodes() const { return streak_nodes_; }

 private:
  int levels_;
  int streak_ = 0;
  int streak_level_ = 0;
  int level_ = 0, substep_ = 0;                 // the last counted attempt's level and failed substep
  std::vector<std::vector<int>> nodes_;         // sorted, per cloth: the last counted attempt's fallback nodes
  std::vector<std::vector<int>> streak_nodes_;  // sorted, per cloth: the union over the streak
};

}  // namespace arcsim
