#include "io/state.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "io/atomic_file.hpp"
#include "math/errors.hpp"
#include "mesh/validate.hpp"
#include "sim/simulation.hpp"

namespace arcsim {

// ---------------------------------------------------------------------------------------------------------
// Byte encoding

namespace {

// Little-endian bytes of the low N bytes of `value`, built in a local array and appended at once (a push_back
// per byte dominated saving large meshes).
template <int N>
void append_le(std::string& out, uint64_t value) {
  char bytes[N];
  for (int i = 0; i < N; ++i) bytes[i] = static_cast<char>(static_cast<uint8_t>(value >> (8 * i)));
  out.append(bytes, N);
}

}  // namespace

void StateWriter::put_f64(double value) {
  static_assert(sizeof(double) == sizeof(uint64_t), "IEEE-754 binary64 expected");
  uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  put_u64(bits);
}

void StateWriter::put_count(size_t count) {
  if (count > UINT32_MAX) throw std::length_error("state file: list of " + std::to_string(count) + " entries");
  put_u32(static_cast<uint32_t>(count));
}

void StateWriter::put_int_list(const std::vector<int>& values) {
  put_count(values.size());
  for (int v : values) put_i32(v);
}

void StateReader::fail(const std::string& problem) const { throw InputError(context_ + ": " + problem); }

const char* StateReader::need(size_t n) {
  if (n > size_ - pos_) fail("ends early (the file is damaged)");
  const char* p = data_ + pos_;
  pos_ += n;
  return p;
}

uint8_t StateReader::get_u8() { return static_cast<uint8_t>(*need(1)); }

bool StateReader::get_bool() {
  const uint8_t b = get_u8();
  if (b > 1) fail("flag byte " + std::to_string(b) + " is neither 0 nor 1");
  return b == 1;
}

uint32_t StateReader::get_u32() {
  const unsigned char* p = reinterpret_cast<const unsigned char*>(need(4));
  uint32_t value = 0;
  for (int i = 0; i < 4; ++i) value |= static_cast<uint32_t>(p[i]) << (8 * i);
  return value;
}

uint64_t StateReader::get_u64() {
  const unsigned char* p = reinterpret_cast<const unsigned char*>(need(8));
  uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value |= static_cast<uint64_t>(p[i]) << (8 * i);
  return value;
}

double StateReader::get_f64() {
  const uint64_t bits = get_u64();
  double value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

size_t StateReader::get_count(size_t min_item_bytes) {
  const size_t count = get_u32();
  if (min_item_bytes > 0 && count > remaining() / min_item_bytes)
    fail("a list of " + std::to_string(count) + " entries is longer than the rest of the section");
  return count;
}

std::vector<int> StateReader::get_int_list() {
  std::vector<int> values(get_count(4));
  for (int& v : values) v = get_i32();
  return values;
}

uint64_t fnv1a64(const char* data, size_t size) {
  uint64_t hash = 14695981039346656037ull;  // FNV offset basis
  for (size_t i = 0; i < size; ++i) {
    hash ^= static_cast<unsigned char>(data[i]);
    hash *= 1099511628211ull;  // FNV prime
  }
  return hash;
}

uint64_t state_checksum(const char* data, size_t size, uint32_t version) {
  if (version < 2) return fnv1a64(data, size);
  constexpr uint64_t kPrime = 1099511628211ull;
  uint64_t hash = 14695981039346656037ull;
  const unsigned char* bytes = reinterpret_cast<const unsigned char*>(data);
  size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    uint64_t word;  // one load (a byte-by-byte assembly was not merged by the compiler)
    std::memcpy(&word, bytes + i, sizeof word);
#if __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
    word = __builtin_bswap64(word);
#endif
    hash = (hash ^ word) * kPrime;
  }
  if (i < size) {
    uint64_t word = 0;
    for (int k = 0; i + k < size; ++k) word |= static_cast<uint64_t>(bytes[i + k]) << (8 * k);
    hash = (hash ^ word) * kPrime;
  }
  return (hash ^ static_cast<uint64_t>(size)) * kPrime;
}

namespace {

constexpr char kMagic[8] = {'A', 'R', 'C', 'S', 'I', 'M', 'S', 'T'};
constexpr size_t kHeaderBytes = 8 + 4 + 4 + 8;  // magic, version, section count, file size
constexpr size_t kTableEntryBytes = 4 + 8;      // tag, payload length
constexpr size_t kChecksumBytes = 8;

// Smallest encoded size of each list item, used to refuse corrupt counts before allocating.
constexpr size_t kNodeBytes = 12 * 8 + 4 + 1 + 8 + 4 + 4;  // x x0 v a, label, preserve, mass, two lists
constexpr size_t kVertBytes = 3 * 8 + 9 * 8 + 4 + 4;        // u, sizing, node, face list
constexpr size_t kEdgeBytes = 4 * 4 + 2 * 8 + 1;            // n, f, rest_theta, damage, preserve
constexpr size_t kFaceBytes = 7 * 4 + 8 + 9 * 8 + 9 * 8 + 8 + 8 + 3 * 8 + 6 * 8 + 4 * 8;
constexpr size_t kObstacleNodeBytes = 9 * 8;

// ---------------------------------------------------------------------------------------------------------
// The state read from a file, held apart until everything is checked so that a failed load changes nothing.

struct StagedCloth {
  size_t material_count = 0;
  Mesh mesh;
};

struct StagedObstacle {
  std::vector<Vec3> x, x0, v;
  bool active = true;
};

struct StagedHandle {
  int cloth = 0;
  std::vector<int> nodes;
  std::vector<Vec3> anchors;
};

struct StagedState {
  double time = 0;
  int64_t step = 0, frame = 0;
  int32_t substep_level = 0, steps_at_substep_level = 0;  // STEP (adaptive time stepping), 0 if absent
  std::vector<StagedCloth> cloths;
  std::vector<StagedObstacle> obstacles;
  std::vector<StagedHandle> handles;
};

// ---------------------------------------------------------------------------------------------------------
// Section codecs

void write_clock(const Simulation& sim, StateWriter& w) {
  w.put_f64(sim.time());
  w.put_i64(sim.step());
  w.put_i64(sim.frame());
}

void read_clock(StateReader& r, StagedState& s) {
  s.time = r.get_f64();
  s.step = r.get_i64();
  s.frame = r.get_i64();
  if (!std::isfinite(s.time)) r.fail("time is not finite");
  if (s.step < 0 || s.step > INT_MAX) r.fail("step " + std::to_string(s.step) + " is out of range");
  if (s.frame < 0 || s.frame > INT_MAX) r.fail("frame " + std::to_string(s.frame) + " is out of range");
}

void write_mesh(const Mesh& m, StateWriter& w) {
  // Exact size on a consistent mesh: every vert sits in one node's list, every edge in two, every face in
  // three verts' lists.
  const size_t V = m.verts.size(), E = m.edges.size(), F = m.faces.size();
  w.reserve(4 * 4 + m.nodes.size() * kNodeBytes + V * kVertBytes + E * kEdgeBytes + F * kFaceBytes +
            4 * (V + 2 * E + 3 * F));
  w.put_count(m.nodes.size());
  for (const Node& n : m.nodes) {
    w.put_matrix(n.x);
    w.put_matrix(n.x0);
    w.put_matrix(n.v);
    w.put_matrix(n.a);
    w.put_i32(n.label);
    w.put_bool(n.preserve);
    w.put_f64(n.mass);
    w.put_int_list(n.verts);
    w.put_int_list(n.edges);
  }
  w.put_count(m.verts.size());
  for (const Vert& v : m.verts) {
    w.put_matrix(v.u);
    w.put_matrix(v.sizing);
    w.put_i32(v.node);
    w.put_int_list(v.faces);
  }
  w.put_count(m.edges.size());
  for (const Edge& e : m.edges) {
    for (int s = 0; s < 2; ++s) w.put_i32(e.n[s]);
    for (int s = 0; s < 2; ++s) w.put_i32(e.f[s]);
    w.put_f64(e.rest_theta);
    w.put_f64(e.damage);
    w.put_bool(e.preserve);
  }
  w.put_count(m.faces.size());
  for (const Face& f : m.faces) {
    for (int i = 0; i < 3; ++i) w.put_i32(f.v[i]);
    for (int i = 0; i < 3; ++i) w.put_i32(f.e[i]);
    w.put_i32(f.material);
    w.put_f64(f.thickness);
    w.put_matrix(f.Fp);
    w.put_matrix(f.Sp);
    w.put_f64(f.damage);
    // Derived rest data is stored rather than recomputed, so that nothing depends on recomputing it exactly.
    w.put_f64(f.rest_area);
    w.put_matrix(f.rest_normal);
    w.put_matrix(f.rest_frame);
    w.put_matrix(f.Dm_inv);
  }
}

// Reads the fields only; index ranges and topology are checked later (check_mesh_indices, check_mesh).
Mesh read_mesh(StateReader& r) {
  Mesh m;
  m.nodes.resize(r.get_count(kNodeBytes));
  for (Node& n : m.nodes) {
    r.get_matrix(n.x);
    r.get_matrix(n.x0);
    r.get_matrix(n.v);
    r.get_matrix(n.a);
    n.label = r.get_i32();
    n.preserve = r.get_bool();
    n.mass = r.get_f64();
    n.verts = r.get_int_list();
    n.edges = r.get_int_list();
  }
  m.verts.resize(r.get_count(kVertBytes));
  for (Vert& v : m.verts) {
    r.get_matrix(v.u);
    r.get_matrix(v.sizing);
    v.node = r.get_i32();
    v.faces = r.get_int_list();
  }
  m.edges.resize(r.get_count(kEdgeBytes));
  for (Edge& e : m.edges) {
    for (int s = 0; s < 2; ++s) e.n[s] = r.get_i32();
    for (int s = 0; s < 2; ++s) e.f[s] = r.get_i32();
    e.rest_theta = r.get_f64();
    e.damage = r.get_f64();
    e.preserve = r.get_bool();
  }
  m.faces.resize(r.get_count(kFaceBytes));
  for (Face& f : m.faces) {
    for (int i = 0; i < 3; ++i) f.v[i] = r.get_i32();
    for (int i = 0; i < 3; ++i) f.e[i] = r.get_i32();
    f.material = r.get_i32();
    f.thickness = r.get_f64();
    r.get_matrix(f.Fp);
    r.get_matrix(f.Sp);
    f.damage = r.get_f64();
    f.rest_area = r.get_f64();
    r.get_matrix(f.rest_normal);
    r.get_matrix(f.rest_frame);
    r.get_matrix(f.Dm_inv);
  }
  return m;
}

void write_cloths(const Simulation& sim, StateWriter& w) {
  w.put_count(sim.cloths.size());
  for (size_t c = 0; c < sim.cloths.size(); ++c) {
    const Cloth& cloth = sim.cloths[c];
    if (!cloth.mesh.is_compact())
      throw std::logic_error("save_state: cloth " + std::to_string(c) + " has removed elements (compact first)");
    w.put_count(cloth.materials.size());
    write_mesh(cloth.mesh, w);
  }
}

void read_cloths(StateReader& r, StagedState& s) {
  s.cloths.resize(r.get_count(5 * 4));  // material count and four element counts
  for (StagedCloth& cloth : s.cloths) {
    cloth.material_count = r.get_u32();
    cloth.mesh = read_mesh(r);
  }
}

void write_obstacles(const Simulation& sim, StateWriter& w) {
  w.put_count(sim.obstacles.size());
  for (const Obstacle& o : sim.obstacles) {
    w.reserve(4 + o.mesh.nodes.size() * kObstacleNodeBytes + 1);
    w.put_count(o.mesh.nodes.size());
    for (const Node& n : o.mesh.nodes) {
      w.put_matrix(n.x);
      w.put_matrix(n.x0);
      w.put_matrix(n.v);
    }
    w.put_bool(o.active);
  }
}

void read_obstacles(StateReader& r, StagedState& s) {
  s.obstacles.resize(r.get_count(4 + 1));  // node count, active
  for (StagedObstacle& o : s.obstacles) {
    const size_t count = r.get_count(kObstacleNodeBytes);
    o.x.resize(count);
    o.x0.resize(count);
    o.v.resize(count);
    for (size_t i = 0; i < count; ++i) {
      o.x[i] = r.get_vec3();
      o.x0[i] = r.get_vec3();
      o.v[i] = r.get_vec3();
    }
    o.active = r.get_bool();
  }
}

void write_handles(const Simulation& sim, StateWriter& w) {
  w.put_count(sim.handles.size());
  for (size_t i = 0; i < sim.handles.size(); ++i) {
    const Handle& h = sim.handles[i];
    if (h.nodes.size() != h.anchors.size())
      throw std::logic_error("save_state: handle " + std::to_string(i) + " has unequal node and anchor lists");
    w.put_i32(h.cloth);
    w.put_count(h.nodes.size());
    for (size_t k = 0; k < h.nodes.size(); ++k) {
      w.put_i32(h.nodes[k]);
      w.put_matrix(h.anchors[k]);
    }
  }
}

void read_handles(StateReader& r, StagedState& s) {
  s.handles.resize(r.get_count(4 + 4));  // cloth, node count
  for (StagedHandle& h : s.handles) {
    h.cloth = r.get_i32();
    const size_t count = r.get_count(4 + 3 * 8);
    h.nodes.resize(count);
    h.anchors.resize(count);
    for (size_t k = 0; k < count; ++k) {
      h.nodes[k] = r.get_i32();
      h.anchors[k] = r.get_vec3();
    }
  }
}

// Adaptive time stepping's level (sim/simulation.hpp): written only by scenes that turn it on.
void write_substep_level(const Simulation& sim, StateWriter& w) {
  w.put_i32(sim.substep_level());
  w.put_i32(sim.steps_at_substep_level());
}

void read_substep_level(StateReader& r, StagedState& s) {
  s.substep_level = r.get_i32();
  s.steps_at_substep_level = r.get_i32();
  if (s.substep_level < 0 || s.substep_level > Simulation::kMaxSubstepLevel)
    r.fail("substep level " + std::to_string(s.substep_level) + " is out of range");
  if (s.steps_at_substep_level < 0) r.fail("negative step count " + std::to_string(s.steps_at_substep_level));
}

bool adaptive_stepping(const Simulation& sim) { return sim.scene().adaptive_step.enabled; }

struct SectionCodec {
  const char* tag;  // exactly 4 ASCII characters
  bool required;
  void (*write)(const Simulation&, StateWriter&);
  void (*read)(StateReader&, StagedState&);
  bool (*present)(const Simulation&) = nullptr;  // optional sections: whether this simulation writes it
};

// Written in this order; read in file order (the staged state is only checked once every section is in).
const SectionCodec kSections[] = {
    {"TIME", true, write_clock, read_clock},
    {"CLTH", true, write_cloths, read_cloths},
    {"OBST", true, write_obstacles, read_obstacles},
    {"HNDL", true, write_handles, read_handles},
    {"STEP", false, write_substep_level, read_substep_level, adaptive_stepping},
};

// ---------------------------------------------------------------------------------------------------------
// Consistency of the staged state, alone and against the simulation's scene

// A tag as it can be printed in a message: non-printable bytes as \xNN.
std::string printable_tag(const std::string& tag) {
  std::string out;
  for (unsigned char c : tag) {
    if (c >= 0x20 && c < 0x7f && c != '\'') {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    }
  }
  return out;
}

std::string index_problem(const char* element, size_t i, const char* field, int value, const char* target,
                          size_t count) {
  return std::string(element) + " " + std::to_string(i) + " " + field + " " + std::to_string(value) +
         " but the mesh has " + std::to_string(count) + " " + target;
}

bool in_range(int value, size_t count) { return value >= 0 && static_cast<size_t>(value) < count; }

// Returns "" or the first reference to a missing element: check_mesh() may only run on a mesh without such.
std::string check_mesh_indices(const Mesh& m) {
  const size_t nn = m.nodes.size(), nv = m.verts.size(), ne = m.edges.size(), nf = m.faces.size();
  for (size_t i = 0; i < nn; ++i) {
    for (int v : m.nodes[i].verts)
      if (!in_range(v, nv)) return index_problem("node", i, "lists vert", v, "verts", nv);
    for (int e : m.nodes[i].edges)
      if (!in_range(e, ne)) return index_problem("node", i, "lists edge", e, "edges", ne);
  }
  for (size_t i = 0; i < nv; ++i) {
    if (!in_range(m.verts[i].node, nn)) return index_problem("vert", i, "has node", m.verts[i].node, "nodes", nn);
    for (int f : m.verts[i].faces)
      if (!in_range(f, nf)) return index_problem("vert", i, "lists face", f, "faces", nf);
  }
  for (size_t i = 0; i < ne; ++i) {
    const Edge& e = m.edges[i];
    for (int s = 0; s < 2; ++s) {
      if (!in_range(e.n[s], nn)) return index_problem("edge", i, "has node", e.n[s], "nodes", nn);
      if (e.f[s] != kNone && !in_range(e.f[s], nf)) return index_problem("edge", i, "has face", e.f[s], "faces", nf);
    }
  }
  for (size_t i = 0; i < nf; ++i) {
    const Face& f = m.faces[i];
    for (int c = 0; c < 3; ++c) {
      if (!in_range(f.v[c], nv)) return index_problem("face", i, "has vert", f.v[c], "verts", nv);
      if (!in_range(f.e[c], ne)) return index_problem("face", i, "has edge", f.e[c], "edges", ne);
    }
  }
  return "";
}

std::string count_mismatch(const std::string& what, size_t in_file, size_t in_scene) {
  return "the state file has " + std::to_string(in_file) + " " + what + ", the scene has " +
         std::to_string(in_scene) + " (was it saved from another scene?)";
}

// Throws InputError "<path>: <problem>" at the first inconsistency.
void check_staged(const StagedState& s, const Simulation& sim, const std::string& path) {
  auto fail = [&](const std::string& problem) { throw InputError(path + ": " + problem); };
  if (s.cloths.size() != sim.cloths.size()) fail(count_mismatch("cloths", s.cloths.size(), sim.cloths.size()));
  for (size_t c = 0; c < s.cloths.size(); ++c) {
    const std::string where = "cloth " + std::to_string(c) + ": ";
    const size_t materials = sim.cloths[c].materials.size();
    if (s.cloths[c].material_count != materials)
      fail(where + count_mismatch("materials", s.cloths[c].material_count, materials));
    const Mesh& m = s.cloths[c].mesh;
    if (m.faces.empty()) fail(where + "the mesh has no faces");
    std::string problem = check_mesh_indices(m);
    if (!problem.empty()) fail(where + problem);
    for (size_t f = 0; f < m.faces.size(); ++f)
      if (!in_range(m.faces[f].material, materials))
        fail(where + "face " + std::to_string(f) + " uses material " + std::to_string(m.faces[f].material) +
             " but the cloth has " + std::to_string(materials));
    // Only structure and finiteness: the stored rest data is taken as it is, not re-derived.
    MeshCheckOptions options;
    options.require_positive_rest_area = false;
    options.require_current_rest_data = false;
    options.require_finite_state = true;
    problem = check_mesh(m, options);
    if (!problem.empty()) fail(where + problem);
  }
  if (s.obstacles.size() != sim.obstacles.size())
    fail(count_mismatch("obstacles", s.obstacles.size(), sim.obstacles.size()));
  for (size_t i = 0; i < s.obstacles.size(); ++i) {
    const StagedObstacle& o = s.obstacles[i];
    const size_t nodes = sim.obstacles[i].mesh.nodes.size();
    if (o.x.size() != nodes) fail("obstacle " + std::to_string(i) + ": " + count_mismatch("nodes", o.x.size(), nodes));
    for (size_t k = 0; k < nodes; ++k)
      if (!o.x[k].allFinite() || !o.x0[k].allFinite() || !o.v[k].allFinite())
        fail("obstacle " + std::to_string(i) + ": node " + std::to_string(k) + " has a non-finite x, x0 or v");
  }
  if (s.handles.size() != sim.handles.size()) fail(count_mismatch("handles", s.handles.size(), sim.handles.size()));
  for (size_t i = 0; i < s.handles.size(); ++i) {
    const StagedHandle& h = s.handles[i];
    const std::string where = "handle " + std::to_string(i) + ": ";
    if (h.cloth != sim.handles[i].cloth)
      fail(where + "holds cloth " + std::to_string(h.cloth) + " in the state file, cloth " +
           std::to_string(sim.handles[i].cloth) + " in the scene");
    const size_t nodes = s.cloths[h.cloth].mesh.nodes.size();
    for (size_t k = 0; k < h.nodes.size(); ++k) {
      if (!in_range(h.nodes[k], nodes))
        fail(where + "node " + std::to_string(h.nodes[k]) + " is out of range (the cloth has " +
             std::to_string(nodes) + " nodes)");
      if (!h.anchors[k].allFinite()) fail(where + "anchor " + std::to_string(k) + " is not finite");
    }
  }
}

void commit(StagedState& s, Simulation& sim) {
  sim.restore_clock(s.time, static_cast<int>(s.step), static_cast<int>(s.frame));
  sim.restore_substep_level(s.substep_level, s.steps_at_substep_level);
  for (size_t c = 0; c < s.cloths.size(); ++c) {
    Cloth& cloth = sim.cloths[c];
    cloth.mesh = std::move(s.cloths[c].mesh);
    cloth.elements = ElementCache();
    cloth.solver = CholeskySolver();
    cloth.elements_dirty = true;
  }
  for (size_t i = 0; i < s.obstacles.size(); ++i) {
    Obstacle& o = sim.obstacles[i];
    for (size_t k = 0; k < o.mesh.nodes.size(); ++k) {
      Node& n = o.mesh.nodes[k];
      n.x = s.obstacles[i].x[k];
      n.x0 = s.obstacles[i].x0[k];
      n.v = s.obstacles[i].v[k];
    }
    o.active = s.obstacles[i].active;
  }
  for (size_t i = 0; i < s.handles.size(); ++i) {
    sim.handles[i].nodes = std::move(s.handles[i].nodes);
    sim.handles[i].anchors = std::move(s.handles[i].anchors);
  }
}

// ---------------------------------------------------------------------------------------------------------
// Envelope: header, section table, checksum

void append_u32(std::string& out, uint32_t value) { append_le<4>(out, value); }

void append_u64(std::string& out, uint64_t value) { append_le<8>(out, value); }

uint32_t decode_u32(const char* p) {
  uint32_t value = 0;
  for (int i = 0; i < 4; ++i) value |= static_cast<uint32_t>(static_cast<unsigned char>(p[i])) << (8 * i);
  return value;
}

uint64_t decode_u64(const char* p) {
  uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value |= static_cast<uint64_t>(static_cast<unsigned char>(p[i])) << (8 * i);
  return value;
}

std::string encode_state(const Simulation& sim) {
  std::vector<std::string> payloads;
  std::vector<const SectionCodec*> written;
  for (const SectionCodec& codec : kSections) {
    if (codec.present && !codec.present(sim)) continue;
    StateWriter w;
    codec.write(sim, w);
    payloads.push_back(w.take());
    written.push_back(&codec);
  }
  const size_t count = payloads.size();
  size_t total = kHeaderBytes + count * kTableEntryBytes + kChecksumBytes;
  for (const std::string& p : payloads) total += p.size();

  std::string out;
  out.reserve(total);
  out.append(kMagic, sizeof kMagic);
  append_u32(out, kStateFormatVersion);
  append_u32(out, static_cast<uint32_t>(count));
  append_u64(out, total);
  for (size_t i = 0; i < count; ++i) {
    out.append(written[i]->tag, 4);
    append_u64(out, payloads[i].size());
  }
  for (const std::string& p : payloads) out += p;
  append_u64(out, state_checksum(out.data(), out.size()));
  return out;
}

struct SectionSpan {
  std::string tag;
  size_t offset = 0, length = 0;
};

// Checks magic, version, size and checksum, and returns the section table. Messages name the path.
std::vector<SectionSpan> parse_envelope(const std::string& bytes, const std::string& path) {
  auto fail = [&](const std::string& problem) { throw InputError(path + ": " + problem); };
  const size_t size = bytes.size();
  const std::string truncated = "truncated state file (" + std::to_string(size) + " bytes)";
  if (size == 0) fail("empty file, not an arcsim state file");
  if (std::memcmp(bytes.data(), kMagic, std::min(size, sizeof kMagic)) != 0) fail("not an arcsim state file");
  if (size < sizeof kMagic + 4) fail(truncated);
  const uint32_t version = decode_u32(bytes.data() + 8);
  if (version < kOldestStateFormatVersion || version > kStateFormatVersion)
    fail("state file version " + std::to_string(version) + ", this arcsim reads versions " +
         std::to_string(kOldestStateFormatVersion) + " to " + std::to_string(kStateFormatVersion));
  if (size < kHeaderBytes + kChecksumBytes) fail(truncated);
  const uint64_t declared = decode_u64(bytes.data() + 16);
  if (size < declared)
    fail("truncated state file (" + std::to_string(size) + " bytes, the header says " + std::to_string(declared) +
         ")");
  const uint64_t stored = decode_u64(bytes.data() + size - kChecksumBytes);
  if (stored != state_checksum(bytes.data(), size - kChecksumBytes, version)) fail("checksum mismatch: the state file is corrupt");
  if (size != declared)
    fail("file size " + std::to_string(size) + " differs from the " + std::to_string(declared) +
         " bytes in its header");

  const uint32_t count = decode_u32(bytes.data() + 12);
  if (count > (size - kHeaderBytes - kChecksumBytes) / kTableEntryBytes)
    fail("section table of " + std::to_string(count) + " entries does not fit in the file");
  std::vector<SectionSpan> spans(count);
  size_t offset = kHeaderBytes + count * kTableEntryBytes;
  const size_t payload_end = size - kChecksumBytes;
  for (uint32_t i = 0; i < count; ++i) {
    const char* entry = bytes.data() + kHeaderBytes + i * kTableEntryBytes;
    spans[i].tag.assign(entry, 4);
    const uint64_t length = decode_u64(entry + 4);
    if (length > payload_end - offset)
      fail("section '" + printable_tag(spans[i].tag) + "' runs past the end of the file");
    spans[i].offset = offset;
    spans[i].length = length;
    offset += length;
  }
  if (offset != payload_end) fail("the section table does not account for the whole file");
  return spans;
}

// ---------------------------------------------------------------------------------------------------------
// Files

std::string read_file(const std::string& path) {
  auto fail = [&](const char* what, int error) {
    throw InputError(path + ": " + what + " (" + std::generic_category().message(error) + ")");
  };
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) fail("cannot open", errno);
  std::string bytes;
  char buffer[1 << 16];
  size_t got;
  while ((got = std::fread(buffer, 1, sizeof buffer, file)) > 0) bytes.append(buffer, got);
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  std::fclose(file);
  if (failed) fail("cannot read", error);
  return bytes;
}

}  // namespace

