#include "app/cli.hpp"

#include <algorithm>
#include <exception>
#include <ostream>

#include "app/command.hpp"
#include "app/version.hpp"
#include "math/errors.hpp"

namespace arcsim {

namespace {

constexpr int kExitSuccess = 0;
constexpr int kExitInternal = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitNumerical = 3;
constexpr int kExitEnvironment = 4;

void print_error(const Console& console, const std::string& message) {
  console.err << kProgramName << ": " << one_line(message) << '\n' << std::flush;
}

// `arcsim help [<command>]`.
int run_help(const std::vector<std::string>& args, const Console& console) {
  if (args.empty()) {
    console.out << general_help();
    return kExitSuccess;
  }
  if (args.size() > 1) throw InputError("help: expected one command name, got " + std::to_string(args.size()));
  const Command* command = find_command(args[0]);
  if (!command) throw InputError("help: unknown command '" + args[0] + "' (try 'arcsim --help')");
  console.out << command->help;
  return kExitSuccess;
}

int dispatch(const std::vector<std::string>& args, const Console& console) {
  if (args.empty()) throw InputError("no command given (try 'arcsim --help')");
  const std::string& first = args[0];
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (first == "--help" || first == "-h") {
    console.out << general_help();
    return kExitSuccess;
  }
  if (first == "--version") {
    console.out << kProgramName << " " << kVersion << "\n";
    return kExitSuccess;
  }
  if (first == "help") return run_help(rest, console);
  const Command* command = find_command(first);
  if (!command) {
    if (!first.empty() && first[0] == '-') throw InputError("unknown option '" + first + "' (try 'arcsim --help')");
    throw InputError("unknown command '" + first + "' (try 'arcsim --help')");
  }
  return command->run(rest, console);
}

}  // namespace

std::string general_help() {
  std::string text = std::string(kProgramName) + " " + kVersion +
                     ": simulation of thin sheets that bend, crease, tear and crack (after ARCSim and Pfaff et al.\n"
                     "2014, \"Adaptive Tearing and Cracking of Thin Sheets\").\n"
                     "\n"
                     "Usage: arcsim <command> [arguments] [options]\n"
                     "\n"
                     "Commands:\n";
  for (const Command& c : command_table()) {
    std::string name = c.name;
    name.resize(std::max<size_t>(name.size() + 2, 12), ' ');
    text += "  " + name + c.summary + "\n";
  }
  text +=
      "  help <cmd>  show the arguments and options of a command\n"
      "\n"
      "Options:\n"
      "  --help, -h  show this help\n"
      "  --version   print the version\n"
      "\n"
      "Example: arcsim simulate conf/demo.json out/demo\n"
      "Exit codes: 0 success, 2 bad input, 3 numerical failure, 4 missing system library, 1 internal error.\n";
  return text;
}

int run_command_line(const std::vector<std::string>& args, const Console& console) {
  try {
    return dispatch(args, console);
  } catch (const InputError& e) {
    print_error(console, e.what());
    return kExitBadInput;
  } catch (const NumericalError& e) {
    print_error(console, std::string("numerical failure: ") + e.what());
    return kExitNumerical;
  } catch (const EnvironmentError& e) {
    print_error(console, e.what());
    return kExitEnvironment;
  } catch (const std::exception& e) {
    print_error(console, std::string("internal error: ") + e.what());
    return kExitInternal;
  } catch (...) {
    print_error(console, "internal error: unknown exception");
    return kExitInternal;
  }
}

}  // namespace arcsim
