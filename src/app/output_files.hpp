// Names of the files the simulate command writes into its output folder (docs/file-formats.md).
#pragma once

#include <string>

namespace arcsim {

constexpr const char* kSceneCopyName = "conf.json";
constexpr const char* kFrameLogName = "log.jsonl";

// NNNNN_CC.obj: cloth CC at frame NNNNN (extended OBJ, write_obj).
std::string cloth_frame_file_name(int frame, int cloth);
// NNNNN_obsCC.obj: a moving obstacle at frame NNNNN (plain OBJ).
std::string obstacle_frame_file_name(int frame, int obstacle);
// NNNNN.state: the lossless simulation state at frame NNNNN (io/state.hpp), written last: its presence marks the
// frame complete, and `arcsim resume` continues from it.
std::string state_file_name(int frame);
// The frame number of a state file name, or -1 if `name` is not one.
int state_file_frame(const std::string& name);
// obsCC.obj: a static obstacle, written once.
std::string static_obstacle_file_name(int obstacle);

// True for the names above and conf.json / log.jsonl: names a scene's own files must not take in the folder.
bool is_output_file_name(const std::string& name);

}  // namespace arcsim
