// Command-line argument parsing shared by the commands: options may stand anywhere after the command name, as
// `--name value` or `--name=value`; `--` ends the options. Errors throw InputError (exit code 2) with one line
// "<command>: <problem>".
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace arcsim {

struct OptionSpec {
  const char* name;  // with the dashes, e.g. "--end-time"
  bool takes_value;
};

struct ParsedArguments {
  std::vector<std::string> positionals;
  std::vector<std::pair<std::string, std::string>> options;  // in command-line order; "" for flags
  bool help = false;                                         // --help or -h was given
};

// Splits `args` into positionals and the options of `specs`. `--help` / `-h` are always accepted.
ParsedArguments parse_arguments(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs,
                                const std::string& command);

// A finite number >= `min` (e.g. a time in seconds), or InputError naming the option.
double number_argument(const std::string& command, const std::string& option, const std::string& text,
                       double min);

// An integer in [min, max], or InputError naming the option.
int integer_argument(const std::string& command, const std::string& option, const std::string& text, int min,
                     int max);

// A frame range "A:B", "A:", ":B" or "N" (frames >= 0) into first/last (limits left as they are where the text
// omits them), or InputError naming --frames.
void frame_range_argument(const std::string& command, const std::string& text, int& first, int& last);

}  // namespace arcsim
