// Binary state files: the whole evolving state of a Simulation, saved losslessly so that a run resumed from a
// file continues bit-identically to one that was never interrupted (`arcsim resume`).
//
// What is NOT in the file is what the scene already determines: materials, remeshing parameters, motions,
// handle and obstacle settings, the time step. A state is therefore loaded into a Simulation freshly
// constructed from the same scene, and then overwrites everything that evolves.
//
// Layout (version 1), all integers little-endian, every double as its raw 8 IEEE-754 bytes:
//   magic "ARCSIMST" (8 bytes) | uint32 format version | uint32 section count S | uint64 file size (bytes,
//   everything included) | section table: S x (4-byte ASCII tag, uint64 payload length) | the S payloads in
//   table order | uint64 FNV-1a 64 checksum of every byte before it.
// Sections of version 1 (all required; each listed once):
//   TIME  time (s), step, frame
//   CLTH  per cloth: material count, then the full mesh: every stored field of nodes, verts, edges and faces,
//         derived rest data included, and the adjacency lists in their stored order (their order steers later
//         floating-point sums, so rebuilding them would break bit-identity)
//   OBST  per obstacle: node positions x, x0, velocities v, and `active`
//   HNDL  per handle: cloth, node indices, anchors
// Optional sections (written only where they apply):
//   STEP  adaptive time stepping's substep level and the steps taken at it (two int32), in scenes that turn
//         adaptive_time_step on
// Later modules add their state (collision history, remeshing reference, fracture flags, random generator)
// as new tagged sections in state.cpp; a reader that meets a tag it does not know refuses the file, naming it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "math/types.hpp"

namespace arcsim {

class Simulation;

// Version 2 (2026-12-03) checksums 64-bit words instead of bytes (8x fewer multiplies: the byte loop was a third
// of the time spent saving a state); version 1 files are still read.
constexpr uint32_t kStateFormatVersion = 2;
constexpr uint32_t kOldestStateFormatVersion = 1;

// Writes the state to `path` atomically (a temporary file renamed over it). Throws InputError "<path>: cannot
// write (...)" if the file cannot be written, NumericalError "<path>: not written: ..." (nothing written) if the
// state holds a non-finite number (Simulation::nonfinite_state), std::logic_error if a cloth mesh holds removed
// elements (the simulation compacts after every topology phase, so a state is only saved between steps).
void save_state(const Simulation& sim, const std::string& path);

// Overwrites the evolving state of `sim` (constructed from the same scene) with the file's and marks every
// cloth's physics caches dirty so they rebuild. Checks everything before changing anything: on error `sim` is
// untouched. Throws InputError "<path>: <problem>" for a missing or unreadable file, a file that is not a state
// file, another format version, a truncated or corrupt file (checksum), unknown, repeated or missing sections,
// and content inconsistent with the scene (numbers of cloths, materials, obstacles, handles, bad references).
void load_state(Simulation& sim, const std::string& path);

// --- Byte-level encoding, for section codecs ---

class StateWriter {
 public:
  void put_u8(uint8_t value) { *grow(1) = static_cast<char>(value); }
  void put_bool(bool value) { put_u8(value ? 1 : 0); }
  void put_u32(uint32_t value) { put_le<4>(value); }
  void put_u64(uint64_t value) { put_le<8>(value); }
  void put_i32(int32_t value) { put_u32(static_cast<uint32_t>(value)); }
  void put_i64(int64_t value) { put_u64(static_cast<uint64_t>(value)); }
  void put_f64(double value);  // the raw bits: -0, denormals and infinities survive
  // A fixed-size Eigen matrix or vector, column by column.
  template <typename Derived>
  void put_matrix(const Eigen::MatrixBase<Derived>& m) {
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      for (Eigen::Index r = 0; r < m.rows(); ++r) put_f64(m(r, c));
  }
  // A count (uint32) then the values; throws std::length_error past 2^32 - 1 entries.
  void put_count(size_t count);
  void put_int_list(const std::vector<int>& values);
  void put_bytes(const char* data, size_t size) {
    if (size > 0) std::memcpy(grow(size), data, size);
  }
  // Makes room for `extra` more bytes, sparing the regrowth of a large payload.
  void reserve(size_t extra) {
    if (used_ + extra > bytes_.size()) bytes_.resize(used_ + extra);
  }
  size_t size() const { return used_; }
  std::string take() {
    bytes_.resize(used_);
    used_ = 0;
    return std::move(bytes_);
  }

 private:
  // The next n bytes of the payload, to be written (the buffer grows geometrically; appending to a
  // std::string value by value dominated saving large meshes).
  char* grow(size_t n) {
    if (used_ + n > bytes_.size()) bytes_.resize(std::max(2 * bytes_.size(), used_ + n));
    char* at = &bytes_[used_];
    used_ += n;
    return at;
  }
  // Little-endian bytes of the low N bytes of `value` (one store on little-endian hosts).
  template <int N>
  void put_le(uint64_t value) {
    static_assert(N == 4 || N == 8, "4- or 8-byte fields");
    char* at = grow(N);
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    if constexpr (N == 8) {
      std::memcpy(at, &value, 8);
    } else {
      const uint32_t low = static_cast<uint32_t>(value);
      std::memcpy(at, &low, N);
    }
#else
    for (int i = 0; i < N; ++i) at[i] = static_cast<char>(static_cast<uint8_t>(value >> (8 * i)));
#endif
  }

  std::string bytes_;  // [0, used_) written; the rest is room
  size_t used_ = 0;
};

// Reads a section's payload. Every read is bounds-checked: running past the end throws InputError
// "<context>: ends early" (context names the file and section), so bad input never reads out of bounds.
class StateReader {
 public:
  StateReader(const char* data, size_t size, std::string context)
      : data_(data), size_(size), context_(std::move(context)) {}
  uint8_t get_u8();
  bool get_bool();  // anything but 0 or 1 is an error
  uint32_t get_u32();
  uint64_t get_u64();
  int32_t get_i32() { return static_cast<int32_t>(get_u32()); }
  int64_t get_i64() { return static_cast<int64_t>(get_u64()); }
  double get_f64();
  template <typename Derived>
  void get_matrix(Eigen::MatrixBase<Derived>& m) {
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      for (Eigen::Index r = 0; r < m.rows(); ++r) m(r, c) = get_f64();
  }
  Vec3 get_vec3() {
    Vec3 v;
    get_matrix(v);
    return v;
  }
  // A count written by put_count; refused if `min_item_bytes` times it exceeds what is left (a corrupt count
  // must not trigger a huge allocation).
  size_t get_count(size_t min_item_bytes);
  std::vector<int> get_int_list();
  size_t remaining() const { return size_ - pos_; }
  // Throws InputError "<context>: <problem>".
  [[noreturn]] void fail(const std::string& problem) const;

 private:
  const char* need(size_t n);
  const char* data_;
  size_t size_;
  size_t pos_ = 0;
  std::string context_;
};

// FNV-1a 64-bit hash of `size` bytes (the checksum of version 1 state files).
uint64_t fnv1a64(const char* data, size_t size);

// The checksum of a state file of `version` over its `size` bytes before the checksum. Version 2 and later: FNV-1a
// steps over the bytes taken as little-endian 64-bit words (a last partial word zero-padded), then over the byte
// count, so that trailing zero bytes still change it. Version 1: fnv1a64.
uint64_t state_checksum(const char* data, size_t size, uint32_t version = kStateFormatVersion);

}  // namespace arcsim
