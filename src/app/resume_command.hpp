// `arcsim resume <out-dir> [<frame>] [options]`: continues a run from a saved frame of its output folder.
#pragma once

#include <string>
#include <vector>

#include "app/console.hpp"

namespace arcsim {

extern const char kResumeHelp[];

int run_resume_command(const std::vector<std::string>& args, const Console& console);

// The frames of the saved states in `out_dir` (NNNNN.state), ascending.
std::vector<int> saved_state_frames(const std::string& out_dir);

// The frame of the last complete saved state in `out_dir` (highest NNNNN.state), or -1 if there is none.
int last_saved_state_frame(const std::string& out_dir);

}  // namespace arcsim
