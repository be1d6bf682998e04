#include "io/obj.hpp"


#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <unordered_set>

#include "io/atomic_file.hpp"
#include "math/errors.hpp"
#include "mesh/validate.hpp"

namespace arcsim {

namespace {

// ------------------------------------------------------------------------------------------------------------
// Messages

// A token quoted in a message: bounded length and printable, so that the message stays one readable line even
// for a binary file.
std::string quoted(std::string_view token) {
  constexpr size_t kMaxShown = 40;
  std::string out = "'";
  for (char c : token.substr(0, kMaxShown)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  if (token.size() > kMaxShown) out += "...";
  return out + "'";
}

// A place in the file being read; fail() throws the one-line InputError "<path>:<line>: <problem>".
struct Where {
  const std::string& path;
  int line;
  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(path + ":" + std::to_string(line) + ": " + problem);
  }
};

// ------------------------------------------------------------------------------------------------------------
// Tokens and numbers

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Splits a line into words, dropping a `#` comment.
std::vector<std::string_view> split_words(std::string_view line) {
  const size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// from_chars does not take a leading '+', which some exporters write.
std::string_view without_plus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') token.remove_prefix(1);
  return token;
}

// Locale-independent, exact (round-trips the 17-digit output of write_obj). Rejects NaN and infinities.
double parse_double(std::string_view token, const Where& where, const std::string& what) {
  const std::string_view t = without_plus(token);
  double value = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (ec != std::errc() || end != t.data() + t.size()) where.fail("bad number " + quoted(token) + " in " + what);
  if (!std::isfinite(value)) where.fail("non-finite number " + quoted(token) + " in " + what);
  return value;
}

long parse_long(std::string_view token, const Where& where, const std::string& what) {
  const std::string_view t = without_plus(token);
  long value = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (ec != std::errc() || end != t.data() + t.size()) where.fail("bad integer " + quoted(token) + " in " + what);
  return value;
}

int parse_int(std::string_view token, const Where& where, const std::string& what) {
  const long value = parse_long(token, where, what);
  if (value < INT32_MIN || value > INT32_MAX) where.fail("integer " + quoted(token) + " out of range in " + what);
  return static_cast<int>(value);
}

// Checks that a line `tag a b c ...` has between min_args and max_args arguments.
void expect_args(const std::vector<std::string_view>& words, size_t min_args, size_t max_args, const Where& where) {
  const size_t args = words.size() - 1;
  const std::string tag(words[0]);
  const std::string need = min_args == max_args ? std::to_string(min_args)
                                                : std::to_string(min_args) + " to " + std::to_string(max_args);
  if (args < min_args) where.fail("too few values for '" + tag + "' (" + std::to_string(args) + ", need " + need + ")");
  if (args > max_args) where.fail("too many values for '" + tag + "' (" + std::to_string(args) + ", need " + need + ")");
}

Vec3 parse_vec3(const std::vector<std::string_view>& words, size_t first, const Where& where) {
  const std::string what = "'" + std::string(words[0]) + "'";
  return Vec3(parse_double(words[first], where, what), parse_double(words[first + 1], where, what),
              parse_double(words[first + 2], where, what));
}

// Nine numbers, row-major.
Mat3 parse_mat3(const std::vector<std::string_view>& words, const Where& where) {
  const std::string what = "'" + std::string(words[0]) + "'";
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = parse_double(words[1 + i], where, what);
  return m;
}

// ------------------------------------------------------------------------------------------------------------
// Raw file contents, before indices are resolved (ms lines may follow the faces that use them, and relative
// indices count back from the elements defined before their own line).

struct RawCorner {
  long node = 0;
  long rest = 0;
  bool has_rest = false;
};

struct RawFace {
  std::vector<RawCorner> corners;
  int line = 0;
  long nodes_before = 0, vts_before = 0, mss_before = 0;  // elements defined above this line
  int material = 0;
  double thickness = 0;
  Mat3 Sp = Mat3::Zero();
  Mat3 Fp = Mat3::Identity();
  double damage = 0;
};

struct RawEdge {
  long n0 = 0, n1 = 0;
  int line = 0;
  long nodes_before = 0;
  double rest_theta = 0, damage = 0;
  bool preserve = false, has_rest_theta = false;
};

struct RawObj {
  std::vector<Vec3> node_x, node_v;
  std::vector<int> node_label;
  std::vector<Vec3> vt, ms;
  std::vector<RawFace> faces;
  std::vector<RawEdge> edges;
  int unknown_tag_lines = 0;
};

// Parses `i`, `i/k`, `i/k/n` or `i//n` (n, a normal index, is ignored).
RawCorner parse_corner(std::string_view token, const Where& where) {
  RawCorner c;
  const size_t slash = token.find('/');
  const std::string_view node = token.substr(0, slash);
  if (node.empty()) where.fail("face corner " + quoted(token) + " has no node index");
  c.node = parse_long(node, where, "face corner " + quoted(token));
  if (slash == std::string_view::npos) return c;
  std::string_view rest = token.substr(slash + 1);
  const size_t slash2 = rest.find('/');
  if (slash2 != std::string_view::npos) {
    const std::string_view normal = rest.substr(slash2 + 1);
    if (normal.find('/') != std::string_view::npos) where.fail("bad face corner " + quoted(token));
    if (!normal.empty()) parse_long(normal, where, "face corner " + quoted(token));  // syntax only
    rest = rest.substr(0, slash2);
  }
  if (!rest.empty()) {
    c.rest = parse_long(rest, where, "face corner " + quoted(token));
    c.has_rest = true;
  }
  return c;
}

// Standard OBJ statements that carry nothing for a sheet, and ARCSim's `ny` (plastic position, which this
// implementation does not keep): skipped without being counted as unknown.
bool is_ignored_standard_tag(std::string_view tag) {
  return tag == "vn" || tag == "vp" || tag == "o" || tag == "g" || tag == "s" || tag == "mtllib" ||
         tag == "usemtl" || tag == "l" || tag == "p" || tag == "ny";
}

constexpr size_t kMaxPolygonCorners = 1000;

void parse_line(const std::vector<std::string_view>& words, const Where& where, RawObj& raw) {
  const std::string_view tag = words[0];
  auto last_node = [&]() -> size_t {
    if (raw.node_x.empty()) where.fail("'" + std::string(tag) + "' before any 'v' line");
    return raw.node_x.size() - 1;
  };
  auto last_face = [&]() -> RawFace& {
    if (raw.faces.empty()) where.fail("'" + std::string(tag) + "' before any 'f' line");
    return raw.faces.back();
  };
  auto last_edge = [&]() -> RawEdge& {
    if (raw.edges.empty()) where.fail("'" + std::string(tag) + "' before any 'e' line");
    return raw.edges.back();
  };

  if (tag == "v") {
    // Extra numbers (w, or vertex colours written by some exporters) are checked but not used.
    expect_args(words, 3, 7, where);
    for (size_t i = 4; i < words.size(); ++i) parse_double(words[i], where, "'v'");
    raw.node_x.push_back(parse_vec3(words, 1, where));
    raw.node_v.push_back(Vec3::Zero());
    raw.node_label.push_back(0);
  } else if (tag == "vt") {
    expect_args(words, 2, 3, where);
    const std::string what = "'vt'";
    Vec3 u(parse_double(words[1], where, what), parse_double(words[2], where, what), 0.0);
    if (words.size() == 4) u.z() = parse_double(words[3], where, what);
    raw.vt.push_back(u);
  } else if (tag == "ms") {
    expect_args(words, 3, 3, where);
    raw.ms.push_back(parse_vec3(words, 1, where));
  } else if (tag == "nv") {
    expect_args(words, 3, 3, where);
    raw.node_v[last_node()] = parse_vec3(words, 1, where);
  } else if (tag == "nl") {
    expect_args(words, 1, 1, where);
    raw.node_label[last_node()] = parse_int(words[1], where, "'nl'");
  } else if (tag == "f") {
    if (words.size() < 4)
      where.fail("face with " + std::to_string(words.size() - 1) + " corners (need at least 3)");
    // The triangulation tries every corner as fan root (quadratic cost): bound it so no file can stall us.
    if (words.size() - 1 > kMaxPolygonCorners)
      where.fail("face with " + std::to_string(words.size() - 1) + " corners (at most " +
                 std::to_string(kMaxPolygonCorners) + ")");
    RawFace face;
    face.line = where.line;
    face.nodes_before = static_cast<long>(raw.node_x.size());
    face.vts_before = static_cast<long>(raw.vt.size());
    face.mss_before = static_cast<long>(raw.ms.size());
    for (size_t i = 1; i < words.size(); ++i) face.corners.push_back(parse_corner(words[i], where));
    raw.faces.push_back(std::move(face));
  } else if (tag == "tm") {
    expect_args(words, 1, 1, where);
    const int material = parse_int(words[1], where, "'tm'");
    if (material < 0) where.fail("negative material index " + quoted(words[1]));
    last_face().material = material;
  } else if (tag == "th") {
    expect_args(words, 1, 1, where);
    const double h = parse_double(words[1], where, "'th'");
    if (h < 0) where.fail("negative thickness " + quoted(words[1]));
    last_face().thickness = h;
  } else if (tag == "tp") {
    expect_args(words, 9, 9, where);
    last_face().Sp = parse_mat3(words, where);
  } else if (tag == "ts") {
    expect_args(words, 9, 9, where);
    last_face().Fp = parse_mat3(words, where);
  } else if (tag == "td") {
    expect_args(words, 1, 1, where);
    const double d = parse_double(words[1], where, "'td'");
    if (d < 0) where.fail("negative damage " + quoted(words[1]));
    last_face().damage = d;
  } else if (tag == "e") {
    expect_args(words, 2, 2, where);
    RawEdge e;
    e.n0 = parse_long(words[1], where, "'e'");
    e.n1 = parse_long(words[2], where, "'e'");
    e.line = where.line;
    e.nodes_before = static_cast<long>(raw.node_x.size());
    raw.edges.push_back(e);
  } else if (tag == "ea") {
    expect_args(words, 1, 1, where);
    RawEdge& e = last_edge();
    e.rest_theta = parse_double(words[1], where, "'ea'");
    e.has_rest_theta = true;
  } else if (tag == "ed") {
    expect_args(words, 1, 1, where);
    const double d = parse_double(words[1], where, "'ed'");
    if (d < 0) where.fail("negative damage " + quoted(words[1]));
    last_edge().damage = d;
  } else if (tag == "ep") {
    // ARCSim writes a bare `ep`; a number, if given, says whether the edge is preserved.
    expect_args(words, 0, 1, where);
    last_edge().preserve = words.size() == 1 || parse_int(words[1], where, "'ep'") != 0;
  } else if (!is_ignored_standard_tag(tag)) {
    ++raw.unknown_tag_lines;
  }
}

RawObj parse_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  RawObj raw;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::vector<std::string_view> words = split_words(line);
    if (words.empty()) continue;
    parse_line(words, Where{path, line_number}, raw);
  }
  if (in.bad()) throw InputError(path + ": read error");
  return raw;
}

