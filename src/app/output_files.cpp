#include "app/output_files.hpp"

#include <cctype>
#include <cstdio>

namespace arcsim {

std::string cloth_frame_file_name(int frame, int cloth) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%05d_%02d.obj", frame, cloth);
  return buffer;
}

std::string obstacle_frame_file_name(int frame, int obstacle) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%05d_obs%02d.obj", frame, obstacle);
  return buffer;
}

std::string static_obstacle_file_name(int obstacle) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "obs%02d.obj", obstacle);
  return buffer;
}

bool is_output_file_name(const std::string& name) {
  if (name == kSceneCopyName || name == kFrameLogName) return true;
  // Any top-level .obj that starts with a digit or with "obs" could be one of ours (frame numbers grow past
  // five digits in long runs), so keep the whole family free.
  const bool obj = name.size() > 4 && name.compare(name.size() - 4, 4, ".obj") == 0;
  if (!obj) return false;
  return std::isdigit(static_cast<unsigned char>(name[0])) || name.compare(0, 3, "obs") == 0;
}

}  // namespace arcsim