void save_state(const Simulation& sim, const std::string& path) {
  const std::string problem = sim.nonfinite_state();
  if (!problem.empty()) throw NumericalError(path + ": not written: " + problem);
  // Renamed whole (a crash of the process never leaves a partial state under this name) but not flushed to the
  // disk one by one: an fsync per frame cost ~4% of a light scene's run (paper-tearing.json, 0.55 s of 12.4 s).
  // After a crash of the machine the newest states may be lost or truncated; they fail their checksum and
  // `arcsim resume` falls back to the newest state that loads (app/resume_command.cpp).
  write_file_atomically(path, encode_state(sim), Durability::kProcessCrash);
}

void load_state(Simulation& sim, const std::string& path) {
  const std::string bytes = read_file(path);
  const std::vector<SectionSpan> spans = parse_envelope(bytes, path);

  StagedState staged;
  std::vector<bool> seen(std::size(kSections), false);
  for (const SectionSpan& span : spans) {
    size_t k = 0;
    while (k < seen.size() && span.tag != kSections[k].tag) ++k;
    const std::string context = path + ": section '" + printable_tag(span.tag) + "'";
    if (k == seen.size())
      throw InputError(context + " is unknown to this arcsim (state format version " +
                       std::to_string(kStateFormatVersion) + ")");
    if (seen[k]) throw InputError(context + " appears twice");
    seen[k] = true;
    StateReader reader(bytes.data() + span.offset, span.length, context);
    kSections[k].read(reader, staged);
    if (reader.remaining() != 0) reader.fail(std::to_string(reader.remaining()) + " bytes left unread");
  }
  for (size_t k = 0; k < seen.size(); ++k)
    if (kSections[k].required && !seen[k])
      throw InputError(path + ": section '" + kSections[k].tag + "' is missing");

  check_staged(staged, sim, path);
  commit(staged, sim);
}

}  // namespace arcsim
