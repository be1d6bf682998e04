// Where a command writes: stdout for results (e.g. JSON progress), stderr for messages and live progress.
#pragma once

#include <ostream>
#include <string>

namespace arcsim {

struct Console {
  std::ostream& out;
  std::ostream& err;
  bool err_is_terminal = false;  // live progress (\r-rewritten line) only on a terminal

  // "arcsim: warning: <text>" on stderr, as one line.
  void warn(const std::string& text) const;
};

// `text` with every line break replaced by a space, so that a message is printed as one line.
std::string one_line(std::string text);

}  // namespace arcsim