// ------------------------------------------------------------------------------------------------------------
// Index resolution and triangulation

// OBJ indices are 1-based; negative ones count back from the last element defined above the line.
int resolve_index(long raw_index, long defined_before, size_t total, const std::string& kind, const Where& where) {
  if (raw_index == 0) where.fail(kind + " index 0 (indices start at 1)");
  if (raw_index > 0) {
    if (static_cast<unsigned long>(raw_index) > total)
      where.fail(kind + " index " + std::to_string(raw_index) + " out of range (" + std::to_string(total) +
                 " defined)");
    return static_cast<int>(raw_index - 1);
  }
  if (raw_index < -defined_before)
    where.fail("relative " + kind + " index " + std::to_string(raw_index) + " out of range (" +
               std::to_string(defined_before) + " defined above)");
  return static_cast<int>(defined_before + raw_index);
}

double corner_angle(const Vec3& at, const Vec3& p, const Vec3& q) {
  const Vec3 a = p - at, b = q - at;
  return std::atan2(a.cross(b).norm(), a.dot(b));  // 0 for a zero-length side, no NaN
}

double smallest_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  return std::min({corner_angle(a, b, c), corner_angle(b, c, a), corner_angle(c, a, b)});
}

// Fan-triangulates a polygon of rest vertices from the corner whose fan has the largest minimum angle (rest
// space), keeping the corner order and hence the orientation. Triangles are returned in fan order.
std::vector<std::array<int, 3>> triangulate(const std::vector<int>& corners, const std::vector<Vec3>& vert_u) {
  const size_t n = corners.size();
  if (n == 3) return {{corners[0], corners[1], corners[2]}};
  size_t best_root = 0;
  double best_angle = -1;
  for (size_t root = 0; root < n; ++root) {
    double fan_min = kInfinity;
    for (size_t i = 1; i + 1 < n; ++i)
      fan_min = std::min(fan_min, smallest_angle(vert_u[corners[root]], vert_u[corners[(root + i) % n]],
                                                 vert_u[corners[(root + i + 1) % n]]));
    if (fan_min > best_angle) {
      best_angle = fan_min;
      best_root = root;
    }
  }
  std::vector<std::array<int, 3>> tris;
  for (size_t i = 1; i + 1 < n; ++i)
    tris.push_back({corners[best_root], corners[(best_root + i) % n], corners[(best_root + i + 1) % n]});
  return tris;
}

