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

std::string state_file_name(int frame) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%05d.state", frame);
  return buffer;
}

int state_file_frame(const std::string& name) {
  const std::string suffix = ".state";
  if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return -1;
  const std::string digits = name.substr(0, name.size() - suffix.size());
  if (digits.size() < 5 || digits.size() > 9) return -1;
  for (char c : digits)
    if (!std::isdigit(static_cast<unsigned char>(c))) return -1;
  return std::stoi(digits);
}

std::string static_obstacle_file_name(int obstacle) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "obs%02d.obj", obstacle);
  return buffer;
}

bool is_output_file_name(const std::string& name) {
  if (name == kSceneCopyName || name == kFrameLogName || state_file_frame(name) >= 0) return true;
  // Any top-level .obj that starts with a digit or with "obs" could be one of ours (frame numbers grow past
  // five digits in long runs), so keep the whole family free.
  const bool obj = name.size() > 4 && name.compare(name.size() - 4, 4, ".obj") == 0;
  if (!obj) return false;
  return std::isdigit(static_cast<unsigned char>(name[0])) || name.compare(0, 3, "obs") == 0;
}

}  // namespace arcsim
