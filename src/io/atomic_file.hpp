// Whole-file writes that never leave a partial file under the final name.
#pragma once

#include <string>

namespace arcsim {

// How far a write must have reached before `path` names it.
enum class Durability {
  kProcessCrash,  // renamed once written: a killed process leaves the old file or the new one
  kPowerLoss,     // also flushed to the disk (fsync) before the rename: survives a crash of the machine
};

// Writes `bytes` to "<path>.tmp.<pid>" and renames it over `path`. Throws InputError "<path>: cannot write
// (<reason>)" and removes the temporary file on any failure (a full disk included).
void write_file_atomically(const std::string& path, const std::string& bytes, Durability durability);

}  // namespace arcsim
