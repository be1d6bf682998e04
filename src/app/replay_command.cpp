#include "app/replay_command.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <system_error>

#include "app/arguments.hpp"
#include "app/output_files.hpp"
#include "io/obj.hpp"
#include "io/scene_parser.hpp"
#include "math/errors.hpp"
#include "render/render.hpp"

namespace arcsim {

namespace fs = std::filesystem;

const char kReplayHelp[] =
    "Usage: arcsim replay <out-dir> [<png-dir>] [options]\n"
    "\n"
    "Renders every saved frame of the run in <out-dir> off-screen (OSMesa) to <png-dir>/NNNNN.png (default\n"
    "<out-dir>/png). The camera is framed once, on where the cloths are over the frames drawn (less the 1% of\n"
    "their vertices farthest out, such as a shard falling away; obstacles only when there is no cloth); cloth\n"
    "fronts are orange, backs blue-grey, borders and cracks dark lines, obstacles grey, over a ground plane with\n"
    "shadows. No display is needed.\n"
    "\n"
    "Options:\n"
    "  --size WxH        image size in pixels (default 1280x720)\n"
    "  --frames A:B      only frames A to B (either may be omitted: 10:, :50)\n"
    "  --every N         every N-th saved frame\n"
    "  --wire            draw the triangle edges\n"
    "  --video FILE      also assemble the images into a video with ffmpeg (if installed)\n"
    "  --quiet           no progress\n"
    "\n"
    "Exit codes: 0 success, 2 bad input (no frames, unreadable frame, bad option), 1 internal error.\n";

namespace {

const char kCommand[] = "replay";

RenderMesh load_render_mesh(const std::string& path, bool highlight_boundary) {
  const ObjData obj = read_obj(path);
  std::vector<std::array<int, 3>> tris;
  tris.reserve(obj.tris.size());
  for (const auto& t : obj.tris) tris.push_back({obj.vert_node[t[0]], obj.vert_node[t[1]], obj.vert_node[t[2]]});
  return make_render_mesh(obj.node_x, std::move(tris), highlight_boundary);
}

void parse_size(const std::string& text, int& width, int& height) {
  char x = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &x, &height, &extra) != 3 || (x != 'x' && x != 'X') ||
      width < 16 || height < 16 || width > 16384 || height > 16384)
    throw InputError(std::string(kCommand) + ": --size: expected WxH with 16 <= W, H <= 16384, got '" + text + "'");
}

}  // namespace

