#include "app/output.hpp"

#include <filesystem>
#include <system_error>

#include "app/output_files.hpp"
#include "app/scene_copy.hpp"
#include "io/errors.hpp"
#include "io/obj.hpp"

namespace arcsim {

namespace fs = std::filesystem;

OutputFolder::OutputFolder(const std::string& dir) : dir_(dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InputError(dir + ": output folder exists and is not a folder");
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the output folder (" + ec.message() + ")");
  const std::string log_path = path(kFrameLogName);
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
  for (size_t c = 0; c < sim.cloths.size(); ++c)
    write_obj(sim.cloths[c].mesh, path(cloth_frame_file_name(frame, static_cast<int>(c))));
  for (size_t i = 0; i < sim.obstacles.size(); ++i)
    if (sim.obstacles[i].motion >= 0)
      write_plain_obj(sim.obstacles[i].mesh, path(obstacle_frame_file_name(frame, static_cast<int>(i))));
}

void OutputFolder::log(const std::string& line) {
  log_ << line << '\n';
  log_.flush();
  if (!log_) throw InputError(path(kFrameLogName) + ": cannot write");
}

}  // namespace arcsim