uint64_t node_pair_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

}  // namespace

ObjData read_obj(const std::string& path) {
  RawObj raw = parse_file(path);
  ObjData obj;
  obj.node_x = std::move(raw.node_x);
  obj.node_v = std::move(raw.node_v);
  obj.node_label = std::move(raw.node_label);
  obj.unknown_tag_lines = raw.unknown_tag_lines;
  obj.has_rest_coords = !raw.vt.empty() || !raw.ms.empty();

  // 3D `ms` rest coordinates take precedence: then /k indices count ms lines, not vt lines.
  const bool use_ms = !raw.ms.empty();
  const std::vector<Vec3>& listed_u = use_ms ? raw.ms : raw.vt;
  const std::string rest_kind = use_ms ? "ms" : "vt";
  const size_t node_count = obj.node_x.size();

  // Rest vertices: the listed ones, then those created for corners without /k. Each belongs to one node.
  std::vector<Vec3> all_u = listed_u;
  std::vector<int> owner(listed_u.size(), kNone);
  std::vector<int> node_first_vert(node_count, kNone);  // reused by corners without /k, as ARCSim does
  std::vector<std::vector<int>> face_verts(raw.faces.size());
  for (size_t f = 0; f < raw.faces.size(); ++f) {
    const RawFace& face = raw.faces[f];
    const Where where{path, face.line};
    for (const RawCorner& c : face.corners) {
      const int node = resolve_index(c.node, face.nodes_before, node_count, "node", where);
      int vert;
      if (c.has_rest) {
        const long before = use_ms ? face.mss_before : face.vts_before;
        vert = resolve_index(c.rest, before, listed_u.size(), rest_kind, where);
        if (owner[vert] == kNone) {
          owner[vert] = node;
        } else if (owner[vert] != node) {
          where.fail("rest vertex " + std::to_string(vert + 1) + " (" + rest_kind + ") used with nodes " +
                     std::to_string(owner[vert] + 1) + " and " + std::to_string(node + 1));
        }
      } else if (node_first_vert[node] != kNone) {
        vert = node_first_vert[node];
      } else {
        vert = static_cast<int>(all_u.size());
        all_u.push_back(obj.node_x[node]);
        owner.push_back(node);
      }
      if (node_first_vert[node] == kNone) node_first_vert[node] = vert;
      face_verts[f].push_back(vert);
    }
  }

  // Drop rest vertices that no face uses (e.g. spare texture coordinates), keeping the order of the others.
  std::vector<int> new_index(all_u.size(), kNone);
  for (size_t k = 0; k < all_u.size(); ++k) {
    if (owner[k] == kNone) continue;
    new_index[k] = static_cast<int>(obj.vert_u.size());
    obj.vert_u.push_back(all_u[k]);
    obj.vert_node.push_back(owner[k]);
  }

  std::unordered_set<uint64_t> sides;  // node pairs joined by a triangle side, to check edge records
  for (size_t f = 0; f < raw.faces.size(); ++f) {
    const RawFace& face = raw.faces[f];
    std::vector<int> corners;
    for (int k : face_verts[f]) corners.push_back(new_index[k]);
    for (const std::array<int, 3>& tri : triangulate(corners, obj.vert_u)) {
      obj.tris.push_back(tri);
      obj.tri_line.push_back(face.line);
      obj.tri_material.push_back(face.material);
      obj.tri_thickness.push_back(face.thickness);
      obj.tri_Sp.push_back(face.Sp);
      obj.tri_Fp.push_back(face.Fp);
      obj.tri_damage.push_back(face.damage);
      for (int i = 0; i < 3; ++i)
        sides.insert(node_pair_key(obj.vert_node[tri[i]], obj.vert_node[tri[(i + 1) % 3]]));
    }
  }

  for (const RawEdge& e : raw.edges) {
    const Where where{path, e.line};
    ObjData::EdgeRecord rec;
    rec.n0 = resolve_index(e.n0, e.nodes_before, node_count, "node", where);
    rec.n1 = resolve_index(e.n1, e.nodes_before, node_count, "node", where);
    if (!sides.count(node_pair_key(rec.n0, rec.n1)))
      where.fail("edge " + std::to_string(rec.n0 + 1) + "-" + std::to_string(rec.n1 + 1) +
                 " is not a side of any face");
    rec.rest_theta = e.rest_theta;
    rec.damage = e.damage;
    rec.preserve = e.preserve;
    rec.has_rest_theta = e.has_rest_theta;
    obj.edges.push_back(rec);
  }
  return obj;
}

