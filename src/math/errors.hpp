// Error types that carry the process exit code the command line maps them to. The bottom layer (with math/types.hpp):
// every module may throw them, so they depend on nothing of the project.
#pragma once

#include <stdexcept>
#include <string>

namespace arcsim {

// Bad input: scene, mesh, material, state file or arguments. One line naming the file and the key, line or
// element at fault. Exit code 2.
struct InputError : std::runtime_error {
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

// The simulation went numerically unstable (NaN, solver failure). Exit code 3.
struct NumericalError : std::runtime_error {
  explicit NumericalError(const std::string& what) : std::runtime_error(what) {}
};

// The machine lacks something the command needs (a system library loaded at run time, such as libOSMesa for
// `replay`): neither the input's fault nor a bug. One line naming what is missing and the Debian package that
// provides it. Exit code 4.
struct EnvironmentError : std::runtime_error {
  explicit EnvironmentError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace arcsim
