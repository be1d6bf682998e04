// `arcsim inspect <out-dir> [options]`: checks the saved frames of a run (valid mesh, finite numbers, no
// intersecting triangles) and measures them (faces, pieces and their sizes), one JSON line per frame.
#pragma once

#include <string>
#include <vector>

#include "app/console.hpp"

namespace arcsim {

extern const char kInspectHelp[];

int run_inspect_command(const std::vector<std::string>& args, const Console& console);

}  // namespace arcsim