namespace {

// Per-element vectors of ObjData may be empty (defaults) or have one entry per element.
void check_size(size_t size, size_t expected, const char* name, const std::string& path) {
  if (size != 0 && size != expected)
    throw InputError(path + ": inconsistent mesh data (" + name + " has " + std::to_string(size) +
                     " entries, expected " + std::to_string(expected) + ")");
}

void check_obj_data(const ObjData& obj, const std::string& path) {
  const size_t nodes = obj.node_x.size(), tris = obj.tris.size();
  check_size(obj.node_v.size(), nodes, "node_v", path);
  check_size(obj.node_label.size(), nodes, "node_label", path);
  if (obj.vert_node.size() != obj.vert_u.size()) check_size(1, 0, "vert_node", path);
  for (size_t k = 0; k < obj.vert_node.size(); ++k)
    if (obj.vert_node[k] < 0 || static_cast<size_t>(obj.vert_node[k]) >= nodes)
      throw InputError(path + ": rest vertex " + std::to_string(k + 1) + " names node " +
                       std::to_string(obj.vert_node[k] + 1) + " of " + std::to_string(nodes));
  check_size(obj.tri_line.size(), tris, "tri_line", path);
  check_size(obj.tri_material.size(), tris, "tri_material", path);
  check_size(obj.tri_thickness.size(), tris, "tri_thickness", path);
  check_size(obj.tri_Sp.size(), tris, "tri_Sp", path);
  check_size(obj.tri_Fp.size(), tris, "tri_Fp", path);
  check_size(obj.tri_damage.size(), tris, "tri_damage", path);
  for (size_t t = 0; t < obj.tri_material.size(); ++t)
    if (obj.tri_material[t] < 0)
      throw InputError(path + ": face " + std::to_string(t + 1) + " has a negative material index");
}

}  // namespace