int run_replay_command(const std::vector<std::string>& args, const Console& console) {
  const std::vector<OptionSpec> specs = {{"--size", true},  {"--frames", true}, {"--every", true},
                                         {"--wire", false}, {"--video", true},  {"--quiet", false}};
  const ParsedArguments parsed = parse_arguments(args, specs, kCommand);
  if (parsed.help) {
    console.out << kReplayHelp;
    return 0;
  }
  int width = 1280, height = 720, first = 0, last = 1000000000, every = 1;
  bool wire = false, quiet = false;
  std::string video;
  for (const auto& [name, value] : parsed.options) {
    if (name == "--size") parse_size(value, width, height);
    else if (name == "--frames") frame_range_argument(kCommand, value, first, last);
    else if (name == "--every") every = integer_argument(kCommand, name, value, 1, 1000000);
    else if (name == "--wire") wire = true;
    else if (name == "--video") video = value;
    else if (name == "--quiet") quiet = true;
  }
  const std::vector<std::string>& pos = parsed.positionals;
  if (pos.empty() || pos.size() > 2)
    throw InputError(std::string(kCommand) + ": usage: arcsim replay <out-dir> [<png-dir>] [options]");
  const std::string dir = pos[0];
  const std::string png_dir = pos.size() == 2 ? pos[1] : (fs::path(dir) / "png").string();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir + ": no such output folder");

  // Frames to draw.
  std::vector<std::pair<int, SavedFrameFiles>> frames = select_saved_frames(dir, first, last, every);
  if (frames.empty()) throw InputError(dir + ": no saved frames (NNNNN_CC.obj) to render");

  // World up from the run's scene; frame time for the video.
  Vec3 up = Vec3::UnitZ();
  double frame_time = 0.04;
  const fs::path scene_copy = fs::path(dir) / kSceneCopyName;
  if (fs::exists(scene_copy, ec)) {
    const Scene scene = load_scene(scene_copy.string());
    up = up_from_gravity(scene.gravity);
    frame_time = scene.step_time * scene.frame_steps * std::max(1, scene.save_every);
  }

  // One camera for the whole animation, framed on the sheets: where their vertices are over every frame drawn,
  // less the farthest 1% along each axis (pieces that fall out of the scene), and not the obstacles (an 8 m floor
  // under sphere-break.json's 0.6 m sphere filled the picture); on the obstacles only when there is no sheet.
  // The stage (ground, shadows) still spans everything.
  RenderOptions options;
  options.up = up;
  options.wireframe = wire;
  std::vector<Vec3> sheet_points;
  Eigen::AlignedBox3d obstacle_bounds;
  for (const auto& [frame, files] : frames) {
    for (const std::string& f : files.cloths) {
      const RenderMesh mesh = load_render_mesh(f, false);
      options.scene_bounds.extend(bounds_of(mesh));
      sheet_points.insert(sheet_points.end(), mesh.positions.begin(), mesh.positions.end());
    }
    for (const std::string& f : files.obstacles) obstacle_bounds.extend(bounds_of(load_render_mesh(f, false)));
  }
  if (!obstacle_bounds.isEmpty()) options.scene_bounds.extend(obstacle_bounds);
  Eigen::AlignedBox3d subject = bulk_bounds(sheet_points, 0.01);
  if (subject.isEmpty()) subject = options.scene_bounds;
  const Camera camera = frame_camera(subject, static_cast<double>(width) / height, options.up);

  fs::create_directories(png_dir, ec);
  if (ec) throw InputError(png_dir + ": cannot create the image folder (" + ec.message() + ")");
  Renderer renderer(width, height);
  const auto start = std::chrono::steady_clock::now();
  int done = 0;
  for (const auto& [frame, files] : frames) {
    std::vector<RenderMesh> cloths, obstacles;
    for (const std::string& f : files.cloths) cloths.push_back(load_render_mesh(f, true));
    for (const std::string& f : files.obstacles) obstacles.push_back(load_render_mesh(f, false));
    char name[32];
    std::snprintf(name, sizeof name, "%05d.png", frame);
    render_frame_png(renderer, cloths, obstacles, camera, options, (fs::path(png_dir) / name).string());
    ++done;
    if (!quiet && console.err_is_terminal)
      console.err << "\rreplay: frame " << done << "/" << frames.size() << std::flush;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!quiet) {
    if (console.err_is_terminal) console.err << "\n";
    console.err << "replay: " << done << " frames rendered to " << png_dir << " (" << width << "x" << height << ", "
                << (seconds > 0 ? done / seconds : 0) << " frames/s)\n";
  }

  if (!video.empty()) {
    if (std::system("command -v ffmpeg >/dev/null 2>&1") != 0)
      throw InputError(std::string(kCommand) + ": --video needs ffmpeg, which is not installed");
    // Frame numbers may have gaps (--every, save_every): feed the images in order through a list file.
    const fs::path list = fs::path(png_dir) / "frames.txt";
    {
      std::ofstream out(list);
      for (const auto& [frame, files] : frames) {
        char name[32];
        std::snprintf(name, sizeof name, "%05d.png", frame);
        out << "file '" << fs::absolute(fs::path(png_dir) / name).string() << "'\nduration " << frame_time * every
            << "\n";
      }
    }
    const std::string command = "ffmpeg -loglevel error -y -f concat -safe 0 -i '" + list.string() +
                                "' -pix_fmt yuv420p -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' '" + video + "'";
    if (std::system(command.c_str()) != 0) throw InputError(std::string(kCommand) + ": ffmpeg failed to write " + video);
    if (!quiet) console.err << "replay: video written to " << video << "\n";
  }
  return 0;
}

}  // namespace arcsim
