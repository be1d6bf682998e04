#include "app/threads.hpp"

#include <omp.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

namespace arcsim {

void configure_threads(int threads) {
  if (threads > 0) {
    omp_set_dynamic(0);
    omp_set_num_threads(threads);
  } else {
    omp_set_dynamic(1);
  }
}

namespace {

double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); }

// A monotonic wall clock (s).
double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

CpuSample sample_cpu() {
  CpuSample s;
  s.wall = wall_seconds();
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) == 0) s.own = seconds(usage.ru_utime) + seconds(usage.ru_stime);
  // Only the CPUs this process may run on (in a container or under taskset the others are someone else's).
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  const bool masked = sched_getaffinity(0, sizeof(allowed), &allowed) == 0;
  const long ticks = sysconf(_SC_CLK_TCK);
  std::ifstream stat("/proc/stat");
  std::string line;
  double busy = 0;
  int cpus = 0;
  while (ticks > 0 && std::getline(stat, line)) {
    // cpuN user nice system idle iowait irq softirq steal ...  (clock ticks)
    if (line.compare(0, 3, "cpu") != 0) break;  // the cpu lines come first
    if (line.size() < 4 || line[3] < '0' || line[3] > '9') continue;  // the machine's total line
    std::istringstream fields(line.substr(3));
    int cpu = -1;
    double user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
    if (!(fields >> cpu >> user >> nice >> system >> idle >> iowait >> irq >> softirq >> steal)) continue;
    if (masked && (cpu < 0 || cpu >= CPU_SETSIZE || !CPU_ISSET(cpu, &allowed))) continue;
    busy += user + nice + system + irq + softirq + steal;
    ++cpus;
  }
  if (cpus > 0) {
    s.machine_busy = busy / static_cast<double>(ticks);
    s.valid = true;
  }
  return s;
}

int cores_left_free(const CpuSample& before, const CpuSample& after, int cores) {
  const double wall = after.wall - before.wall;
  if (!before.valid || !after.valid || !(wall > 0)) return std::max(1, cores);
  const double others = std::max(0.0, (after.machine_busy - before.machine_busy) - (after.own - before.own)) / wall;
  const double free = static_cast<double>(cores) - others;
  return std::clamp(static_cast<int>(std::lround(free)), 1, std::max(1, cores));
}

ThreadGovernor::ThreadGovernor(int threads) {
  if (threads > 0) {
    team_ = threads;
    return;
  }
  last_ = sample_cpu();
  if (!last_.valid) return;  // no /proc/stat: OpenMP's dynamic teams stay in charge
  active_ = true;
  // Never more than OMP_NUM_THREADS, when the user set it (the maximum team OpenMP would have used).
  cores_ = std::max(1, std::min(omp_get_num_procs(), omp_get_max_threads()));
  team_ = cores_;
  omp_set_dynamic(0);
  omp_set_num_threads(team_);
}

void ThreadGovernor::frame_done() {
  if (!active_) return;
  // Frames can be a millisecond long: read the counters only once enough wall time has passed.
  if (wall_seconds() - last_.wall < kMinInterval) return;
  const CpuSample now = sample_cpu();
  const int team = cores_left_free(last_, now, cores_);
  last_ = now;
  if (team == team_) return;
  team_ = team;
  omp_set_num_threads(team_);
}

}  // namespace arcsim
