// `arcsim simulate <scene.json> [<out-dir>] [options]`: runs a scene offline, writing every frame to out-dir.
#pragma once

#include <string>
#include <vector>

#include "app/console.hpp"
#include "math/types.hpp"

namespace arcsim {

extern const char kSimulateHelp[];

struct SimulateOptions {
  std::string scene;
  std::string out_dir;           // "" = dry run: simulate, write nothing
  double end_time = kInfinity;   // s; infinity keeps the scene's end
  double end_frame = kInfinity;  // frames; infinity keeps the scene's end
  int threads = 0;               // OpenMP threads; 0 = follow the free cores (app/threads.hpp)
  bool quiet = false;            // no warnings, no progress
  bool json_progress = false;    // --progress json: one JSON object per frame on stdout
  bool help = false;
};

// Parses the arguments after `simulate`. Throws InputError (exit 2) for bad ones.
SimulateOptions parse_simulate_options(const std::vector<std::string>& args);

// Runs the simulation; returns the exit code (0). Throws InputError / NumericalError as described in command.hpp;
// after a NumericalError every frame written before the failure stays in the output folder.
int run_simulate(const SimulateOptions& options, const Console& console);

class OutputFolder;
class Simulation;

// The frame loop shared by simulate and resume: advances `sim` to its end, writing every saved frame (and its
// state file) to `out` (may be null), logging and reporting progress. Keeps frames written before a
// NumericalError and rethrows it with where they are.
void run_frames(Simulation& sim, OutputFolder* out, const SimulateOptions& options, const Console& console);

// Counts and module wall times of the current frame, for log.jsonl and progress.
struct FrameReport;
void describe_frame(const Simulation& sim, FrameReport& report);

// The command-table entry: parse, then print help or run.
int run_simulate_command(const std::vector<std::string>& args, const Console& console);

}  // namespace arcsim
