// The `arcsim` program: see app/cli.hpp for the command line and docs/file-formats.md for what it writes.
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "app/cli.hpp"
#include "app/heap.hpp"

int main(int argc, char** argv) {
  arcsim::keep_freed_memory_in_heap();
  const std::vector<std::string> args(argv + 1, argv + argc);
  const arcsim::Console console{std::cout, std::cerr, ::isatty(::fileno(stderr)) == 1};
  return arcsim::run_command_line(args, console);
}