Mesh build_mesh(const ObjData& obj, const std::string& path) {
  check_obj_data(obj, path);
  if (obj.tris.empty()) throw InputError(path + ": no faces");
  TriangleInput input;
  input.node_count = obj.node_x.size();
  input.vert_node = obj.vert_node;
  input.vert_u = obj.vert_u;
  input.tris = obj.tris;
  input.tri_source_line = obj.tri_line;
  validate_triangles(input, path);

  Mesh mesh;
  try {
    mesh = Mesh::from_triangles(obj.node_x, obj.vert_u, obj.vert_node, obj.tris, obj.tri_material);
  } catch (const std::logic_error& e) {
    // Only reachable if validation let a non-manifold input through; still a bad file, not a crash.
    throw InputError(path + ": " + e.what());
  }

  for (size_t n = 0; n < mesh.nodes.size(); ++n) {
    if (!obj.node_v.empty()) mesh.nodes[n].v = obj.node_v[n];
    if (!obj.node_label.empty()) mesh.nodes[n].label = obj.node_label[n];
  }
  for (size_t t = 0; t < mesh.faces.size(); ++t) {
    Face& face = mesh.faces[t];
    if (!obj.tri_thickness.empty()) face.thickness = obj.tri_thickness[t];
    if (!obj.tri_Sp.empty()) face.Sp = obj.tri_Sp[t];
    if (!obj.tri_Fp.empty()) face.Fp = obj.tri_Fp[t];
    if (!obj.tri_damage.empty()) face.damage = obj.tri_damage[t];
  }
  for (const ObjData::EdgeRecord& rec : obj.edges) {
    const int nodes = static_cast<int>(mesh.nodes.size());
    const int e = (rec.n0 >= 0 && rec.n0 < nodes && rec.n1 >= 0 && rec.n1 < nodes) ? mesh.find_edge(rec.n0, rec.n1)
                                                                                    : kNone;
    if (e == kNone)
      throw InputError(path + ": edge record " + std::to_string(rec.n0 + 1) + "-" + std::to_string(rec.n1 + 1) +
                       " is not an edge of the mesh");
    Edge& edge = mesh.edges[e];
    if (rec.has_rest_theta) edge.rest_theta = rec.rest_theta;
    edge.damage = rec.damage;
    edge.preserve = rec.preserve;
  }
  // As in ARCSim: remeshing must keep the sheet outline, rest-space seams and handle (labelled) nodes.
  for (size_t n = 0; n < mesh.nodes.size(); ++n) {
    Node& node = mesh.nodes[n];
    if (node.label != 0 || node.verts.size() > 1 || mesh.is_boundary_node(static_cast<int>(n))) node.preserve = true;
  }
  return mesh;
}

