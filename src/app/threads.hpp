// How many OpenMP threads a run uses.
#pragma once

namespace arcsim {

// threads > 0: exactly that many (the user asked). threads == 0: as many as the cores the machine has free,
// decided per parallel region (OpenMP dynamic teams, which follow the load average). WHY: a parallel region
// ends in a barrier, and when another process holds a core the barrier waits for a scheduler time slice;
// measured on a loaded 2-core machine, ARCSim's sphere.json took 45 s with two fixed threads and 17 s with one.
// Results do not depend on the thread count (every parallel reduction is ordered), so this only changes speed.
void configure_threads(int threads);

}  // namespace arcsim
