#include "app/simulate_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <ostream>

#include "app/arguments.hpp"
#include "app/frame_report.hpp"
#include "app/output.hpp"
#include "app/progress.hpp"
#include "app/threads.hpp"
#include "io/scene_parser.hpp"
#include "math/errors.hpp"
#include "sim/remesh_cloth.hpp"
#include "sim/simulation.hpp"

namespace arcsim {

const char kSimulateHelp[] =
    "Usage: arcsim simulate <scene.json> [<out-dir>] [options]\n"
    "\n"
    "Runs the scene offline. With <out-dir>, writes into it (created if needed): conf.json and the files the\n"
    "scene references (so that <out-dir>/conf.json runs on its own), NNNNN_CC.obj for every cloth at frame 0\n"
    "and every saved frame, obstacles (obsCC.obj once if static, NNNNN_obsCC.obj per frame if moving) and\n"
    "log.jsonl (one line per frame with wall times per module). Without <out-dir> nothing is written.\n"
    "See docs/file-formats.md.\n"
    "\n"
    "Options (anywhere after the command):\n"
    "  --end-time T      stop at simulated time T seconds (overrides the scene's end)\n"
    "  --end-frame N     stop after frame N (overrides the scene's end)\n"
    "  --threads N       use exactly N threads (default: the cores left free by other processes)\n"
    "  --quiet           print no warnings and no progress (errors only)\n"
    "  --progress json   print one JSON object per frame on stdout (frame, total, time, faces, nodes, wall)\n"
    "  --help, -h        show this help\n"
    "\n"
    "Exit codes: 0 success, 2 bad input (scene, mesh, arguments), 3 numerical failure (the frames written\n"
    "before it are kept), 1 internal error.\n";

namespace {

const char kCommand[] = "simulate";

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void count_elements(const Simulation& sim, FrameReport& report) {
  report.nodes = report.faces = 0;
  report.meshes.clear();
  for (size_t i = 0; i < sim.cloths.size(); ++i) {
    const Cloth& c = sim.cloths[i];
    report.nodes += static_cast<long long>(c.mesh.nodes.size());
    report.faces += static_cast<long long>(c.mesh.faces.size());
    const MeshSizeStats s = mesh_size_stats(c.mesh);
    ClothMeshReport m;
    m.faces = s.faces;
    m.edge_min = s.edge_min, m.edge_median = s.edge_median, m.edge_max = s.edge_max;
    if (i < sim.remesh_stats.size()) {
      const RemeshStats& r = sim.remesh_stats[i];
      m.remeshed = true;
      m.splits = r.splits, m.flips = r.flips, m.collapses = r.collapses, m.guarded = r.guarded;
    }
    report.meshes.push_back(m);
  }
}

void copy_module_times(const ModuleTimes& times, FrameWallTimes& wall) {
  wall.physics = times.physics;
  wall.collision = times.collision;
  wall.remeshing = times.remeshing;
  wall.plasticity = times.plasticity;
  wall.fracture = times.fracture;
}

// The frame's collision warnings (the first few, and how many more), each on its own line.
void print_collision_warnings(const ImpactZoneTotals& totals, Progress& progress, const Console& console) {
  if (totals.warnings == 0) return;
  progress.end_line();
  for (const std::string& w : totals.first_warnings) console.warn(w);
  const long long more = totals.warnings - static_cast<long long>(totals.first_warnings.size());
  if (more > 0) console.warn("collision: " + std::to_string(more) + " more warnings in this frame (log.jsonl: "
                             "impact_zones.warnings counts them)");
}

}  // namespace

SimulateOptions parse_simulate_options(const std::vector<std::string>& args) {
  const std::vector<OptionSpec> specs = {
      {"--end-time", true}, {"--end-frame", true}, {"--threads", true}, {"--quiet", false}, {"--progress", true}};
  const ParsedArguments parsed = parse_arguments(args, specs, kCommand);
  SimulateOptions options;
  options.help = parsed.help;
  if (options.help) return options;
  for (const auto& [name, value] : parsed.options) {
    if (name == "--end-time") {
      options.end_time = number_argument(kCommand, name, value, 0);
    } else if (name == "--end-frame") {
      options.end_frame = integer_argument(kCommand, name, value, 0, 1000000000);
    } else if (name == "--threads") {
      options.threads = integer_argument(kCommand, name, value, 1, 1024);
    } else if (name == "--quiet") {
      options.quiet = true;
    } else if (name == "--progress") {
      if (value != "json")
        throw InputError(std::string(kCommand) + ": --progress: the only style is 'json', got '" + value + "'");
      options.json_progress = true;
    }
  }
  const std::vector<std::string>& pos = parsed.positionals;
  if (pos.empty())
    throw InputError(std::string(kCommand) + ": missing the scene file (usage: arcsim simulate <scene.json> "
                                             "[<out-dir>] [options])");
  if (pos.size() > 2)
    throw InputError(std::string(kCommand) + ": unexpected argument '" + pos[2] + "' (usage: arcsim simulate " +
                     "<scene.json> [<out-dir>] [options])");
  options.scene = pos[0];
  if (pos.size() == 2) {
    if (pos[1].empty()) throw InputError(std::string(kCommand) + ": the output folder name is empty");
    options.out_dir = pos[1];
  }
  return options;
}

int run_simulate(const SimulateOptions& options, const Console& console) {
  configure_threads(options.threads);

  const Scene scene = load_scene(options.scene);
  const auto warn = [&](const std::vector<std::string>& warnings) {
    if (!options.quiet)
      for (const std::string& w : warnings) console.warn(w);
  };
  warn(scene.warnings);
  Simulation sim(scene);
  if (options.end_time < kInfinity) sim.set_end_time(options.end_time);
  if (options.end_frame < kInfinity) sim.set_end_frame(options.end_frame);
  if (!std::isfinite(sim.total_frames()))
    warn({options.scene + ": the scene sets no end_time or end_frame (nor duration): the run goes on until it is "
                          "interrupted; --end-time or --end-frame set one"});

  // Frame 0: the initial state.
  std::unique_ptr<OutputFolder> out;
  FrameReport report;
  const auto start = std::chrono::steady_clock::now();
  if (!options.out_dir.empty()) {
    out = std::make_unique<OutputFolder>(options.out_dir);
    warn(out->write_scene(scene));
    out->write_static_obstacles(sim);
    out->write_frame(sim);
    report.saved = true;
  }
  describe_frame(sim, report);
  report.wall.output = report.wall.total = seconds_since(start);
  if (out) out->log(frame_log_line(report));
  run_frames(sim, out.get(), options, console);
  return 0;
}

void describe_frame(const Simulation& sim, FrameReport& report) {
  report.frame = sim.frame();
  report.time = sim.time();
  count_elements(sim, report);
  copy_module_times(sim.times, report.wall);
  if (sim.scene().enabled("plasticity")) report.plastic_work = sim.plastic_work;
  report.has_impact_zones = sim.scene().enabled("collision");
  report.impact_zones = sim.collision_totals();
  // Fracture ran in this frame if it is active now or was before passive_time switched it off in this frame.
  report.has_fracture = sim.scene().enabled("fracture") && !sim.fracture_stats.empty();
  for (const FractureStats& f : sim.fracture_stats) report.fracture += f;
  report.has_time_step = sim.scene().adaptive_step.enabled;
  report.substeps = sim.time_step_stats.substeps;
  report.retries = sim.time_step_stats.retries;
  report.held_steps = sim.time_step_stats.held_steps;
  report.substep_level = sim.time_step_stats.level;
  report.smallest_step = sim.time_step_stats.smallest;
  report.retry_cause = sim.time_step_stats.cause;
  report.solves = sim.times.solver.solves;
  report.factorizations = sim.times.solver.factorizations;
  report.solver_iterations = sim.times.solver.iterations;
  report.residuals = sim.times.solver.residuals;
}

void run_frames(Simulation& sim, OutputFolder* out, const SimulateOptions& options, const Console& console) {
  const ProgressStyle style = choose_progress_style(options.quiet, options.json_progress, console.err_is_terminal);
  Progress progress(style, console, sim.total_frames());
  const int save_every = std::max(1, sim.scene().save_every);
  int last_saved = sim.frame();
  ThreadGovernor threads(options.threads);
  try {
    while (!sim.finished()) {
      sim.times.clear();
      sim.clear_collision_totals();
      const int first_step = sim.step();
      const auto frame_start = std::chrono::steady_clock::now();
      sim.advance_frame();
      FrameReport report;
      describe_frame(sim, report);
      report.steps = sim.step() - first_step;
      const auto output_start = std::chrono::steady_clock::now();
      if (out && sim.step() % save_every == 0) {
        out->write_frame(sim);
        report.saved = true;
        last_saved = sim.frame();
      }
      report.wall.output = seconds_since(output_start);
      report.wall.total = seconds_since(frame_start);
      if (out) out->log(frame_log_line(report));
      if (!options.quiet) print_collision_warnings(report.impact_zones, progress, console);
      progress.frame_done(report);
      threads.frame_done();
    }
  } catch (const NumericalError& e) {
    progress.end_line();
    std::string kept = out ? "; frames up to " + std::to_string(last_saved) + " are kept in " + out->dir() : "";
    throw NumericalError(std::string(e.what()) + kept);
  } catch (...) {
    progress.end_line();
    throw;
  }
  progress.summary(sim.frame(), sim.time(), out ? out->dir() : std::string());
}

int run_simulate_command(const std::vector<std::string>& args, const Console& console) {
  const SimulateOptions options = parse_simulate_options(args);
  if (options.help) {
    console.out << kSimulateHelp;
    return 0;
  }
  return run_simulate(options, console);
}

}  // namespace arcsim
