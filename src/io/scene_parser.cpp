#include "io/scene_parser.hpp"

#include <json/json.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>

#include "math/errors.hpp"

namespace arcsim {

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------------------------
// Locations and messages

// Where a value sits, for messages: the file it was read from and its key path inside that file.
struct Loc {
  std::string file;
  std::string path;  // "" = the file's top level

  Loc key(const std::string& k) const { return {file, path.empty() ? k : path + "." + k}; }
  Loc index(size_t i) const { return {file, path + "[" + std::to_string(i) + "]"}; }
  std::string str() const { return path.empty() ? file : file + ": " + path; }
};

[[noreturn]] void fail(const Loc& at, const std::string& problem) { throw InputError(at.str() + ": " + problem); }

// Shortest decimal form that reads back as the same double ("0.5", "2e+07", "inf").
std::string number(double x) {
  if (std::isnan(x)) return "NaN";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

// A short rendering of a JSON value for "got ..." messages.
std::string show(const Json::Value& v) {
  if (v.isNumeric()) return number(v.asDouble());
  Json::StreamWriterBuilder w;
  w["indentation"] = "";
  std::string s = Json::writeString(w, v);
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

std::string in_quotes(const std::string& s) { return "\"" + s + "\""; }

// ---------------------------------------------------------------------------------------------------------------
// JSON files

// Turns jsoncpp's "* Line 3, Column 7\n  Syntax error: ...\n" into "<file>:3:7: Syntax error: ...".
std::string parse_error_line(const std::string& file, const std::string& errs) {
  int line = 0, column = 0;
  std::string message;
  std::istringstream in(errs);
  std::string first;
  std::getline(in, first);
  if (std::sscanf(first.c_str(), "* Line %d, Column %d", &line, &column) == 2) {
    std::string rest;
    while (std::getline(in, rest)) {
      const size_t start = rest.find_first_not_of(" \t");
      if (start == std::string::npos) continue;
      if (rest.compare(start, 2, "* ") == 0) break;  // a second error: keep the first only
      if (!message.empty()) message += " ";
      message += rest.substr(start);
    }
    return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message;
  }
  std::string flat = errs;
  std::replace(flat.begin(), flat.end(), '\n', ' ');
  return file + ": " + flat;
}

Json::Value read_json_file(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path + ": cannot open file (missing or not a regular file)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file");
  Json::CharReaderBuilder builder;
  builder["allowComments"] = true;
  builder["allowSpecialFloats"] = true;  // so NaN / Infinity reach our checks and get a key path
  builder["rejectDupKeys"] = true;
  builder["failIfExtra"] = true;
  Json::Value root;
  std::string errs;
  if (!Json::parseFromStream(builder, in, &root, &errs)) throw InputError(parse_error_line(path, errs));
  return root;
}

// ---------------------------------------------------------------------------------------------------------------
// Value conversion

// Accepted range of a real value. Infinite values pass only when `allow_infinite` (keys whose ARCSim default
// is infinite, where infinity means "off").
struct Limits {
  double lo = -kInfinity, hi = kInfinity;
  bool lo_open = false, hi_open = false;
  bool allow_infinite = false;

  bool contains(double x) const {
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  std::string describe() const {
    const bool has_lo = lo > -kInfinity, has_hi = hi < kInfinity;
    if (has_lo && has_hi)
      return std::string("in ") + (lo_open ? "(" : "[") + number(lo) + ", " + number(hi) + (hi_open ? ")" : "]");
    if (has_lo) return std::string(lo_open ? "> " : ">= ") + number(lo);
    if (has_hi) return std::string(hi_open ? "< " : "<= ") + number(hi);
    return "finite";
  }
};

const Limits kFinite{};
const Limits kNonNegative{0, kInfinity};
const Limits kPositive{0, kInfinity, true};
Limits or_infinite(Limits l) {
  l.allow_infinite = true;
  return l;
}

const char* type_name(const Json::Value& v) {
  switch (v.type()) {
    case Json::nullValue: return "null";
    case Json::intValue:
    case Json::uintValue:
    case Json::realValue: return "a number";
    case Json::stringValue: return "a string";
    case Json::booleanValue: return "a boolean";
    case Json::arrayValue: return "an array";
    case Json::objectValue: return "an object";
  }
  return "a value";
}

[[noreturn]] void wrong_type(const Json::Value& v, const Loc& at, const std::string& expected) {
  fail(at, "must be " + expected + ", got " + type_name(v) + " " + show(v));
}

double check_real(double x, const Loc& at, const Limits& limits) {
  if (std::isnan(x)) fail(at, "must be a number, got NaN");
  if (std::isinf(x) && !limits.allow_infinite) fail(at, "must be finite, got " + number(x));
  if (!limits.contains(x)) fail(at, "must be " + limits.describe() + ", got " + number(x));
  return x;
}

double to_real(const Json::Value& v, const Loc& at, const Limits& limits = kFinite) {
  if (!v.isNumeric() || v.isBool()) wrong_type(v, at, "a number");
  return check_real(v.asDouble(), at, limits);
}

int to_int(const Json::Value& v, const Loc& at, int lo = std::numeric_limits<int>::min(),
           int hi = std::numeric_limits<int>::max()) {
  if (v.isBool() || !v.isNumeric()) wrong_type(v, at, "an integer");
  if (!v.isInt()) fail(at, "must be an integer, got " + show(v));
  const int i = v.asInt();
  if (i < lo || i > hi) {
    std::string range = hi == std::numeric_limits<int>::max()
                            ? ">= " + std::to_string(lo)
                            : "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    fail(at, "must be " + range + ", got " + std::to_string(i));
  }
  return i;
}

bool to_bool(const Json::Value& v, const Loc& at) {
  if (!v.isBool()) wrong_type(v, at, "true or false");
  return v.asBool();
}

std::string to_string(const Json::Value& v, const Loc& at) {
  if (!v.isString()) wrong_type(v, at, "a string");
  return v.asString();
}

const Json::Value& to_array(const Json::Value& v, const Loc& at, int size = -1) {
  if (!v.isArray()) wrong_type(v, at, size < 0 ? std::string("an array") : "an array of " + std::to_string(size));
  if (size >= 0 && v.size() != static_cast<unsigned>(size))
    fail(at, "must be an array of " + std::to_string(size) + " numbers, got " + std::to_string(v.size()) +
                 " elements");
  return v;
}

template <int N>
Eigen::Matrix<double, N, 1> to_vec(const Json::Value& v, const Loc& at, const Limits& limits = kFinite) {
  to_array(v, at, N);
  Eigen::Matrix<double, N, 1> out;
  for (int i = 0; i < N; ++i) out[i] = to_real(v[i], at.index(i), limits);
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// Objects with key bookkeeping

// A value found under a key (nullptr when absent or null, which ARCSim also treats as absent) and its location.
struct Found {
  const Json::Value* value = nullptr;
  Loc at;
  explicit operator bool() const { return value != nullptr; }
};

// Reads the keys of one JSON object and afterwards warns about the keys nobody asked for.
class ObjectReader {
 public:
  ObjectReader(const Json::Value& object, Loc at, std::vector<std::string>& warnings)
      : object_(object), at_(std::move(at)), warnings_(warnings) {
    if (!object.isObject()) wrong_type(object, at_, "an object");
  }

  Found get(const std::string& key) {
    known_.insert(key);
    const Json::Value* v = object_.find(key.data(), key.data() + key.size());
    if (v && v->isNull()) v = nullptr;
    return {v, at_.key(key)};
  }
  bool has(const std::string& key) const {
    const Json::Value* v = object_.find(key.data(), key.data() + key.size());
    return v && !v->isNull();
  }
  const Loc& at() const { return at_; }
  // A key that is accepted but has no effect: warn when present.
  void ignore(const std::string& key, const std::string& why) {
    known_.insert(key);
    if (has(key)) warn(at_.key(key), "ignored (" + why + ")");
  }
  void warn(const Loc& at, const std::string& text) { warnings_.push_back(at.str() + ": " + text); }
  void warn_unknown() const {
    for (const std::string& key : object_.getMemberNames())
      if (!known_.count(key)) warnings_.push_back(at_.key(key).str() + ": unknown key, ignored");
  }

 private:
  const Json::Value& object_;
  Loc at_;
  std::vector<std::string>& warnings_;
  std::set<std::string> known_;
};

double get_real(const Found& f, double fallback, const Limits& limits = kFinite) {
  return f ? to_real(*f.value, f.at, limits) : fallback;
}
int get_int(const Found& f, int fallback, int lo = std::numeric_limits<int>::min(),
            int hi = std::numeric_limits<int>::max()) {
  return f ? to_int(*f.value, f.at, lo, hi) : fallback;
}
bool get_bool(const Found& f, bool fallback) { return f ? to_bool(*f.value, f.at) : fallback; }
std::string get_string(const Found& f, const std::string& fallback) {
  return f ? to_string(*f.value, f.at) : fallback;
}
Vec3 get_vec3(const Found& f, const Vec3& fallback) { return f ? to_vec<3>(*f.value, f.at) : fallback; }
const Json::Value& required(const Found& f, const std::string& why = "required") {
  if (!f) fail(f.at, why);
  return *f.value;
}

// ---------------------------------------------------------------------------------------------------------------
// Paths

std::string scene_dir_of(const std::string& scene_path) {
  const fs::path dir = fs::path(scene_path).parent_path();
  return dir.empty() ? std::string(".") : dir.string();
}

bool is_file(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// A printf-style obstacle pattern with exactly one integer conversion (%d, %i, %03d, ...), expanded by hand
// so a user-written format string never reaches printf.
class IndexPattern {
 public:
  IndexPattern(const std::string& pattern, const Loc& at) {
    std::string literal;
    int conversions = 0;
    for (size_t i = 0; i < pattern.size(); ++i) {
      if (pattern[i] != '%') {
        literal += pattern[i];
        continue;
      }
      if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
        literal += '%';
        ++i;
        continue;
      }
      size_t j = i + 1;
      zero_pad_ = j < pattern.size() && pattern[j] == '0';
      while (j < pattern.size() && pattern[j] == '0') ++j;
      size_t width_start = j;
      while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) ++j;
      if (j >= pattern.size() || (pattern[j] != 'd' && pattern[j] != 'i') || j - width_start > 2)
        fail(at, "obstacle pattern " + in_quotes(pattern) + ": only one %d-style integer conversion is supported");
      width_ = j > width_start ? std::stoi(pattern.substr(width_start, j - width_start)) : 0;
      prefix_ = literal;
      literal.clear();
      ++conversions;
      i = j;
    }
    if (conversions != 1)
      fail(at, "obstacle pattern " + in_quotes(pattern) + " must contain exactly one integer conversion like %d, got " +
                   std::to_string(conversions));
    suffix_ = literal;
  }
  std::string operator()(int index) const {
    std::string digits = std::to_string(index);
    if (static_cast<int>(digits.size()) < width_) digits.insert(0, width_ - digits.size(), zero_pad_ ? '0' : ' ');
    return prefix_ + digits + suffix_;
  }

 private:
  std::string prefix_, suffix_;
  int width_ = 0;
  bool zero_pad_ = false;
};

// ---------------------------------------------------------------------------------------------------------------
// The scene parser

const char* const kModules[] = {"proximity", "physics",    "strainlimiting", "collision", "remeshing",
                                "separation", "popfilter", "plasticity",     "fracture"};

// Material keys read for isotropic materials only (ARCSim ignores them next to a data-driven `data` file).
const char* const kIsotropicOnlyKeys[] = {"thickness",     "density",   "elastic_modulus",
                                          "poisson_ratio", "toughness", "fracture_bending_mult"};

class SceneParser {
 public:
  SceneParser(Scene& scene, const std::string& file) : scene_(scene), file_(file) {}

  void parse(const Json::Value& root) {
    if (!root.isObject()) fail(Loc{file_, ""}, "the top level must be a JSON object, got " + show(root));
    ObjectReader top(root, Loc{file_, ""}, scene_.warnings);
    parse_timing(top);
    parse_disable(top.get("disable"));
    parse_magic(top.get("magic"));
    parse_fracture(top.get("fracture"));
    parse_solver(top.get("solver"));
    parse_cloths(top.get("cloths"));
    parse_motions(top.get("motions"));
    parse_handles(top.get("handles"));
    parse_obstacles(top.get("obstacles"));
    parse_morphs(top.get("morphs"));
    scene_.gravity = get_vec3(top.get("gravity"), Vec3::Zero());
    parse_wind(top.get("wind"));
    scene_.friction = get_real(top.get("friction"), 0.6, kNonNegative);
    scene_.obs_friction = get_real(top.get("obs_friction"), 0.3, kNonNegative);
    top.ignore("remeshing_frames", "ARCSim 0.3 never read it: remeshing runs once per frame");
    top.warn_unknown();
    disable_unused_modules();
    check_required_for_enabled_modules();
  }

  // Material outside any scene (load_material_file).
  Material parse_material_file(const std::string& path) {
    const Json::Value root = read_json_file(path);
    const Loc at{path, ""};
    if (root.isObject() && (root.isMember("stretching") || root.isMember("bending")))
      fail(at, "is an ARCSim data-driven (DDE) material file; name it with `data` in a scene material instead");
    const Json::Value empty(Json::objectValue);
    Material m = parse_isotropic(empty, at, &root, Loc{path, ""});
    if (m.name.empty()) m.name = fs::path(path).stem().string();
    return m;
  }

 private:
  Scene& scene_;
  std::string file_;

  Loc at(const std::string& path) const { return Loc{file_, path}; }

  void add_referenced(const std::string& path) {
    if (std::find(scene_.referenced_files.begin(), scene_.referenced_files.end(), path) ==
        scene_.referenced_files.end())
      scene_.referenced_files.push_back(path);
  }

  // Resolves a file named at `where`; fails naming the key and every path tried.
  std::string resolve(const std::string& name, const Loc& where) {
    if (name.empty()) fail(where, "must name a file, got an empty string");
    const std::vector<std::string> tried = scene_path_candidates(name, file_);
    for (const std::string& candidate : tried)
      if (is_file(candidate)) {
        add_referenced(candidate);
        return candidate;
      }
    std::string list;
    for (const std::string& t : tried) list += (list.empty() ? "" : ", ") + t;
    fail(where, "file " + in_quotes(name) + " not found (tried " + list + ")");
  }

  // --- timing ------------------------------------------------------------------------------------------------

  void parse_timing(ObjectReader& top) {
    const Found frame_time = top.get("frame_time");
    const Found timestep = top.get("timestep");
    const Found frame_steps = top.get("frame_steps"), end_time = top.get("end_time"),
                end_frame = top.get("end_frame"), save_frames = top.get("save_frames"),
                save_every = top.get("save_every"), duration = top.get("duration");
    if (frame_time) {
      // Style A. ARCSim reads nothing of style B here, not even `duration`.
      scene_.frame_time = to_real(*frame_time.value, frame_time.at, kPositive);
      scene_.frame_steps = get_int(frame_steps, 1, 1);
      scene_.step_time = scene_.frame_time / scene_.frame_steps;
      scene_.end_time = get_real(end_time, kInfinity, or_infinite(kNonNegative));
      scene_.end_frame = get_real(end_frame, kInfinity, or_infinite(kNonNegative));
      scene_.save_every = 1;
      for (const Found* f : {&timestep, &save_frames, &save_every, &duration})
        if (*f)
          top.warn(f->at, "ignored because frame_time is given (as in ARCSim)" +
                              std::string(f == &duration ? "; use end_time to stop the run" : ""));
    } else if (timestep) {
      // Style B.
      scene_.step_time = to_real(*timestep.value, timestep.at, kPositive);
      scene_.frame_steps = get_int(save_frames, 1, 1);
      scene_.save_every = get_int(save_every, 1, 1);
      scene_.frame_time = scene_.step_time * scene_.frame_steps;
      scene_.end_time = get_real(duration, kInfinity, or_infinite(kNonNegative));
      scene_.end_frame = kInfinity;
      for (const Found* f : {&frame_steps, &end_time, &end_frame})
        if (*f)
          top.warn(f->at, "ignored because timestep is given (as in ARCSim); use save_frames / duration");
    } else {
      fail(Loc{file_, ""}, "no time step: give frame_time (with frame_steps, end_time) or timestep (with "
                           "save_frames, save_every, duration)");
    }
    scene_.passive_time = get_real(top.get("passive_time"), kInfinity, or_infinite(kNonNegative));
    parse_adaptive_step(top.get("adaptive_time_step"));
    scene_.collision_budget = get_real(top.get("collision_budget"), kDefaultCollisionBudget, kPositive);
  }

  // `adaptive_time_step`: true, false, or an object of settings (an object turns it on unless "enabled": false).
  void parse_adaptive_step(const Found& f) {
    AdaptiveStepSpec& a = scene_.adaptive_step;
    if (!f) return;
    if (f.value->isBool()) {
      a.enabled = f.value->asBool();
    } else {
      ObjectReader r(*f.value, f.at, scene_.warnings);
      a.enabled = get_bool(r.get("enabled"), true);
      a.min_step = get_real(r.get("min_step"), 0, kNonNegative);
      a.max_motion = get_real(r.get("max_motion"), kInfinity, or_infinite(kPositive));
      a.max_correction = get_real(r.get("max_correction"), kInfinity, or_infinite(kPositive));
      a.reject_fallbacks = get_bool(r.get("reject_fallbacks"), true);
      a.grow_after = get_int(r.get("grow_after"), 8, 1);
      r.warn_unknown();
    }
    if (a.min_step == 0) a.min_step = scene_.step_time / 1024;
    if (a.enabled && a.min_step > scene_.step_time)
      fail(f.at.key("min_step"), "must not exceed the scene's time step (" + number(scene_.step_time) + " s), got " +
                                     number(a.min_step));
  }

  // --- modules and tunables ----------------------------------------------------------------------------------

  void parse_disable(const Found& f) {
    if (!f) return;
    const Json::Value& list = to_array(*f.value, f.at);
    for (unsigned i = 0; i < list.size(); ++i) {
      const Loc item = f.at.index(i);
      const std::string name = to_string(list[i], item);
      if (name.empty()) continue;  // sphere-break.json lists "": harmless
      if (std::find(std::begin(kModules), std::end(kModules), name) == std::end(kModules)) {
        std::string known;
        for (const char* m : kModules) known += (known.empty() ? "" : ", ") + std::string(m);
        scene_.warnings.push_back(item.str() + ": unknown module " + in_quotes(name) +
                                  " ignored (as in ARCSim); modules are " + known);
        continue;
      }
      scene_.disabled.insert(name);
    }
  }

  void parse_magic(const Found& f) {
    MagicParams& m = scene_.magic;
    if (!f) {
      m.projection_thickness = 0.1 * m.repulsion_thickness;
      return;
    }
    ObjectReader r(*f.value, f.at, scene_.warnings);
    m.fixed_high_res_mesh = get_bool(r.get("fixed_high_res_mesh"), m.fixed_high_res_mesh);
    m.remesh_at_start = get_bool(r.get("remesh_at_start"), m.remesh_at_start);
    m.handle_stiffness = get_real(r.get("handle_stiffness"), m.handle_stiffness, kNonNegative);
    m.collision_stiffness = get_real(r.get("collision_stiffness"), m.collision_stiffness, kNonNegative);
    m.repulsion_thickness = get_real(r.get("repulsion_thickness"), m.repulsion_thickness, kPositive);
    m.projection_thickness = get_real(r.get("projection_thickness"), 0.1 * m.repulsion_thickness, kNonNegative);
    m.edge_flip_threshold = get_real(r.get("edge_flip_threshold"), m.edge_flip_threshold);
    m.rib_stiffening = get_real(r.get("rib_stiffening"), m.rib_stiffening, kNonNegative);
    m.combine_tensors = get_bool(r.get("combine_tensors"), m.combine_tensors);
    m.preserve_creases = get_bool(r.get("preserve_creases"), m.preserve_creases);
    m.add_jitter = get_bool(r.get("add_jitter"), m.add_jitter);
    m.separation_step_size = get_real(r.get("separation_step_size"), m.separation_step_size, kPositive);
    m.relax_method = get_int(r.get("relax_method"), m.relax_method, 0, 1);
    m.max_cracks = get_int(r.get("max_cracks"), m.max_cracks, 0);
    m.enable_localopt = get_bool(r.get("enable_localopt"), m.enable_localopt);
    r.warn_unknown();
  }

  // `solver` (ours): how the implicit step's linear systems are solved (physics/solver_settings.hpp).
  void parse_solver(const Found& f) {
    if (!f) return;
    SolverSettings& s = scene_.solver;
    ObjectReader r(*f.value, f.at, scene_.warnings);
    s.pcg_min_nodes = get_int(r.get("pcg_min_nodes"), s.pcg_min_nodes, 0);
    s.pcg_tolerance = get_real(r.get("pcg_tolerance"), s.pcg_tolerance, Limits{0, 1, true, true});
    s.pcg_max_iterations = get_int(r.get("pcg_max_iterations"), s.pcg_max_iterations, 1, 1000);
    s.block_max_nodes = get_int(r.get("block_max_nodes"), s.block_max_nodes, 0);
    r.warn_unknown();
  }

  void parse_fracture(const Found& f) {
    if (!f) return;
    FractureSpec& s = scene_.fracture;
    ObjectReader r(*f.value, f.at, scene_.warnings);
    s.zone_rings = get_int(r.get("zone_rings"), s.zone_rings, 1, 20);
    s.max_zone_rings = get_int(r.get("max_zone_rings"), std::max(s.max_zone_rings, s.zone_rings), s.zone_rings, 40);
    s.support_stress = get_real(r.get("support_stress"), s.support_stress, kPositive);
    s.substepping = get_bool(r.get("substepping"), s.substepping);
    s.local_remesh = get_bool(r.get("local_remesh"), s.local_remesh);
    s.reproject = get_bool(r.get("reproject"), s.reproject);
    s.virtual_iterations = get_int(r.get("virtual_iterations"), s.virtual_iterations, 1, 50);
    if (const Found openings = r.get("substep_openings")) {
      const std::string mode = to_string(*openings.value, openings.at);
      if (mode != "one" && mode != "independent")
        fail(openings.at, "must be \"one\" or \"independent\", got \"" + mode + "\"");
      s.independent_openings = mode == "independent";
    }
    r.warn_unknown();
  }

  void parse_wind(const Found& f) {
    if (!f) return;
    ObjectReader r(*f.value, f.at, scene_.warnings);
    scene_.wind.density = get_real(r.get("density"), 1, kNonNegative);
    scene_.wind.velocity = get_vec3(r.get("velocity"), Vec3::Zero());
    scene_.wind.drag = get_real(r.get("drag"), 0, kNonNegative);
    r.warn_unknown();
  }

  // --- transforms and velocities -----------------------------------------------------------------------------

  // `rotate` = [angle (deg), axis x, y, z] -> unit quaternion. For keyframe velocities the angle is a rate
  // (deg/s) and the result is returned through `angular_velocity` (rad/s) instead.
  static Vec3 read_rotation_vector(const Json::Value& v, const Loc& at, double* degrees) {
    const Eigen::Vector4d r = to_vec<4>(v, at);
    const Vec3 axis = r.tail<3>();
    *degrees = r[0];
    if (axis.norm() == 0) {
      if (r[0] != 0) fail(at, "rotation axis is zero but the angle is " + number(r[0]) + " degrees");
      return Vec3::UnitX();
    }
    return axis;
  }

  Transform parse_transform(const Found& f, const Limits& scale_limits) {
    Transform t;
    if (!f) return t;
    ObjectReader r(*f.value, f.at, scene_.warnings);
    t.translation = get_vec3(r.get("translate"), Vec3::Zero());
    t.scale = get_real(r.get("scale"), 1, scale_limits);
    if (const Found rot = r.get("rotate")) {
      double degrees = 0;
      const Vec3 axis = read_rotation_vector(*rot.value, rot.at, &degrees);
      t.rotation = Transform::rotation_from_degrees(degrees, axis);
    }
    r.warn_unknown();
    return t;
  }

  // --- cloths and materials ----------------------------------------------------------------------------------

  void parse_cloths(const Found& f) {
    const Json::Value& list = to_array(required(f, "required: the scene needs at least one cloth"), f.at);
    if (list.empty()) fail(f.at, "must list at least one cloth");
    for (unsigned i = 0; i < list.size(); ++i) scene_.cloths.push_back(parse_cloth(list[i], f.at.index(i)));
  }

  ClothSpec parse_cloth(const Json::Value& v, const Loc& where) {
    ObjectReader r(v, where, scene_.warnings);
    ClothSpec c;
    const Found mesh = r.get("mesh");
    c.mesh = resolve(to_string(required(mesh), mesh.at), mesh.at);
    c.transform = parse_transform(r.get("transform"), kPositive);
    if (const Found vel = r.get("velocity")) {
      ObjectReader vr(*vel.value, vel.at, scene_.warnings);
      c.velocity.linear = get_vec3(vr.get("linear"), Vec3::Zero());
      c.velocity.angular = get_vec3(vr.get("angular"), Vec3::Zero());
      c.velocity.origin = get_vec3(vr.get("origin"), Vec3::Zero());
      vr.warn_unknown();
    }
    const Found materials = r.get("materials");
    const Json::Value& list = to_array(required(materials), materials.at);
    if (list.empty()) fail(materials.at, "must list at least one material");
    for (unsigned i = 0; i < list.size(); ++i) c.materials.push_back(parse_material(list[i], materials.at.index(i)));
    c.remeshing = parse_remeshing(r.get("remeshing"));
    if (const Found ref = r.get("reference")) {
      const std::string name = to_string(*ref.value, ref.at);
      if (name == "linear" || name == "sphere") {
        c.reference = name;
      } else {
        c.reference = resolve(name, ref.at);
        c.reference_is_mesh = true;
      }
    }
    r.warn_unknown();
    return c;
  }

  Material parse_material(const Json::Value& v, const Loc& where) {
    ObjectReader inline_keys(v, where, scene_.warnings);
    const Found data = inline_keys.get("data");
    const std::string data_name = get_string(data, "");
    if (data_name.empty()) {
      Material m = parse_isotropic(v, where, nullptr, Loc{});
      if (m.name.empty()) m.name = where.str();
      return m;
    }
    const std::string data_path = resolve(data_name, data.at);
    const std::string origin = " (material data named by " + data.at.str() + ")";
    try {
      const Json::Value file = read_json_file(data_path);
      if (!file.isObject()) fail(Loc{data_path, ""}, "the top level must be a JSON object");
      Material m;
      if (file.isMember("stretching") || file.isMember("bending"))
        m = parse_dde(v, where, file, data_path);
      else
        m = parse_isotropic(v, where, &file, Loc{data_path, ""});
      if (m.name.empty()) m.name = fs::path(data_path).stem().string();
      return m;
    } catch (const InputError& e) {
      const std::string what = e.what();
      // Problems inside the data file get a pointer back to the scene key that named it.
      if (what.compare(0, data_path.size(), data_path) == 0) throw InputError(what + origin);
      throw;
    }
  }

  // Keys every material may have; `get` looks a key up in the inline object first, then in the material file.
  template <typename Get>
  void parse_common_material_keys(Material& m, Get&& get) {
    m.name = get_string(get("name"), "");
    get_string(get("description"), "");
    m.stretching_mult = get_real(get("stretching_mult"), 1, kNonNegative);
    m.bending_mult = get_real(get("bending_mult"), 1, kNonNegative);
    m.damping = get_real(get("damping"), 0, kNonNegative);
    if (const Found limits = get("strain_limits")) {
      const Vec2 l = to_vec<2>(*limits.value, limits.at, or_infinite(kNonNegative));
      if (l[0] > l[1]) fail(limits.at, "min " + number(l[0]) + " is larger than max " + number(l[1]));
      m.strain_limits = l;
    }
    m.yield_curv = get_real(get("yield_curv"), kInfinity, or_infinite(kPositive));
    m.weakening = get_real(get("weakening"), 0, kNonNegative);
    m.yield_stretch = get_real(get("yield_stretch"), kInfinity, or_infinite(kPositive));
    m.plastic_flow = get_real(get("plastic_flow"), 0, kNonNegative);
    m.plastic_limit = get_real(get("plastic_limit"), kInfinity, or_infinite(Limits{1, kInfinity}));
    m.yield_stress = get_real(get("yield_stress"), kInfinity, or_infinite(kPositive));
    m.flow_rate = get_real(get("flow_rate"), 0, kNonNegative);
  }

  // Isotropic material from the inline object `v`, with defaults from one of our material files when `file`
  // is given (inline keys override the file's).
  Material parse_isotropic(const Json::Value& v, const Loc& where, const Json::Value* file, const Loc& file_at) {
    ObjectReader inline_keys(v, where, scene_.warnings);
    inline_keys.get("data");
    std::unique_ptr<ObjectReader> file_keys;
    if (file) file_keys = std::make_unique<ObjectReader>(*file, file_at, scene_.warnings);
    auto get = [&](const std::string& key) {
      Found found = inline_keys.get(key);
      if (file_keys) {
        Found from_file = file_keys->get(key);
        if (!found) found = from_file;
      }
      return found;
    };
    Material m;
    m.data_driven = false;
    parse_common_material_keys(m, get);
    const Found thickness = get("thickness");
    m.thickness = to_real(required(thickness, "required for an isotropic material (ARCSim aborts without it)"),
                          thickness.at, kPositive);
    const Found density = get("density");
    m.density = get_real(density, 0, kNonNegative);
    if (m.density == 0) inline_keys.warn(density.at, "is 0 (ARCSim's default when absent): the sheet has no mass");
    m.youngs_modulus = get_real(get("elastic_modulus"), 0, kNonNegative);
    m.poisson_ratio = get_real(get("poisson_ratio"), 0, Limits{0, 0.5, false, true});
    m.toughness = get_real(get("toughness"), 0, kNonNegative);
    m.fracture_bending_mult = get_real(get("fracture_bending_mult"), 0, kNonNegative);
    for (const char* key : {"thicken", "density_mult"}) {
      inline_keys.ignore(key, "only data-driven materials use it");
      if (file_keys) file_keys->ignore(key, "only data-driven materials use it");
    }
    ignore_never_read_material_keys(inline_keys);
    if (file_keys) ignore_never_read_material_keys(*file_keys);
    inline_keys.warn_unknown();
    if (file_keys) file_keys->warn_unknown();
    return m;
  }

  static void ignore_never_read_material_keys(ObjectReader& r) {
    r.ignore("bending_factor", "ARCSim 0.3 never read it; bending_mult scales bending stiffness");
    r.ignore("bend_width", "ARCSim 0.3 never read it");
    r.ignore("initiation_factor", "ARCSim 0.3 never read it");
  }

  // ARCSim data-driven material: `file` holds density (kg/m^2), stretching (6 x 4), bending (3 x 5).
  Material parse_dde(const Json::Value& v, const Loc& where, const Json::Value& file, const std::string& data_path) {
    ObjectReader inline_keys(v, where, scene_.warnings);
    inline_keys.get("data");
    Material m;
    m.data_driven = true;
    parse_common_material_keys(m, [&](const std::string& key) { return inline_keys.get(key); });
    m.thicken = get_real(inline_keys.get("thicken"), 1, kPositive);
    m.density_mult = get_real(inline_keys.get("density_mult"), 1, kNonNegative);
    for (const char* key : kIsotropicOnlyKeys)
      inline_keys.ignore(key, "ARCSim reads it only for isotropic materials, not with a data-driven `data` file");
    ignore_never_read_material_keys(inline_keys);
    inline_keys.warn_unknown();

    ObjectReader r(file, Loc{data_path, ""}, scene_.warnings);
    const Found density = r.get("density");
    m.dde_area_density = to_real(required(density), density.at, kPositive);
    const Found stretching = r.get("stretching");
    const Json::Value& rows = to_array(required(stretching), stretching.at);
    if (rows.size() != 6) fail(stretching.at, "must have 6 rows of 4 numbers, got " + std::to_string(rows.size()) + " rows");
    for (unsigned i = 0; i < 6; ++i) {
      const Eigen::Vector4d row = to_vec<4>(rows[i], stretching.at.index(i));
      for (int j = 0; j < 4; ++j) m.dde_stretching[i][j] = row[j];
    }
    const auto& s = m.dde_stretching[0];
    // The linearised model uses only row 0 (the small-strain sample).
    if (!(s[0] > 0 && s[2] > 0 && s[3] > 0))
      fail(stretching.at.index(0), "small-strain sample [k11, k12, k22, k33] must have k11, k22, k33 > 0");
    // ARCSim's navy-sparkle-sweat.json has k12^2 > k11 k22: fine for ARCSim's full table, indefinite for ours.
    if (!(s[0] * s[2] > s[1] * s[1]))
      r.warn(stretching.at.index(0), "small-strain sample is not positive definite (k12^2 >= k11 k22): the "
                                     "linearised membrane energy can be unstable");
    const Found bending = r.get("bending");
    const Json::Value& brows = to_array(required(bending), bending.at);
    if (brows.size() != 3) fail(bending.at, "must have 3 rows of 5 numbers, got " + std::to_string(brows.size()) + " rows");
    for (unsigned i = 0; i < 3; ++i) {
      const Eigen::Matrix<double, 5, 1> row = to_vec<5>(brows[i], bending.at.index(i), kNonNegative);
      for (int j = 0; j < 5; ++j) m.dde_bending[i][j] = row[j];
    }
    r.warn_unknown();
    return m;
  }

  RemeshingParams parse_remeshing(const Found& f) {
    RemeshingParams p;
    if (!f) return p;
    ObjectReader r(*f.value, f.at, scene_.warnings);
    p.refine_angle = get_real(r.get("refine_angle"), kInfinity, or_infinite(kPositive));
    const Found compression = r.get("refine_compression");
    p.has_refine_compression = bool(compression);
    p.refine_compression = get_real(compression, kInfinity, kPositive);
    p.refine_velocity = get_real(r.get("refine_velocity"), kInfinity, or_infinite(kPositive));
    if (const Found size = r.get("size")) {
      const Vec2 s = to_vec<2>(*size.value, size.at, or_infinite(kPositive));
      if (std::isinf(s[0])) fail(size.at.index(0), "must be finite, got " + number(s[0]));
      if (s[0] > s[1]) fail(size.at, "min " + number(s[0]) + " is larger than max " + number(s[1]));
      p.size_min = s[0];
      p.size_max = s[1];
      p.has_size = true;
    }
    p.size_uniform = get_real(r.get("size_uniform"), kInfinity, or_infinite(kPositive));
    const Found aspect = r.get("aspect_min");
    p.has_aspect_min = bool(aspect);
    p.aspect_min = get_real(aspect, -kInfinity, Limits{0, 1});
    const Found fracture = r.get("refine_fracture");
    p.has_refine_fracture = bool(fracture);
    p.refine_fracture = get_real(fracture, kInfinity, kNonNegative);
    // How plastic state follows remeshing edits (plasticity/plastic_embedding.hpp).
    if (const Found transfer = r.get("plastic_transfer")) {
      const std::string mode = to_string(*transfer.value, transfer.at);
      if (mode != "embedding" && mode != "interpolate")
        fail(transfer.at, "must be \"embedding\" or \"interpolate\", got \"" + mode + "\"");
      p.plastic_embedding = mode == "embedding";
    }
    r.warn_unknown();
    return p;
  }

  // --- motions, handles, obstacles ---------------------------------------------------------------------------

  void parse_motions(const Found& f) {
    if (!f) return;
    if (f.value->isObject())
      fail(f.at, "the object form (motfile, fps, transform: .mot motion files) is not supported; give an array "
                 "of keyframe arrays");
    const Json::Value& list = to_array(*f.value, f.at);
    for (unsigned i = 0; i < list.size(); ++i) scene_.motions.push_back(parse_motion(list[i], f.at.index(i)));
  }

  Motion parse_motion(const Json::Value& v, const Loc& where) {
    const Json::Value& keys = to_array(v, where);
    if (keys.empty()) fail(where, "a motion needs at least one keyframe");
    Motion motion;
    for (unsigned k = 0; k < keys.size(); ++k) {
      const Loc key_at = where.index(k);
      ObjectReader r(keys[k], key_at, scene_.warnings);
      Keyframe key;
      const Found time = r.get("time");
      key.time = to_real(required(time), time.at);
      if (k > 0 && !(key.time > motion.keys.back().time))
        fail(time.at, "keyframe times must increase, got " + number(key.time) + " after " +
                          number(motion.keys.back().time));
      key.transform = parse_transform(r.get("transform"), kNonNegative);  // scale 0 shrinks to a point (tshirt)
      if (const Found vel = r.get("velocity")) {
        ObjectReader vr(*vel.value, vel.at, scene_.warnings);
        key.has_velocity = true;
        key.velocity = get_vec3(vr.get("translate"), Vec3::Zero());
        // ARCSim: the transform default scale 1 means "no scale change"; any other value is the rate itself.
        const double scale = get_real(vr.get("scale"), 1);
        key.scale_rate = scale == 1 ? 0 : scale;
        if (const Found rot = vr.get("rotate")) {
          double degrees_per_s = 0;
          const Vec3 axis = read_rotation_vector(*rot.value, rot.at, &degrees_per_s);
          key.angular_velocity = axis.normalized() * (degrees_per_s * M_PI / 180);
        }
        vr.warn_unknown();
      }
      r.warn_unknown();
      motion.keys.push_back(key);
    }
    motion.finalize();
    return motion;
  }

  int parse_motion_index(const Found& f) {
    if (!f) return -1;
    const int m = to_int(*f.value, f.at);
    if (m < -1 || m >= static_cast<int>(scene_.motions.size()))
      fail(f.at, "motion index " + std::to_string(m) + " out of range (the scene has " +
                     std::to_string(scene_.motions.size()) + " motions; -1 = none)");
    return m;
  }

  std::vector<int> parse_node_list(const Found& f) {
    const Json::Value& list = to_array(*f.value, f.at);
    std::vector<int> nodes;
    for (unsigned i = 0; i < list.size(); ++i) nodes.push_back(to_int(list[i], f.at.index(i), 0));
    return nodes;
  }

  void parse_handles(const Found& f) {
    if (!f) return;
    const Json::Value& list = to_array(*f.value, f.at);
    for (unsigned i = 0; i < list.size(); ++i) scene_.handles.push_back(parse_handle(list[i], f.at.index(i)));
  }

  HandleSpec parse_handle(const Json::Value& v, const Loc& where) {
    ObjectReader r(v, where, scene_.warnings);
    HandleSpec h;
    const Found type = r.get("type");
    h.type = get_string(type, "node");
    if (h.type != "node" && h.type != "circle" && h.type != "glue" && h.type != "soft")
      fail(type.at, "unknown handle type " + in_quotes(h.type) + " (node, circle, glue or soft)");
    const Found cloth = r.get("cloth");
    h.cloth = get_int(cloth, 0);
    if (h.cloth < 0 || h.cloth >= static_cast<int>(scene_.cloths.size()))
      fail(cloth.at, "cloth index " + std::to_string(h.cloth) + " out of range (the scene has " +
                         std::to_string(scene_.cloths.size()) + " cloths)");
    if (h.type == "node") {
      h.label = get_int(r.get("label"), -1, -1);
      const Found nodes = r.get("nodes");
      if (h.label == -1)
        h.nodes = parse_node_list(Found{&required(nodes, "required when no label is given"), nodes.at});
      else if (nodes)
        r.warn(nodes.at, "ignored because label is given (as in ARCSim)");
      h.motion = parse_motion_index(r.get("motion"));
    } else if (h.type == "circle") {
      const Found label = r.get("label");
      h.label = to_int(required(label), label.at, 0);
      h.motion = parse_motion_index(r.get("motion"));
      const Found circumference = r.get("circumference");
      h.circumference = to_real(required(circumference), circumference.at, kPositive);
      const Found u = r.get("u");
      h.u = to_vec<2>(required(u), u.at);
      const Found center = r.get("center"), axis0 = r.get("axis0"), axis1 = r.get("axis1");
      h.center = to_vec<3>(required(center), center.at);
      h.axis0 = to_vec<3>(required(axis0), axis0.at);
      h.axis1 = to_vec<3>(required(axis1), axis1.at);
    } else if (h.type == "glue") {
      const Found nodes = r.get("nodes");
      h.nodes = parse_node_list(Found{&required(nodes), nodes.at});
      if (h.nodes.size() != 2) fail(nodes.at, "a glue handle joins exactly 2 nodes, got " + std::to_string(h.nodes.size()));
    } else {  // soft
      const Found center = r.get("center"), radius = r.get("radius");
      h.center = to_vec<3>(required(center), center.at);
      h.radius = to_real(required(radius), radius.at, kPositive);
      h.motion = parse_motion_index(r.get("motion"));
    }
    h.start_time = get_real(r.get("start_time"), 0, kNonNegative);
    const Found end = r.get("end_time");
    h.end_time = get_real(end, kInfinity, or_infinite(kNonNegative));
    if (h.end_time < h.start_time)
      fail(end.at, "must not be before start_time " + number(h.start_time) + ", got " + number(h.end_time));
    h.fade_time = get_real(r.get("fade_time"), 0, kNonNegative);
    r.warn_unknown();
    return h;
  }

  void parse_obstacles(const Found& f) {
    if (!f) return;
    if (f.value->isString()) {
      parse_obstacle_pattern(f.value->asString(), f.at);
      return;
    }
    const Json::Value& list = to_array(*f.value, f.at);
    for (unsigned i = 0; i < list.size(); ++i) scene_.obstacles.push_back(parse_obstacle(list[i], f.at.index(i)));
  }

  // ARCSim's "obstacles": "path%d.obj" form: files 0, 1, ... until one is missing; obstacle i follows motion i.
  void parse_obstacle_pattern(const std::string& pattern, const Loc& where) {
    const IndexPattern name(pattern, where);
    const int kMaxObstacles = 100000;  // a bound, so a pathological folder cannot make this loop forever
    for (int i = 0; i < kMaxObstacles; ++i) {
      std::string found;
      for (const std::string& candidate : scene_path_candidates(name(i), file_))
        if (is_file(candidate)) {
          found = candidate;
          break;
        }
      if (found.empty()) {
        if (i == 0) resolve(name(0), where);  // fails, listing the paths tried
        return;
      }
      add_referenced(found);
      ObstacleSpec o;
      o.mesh = found;
      o.motion = i < static_cast<int>(scene_.motions.size()) ? i : -1;
      scene_.obstacles.push_back(o);
    }
  }

  ObstacleSpec parse_obstacle(const Json::Value& v, const Loc& where) {
    ObjectReader r(v, where, scene_.warnings);
    ObstacleSpec o;
    const Found mesh = r.get("mesh");
    o.mesh = resolve(to_string(required(mesh), mesh.at), mesh.at);
    o.transform = parse_transform(r.get("transform"), kPositive);
    o.motion = parse_motion_index(r.get("motion"));
    o.start_time = get_real(r.get("start_time"), 0, kNonNegative);
    const Found end = r.get("end_time");
    o.end_time = get_real(end, kInfinity, or_infinite(kNonNegative));
    if (o.end_time < o.start_time)
      fail(end.at, "must not be before start_time " + number(o.start_time) + ", got " + number(o.end_time));
    const Found proxy = r.get("proxy");
    o.proxy = get_string(proxy, "");
    if (!o.proxy.empty() && o.proxy != "floor")
      fail(proxy.at, "unknown collision proxy " + in_quotes(o.proxy) + " (only \"floor\" exists)");
    r.warn_unknown();
    return o;
  }

  void parse_morphs(const Found& f) {
    if (!f) return;
    const Json::Value& list = to_array(*f.value, f.at);
    if (!list.empty()) fail(f.at, "morph targets are not supported (ARCSim 0.3 exits when it uses them)");
  }

  // --- whole-scene checks ------------------------------------------------------------------------------------

  // As ARCSim: modules with nothing to do are switched off after parsing.
  void disable_unused_modules() {
    bool strain_limits = false, plasticity = false, fracture = false;
    for (const ClothSpec& c : scene_.cloths)
      for (const Material& m : c.materials) {
        strain_limits |= std::isfinite(m.strain_limits[0]) || std::isfinite(m.strain_limits[1]);
        plasticity |= std::isfinite(m.yield_curv) || (std::isfinite(m.yield_stress) && m.flow_rate > 0);
        fracture |= m.toughness > 0;
      }
    if (!strain_limits) scene_.disabled.insert("strainlimiting");
    if (!plasticity) scene_.disabled.insert("plasticity");
    if (!fracture) scene_.disabled.insert("fracture");
  }

  // Keys whose ARCSim defaults give inf/NaN sizing: required while the module that uses them runs.
  void check_required_for_enabled_modules() {
    const bool remeshing = scene_.enabled("remeshing");
    const bool fracture = scene_.enabled("fracture");
    for (size_t i = 0; i < scene_.cloths.size(); ++i) {
      const ClothSpec& c = scene_.cloths[i];
      const Loc remeshing_at = at("cloths[" + std::to_string(i) + "].remeshing");
      const std::string why_remesh =
          "required while the remeshing module is enabled (ARCSim's default gives inf/NaN sizing); add it or "
          "\"disable\": [\"remeshing\"]";
      if (remeshing) {
        if (!c.remeshing.has_size) fail(remeshing_at.key("size"), why_remesh);
        if (!c.remeshing.has_aspect_min) fail(remeshing_at.key("aspect_min"), why_remesh);
        if (!c.remeshing.has_refine_compression) fail(remeshing_at.key("refine_compression"), why_remesh);
      }
      const bool breakable = std::any_of(c.materials.begin(), c.materials.end(),
                                         [](const Material& m) { return m.toughness > 0; });
      if (fracture && breakable && !c.remeshing.has_refine_fracture)
        fail(remeshing_at.key("refine_fracture"),
             "required when a material has toughness > 0 and the fracture module is enabled (ARCSim's default "
             "gives NaN sizing); 0 turns the fracture refinement off");
    }
  }
};

}  // namespace

std::vector<std::string> scene_path_candidates(const std::string& name, const std::string& scene_path) {
  const fs::path p(name);
  if (p.is_absolute()) return {p.lexically_normal().string()};
  const fs::path dir = scene_dir_of(scene_path);
  std::vector<std::string> out;
  // The parent comes before the working directory: an ARCSim scene run from elsewhere must find ARCSim's
  // materials/paper.json, not a same-named file that happens to sit in the caller's directory.
  for (const fs::path& candidate : {dir / p, dir / ".." / p, p}) {
    const std::string s = candidate.lexically_normal().string();
    if (std::find(out.begin(), out.end(), s) == out.end()) out.push_back(s);
  }
  return out;
}

Scene load_scene(const std::string& path) {
  Scene scene;
  scene.path = path;
  scene.base_dir = scene_dir_of(path);
  const Json::Value root = read_json_file(path);
  SceneParser(scene, path).parse(root);
  return scene;
}

Material load_material_file(const std::string& path, std::vector<std::string>* warnings) {
  Scene scratch;
  Material m = SceneParser(scratch, path).parse_material_file(path);
  if (warnings) warnings->insert(warnings->end(), scratch.warnings.begin(), scratch.warnings.end());
  return m;
}

}  // namespace arcsim
