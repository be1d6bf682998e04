// `arcsim replay <out-dir> [<png-dir>] [options]`: renders the saved frames of a run to PNG images off-screen.
#pragma once

#include <string>
#include <vector>

#include "app/console.hpp"

namespace arcsim {

extern const char kReplayHelp[];

int run_replay_command(const std::vector<std::string>& args, const Console& console);

}  // namespace arcsim
