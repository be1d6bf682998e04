// How many OpenMP threads a run uses.
#pragma once

namespace arcsim {

// threads > 0: exactly that many (the user asked). threads == 0: OpenMP's dynamic teams until a
// ThreadGovernor takes over (simulate and resume hand it the frames). WHY not fixed teams of every core: a
// parallel region ends in a barrier, and when another process holds a core the barrier waits for a scheduler
// time slice; measured on a loaded 2-core machine, ARCSim's sphere.json took 45 s with two fixed threads and
// 17 s with one. Results do not depend on the thread count (every parallel reduction is ordered), so this only
// changes speed.
void configure_threads(int threads);

// CPU time counters at one instant: the busy time of the CPUs this process may run on (/proc/stat's per-CPU
// lines, for the CPUs of its affinity mask: user, nice, system, irq, softirq and a hypervisor's steal), this
// process's own CPU time (user + system) and a monotonic wall clock, all in seconds.
struct CpuSample {
  bool valid = false;  // /proc/stat could be read
  double machine_busy = 0, own = 0, wall = 0;
};
CpuSample sample_cpu();

// The team size for the coming work: the cores that other processes left idle between two samples (busy time
// of the machine not spent by this process, per second of wall), rounded, between 1 and `cores`.
int cores_left_free(const CpuSample& before, const CpuSample& after, int cores);

// Sizes the teams of a run whose thread count the user left open, frame by frame. OpenMP's dynamic teams follow
// the 15-minute load average less 0.1 cores (libgomp), which counts this very process: on a 2-core machine a
// run of a few minutes, or one started after other work, drops to one thread and stays there with the other
// core idle (flag.json's first second took 17.6 s instead of 14.6-15.3 s). The governor instead measures what other processes used
// during the last frames (at least kMinInterval of wall) and sizes the fixed team from that.
class ThreadGovernor {
 public:
  // threads: the --threads option (> 0: fixed, the governor does nothing).
  explicit ThreadGovernor(int threads);
  // Call after each frame.
  void frame_done();
  int team() const { return team_; }

  static constexpr double kMinInterval = 0.25;  // s of wall between two decisions (/proc/stat ticks at 10 ms)

 private:
  bool active_ = false;
  int cores_ = 1, team_ = 1;
  CpuSample last_;
};

}  // namespace arcsim
