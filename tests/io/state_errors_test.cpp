// Bad state files are refused with one-line InputErrors naming the file and the problem, and leave the
// Simulation untouched: missing, not a state file, other version, every truncation, every flipped byte,
// unknown / missing / repeated sections, and content that does not fit the scene.
#include <gtest/gtest.h>

#include <stdlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "io/scene_parser.hpp"
#include "io/state.hpp"
#include "math/errors.hpp"
#include "sim/simulation.hpp"
#include "support/files.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

// Two triangles: the smallest sheet, so that a state file is small enough to try every prefix and byte.
constexpr const char* kTinyObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";

struct SceneShape {
  int cloths = 1, materials = 1, obstacles = 1, handles = 1;
};

std::string tiny_scene(const fs::path& obj, const SceneShape& shape) {
  std::string material = R"({"thickness": 1e-3, "density": 500, "elastic_modulus": 1e6, "poisson_ratio": 0.3})";
  std::string cloths, obstacles, handles;
  for (int c = 0; c < shape.cloths; ++c) {
    std::string materials;
    for (int m = 0; m < shape.materials; ++m) materials += (m ? ", " : "") + material;
    cloths += std::string(c ? ", " : "") + R"({"mesh": ")" + obj.string() + R"(", "materials": [)" + materials + "]}";
  }
  for (int o = 0; o < shape.obstacles; ++o)
    obstacles += std::string(o ? ", " : "") + R"({"mesh": ")" + obj.string() + R"(", "transform": {"translate": [0, 0, -1]}})";
  for (int h = 0; h < shape.handles; ++h) handles += std::string(h ? ", " : "") + R"({"nodes": [0, 2]})";
  return R"({"timestep": 0.01, "disable": ["remeshing"], "gravity": [0, 0, -9.8], "cloths": [)" + cloths +
         R"(], "obstacles": [)" + obstacles + R"(], "handles": [)" + handles + "]}";
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The InputError message of loading `path` into `sim`, or "" if it loaded. Any other exception fails the test.
std::string load_error(Simulation& sim, const std::string& path) {
  try {
    load_state(sim, path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The sections of a valid state file, decoded independently of the library (layout of io/state.hpp), so that
// tests can re-assemble files with sections renamed, dropped, repeated or resized.
struct Section {
  std::string tag, payload;
};

uint64_t get_le(const std::string& bytes, size_t at, int width) {
  uint64_t value = 0;
  for (int i = width - 1; i >= 0; --i) value = (value << 8) | static_cast<unsigned char>(bytes[at + i]);
  return value;
}

void put_le(std::string& out, uint64_t value, int width) {
  for (int i = 0; i < width; ++i) out += static_cast<char>((value >> (8 * i)) & 0xff);
}

std::vector<Section> split_sections(const std::string& bytes) {
  const size_t count = get_le(bytes, 12, 4);
  std::vector<Section> sections(count);
  size_t offset = 24 + 12 * count;
  for (size_t i = 0; i < count; ++i) {
    sections[i].tag = bytes.substr(24 + 12 * i, 4);
    const size_t length = get_le(bytes, 24 + 12 * i + 4, 8);
    sections[i].payload = bytes.substr(offset, length);
    offset += length;
  }
  return sections;
}

std::string assemble(const std::vector<Section>& sections, uint32_t version = kStateFormatVersion) {
  std::string out = "ARCSIMST";
  put_le(out, version, 4);
  put_le(out, sections.size(), 4);
  size_t total = 24 + 12 * sections.size() + 8;
  for (const Section& s : sections) total += s.payload.size();
  put_le(out, total, 8);
  for (const Section& s : sections) {
    out += s.tag;
    put_le(out, s.payload.size(), 8);
  }
  for (const Section& s : sections) out += s.payload;
  put_le(out, state_checksum(out.data(), out.size(), version), 8);
  return out;
}

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }
bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class StateErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(dir_.path.empty());
    obj_ = dir_.path / "tiny.obj";
    std::ofstream(obj_) << kTinyObj;
    scene_ = make_scene(SceneShape());
    Simulation sim(scene_);
    sim.advance_step();  // some motion, so that the state is not all zeros
    good_ = path("good.state");
    save_state(sim, good_);
    bytes_ = read_bytes(good_);
  }
  Scene make_scene(const SceneShape& shape) {
    const std::string file = path("scene" + std::to_string(scenes_++) + ".json");
    std::ofstream(file) << tiny_scene(obj_, shape);
    return load_scene(file);
  }
  std::string path(const std::string& name) const { return (dir_.path / name).string(); }
  // Loading must not have touched the simulation: still at its initial clock and positions.
  static void expect_untouched(const Simulation& sim, const Scene& scene) {
    const Simulation fresh(scene);
    EXPECT_EQ(sim.step(), 0);
    EXPECT_EQ(sim.time(), 0.0);
    ASSERT_EQ(sim.cloths.size(), fresh.cloths.size());
    EXPECT_EQ(sim.cloths[0].mesh.nodes.size(), fresh.cloths[0].mesh.nodes.size());
    EXPECT_EQ(sim.cloths[0].mesh.nodes[1].x, fresh.cloths[0].mesh.nodes[1].x);
  }

  TempDir dir_;
  fs::path obj_;
  int scenes_ = 0;
  Scene scene_;
  std::string good_, bytes_;
};

TEST_F(StateErrors, TheGoodFileLoads) {
  Simulation sim(scene_);
  EXPECT_EQ(load_error(sim, good_), "");
  EXPECT_EQ(sim.step(), 1);
  EXPECT_LT(bytes_.size(), 4000u);  // small enough for the exhaustive tests below
}

TEST_F(StateErrors, MissingFile) {
  Simulation sim(scene_);
  const std::string missing = path("nowhere.state");
  EXPECT_EQ(load_error(sim, missing), missing + ": cannot open (No such file or directory)");
}

TEST_F(StateErrors, NotAStateFile) {
  Simulation sim(scene_);
  EXPECT_EQ(load_error(sim, obj_.string()), obj_.string() + ": not an arcsim state file");
  std::string bytes = bytes_;
  bytes[3] = 'x';
  write_bytes(path("magic.state"), bytes);
  EXPECT_EQ(load_error(sim, path("magic.state")), path("magic.state") + ": not an arcsim state file");
  write_bytes(path("empty.state"), "");
  EXPECT_EQ(load_error(sim, path("empty.state")), path("empty.state") + ": empty file, not an arcsim state file");
  expect_untouched(sim, scene_);
}

TEST_F(StateErrors, OtherFormatVersion) {
  Simulation sim(scene_);
  // A well-formed file of the next version (checksum valid), and one whose version bytes alone were changed.
  const std::string next = std::to_string(kStateFormatVersion + 1);
  write_bytes(path("next.state"), assemble(split_sections(bytes_), kStateFormatVersion + 1));
  EXPECT_EQ(load_error(sim, path("next.state")),
            path("next.state") + ": state file version " + next + ", this arcsim reads versions 1 to 2");
  std::string bytes = bytes_;
  bytes[10] = 1;  // version 65536 + 2
  write_bytes(path("v65538.state"), bytes);
  EXPECT_EQ(load_error(sim, path("v65538.state")),
            path("v65538.state") + ": state file version 65538, this arcsim reads versions 1 to 2");
  write_bytes(path("v0.state"), assemble(split_sections(bytes_), 0));
  EXPECT_EQ(load_error(sim, path("v0.state")),
            path("v0.state") + ": state file version 0, this arcsim reads versions 1 to 2");
  expect_untouched(sim, scene_);
}

// Version 1 files (byte-wise FNV-1a checksum) still load, to the same simulation as the version 2 file; a version 1
// file with a version 2 checksum, or the other way round, is refused as corrupt.
TEST_F(StateErrors, VersionOneFilesStillLoadAndEachVersionChecksItsOwnChecksum) {
  const std::vector<Section> sections = split_sections(bytes_);
  write_bytes(path("v1.state"), assemble(sections, 1));
  Simulation from_v1(scene_), from_v2(scene_);
  EXPECT_EQ(load_error(from_v1, path("v1.state")), "");
  write_bytes(path("v2.state"), assemble(sections, 2));
  EXPECT_EQ(load_error(from_v2, path("v2.state")), "");
  ASSERT_EQ(from_v1.cloths[0].mesh.nodes.size(), from_v2.cloths[0].mesh.nodes.size());
  for (size_t n = 0; n < from_v1.cloths[0].mesh.nodes.size(); ++n)
    EXPECT_EQ(from_v1.cloths[0].mesh.nodes[n].x, from_v2.cloths[0].mesh.nodes[n].x);

  std::string swapped = assemble(sections, 1);
  swapped.resize(swapped.size() - 8);
  put_le(swapped, state_checksum(swapped.data(), swapped.size(), 2), 8);
  write_bytes(path("v1-word.state"), swapped);
  Simulation sim(scene_);
  EXPECT_EQ(load_error(sim, path("v1-word.state")),
            path("v1-word.state") + ": checksum mismatch: the state file is corrupt");
  expect_untouched(sim, scene_);
}

// The word checksum sees a change in any byte, in a trailing partial word, and in trailing zero bytes.
TEST(StateChecksum, ChangesWithAnyByteAndWithTrailingZeros) {
  std::string data(37, '\0');
  for (size_t i = 0; i < data.size(); ++i) data[i] = static_cast<char>(i * 7 + 3);
  const uint64_t base = state_checksum(data.data(), data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    std::string changed = data;
    changed[i] = static_cast<char>(changed[i] ^ 0x10);
    EXPECT_NE(state_checksum(changed.data(), changed.size()), base) << "byte " << i;
  }
  std::string padded = data + std::string(3, '\0');
  EXPECT_NE(state_checksum(padded.data(), padded.size()), base);
  EXPECT_NE(state_checksum(data.data(), 32), state_checksum((data.substr(0, 32) + std::string(8, '\0')).data(), 40));
  EXPECT_NE(state_checksum(data.data(), data.size(), 1), base);
}

TEST_F(StateErrors, EveryTruncationIsReported) {
  Simulation sim(scene_);
  int accepted = 0, unclear = 0;
  for (size_t length = 1; length < bytes_.size(); ++length) {
    // A new file each time: rewriting one file in place makes the file system flush it, which is slow.
    const std::string cut = path("cut" + std::to_string(length) + ".state");
    write_bytes(cut, bytes_.substr(0, length));
    const std::string message = load_error(sim, cut);
    fs::remove(cut);
    if (message.empty()) ++accepted;
    else if (!starts_with(message, cut + ": truncated state file (")) {
      if (++unclear <= 3) ADD_FAILURE() << "length " << length << ": " << message;
    }
  }
  const std::string cut = path("cut.state");
  EXPECT_EQ(accepted, 0);
  EXPECT_EQ(unclear, 0);
  write_bytes(cut, bytes_.substr(0, 100));
  EXPECT_EQ(load_error(sim, cut),
            cut + ": truncated state file (100 bytes, the header says " + std::to_string(bytes_.size()) + ")");
  expect_untouched(sim, scene_);
}

TEST_F(StateErrors, EveryFlippedByteIsDetected) {
  Simulation sim(scene_);
  int accepted = 0, unexpected = 0;
  for (size_t at = 0; at < bytes_.size(); ++at) {
    std::string bytes = bytes_;
    bytes[at] = static_cast<char>(bytes[at] ^ (at % 2 ? 0x01 : 0x80));
    const std::string bad = path("flipped" + std::to_string(at) + ".state");
    write_bytes(bad, bytes);
    const std::string message = load_error(sim, bad);
    fs::remove(bad);
    // Magic and version are read first; a changed size field may read as a truncation; anything else
    // (the section table, payloads, the checksum itself) is a checksum mismatch.
    bool expected;
    if (at < 8) expected = message == bad + ": not an arcsim state file";
    else if (at < 12) expected = contains(message, ": state file version ");
    else if (at >= 16 && at < 24) expected = contains(message, "checksum mismatch") || contains(message, "truncated");
    else expected = message == bad + ": checksum mismatch: the state file is corrupt";
    if (message.empty()) ++accepted;
    else if (!expected && ++unexpected <= 3) ADD_FAILURE() << "byte " << at << ": " << message;
  }
  EXPECT_EQ(accepted, 0);
  EXPECT_EQ(unexpected, 0);
  const std::string bad = path("flipped.state");
  write_bytes(bad, bytes_ + "junk");
  EXPECT_EQ(load_error(sim, bad), bad + ": checksum mismatch: the state file is corrupt");
  expect_untouched(sim, scene_);
}

TEST_F(StateErrors, UnknownMissingAndRepeatedSections) {
  const std::vector<Section> sections = split_sections(bytes_);
  ASSERT_EQ(sections.size(), 4u);
  EXPECT_EQ(sections[0].tag + sections[1].tag + sections[2].tag + sections[3].tag, "TIMECLTHOBSTHNDL");
  // Re-assembling unchanged gives the original bytes (the test's decoder agrees with the writer).
  EXPECT_TRUE(assemble(sections) == bytes_);
  Simulation sim(scene_);

  std::vector<Section> renamed = sections;
  renamed.push_back({"COLL", "\x01\x02"});
  write_bytes(path("unknown.state"), assemble(renamed));
  EXPECT_EQ(load_error(sim, path("unknown.state")),
            path("unknown.state") + ": section 'COLL' is unknown to this arcsim (state format version 2)");

  renamed = sections;
  renamed[2].tag = std::string("O\0\x7f'", 4);
  write_bytes(path("binary-tag.state"), assemble(renamed));
  EXPECT_EQ(load_error(sim, path("binary-tag.state")),
            path("binary-tag.state") + ": section 'O\\x00\\x7f\\x27' is unknown to this arcsim (state format version 2)");

  std::vector<Section> dropped = sections;
  dropped.erase(dropped.begin() + 3);
  write_bytes(path("dropped.state"), assemble(dropped));
  EXPECT_EQ(load_error(sim, path("dropped.state")), path("dropped.state") + ": section 'HNDL' is missing");

  std::vector<Section> repeated = sections;
  repeated.push_back(sections[0]);
  write_bytes(path("twice.state"), assemble(repeated));
  EXPECT_EQ(load_error(sim, path("twice.state")), path("twice.state") + ": section 'TIME' appears twice");

  // Sections may come in any order.
  std::vector<Section> reordered = {sections[3], sections[1], sections[0], sections[2]};
  write_bytes(path("reordered.state"), assemble(reordered));
  Simulation other(scene_);
  EXPECT_EQ(load_error(other, path("reordered.state")), "");
  EXPECT_EQ(other.step(), 1);
  expect_untouched(sim, scene_);
}

TEST_F(StateErrors, SectionLengthsMustMatchTheirContent) {
  const std::vector<Section> sections = split_sections(bytes_);
  Simulation sim(scene_);
  std::vector<Section> longer = sections;
  longer[0].payload += "xyz";
  write_bytes(path("long.state"), assemble(longer));
  EXPECT_EQ(load_error(sim, path("long.state")), path("long.state") + ": section 'TIME': 3 bytes left unread");
  std::vector<Section> shorter = sections;
  shorter[0].payload.pop_back();
  write_bytes(path("short.state"), assemble(shorter));
  EXPECT_EQ(load_error(sim, path("short.state")), path("short.state") + ": section 'TIME': ends early (the file is damaged)");
  // Cut inside the last face: its count no longer fits what is left.
  shorter = sections;
  shorter[1].payload.resize(shorter[1].payload.size() - 5);
  write_bytes(path("short.state"), assemble(shorter));
  EXPECT_EQ(load_error(sim, path("short.state")),
            path("short.state") + ": section 'CLTH': a list of 2 entries is longer than the rest of the section");
  // A corrupt count (here the number of cloths, 2^32 - 1) is refused before anything is allocated for it.
  std::vector<Section> huge = sections;
  huge[1].payload[0] = huge[1].payload[1] = huge[1].payload[2] = huge[1].payload[3] = '\xff';
  write_bytes(path("huge.state"), assemble(huge));
  EXPECT_TRUE(contains(load_error(sim, path("huge.state")), "section 'CLTH': a list of 4294967295 entries"));
  expect_untouched(sim, scene_);
}

TEST_F(StateErrors, CountsMustMatchTheScene) {
  struct Case {
    SceneShape loaded_into;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{2, 1, 1, 1}, "the state file has 1 cloths, the scene has 2 (was it saved from another scene?)"},
      {{1, 2, 1, 1}, "cloth 0: the state file has 1 materials, the scene has 2 (was it saved from another scene?)"},
      {{1, 1, 0, 1}, "the state file has 1 obstacles, the scene has 0 (was it saved from another scene?)"},
      {{1, 1, 1, 2}, "the state file has 1 handles, the scene has 2 (was it saved from another scene?)"},
  };
  for (const Case& c : cases) {
    const Scene other = make_scene(c.loaded_into);
    Simulation sim(other);
    EXPECT_EQ(load_error(sim, good_), good_ + ": " + c.message);
    expect_untouched(sim, other);
  }
}

