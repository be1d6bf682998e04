// The command table of the `arcsim` program. Each command is a name, a one-line summary for `arcsim --help`, its
// full help text and the function that runs it. New commands (replay, resume, ...) are added in commands.cpp.
#pragma once

#include <string>
#include <vector>

#include "app/console.hpp"

namespace arcsim {

struct Command {
  const char* name;
  const char* summary;  // one line, for the command list
  const char* help;     // full text for `arcsim help <name>` (usage first)
  // Runs the command with the arguments that follow its name. Returns the exit code; throws InputError (exit 2)
  // for bad arguments or input and NumericalError (exit 3) when the simulation fails.
  int (*run)(const std::vector<std::string>& args, const Console& console);
};

// Every command, in the order `arcsim --help` lists them.
const std::vector<Command>& command_table();

// The command called `name`, or nullptr.
const Command* find_command(const std::string& name);

}  // namespace arcsim
