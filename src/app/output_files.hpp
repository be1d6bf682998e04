// Names of the files the simulate command writes into its output folder (docs/file-formats.md).
#pragma once

#include <map>
#include <string>
#include <vector>

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

// The files of one saved frame of a run folder.
struct SavedFrameFiles {
  std::vector<std::string> cloths;     // NNNNN_CC.obj, CC = 0, 1, ... (paths)
  std::vector<std::string> obstacles;  // per obstacle index: its file at this frame (moving) or obsCC.obj
};
// Saved frames of the run folder `dir`: frame number -> files. A frame is listed when its cloth 0 file exists
// (frame files are written under a temporary name and renamed, so a listed file is whole). Used by `replay`
// and `inspect`.
std::map<int, SavedFrameFiles> find_saved_frames(const std::string& dir);
// The saved frames of `dir` numbered first..last, every `every`-th of them in order (the --frames and --every
// options of `replay` and `inspect`).
std::vector<std::pair<int, SavedFrameFiles>> select_saved_frames(const std::string& dir, int first, int last,
                                                                 int every);

// True for the names above and conf.json / log.jsonl: names a scene's own files must not take in the folder.
bool is_output_file_name(const std::string& name);

}  // namespace arcsim
