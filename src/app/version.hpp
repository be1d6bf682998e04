// The program's version: the one place it is written down (printed by `arcsim --version`).
#pragma once

namespace arcsim {

constexpr const char* kProgramName = "arcsim";
constexpr const char* kVersion = "0.1.0";

}  // namespace arcsim
