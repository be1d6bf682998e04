#include "app/resume_command.hpp"

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <memory>
#include <system_error>

#include "app/arguments.hpp"
#include "app/frame_report.hpp"
#include "app/output.hpp"
#include "app/output_files.hpp"
#include "app/simulate_command.hpp"
#include "app/threads.hpp"
#include "io/scene_parser.hpp"
#include "io/state.hpp"
#include "math/errors.hpp"
#include "sim/simulation.hpp"

namespace arcsim {

namespace fs = std::filesystem;

const char kResumeHelp[] =
    "Usage: arcsim resume <out-dir> [<frame>] [options]\n"
    "\n"
    "Continues the run whose output is in <out-dir>, using the folder's own copy of the scene (conf.json), from\n"
    "the saved state of <frame> (NNNNN.state), or from the last complete saved frame when <frame> is omitted\n"
    "(a run killed in the middle of a frame resumes from the frame before; after a crash of the machine, newer\n"
    "states that do not load are skipped with a warning). The continuation is bit-identical\n"
    "to an uninterrupted run. Frames after the resume point are overwritten as the run proceeds, and log.jsonl\n"
    "keeps its lines up to the resume point.\n"
    "\n"
    "Options: --end-time T, --end-frame N, --threads N, --quiet, --progress json (as for simulate).\n"
    "\n"
    "Exit codes: 0 success, 2 bad input (missing folder or frame, corrupt or foreign state file), 3 numerical\n"
    "failure, 1 internal error.\n";

namespace {

const char kCommand[] = "resume";

}  // namespace

std::vector<int> saved_state_frames(const std::string& out_dir) {
  std::vector<int> frames;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out_dir, ec)) {
    const int frame = state_file_frame(entry.path().filename().string());
    if (frame >= 0) frames.push_back(frame);
  }
  std::sort(frames.begin(), frames.end());
  return frames;
}

int last_saved_state_frame(const std::string& out_dir) {
  const std::vector<int> frames = saved_state_frames(out_dir);
  return frames.empty() ? -1 : frames.back();
}

int run_resume_command(const std::vector<std::string>& args, const Console& console) {
  const std::vector<OptionSpec> specs = {
      {"--end-time", true}, {"--end-frame", true}, {"--threads", true}, {"--quiet", false}, {"--progress", true}};
  const ParsedArguments parsed = parse_arguments(args, specs, kCommand);
  if (parsed.help) {
    console.out << kResumeHelp;
    return 0;
  }
  SimulateOptions options;
  for (const auto& [name, value] : parsed.options) {
    if (name == "--end-time") options.end_time = number_argument(kCommand, name, value, 0);
    else if (name == "--end-frame") options.end_frame = integer_argument(kCommand, name, value, 0, 1000000000);
    else if (name == "--threads") options.threads = integer_argument(kCommand, name, value, 1, 1024);
    else if (name == "--quiet") options.quiet = true;
    else if (name == "--progress") {
      if (value != "json")
        throw InputError(std::string(kCommand) + ": --progress: the only style is 'json', got '" + value + "'");
      options.json_progress = true;
    }
  }
  const std::vector<std::string>& pos = parsed.positionals;
  if (pos.empty() || pos.size() > 2)
    throw InputError(std::string(kCommand) + ": usage: arcsim resume <out-dir> [<frame>] [options]");
  const std::string dir = pos[0];
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir + ": no such output folder");
  configure_threads(options.threads);

  Scene scene = load_scene((fs::path(dir) / kSceneCopyName).string());
  if (!options.quiet)
    for (const std::string& w : scene.warnings) console.warn(w);
  // The saved state replaces every mesh the constructor builds, so the start-up remesh would be thrown away.
  scene.magic.remesh_at_start = false;
  std::unique_ptr<Simulation> sim;
  int frame = -1;
  if (pos.size() == 2) {
    frame = integer_argument(kCommand, "<frame>", pos[1], 0, 1000000000);
    const std::string state_path = (fs::path(dir) / state_file_name(frame)).string();
    if (!fs::exists(state_path, ec))
      throw InputError(dir + ": frame " + std::to_string(frame) + " has no saved state (" + state_file_name(frame) +
                       ")");
    sim = std::make_unique<Simulation>(scene);
    load_state(*sim, state_path);
  } else {
    // The newest state that loads: states are not flushed to the disk one by one, so after a crash of the
    // machine the newest ones may be empty or truncated (they fail their size or checksum check).
    const std::vector<int> frames = saved_state_frames(dir);
    if (frames.empty()) throw InputError(dir + ": no saved state (NNNNN.state) to resume from");
    for (auto it = frames.rbegin(); it != frames.rend() && !sim; ++it) {
      auto candidate = std::make_unique<Simulation>(scene);
      try {
        load_state(*candidate, (fs::path(dir) / state_file_name(*it)).string());
      } catch (const InputError& e) {
        if (std::next(it) == frames.rend()) throw;  // no older state to fall back to: the newest error stands
        console.warn(std::string(e.what()) + "; resuming from an earlier frame");
        continue;
      }
      sim = std::move(candidate);
      frame = *it;
    }
  }
  if (options.end_time < kInfinity) sim->set_end_time(options.end_time);
  if (options.end_frame < kInfinity) sim->set_end_frame(options.end_frame);

  // States of later frames belong to the abandoned continuation: remove them so that "the last saved state"
  // always means this run's.
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const int f = state_file_frame(entry.path().filename().string());
    if (f > frame) fs::remove(entry.path(), ec);
  }
  OutputFolder out(dir, frame);
  run_frames(*sim, &out, options, console);
  return 0;
}

}  // namespace arcsim
