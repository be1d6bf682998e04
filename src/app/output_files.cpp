#include "app/output_files.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <system_error>

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

std::map<int, SavedFrameFiles> find_saved_frames(const std::string& dir) {
  namespace fs = std::filesystem;
  std::map<int, SavedFrameFiles> frames;
  std::error_code ec;
  std::map<int, std::string> static_obstacles;
  std::map<int, std::map<int, std::string>> moving;  // frame -> obstacle -> file
  std::map<int, std::map<int, std::string>> cloth_files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    int frame = -1, index = -1;
    char tail = 0;
    if (std::sscanf(name.c_str(), "%d_obs%d.ob%c", &frame, &index, &tail) == 3 && tail == 'j')
      moving[frame][index] = entry.path().string();
    else if (std::sscanf(name.c_str(), "obs%d.ob%c", &index, &tail) == 2 && tail == 'j')
      static_obstacles[index] = entry.path().string();
    else if (std::sscanf(name.c_str(), "%d_%d.ob%c", &frame, &index, &tail) == 3 && tail == 'j' &&
             name == cloth_frame_file_name(frame, index))
      cloth_files[frame][index] = entry.path().string();
  }
  int obstacle_count = 0;
  for (const auto& [i, f] : static_obstacles) obstacle_count = std::max(obstacle_count, i + 1);
  for (const auto& [frame, files] : moving)
    for (const auto& [i, f] : files) obstacle_count = std::max(obstacle_count, i + 1);
  for (const auto& [frame, files] : cloth_files) {
    SavedFrameFiles ff;
    for (int c = 0; files.count(c); ++c) ff.cloths.push_back(files.at(c));
    if (ff.cloths.empty()) continue;
    for (int i = 0; i < obstacle_count; ++i) {
      if (moving.count(frame) && moving[frame].count(i)) ff.obstacles.push_back(moving[frame][i]);
      else if (static_obstacles.count(i)) ff.obstacles.push_back(static_obstacles[i]);
    }
    frames[frame] = ff;
  }
  return frames;
}

std::vector<std::pair<int, SavedFrameFiles>> select_saved_frames(const std::string& dir, int first, int last,
                                                                 int every) {
  std::vector<std::pair<int, SavedFrameFiles>> frames;
  int index = 0;
  for (const auto& [frame, files] : find_saved_frames(dir)) {
    if (frame < first || frame > last) continue;
    if (index++ % every == 0) frames.emplace_back(frame, files);
  }
  return frames;
}

}  // namespace arcsim
