#include "app/inspect_command.hpp"

#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <system_error>

#include "app/arguments.hpp"
#include "app/json_line.hpp"
#include "app/output_files.hpp"
#include "collision/intersections.hpp"
#include "io/obj.hpp"
#include "math/errors.hpp"
#include "mesh/pieces.hpp"
#include "mesh/validate.hpp"

namespace arcsim {

namespace fs = std::filesystem;

const char kInspectHelp[] =
    "Usage: arcsim inspect <out-dir> [options]\n"
    "\n"
    "Checks and measures the saved frames of a run (the folder `arcsim simulate` wrote). For each frame it prints\n"
    "one JSON line on stdout: per sheet its faces, nodes, pieces (faces joined through shared nodes: the shards\n"
    "of a broken sheet), the face count and rest area (m^2) of every piece, largest first, whether its mesh is\n"
    "valid (manifold, oriented, finite, no degenerate face; the first problem otherwise); and the number of\n"
    "intersecting pairs of non-adjacent triangles (exact test) within and between sheets and between sheets and\n"
    "obstacles. A summary goes to stderr. See docs/file-formats.md.\n"
    "\n"
    "Options:\n"
    "  --frames A:B      only frames A to B (either may be omitted: 10:, :50)\n"
    "  --every N         every N-th saved frame\n"
    "  --last            only the last saved frame\n"
    "  --quiet           no summary on stderr\n"
    "\n"
    "Exit codes: 0 every frame inspected is valid and free of intersections, 3 a frame is not (the first one is\n"
    "named on stderr; every frame is still reported), 2 bad input (no such folder, no frames, bad option).\n";

namespace {

const char kCommand[] = "inspect";

struct SheetReport {
  std::optional<Mesh> mesh;  // empty when the file could not be read as a valid mesh
  std::string problem;       // "" when valid
};

SheetReport load_sheet(const std::string& path) {
  SheetReport r;
  try {
    r.mesh = load_obj_mesh(path);
  } catch (const InputError& e) {
    r.problem = one_line(e.what());
    return r;
  }
  MeshCheckOptions options;
  std::string problem = check_mesh(*r.mesh, options);
  if (problem.empty()) problem = nonfinite_state(*r.mesh);
  if (!problem.empty()) r.problem = fs::path(path).filename().string() + ": " + problem;
  return r;
}

}  // namespace

int run_inspect_command(const std::vector<std::string>& args, const Console& console) {
  const std::vector<OptionSpec> specs = {
      {"--frames", true}, {"--every", true}, {"--last", false}, {"--quiet", false}};
  const ParsedArguments parsed = parse_arguments(args, specs, kCommand);
  if (parsed.help) {
    console.out << kInspectHelp;
    return 0;
  }
  int first = 0, last = 1000000000, every = 1;
  bool only_last = false, quiet = false;
  for (const auto& [name, value] : parsed.options) {
    if (name == "--frames") frame_range_argument(kCommand, value, first, last);
    else if (name == "--every") every = integer_argument(kCommand, name, value, 1, 1000000);
    else if (name == "--last") only_last = true;
    else if (name == "--quiet") quiet = true;
  }
  if (parsed.positionals.size() != 1)
    throw InputError(std::string(kCommand) + ": usage: arcsim inspect <out-dir> [options]");
  const std::string dir = parsed.positionals[0];
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir + ": no such output folder");

  std::vector<std::pair<int, SavedFrameFiles>> frames = select_saved_frames(dir, first, last, every);
  if (only_last && !frames.empty()) frames.erase(frames.begin(), frames.end() - 1);
  if (frames.empty()) throw InputError(dir + ": no saved frames (NNNNN_CC.obj) to inspect");

  std::string first_failure;
  int failed_frames = 0;
  std::string last_summary;
  for (const auto& [frame, files] : frames) {
    std::vector<SheetReport> sheets;
    for (const std::string& f : files.cloths) sheets.push_back(load_sheet(f));
    std::vector<Mesh> obstacle_meshes;
    std::string frame_problem;
    for (const std::string& f : files.obstacles) {
      try {
        obstacle_meshes.push_back(load_obj_mesh(f));
      } catch (const InputError& e) {
        frame_problem = one_line(e.what());
      }
    }

    std::vector<JsonLine> sheet_lines;
    std::vector<const Mesh*> readable, obstacles;
    std::ostringstream summary;
    for (size_t c = 0; c < sheets.size(); ++c) {
      const SheetReport& s = sheets[c];
      JsonLine line;
      if (s.mesh) {
        readable.push_back(&*s.mesh);
        int live_faces = 0, live_nodes = 0;
        for (const Face& f : s.mesh->faces) live_faces += !f.dead;
        for (const Node& n : s.mesh->nodes) live_nodes += !n.dead;
        const std::vector<Piece> pieces = mesh_pieces(*s.mesh);
        std::vector<long long> faces_of;
        std::vector<double> area_of;
        for (const Piece& p : pieces) {
          faces_of.push_back(p.faces);
          area_of.push_back(p.rest_area);
        }
        line.integer("faces", live_faces).integer("nodes", live_nodes).integer("pieces",
                                                                              static_cast<long long>(pieces.size()));
        line.integers("piece_faces", faces_of).numbers("piece_rest_area", area_of);
        summary << (c ? "; " : "") << "sheet " << c << ": " << live_faces << " faces, " << pieces.size()
                << (pieces.size() == 1 ? " piece" : " pieces");
      }
      line.boolean("valid", s.problem.empty());
      if (!s.problem.empty()) {
        line.text("problem", s.problem);
        if (frame_problem.empty()) frame_problem = s.problem;
      }
      sheet_lines.push_back(line);
    }
    for (const Mesh& m : obstacle_meshes) obstacles.push_back(&m);
    // Faces are numbered as in the frame files (1-based, like OBJ) in messages.
    const std::vector<IntersectingPair> crossing = intersecting_pairs(readable, obstacles);
    if (frame_problem.empty() && !crossing.empty()) {
      const IntersectingPair& p = crossing.front();
      std::ostringstream what;
      what << crossing.size() << " intersecting triangle pair" << (crossing.size() == 1 ? "" : "s")
           << " (first: sheet " << p.sheet_a << " face " << p.face_a + 1 << " and "
           << (p.obstacle ? "obstacle " : "sheet ") << p.sheet_b << " face " << p.face_b + 1 << ")";
      frame_problem = what.str();
    }

    JsonLine out;
    out.integer("frame", frame).objects("sheets", sheet_lines);
    out.integer("intersections", static_cast<long long>(crossing.size())).boolean("clean", frame_problem.empty());
    console.out << out.str() << "\n";
    if (!frame_problem.empty()) {
      ++failed_frames;
      if (first_failure.empty()) first_failure = "frame " + std::to_string(frame) + ": " + frame_problem;
    }
    last_summary = "frame " + std::to_string(frame) + ": " + summary.str();
  }
  console.out.flush();
  if (!first_failure.empty()) {
    console.err << "arcsim: inspect: " << dir << ": " << failed_frames << " of " << frames.size()
                << " frames fail; first: " << first_failure << "\n";
    return 3;
  }
  if (!quiet)
    console.err << "inspect: " << frames.size() << " frame" << (frames.size() == 1 ? "" : "s")
                << " valid, no intersections; " << last_summary << "\n";
  return 0;
}

}  // namespace arcsim
