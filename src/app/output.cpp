#include "app/output.hpp"

#include <json/json.h>

#include <filesystem>
#include <memory>
#include <system_error>

#include "app/output_files.hpp"
#include "app/scene_copy.hpp"
#include "io/obj.hpp"
#include "io/state.hpp"
#include "math/errors.hpp"

namespace arcsim {

namespace fs = std::filesystem;

namespace {

// The lines of an existing log.jsonl whose frame is at most `last_frame` (lines that do not parse are dropped:
// a run killed while writing may leave half a line).
std::string log_lines_up_to(const std::string& log_path, int last_frame) {
  std::ifstream in(log_path);
  std::string kept, line;
  Json::CharReaderBuilder builder;
  const std::unique_ptr<Json::CharReader> reader(builder.newCharReader());
  while (std::getline(in, line)) {
    Json::Value value;
    std::string errors;
    if (!reader->parse(line.data(), line.data() + line.size(), &value, &errors) || !value.isObject()) continue;
    if (!value["frame"].isInt() || value["frame"].asInt() > last_frame) continue;
    kept += line + '\n';
  }
  return kept;
}

}  // namespace

OutputFolder::OutputFolder(const std::string& dir, int resume_frame) : dir_(dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InputError(dir + ": output folder exists and is not a folder");
  const std::string log_path = path(kFrameLogName);
  if (resume_frame >= 0) {
    if (!fs::is_directory(dir, ec)) throw InputError(dir + ": no such output folder");
    const std::string kept = log_lines_up_to(log_path, resume_frame);
    log_.open(log_path, std::ios::out | std::ios::trunc);
    if (!log_) throw InputError(log_path + ": cannot write");
    log_ << kept;
    log_.flush();
    return;
  }
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the output folder (" + ec.message() + ")");
  log_.open(log_path, std::ios::out | std::ios::trunc);
  if (!log_) throw InputError(log_path + ": cannot write");
}

std::string OutputFolder::path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

std::vector<std::string> OutputFolder::write_scene(const Scene& scene) { return copy_scene_files(scene, dir_); }

void OutputFolder::write_static_obstacles(const Simulation& sim) {
  for (size_t i = 0; i < sim.obstacles.size(); ++i)
    if (sim.obstacles[i].motion < 0)
      write_plain_obj(sim.obstacles[i].mesh, path(static_obstacle_file_name(static_cast<int>(i))));
}

void OutputFolder::write_frame(const Simulation& sim) {
  const int frame = sim.frame();
  // Nothing non-finite ever reaches the disk: a frame is written whole from a finite state, or not at all.
  const std::string problem = sim.nonfinite_state();
  if (!problem.empty())
    throw NumericalError("frame " + std::to_string(frame) + " not written: " + problem + " (step " +
                         std::to_string(sim.step()) + ")");
  for (size_t c = 0; c < sim.cloths.size(); ++c)
    write_obj(sim.cloths[c].mesh, path(cloth_frame_file_name(frame, static_cast<int>(c))));
  for (size_t i = 0; i < sim.obstacles.size(); ++i)
    if (sim.obstacles[i].motion >= 0)
      write_plain_obj(sim.obstacles[i].mesh, path(obstacle_frame_file_name(frame, static_cast<int>(i))));
  save_state(sim, path(state_file_name(frame)));
}

void OutputFolder::log(const std::string& line) {
  log_ << line << '\n';
  log_.flush();
  if (!log_) throw InputError(path(kFrameLogName) + ": cannot write");
}

}  // namespace arcsim