Mesh load_obj_mesh(const std::string& path) { return build_mesh(read_obj(path), path); }

// ------------------------------------------------------------------------------------------------------------
// Writing

namespace {

// %.17g without the locale: every double reads back bit-identically.
void append_number(std::string& out, double x) {
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x, std::chars_format::general, 17);
  out.append(buffer, result.ptr);
}

void append_int(std::string& out, long long n) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, n);
  out.append(buffer, result.ptr);
}

void append_line(std::string& out, const char* tag, std::initializer_list<double> values) {
  out += tag;
  for (double x : values) {
    out += ' ';
    append_number(out, x);
  }
  out += '\n';
}

void append_vec3(std::string& out, const char* tag, const Vec3& x) { append_line(out, tag, {x.x(), x.y(), x.z()}); }

void append_mat3(std::string& out, const char* tag, const Mat3& m) {
  append_line(out, tag, {m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2)});
}

// 1-based file numbers of the live elements (dead ones are skipped and get kNone).
template <typename T>
std::vector<int> live_numbers(const std::vector<T>& items, size_t& count) {
  std::vector<int> number(items.size(), kNone);
  count = 0;
  for (size_t i = 0; i < items.size(); ++i)
    if (!items[i].dead) number[i] = static_cast<int>(++count);
  return number;
}

// The rest angle each edge gets when the written file is read back without an edge record, bit for bit. The
// reader (Mesh::from_triangles) adds the faces in file order (the live faces in index order); the first of an
// edge's two faces creates it, oriented along that face's winding, and its rest angle is the rest dihedral taken
// in that orientation. Ours may be stored the other way round after edits (f[0] is the face running n[0] -> n[1]):
// then the same dihedral is taken with the ends and the faces swapped, as the reader will. Boundary edges and seams
// (the faces do not share the edge's rest verts) get 0 either way. NaN (every edge record explicit) where the
// reader would not rebuild the same edges.
std::vector<double> default_rest_angles_on_reload(const Mesh& mesh) {
  std::vector<double> angles(mesh.edges.size(), 0.0);
  // Meshes are built and edited face by face (Mesh::add_face refuses what the reader would), so the one way the
  // reader's rebuild can differ is two edges between the same nodes, which it would merge.
  for (size_t e = 0; e < mesh.edges.size(); ++e) {
    const Edge& edge = mesh.edges[e];
    if (!edge.dead && mesh.find_edge(edge.n[0], edge.n[1]) != static_cast<int>(e)) {
      std::fill(angles.begin(), angles.end(), std::nan(""));
      return angles;
    }
  }
  for (size_t e = 0; e < mesh.edges.size(); ++e) {
    const Edge& edge = mesh.edges[e];
    if (edge.dead || edge.is_boundary()) continue;
    const bool reversed = edge.f[1] < edge.f[0];  // the reader meets f[1] (running n[1] -> n[0]) first
    const int n0 = edge.n[reversed ? 1 : 0], n1 = edge.n[reversed ? 0 : 1];
    const Face& A = mesh.faces[edge.f[reversed ? 1 : 0]];
    const Face& B = mesh.faces[edge.f[reversed ? 0 : 1]];
    int a0 = kNone, a1 = kNone, a2 = kNone, b0 = kNone, b1 = kNone, b3 = kNone;
    for (int i = 0; i < 3; ++i) {
      const int n = mesh.verts[A.v[i]].node;
      (n == n0 ? a0 : n == n1 ? a1 : a2) = A.v[i];
    }
    for (int i = 0; i < 3; ++i) {
      const int n = mesh.verts[B.v[i]].node;
      (n == n0 ? b0 : n == n1 ? b1 : b3) = B.v[i];
    }
    if (a0 != b0 || a1 != b1) continue;
    angles[e] = dihedral_angle(mesh.verts[a0].u, mesh.verts[a1].u, mesh.verts[a2].u, mesh.verts[b3].u);
  }
  return angles;
}

}  // namespace

