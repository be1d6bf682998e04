// Makes an output folder self-contained: the scene is copied to <out>/conf.json and every file it references
// (meshes, material data, obstacle meshes) into <out>, so that <out>/conf.json loads from <out> alone.
#pragma once

#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace arcsim {

// Where the copies go: a file the scene names by a plain relative path ("meshes/a.obj", resolved under the scene
// folder, its parent or the working directory) is copied to that same relative path inside `out_dir`, which is
// where the scene loader looks first. A file named by an absolute path or one with "..", or whose relative path
// would clash with another copy or with the output files themselves, goes to files/<basename> and the copied
// conf.json is rewritten (re-serialised; comments are then lost) to name it there. Returns warnings for files
// that could not be placed. Throws InputError if something cannot be written.
std::vector<std::string> copy_scene_files(const Scene& scene, const std::string& out_dir);

}  // namespace arcsim
