// The `arcsim` command line: dispatch to the command table, --help / help <command> / --version, and the mapping
// of errors to exit codes (0 success, 2 bad input, 3 numerical failure, 1 anything unexpected). Every error is
// printed as one line "arcsim: ..." on stderr.
#pragma once

#include <string>
#include <vector>

#include "app/console.hpp"

namespace arcsim {

// Runs the program with the arguments after the program name; returns the exit code. Never throws.
int run_command_line(const std::vector<std::string>& args, const Console& console);

// The text of `arcsim --help`.
std::string general_help();

}  // namespace arcsim