void write_obj(const Mesh& mesh, const std::string& path) {
  size_t node_count = 0, vert_count = 0, face_count = 0;
  const std::vector<int> node_number = live_numbers(mesh.nodes, node_count);
  const std::vector<int> vert_number = live_numbers(mesh.verts, vert_count);
  live_numbers(mesh.faces, face_count);

  std::string out;
  out.reserve(128 * (node_count + vert_count + face_count));
  out += "# arcsim extended OBJ: " + std::to_string(node_count) + " nodes, " + std::to_string(vert_count) +
         " rest vertices, " + std::to_string(face_count) + " faces\n";
  out += "# ms = 3D rest position, vt = its x y for other tools, f node/rest-vertex\n";
  for (const Node& n : mesh.nodes) {
    if (n.dead) continue;
    append_vec3(out, "v", n.x);
    if (n.v != Vec3::Zero()) append_vec3(out, "nv", n.v);
    if (n.label != 0) {
      out += "nl ";
      append_int(out, n.label);
      out += '\n';
    }
  }
  for (const Vert& v : mesh.verts) {
    if (v.dead) continue;
    append_vec3(out, "ms", v.u);
    append_line(out, "vt", {v.u.x(), v.u.y()});
  }
  for (const Face& f : mesh.faces) {
    if (f.dead) continue;
    out += "f";
    for (int i = 0; i < 3; ++i) {
      out += ' ';
      append_int(out, node_number[mesh.verts[f.v[i]].node]);
      out += '/';
      append_int(out, vert_number[f.v[i]]);
    }
    out += '\n';
    if (f.material != 0) {
      out += "tm ";
      append_int(out, f.material);
      out += '\n';
    }
    if (f.thickness != 0) append_line(out, "th", {f.thickness});
    if (f.Sp != Mat3::Zero()) append_mat3(out, "tp", f.Sp);
    if (f.Fp != Mat3::Identity()) append_mat3(out, "ts", f.Fp);
    if (f.damage != 0) append_line(out, "td", {f.damage});
  }
  const std::vector<double> default_angle = default_rest_angles_on_reload(mesh);
  for (size_t e = 0; e < mesh.edges.size(); ++e) {
    const Edge& edge = mesh.edges[e];
    if (edge.dead) continue;
    // Bitwise comparison on purpose: any difference from what the reader recomputes must be recorded.
    const bool custom_angle = !(edge.rest_theta == default_angle[e]);
    if (!custom_angle && !edge.preserve && edge.damage == 0) continue;
    out += "e ";
    append_int(out, node_number[edge.n[0]]);
    out += ' ';
    append_int(out, node_number[edge.n[1]]);
    out += '\n';
    if (custom_angle) append_line(out, "ea", {edge.rest_theta});
    if (edge.damage != 0) append_line(out, "ed", {edge.damage});
    if (edge.preserve) out += "ep\n";
  }
  // Frames are outputs, not resume points (states are): renamed whole, but not flushed to the disk one by one.
  write_file_atomically(path, out, Durability::kProcessCrash);
}

void write_plain_obj(const Mesh& mesh, const std::string& path) {
  size_t node_count = 0;
  const std::vector<int> node_number = live_numbers(mesh.nodes, node_count);
  std::string out;
  out.reserve(64 * (node_count + mesh.faces.size()));
  for (const Node& n : mesh.nodes)
    if (!n.dead) append_vec3(out, "v", n.x);
  for (const Face& f : mesh.faces) {
    if (f.dead) continue;
    out += "f";
    for (int i = 0; i < 3; ++i) {
      out += ' ';
      append_int(out, node_number[mesh.verts[f.v[i]].node]);
    }
    out += '\n';
  }
  write_file_atomically(path, out, Durability::kProcessCrash);
}

}  // namespace arcsim
