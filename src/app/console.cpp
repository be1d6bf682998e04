#include "app/console.hpp"

#include <algorithm>

#include "app/version.hpp"

namespace arcsim {

std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

void Console::warn(const std::string& text) const {
  err << kProgramName << ": warning: " << one_line(text) << '\n' << std::flush;
}

}  // namespace arcsim
