#include <algorithm>

#include "app/command.hpp"
#include "app/inspect_command.hpp"
#include "app/replay_command.hpp"
#include "app/resume_command.hpp"
#include "app/simulate_command.hpp"

namespace arcsim {

const std::vector<Command>& command_table() {
  // Constant data, built once. To add a command, write its run function and help text in its own file and add a
  // row here.
  static const std::vector<Command> table = {
      {"simulate", "run a scene offline and write its frames to a folder", kSimulateHelp, run_simulate_command},
      {"resume", "continue a run from a saved frame of its output folder", kResumeHelp, run_resume_command},
      {"replay", "render the saved frames of a run to PNG images, off-screen", kReplayHelp, run_replay_command},
      {"inspect", "check and measure the saved frames of a run: valid mesh, intersections, pieces", kInspectHelp,
       run_inspect_command},
  };
  return table;
}

const Command* find_command(const std::string& name) {
  const std::vector<Command>& table = command_table();
  const auto it = std::find_if(table.begin(), table.end(), [&](const Command& c) { return name == c.name; });
  return it == table.end() ? nullptr : &*it;
}

}  // namespace arcsim
