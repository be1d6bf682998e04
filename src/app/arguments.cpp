#include "app/arguments.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "math/errors.hpp"

namespace arcsim {

namespace {

[[noreturn]] void bad_argument(const std::string& command, const std::string& problem) {
  throw InputError(command + ": " + problem + " (see 'arcsim help " + command + "')");
}

const OptionSpec* find_spec(const std::vector<OptionSpec>& specs, const std::string& name) {
  for (const OptionSpec& s : specs)
    if (name == s.name) return &s;
  return nullptr;
}

}  // namespace

ParsedArguments parse_arguments(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs,
                                const std::string& command) {
  ParsedArguments parsed;
  bool options_ended = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (options_ended || arg.size() < 2 || arg[0] != '-') {
      parsed.positionals.push_back(arg);
      continue;
    }
    if (arg == "--") {
      options_ended = true;
      continue;
    }
    if (arg == "--help" || arg == "-h") {
      parsed.help = true;
      continue;
    }
    const size_t equals = arg.find('=');
    const std::string name = arg.substr(0, equals);
    const OptionSpec* spec = find_spec(specs, name);
    if (!spec) bad_argument(command, "unknown option '" + name + "'");
    std::string value;
    if (equals != std::string::npos) {
      if (!spec->takes_value) bad_argument(command, "option " + name + " takes no value");
      value = arg.substr(equals + 1);
    } else if (spec->takes_value) {
      if (i + 1 >= args.size()) bad_argument(command, "option " + name + " needs a value");
      value = args[++i];
    }
    parsed.options.emplace_back(name, value);
  }
  return parsed;
}

double number_argument(const std::string& command, const std::string& option, const std::string& text,
                       double min) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = text.empty() ? NAN : std::strtod(begin, &end);
  const bool parsed = !text.empty() && end == begin + text.size();
  if (!parsed || !std::isfinite(value) || value < min) {
    char bound[64];
    if (std::isfinite(min))
      std::snprintf(bound, sizeof bound, "a number >= %g", min);
    else
      std::snprintf(bound, sizeof bound, "a finite number");
    bad_argument(command, option + ": expected " + bound + ", got '" + text + "'");
  }
  return value;
}

int integer_argument(const std::string& command, const std::string& option, const std::string& text, int min,
                     int max) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(begin, &end, 10);
  const bool parsed = !text.empty() && end == begin + text.size() && errno == 0;
  if (!parsed || value < min || value > max)
    bad_argument(command, option + ": expected an integer in [" + std::to_string(min) + ", " +
                              std::to_string(max) + "], got '" + text + "'");
  return static_cast<int>(value);
}

void frame_range_argument(const std::string& command, const std::string& text, int& first, int& last) {
  const size_t colon = text.find(':');
  if (colon == std::string::npos) {
    first = last = integer_argument(command, "--frames", text, 0, 1000000000);
    return;
  }
  const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
  if (!a.empty()) first = integer_argument(command, "--frames", a, 0, 1000000000);
  if (!b.empty()) last = integer_argument(command, "--frames", b, 0, 1000000000);
  if (first > last) throw InputError(command + ": --frames: empty range '" + text + "'");
}

}  // namespace arcsim
