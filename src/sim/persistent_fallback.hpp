#pragma once
// Adaptive time stepping's test for a collision fallback that step refinement cannot remove.
//
// A step whose collision response needs a fallback (a rigid, carried or held impact zone) is redone in ever more
// substeps. That helps when the fallback comes from the step's length (nodes travelling too far per substep for
// the zone solve). It cannot help when the fallback comes from the state the step starts in (the lips of a fresh
// crack pressed together, shards already locked into each other): then the first substep needs it at every
// length. Refining anyway doubles the cost at every level down to the smallest substep, and the run then spends
// thousands of steps growing back (paper-ornament.json's landing on a 2-core AMD guest: 1024 substeps a step,
// ~16 000 substeps and 22 minutes for one such contact). Such a step is taken as at the finest substep at once,
// where stacked crack lips keep the side they start on (Simulation::collision_step), which is what resolves
// these contacts at the smallest substep too (the ornament's landing: 66 substeps and 37 s).
#include <vector>

namespace arcsim {

class PersistentFallback {
 public:
  explicit PersistentFallback(int levels) : levels_(levels) {}
  // One failed attempt of the step: the index of the substep that failed and, per cloth, the nodes its collision
  // response had to fall back on (all empty if the failure had another cause).
  void record_failure(int failed_substep, const std::vector<std::vector<int>>& fallback_nodes);
  // Whether the last `levels` attempts in a row failed in their first substep on fallbacks sharing a node with
  // the attempt before: the fallback is in the start state, and the next attempt should be taken as the finest.
  bool persistent() const { return streak_ >= levels_; }
  int streak() const { return streak_; }

 private:
  int levels_;
  int streak_ = 0;
  std::vector<std::vector<int>> nodes_;  // sorted, per cloth: the last counted attempt's fallback nodes
};

}  // namespace arcsim
