#include "app/frame_report.hpp"

#include "app/json_line.hpp"

namespace arcsim {

std::string frame_log_line(const FrameReport& r) {
  JsonLine wall;
  wall.number("physics", r.wall.physics)
      .number("collision", r.wall.collision)
      .number("remeshing", r.wall.remeshing)
      .number("plasticity", r.wall.plasticity)
      .number("fracture", r.wall.fracture)
      .number("output", r.wall.output)
      .number("total", r.wall.total);
  JsonLine line;
  line.integer("frame", r.frame)
      .number("time", r.time)
      .integer("steps", r.steps)
      .integer("nodes", r.nodes)
      .integer("faces", r.faces)
      .boolean("saved", r.saved)
      .object("wall", wall);
  return line.str();
}

std::string progress_json_line(const FrameReport& r, double total_frames) {
  JsonLine line;
  line.integer("frame", r.frame)
      .number("total", total_frames)
      .number("time", r.time)
      .integer("faces", r.faces)
      .integer("nodes", r.nodes)
      .number("wall", r.wall.total);
  return line.str();
}

}  // namespace arcsim
