#include "app/scene_copy.hpp"

#include <json/json.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include "app/json_line.hpp"
#include "app/output_files.hpp"
#include "io/scene_parser.hpp"
#include "math/errors.hpp"

namespace arcsim {

namespace fs = std::filesystem;

namespace {

// A path that names one file however it was spelt, for comparisons.
std::string identity_of(const std::string& path) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(path, ec);
  if (!ec) return canonical.string();
  return fs::absolute(path, ec).lexically_normal().string();
}

bool is_regular_file(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// A relative path that stays inside the folder it is resolved against and does not clash with the files the
// simulate command writes at the top of the output folder.
bool is_safe_relative(const std::string& name) {
  const fs::path p(name);
  if (name.empty() || p.is_absolute() || p.has_root_name()) return false;
  for (const fs::path& part : p)
    if (part == "..") return false;
  const fs::path normal = p.lexically_normal();
  if (normal.empty() || normal == "." || !normal.has_filename()) return false;
  const bool top_level = !normal.has_parent_path();
  return !(top_level && is_output_file_name(normal.string()));
}

// "a/b%03d.obj" with the index put in, as the scene loader reads obstacle patterns (one %d / %i conversion with
// optional zero padding and width; %% is a literal %). Empty if the pattern is not of that form.
std::string format_index_pattern(const std::string& pattern, int index) {
  std::string out;
  int conversions = 0;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      out += pattern[i];
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    size_t j = i + 1;
    const bool zero_pad = j < pattern.size() && pattern[j] == '0';
    while (j < pattern.size() && pattern[j] == '0') ++j;
    const size_t width_start = j;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) ++j;
    if (j >= pattern.size() || (pattern[j] != 'd' && pattern[j] != 'i') || j - width_start > 2) return "";
    const size_t width = j > width_start ? std::stoul(pattern.substr(width_start, j - width_start)) : 0;
    std::string digits = std::to_string(index);
    if (digits.size() < width) digits.insert(0, width - digits.size(), zero_pad ? '0' : ' ');
    out += digits;
    ++conversions;
    i = j;
  }
  return conversions == 1 ? out : "";
}

// The scene loader's bound on the files of one obstacle pattern.
constexpr int kMaxPatternFiles = 100000;

// The first existing file among the loader's candidates for `name`.
std::string resolve_like_loader(const std::string& name, const std::string& scene_path) {
  for (const std::string& candidate : scene_path_candidates(name, scene_path))
    if (is_regular_file(candidate)) return candidate;
  return "";
}

// Plans the copies: which source file goes to which path inside the output folder.
class CopyPlan {
 public:
  explicit CopyPlan(const Scene& scene) : scene_(scene) {
    for (const std::string& f : scene.referenced_files) referenced_.insert(identity_of(f));
  }

  // Walks the scene's JSON, planning a copy for every string that names a referenced file and rewriting the
  // strings that must point into files/. Returns true if the JSON was changed.
  bool plan(Json::Value& root) {
    // (isMember first: operator[] on a missing key would add it as null.)
    if (root.isObject() && root.isMember("obstacles") && root["obstacles"].isString())
      plan_obstacle_pattern(root["obstacles"]);
    walk(root, &root);
    return rewritten_;
  }

  const std::map<std::string, std::string>& copies() const { return copies_; }  // destination -> source
  const std::set<std::string>& placed() const { return placed_; }              // identities of sources

 private:
  void walk(Json::Value& value, const Json::Value* root) {
    if (value.isObject()) {
      for (const std::string& key : value.getMemberNames()) {
        Json::Value& child = value[key];
        // The obstacle pattern was handled on its own.
        if (&value == root && key == "obstacles" && child.isString()) continue;
        walk(child, nullptr);
      }
    } else if (value.isArray()) {
      for (Json::Value& child : value) walk(child, nullptr);
    } else if (value.isString()) {
      plan_string(value);
    }
  }

  // A string naming a referenced file: copied to the same relative path, or to files/ with the string rewritten.
  void plan_string(Json::Value& value) {
    const std::string name = value.asString();
    if (name.empty()) return;
    const std::string source = resolve_like_loader(name, scene_.path);
    if (source.empty() || !referenced_.count(identity_of(source))) return;
    if (is_safe_relative(name) && claim(fs::path(name).lexically_normal().generic_string(), source)) return;
    const std::string dest = unique_files_name(fs::path(source).filename().string(), source);
    claim(dest, source);
    value = dest;
    rewritten_ = true;
  }

  void plan_obstacle_pattern(Json::Value& value) {
    const std::string pattern = value.asString();
    const bool safe = is_safe_relative(pattern);
    std::string target = pattern;
    if (!safe) {
      const fs::path p(pattern);
      const std::string base = p.filename().string();
      std::string flat = pattern;  // conversion in a folder name: keep the whole path, flattened
      std::replace(flat.begin(), flat.end(), '/', '_');
      target = "files/" + (base.find('%') != std::string::npos ? base : flat);
    }
    std::vector<std::pair<std::string, std::string>> planned;  // destination, source
    for (int i = 0; i < kMaxPatternFiles; ++i) {
      const std::string name = format_index_pattern(pattern, i);
      const std::string dest = format_index_pattern(target, i);
      if (name.empty() || dest.empty()) return;
      const std::string source = resolve_like_loader(name, scene_.path);
      if (source.empty() || !referenced_.count(identity_of(source))) break;
      const std::string normal = fs::path(dest).lexically_normal().generic_string();
      if (!is_safe_relative(normal) || !free_for(normal, source)) return;  // left unplaced: warned about
      planned.emplace_back(normal, source);
    }
    for (const auto& [dest, source] : planned) claim(dest, source);
    if (!safe) {
      value = target;
      rewritten_ = true;
    }
  }

