// Helpers for the tests of the `arcsim` program: they run the real binary (env ARCSIM_BIN; the tests skip when
// it is unset) in temporary folders and look at its exit code, stdout, stderr and output files.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace arcsim::app_test {

namespace fs = std::filesystem;

// The binary under test, as an absolute path, or "" when ARCSIM_BIN is unset.
inline std::string binary() {
  const char* bin = std::getenv("ARCSIM_BIN");
  if (!bin || !*bin) return "";
  return fs::absolute(bin).string();
}

#define ARCSIM_REQUIRE_BINARY()                                                  \
  do {                                                                           \
    if (::arcsim::app_test::binary().empty()) GTEST_SKIP() << "ARCSIM_BIN is not set"; \
  } while (0)

// A file of the repository (e.g. "conf/demo.json"): looked up in the working directory (where `make check`
// runs the tests), then beside the binary's folder (bin/..).
inline std::string repo_file(const std::string& relative) {
  if (fs::exists(relative)) return fs::absolute(relative).string();
  const std::string bin = binary();
  if (!bin.empty()) {
    const fs::path beside = fs::path(bin).parent_path().parent_path() / relative;
    if (fs::exists(beside)) return beside.string();
  }
  return "";
}

// A fresh folder, removed with everything in it at the end of the test.
class TempFolder {
 public:
  TempFolder() {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            ("arcsim-app-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;

  const fs::path& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

  // Writes `text` to the relative path `name`, creating folders; returns the full path.
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }

 private:
  fs::path path_;
};

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Single-quoted for /bin/sh.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct RunResult {
  int exit_code = -1;  // -1 if the process did not exit normally (e.g. killed by a signal: a crash)
  std::string out, err;
};

// Runs the binary with `args` in the folder `cwd` (the test's working directory if empty), stdin closed, with
// the environment variables `env` ("NAME=value") added.
inline RunResult run_arcsim(const std::vector<std::string>& args, const std::string& cwd = "",
                            const std::vector<std::string>& env = {}) {
  static std::atomic<int> counter{0};
  const std::string stem = (fs::temp_directory_path() / ("arcsim-app-run-" + std::to_string(::getpid()) + "-" +
                                                         std::to_string(counter++)))
                               .string();
  std::string command;
  if (!cwd.empty()) command += "cd " + shell_quote(cwd) + " && ";
  for (const std::string& e : env) command += "export " + shell_quote(e) + " && ";
  command += shell_quote(binary());
  for (const std::string& a : args) command += " " + shell_quote(a);
  command += " </dev/null >" + shell_quote(stem + ".out") + " 2>" + shell_quote(stem + ".err");
  const int status = std::system(command.c_str());
  RunResult r;
  r.exit_code = status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(stem + ".out");
  r.err = read_text(stem + ".err");
  std::remove((stem + ".out").c_str());
  std::remove((stem + ".err").c_str());
  return r;
}

// A 1 m x 1 m sheet of 2 x 2 cells (9 nodes, 8 faces, CCW), its two corners at y = 1 labelled 1.
inline std::string tiny_sheet_obj() {
  return "v 0 0 0\nv 0.5 0 0\nv 1 0 0\nv 0 0.5 0\nv 0.5 0.5 0\nv 1 0.5 0\n"
         "v 0 1 0\nnl 1\nv 0.5 1 0\nv 1 1 0\nnl 1\n"
         "f 1 2 5\nf 1 5 4\nf 2 3 6\nf 2 6 5\nf 4 5 8\nf 4 8 7\nf 5 6 9\nf 5 9 8\n";
}

// A small valid scene around `mesh` (a path as the scene names it): a soft sheet hanging by label 1, 3 frames of
// 2 steps. `extra` is spliced in as further top-level keys (",\"key\": value ...").
inline std::string tiny_scene(const std::string& mesh, const std::string& material =
                                                           "{\"thickness\": 1e-3, \"density\": 500, "
                                                           "\"elastic_modulus\": 1e6, \"poisson_ratio\": 0.3}",
                              const std::string& extra = "") {
  return "{\n"
         "  \"frame_time\": 0.02, \"frame_steps\": 2, \"end_frame\": 3,\n"
         "  \"cloths\": [{\"mesh\": \"" + mesh + "\", \"materials\": [" + material + "]}],\n"
         "  \"handles\": [{\"label\": 1}],\n"
         "  \"gravity\": [0, 0, -9.8],\n"
         "  \"disable\": [\"remeshing\"]" + extra + "\n"
         "}\n";
}

}  // namespace arcsim::app_test
