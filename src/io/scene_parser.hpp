// Reads ARCSim 0.3 scene files (JSON with // comments) into a Scene, with ARCSim's defaults, strict checks and
// our extensions (isotropic material files, stretching plasticity keys). docs/scene-format.md lists every key.
//
// Errors throw InputError with one line "<file>: <key path>: <problem>", e.g.
//   scene.json: cloths[0].materials[0].poisson_ratio: must be in [0, 0.5), got 0.5
// JSON syntax errors read "<file>:<line>:<column>: <parser message>". Questionable but accepted input (unknown
// keys, keys ARCSim ignored) adds a line to Scene::warnings instead.
#pragma once

#include <string>
#include <vector>

#include "physics/material.hpp"
#include "scene/scene.hpp"

namespace arcsim {

// Parses the scene file at `path`. Relative paths inside it (meshes, material data, reference meshes) are looked
// up in the scene file's folder, then the scene folder's parent (ARCSim's conf/ beside meshes/ layout), then the
// current working directory. Meshes are not loaded here; their resolved paths are checked to exist.
Scene load_scene(const std::string& path);

// Reads one of our isotropic material files (materials/*.json: thickness, density, elastic_modulus, ...), with
// the same checks as a scene's inline material. Throws InputError for a DDE file or bad values. Warnings (unknown
// keys) are appended to `warnings` when given.
Material load_material_file(const std::string& path, std::vector<std::string>* warnings = nullptr);

// The search order used for a relative path `name` named in the scene at `scene_path`: the candidates tried,
// in order (an absolute `name` gives just itself).
std::vector<std::string> scene_path_candidates(const std::string& name, const std::string& scene_path);

}  // namespace arcsim