TEST_F(StateErrors, BadReferencesAndValuesInsideAWellFormedFile) {
  // Written by save_state itself from a corrupted simulation, so the checksum is valid and only the content
  // checks can catch them.
  struct Case {
    void (*corrupt)(Simulation&);
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](Simulation& s) { s.cloths[0].mesh.faces[1].v[2] = 99; }, "cloth 0: face 1 has vert 99 but the mesh has 4 verts"},
      {[](Simulation& s) { s.cloths[0].mesh.nodes[2].edges.push_back(-3); },
       "cloth 0: node 2 lists edge -3 but the mesh has 5 edges"},
      {[](Simulation& s) { s.cloths[0].mesh.edges[0].f[1] = 7; }, "cloth 0: edge 0 has face 7 but the mesh has 2 faces"},
      {[](Simulation& s) { s.cloths[0].mesh.faces[0].material = 1; }, "cloth 0: face 0 uses material 1 but the cloth has 1"},
      {[](Simulation& s) { s.handles[0].nodes[1] = 4; }, "handle 0: node 4 is out of range (the cloth has 4 nodes)"},
      {[](Simulation& s) { s.restore_clock(0, -1, 0); }, "section 'TIME': step -1 is out of range"},
  };
  for (const Case& c : cases) {
    Simulation source(scene_);
    c.corrupt(source);
    const std::string bad = path("bad.state");
    save_state(source, bad);
    Simulation sim(scene_);
    EXPECT_EQ(load_error(sim, bad), bad + ": " + c.message);
    expect_untouched(sim, scene_);
  }
  // Broken adjacency is found by the mesh checks (message from mesh/validate.hpp).
  {
    Simulation source(scene_);
    source.cloths[0].mesh.verts[0].faces.clear();
    save_state(source, path("bad.state"));
    Simulation sim(scene_);
    EXPECT_TRUE(starts_with(load_error(sim, path("bad.state")), path("bad.state") + ": cloth 0: "));
    expect_untouched(sim, scene_);
  }
  // So is a non-finite number. save_state refuses to write one, so the file is saved with a marker value in its
  // place, the marker's 8 bytes are overwritten with a NaN's and the checksum is made valid again.
  {
    Simulation source(scene_);
    constexpr double kMarker = 1234.5678125;  // exact in binary; nowhere else in the state
    source.cloths[0].mesh.nodes[3].v.y() = kMarker;
    save_state(source, path("nan.state"));
    std::string bytes = read_bytes(path("nan.state"));
    std::string marker(8, '\0'), nan(8, '\0');
    const double nan_value = std::nan("");
    std::memcpy(marker.data(), &kMarker, 8);
    std::memcpy(nan.data(), &nan_value, 8);
    const size_t at = bytes.find(marker);
    ASSERT_NE(at, std::string::npos);
    ASSERT_EQ(bytes.find(marker, at + 1), std::string::npos);
    bytes.replace(at, 8, nan);
    bytes.resize(bytes.size() - 8);
    put_le(bytes, state_checksum(bytes.data(), bytes.size()), 8);
    write_bytes(path("nan.state"), bytes);
    Simulation sim(scene_);
    const std::string error = load_error(sim, path("nan.state"));
    EXPECT_TRUE(starts_with(error, path("nan.state") + ": cloth 0: node 3")) << error;
    expect_untouched(sim, scene_);
  }
}

TEST_F(StateErrors, ANonFiniteStateIsNeverWritten) {
  Simulation source(scene_);
  source.cloths[0].mesh.faces[1].Fp(0, 0) = std::numeric_limits<double>::infinity();
  try {
    save_state(source, path("inf.state"));
    FAIL() << "a state with an infinite Fp was written";
  } catch (const NumericalError& e) {
    EXPECT_EQ(std::string(e.what()), path("inf.state") + ": not written: cloth 0 face 1: has non-finite thickness, "
                                                         "Fp, Sp or damage");
  }
  EXPECT_FALSE(fs::exists(path("inf.state")));
}

TEST_F(StateErrors, UnwritablePathIsAnInputError) {
  const Simulation sim(scene_);
  const std::string target = path("no-such-folder/x.state");
  try {
    save_state(sim, target);
    ADD_FAILURE() << "saved into a missing folder";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), target + ": cannot write (No such file or directory)");
  }
}

}  // namespace
}  // namespace arcsim
