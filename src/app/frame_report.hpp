// What the simulate command reports about each frame: a line of out/log.jsonl and of `--progress json`.
#pragma once

#include <string>

namespace arcsim {

// Wall-clock seconds spent on one frame, by module (Simulation::times) plus writing the frame files.
struct FrameWallTimes {
  double physics = 0, collision = 0, remeshing = 0, plasticity = 0, fracture = 0, output = 0;
  double total = 0;  // the whole frame: stepping and output
};

struct FrameReport {
  int frame = 0;
  double time = 0;        // simulated time at the end of the frame (s)
  int steps = 0;          // time steps taken in this frame
  long long nodes = 0;    // over all cloths
  long long faces = 0;
  bool saved = false;     // frame files were written for it
  FrameWallTimes wall;
};

// {"frame":..,"time":..,"steps":..,"nodes":..,"faces":..,"saved":..,"wall":{"physics":..,...,"total":..}}
std::string frame_log_line(const FrameReport& report);

// {"frame":..,"total":..,"time":..,"faces":..,"nodes":..,"wall":..}; total is null when the run is unbounded,
// wall is the frame's total wall time (s).
std::string progress_json_line(const FrameReport& report, double total_frames);

}  // namespace arcsim
