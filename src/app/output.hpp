// The output folder of a simulate run: frame files, the scene copy and log.jsonl (layout: docs/file-formats.md).
#pragma once

#include <fstream>
#include <string>
#include <vector>

#include "scene/scene.hpp"
#include "sim/simulation.hpp"

namespace arcsim {

class OutputFolder {
 public:
  // Creates the folder and its parents (an existing folder is reused) and starts a new log.jsonl. Throws
  // InputError naming the path if that fails. With `resume_frame` >= 0 (arcsim resume) the folder must exist and
  // log.jsonl keeps its lines up to that frame; later lines are dropped, new ones appended.
  explicit OutputFolder(const std::string& dir, int resume_frame = -1);

  const std::string& dir() const { return dir_; }

  // conf.json and the files the scene references (app/scene_copy.hpp). Returns warnings.
  std::vector<std::string> write_scene(const Scene& scene);
  // obsCC.obj for every obstacle without a motion (they never move, so once is enough).
  void write_static_obstacles(const Simulation& sim);
  // NNNNN_CC.obj for every cloth and NNNNN_obsCC.obj for every moving obstacle, at the simulation's frame, then
  // NNNNN.state (written last, atomically: a frame with a state file is complete).
  void write_frame(const Simulation& sim);
  // One line of log.jsonl, flushed at once so that a crash or a numerical failure keeps it.
  void log(const std::string& line);

 private:
  std::string path(const std::string& name) const;

  std::string dir_;
  std::ofstream log_;
};

}  // namespace arcsim