  bool free_for(const std::string& dest, const std::string& source) const {
    const auto it = copies_.find(dest);
    return it == copies_.end() || identity_of(it->second) == identity_of(source);
  }

  // Reserves `dest` for `source`; false if another file already goes there.
  bool claim(const std::string& dest, const std::string& source) {
    if (!free_for(dest, source)) return false;
    copies_[dest] = source;
    placed_.insert(identity_of(source));
    return true;
  }

  // files/<basename>, or files/<stem>_2<ext>, ... when a different file already took that name.
  std::string unique_files_name(const std::string& basename, const std::string& source) const {
    const fs::path b(basename);
    for (int n = 1;; ++n) {
      const std::string name =
          n == 1 ? basename : b.stem().string() + "_" + std::to_string(n) + b.extension().string();
      const std::string dest = "files/" + name;
      if (free_for(dest, source)) return dest;
    }
  }

  const Scene& scene_;
  std::set<std::string> referenced_;
  std::map<std::string, std::string> copies_;
  std::set<std::string> placed_;
  bool rewritten_ = false;
};

Json::Value read_scene_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  Json::CharReaderBuilder builder;
  builder["allowComments"] = true;
  builder["allowSpecialFloats"] = true;
  Json::Value root;
  std::string errors;
  if (!in || !Json::parseFromStream(builder, in, &root, &errors))
    throw InputError(path + ": cannot read the scene again to copy it");
  return root;
}

// JSON text of `value` for a rewritten scene: numbers in their shortest exact form (jsoncpp's writer prints
// 0.3 as 0.29999999999999999), infinities as the loader's Infinity, arrays of scalars on one line.
void append_json(const Json::Value& value, const std::string& indent, std::string& out) {
  switch (value.type()) {
    case Json::nullValue:
      out += "null";
      return;
    case Json::booleanValue:
      out += value.asBool() ? "true" : "false";
      return;
    case Json::intValue:
    case Json::uintValue:
      out += value.isInt64() ? std::to_string(value.asInt64()) : std::to_string(value.asUInt64());
      return;
    case Json::realValue: {
      const double x = value.asDouble();
      out += std::isinf(x) ? (x > 0 ? "Infinity" : "-Infinity") : json_number(x);
      return;
    }
    case Json::stringValue:
      out += Json::valueToQuotedString(value.asCString());
      return;
    case Json::arrayValue: {
      const bool flat = std::none_of(value.begin(), value.end(), [](const Json::Value& v) {
        return v.isArray() || v.isObject();
      });
      const std::string inner = indent + "    ";
      out += '[';
      for (Json::ArrayIndex i = 0; i < value.size(); ++i) {
        out += i > 0 ? (flat ? ", " : ",\n" + inner) : (flat ? "" : "\n" + inner);
        append_json(value[i], inner, out);
      }
      out += flat || value.empty() ? "]" : "\n" + indent + "]";
      return;
    }
    case Json::objectValue: {
      const std::string inner = indent + "    ";
      out += '{';
      bool first = true;
      for (const std::string& key : value.getMemberNames()) {
        out += (first ? "\n" : ",\n") + inner + Json::valueToQuotedString(key.c_str()) + ": ";
        append_json(value[key], inner, out);
        first = false;
      }
      out += value.empty() ? "}" : "\n" + indent + "}";
      return;
    }
  }
}

[[noreturn]] void cannot_write(const std::string& path, const std::error_code& ec) {
  throw InputError(path + ": cannot write (" + ec.message() + ")");
}

// Writes through a temporary file and a rename, as the frame files are, so no reader sees half a file.
void write_text_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw InputError(path + ": cannot write");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) cannot_write(path, ec);
}

void copy_file_atomically(const std::string& source, const std::string& dest) {
  std::error_code ec;
  if (fs::exists(dest, ec) && fs::equivalent(source, dest, ec)) return;  // re-running inside the output folder
  fs::create_directories(fs::path(dest).parent_path(), ec);
  if (ec) cannot_write(fs::path(dest).parent_path().string(), ec);
  const std::string tmp = dest + ".tmp";
  fs::copy_file(source, tmp, fs::copy_options::overwrite_existing, ec);
  if (ec) cannot_write(dest, ec);
  fs::rename(tmp, dest, ec);
  if (ec) cannot_write(dest, ec);
}

}  // namespace

std::vector<std::string> copy_scene_files(const Scene& scene, const std::string& out_dir) {
  Json::Value root = read_scene_json(scene.path);
  CopyPlan plan(scene);
  const bool rewritten = plan.plan(root);

  std::vector<std::string> warnings;
  for (const std::string& f : scene.referenced_files)
    if (!plan.placed().count(identity_of(f)))
      warnings.push_back(f + ": not copied into " + out_dir + " (could not tell where the scene names it); " +
                         out_dir + "/conf.json may not load on its own");

  for (const auto& [dest, source] : plan.copies()) copy_file_atomically(source, (fs::path(out_dir) / dest).string());

  const std::string conf = (fs::path(out_dir) / kSceneCopyName).string();
  if (rewritten) {
    std::string json;
    append_json(root, "", json);
    std::ostringstream text;
    std::string from = scene.path;
    std::replace(from.begin(), from.end(), '\n', ' ');
    text << "// Copied by arcsim simulate from " << from << ", with paths rewritten into this folder.\n"
         << json << "\n";
    write_text_atomically(conf, text.str());
  } else {
    copy_file_atomically(scene.path, conf);
  }
  return warnings;
}

}  // namespace arcsim
