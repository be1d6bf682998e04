#include "app/frame_report.hpp"

#include <algorithm>
#include <string>

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
  if (!r.plastic_work.empty()) {
    JsonLine work;
    double total = 0;
    for (double w : r.plastic_work) total += w;
    work.number("total", total);
    for (size_t c = 0; c < r.plastic_work.size(); ++c)
      work.number(("cloth" + std::to_string(c)).c_str(), r.plastic_work[c]);
    line.object("plastic_work", work);
  }
  if (!r.meshes.empty()) {
    JsonLine meshes;
    for (size_t c = 0; c < r.meshes.size(); ++c) {
      const ClothMeshReport& m = r.meshes[c];
      JsonLine mesh;
      mesh.integer("faces", m.faces)
          .number("edge_min", m.edge_min)
          .number("edge_median", m.edge_median)
          .number("edge_max", m.edge_max);
      if (m.remeshed)
        mesh.integer("splits", m.splits).integer("flips", m.flips).integer("collapses", m.collapses)
            .integer("guarded", m.guarded);
      meshes.object(("cloth" + std::to_string(c)).c_str(), mesh);
    }
    line.object("meshes", meshes);
  }
  if (r.has_impact_zones) {
    const ImpactZoneTotals& z = r.impact_zones;
    JsonLine zones;
    zones.integer("steps", z.steps)
        .integer("impacts", z.impacts)
        .integer("zones", z.zones)
        .integer("iterations", z.iterations)
        .integer("largest_zone", z.largest_zone)
        .integer("fallback_zones", z.fallback_zones)
        .integer("ill_conditioned_zones", z.ill_conditioned_zones)
        .integer("unresolved_steps", z.unresolved_steps)
        .number("work", z.work)
        .number("largest_work", z.largest_work)
        .integer("warnings", z.warnings);
    line.object("impact_zones", zones);
  }
  if (r.has_fracture) {
    const FractureStats& f = r.fracture;
    JsonLine fracture;
    fracture.integer("cracks", f.cracks)
        .integer("refused", f.refused)
        .integer("substeps", f.substeps)
        .integer("candidates", f.candidates)
        .integer("largest_zone", f.largest_zone)
        .integer("remesh_edits", f.remesh_edits)
        .number("max_ratio", f.max_ratio)
        .number("seconds", f.seconds);
    line.object("fracture", fracture);
  }
  if (r.has_time_step) {
    JsonLine step;
    step.integer("substeps", r.substeps)
        .integer("retries", r.retries)
        .integer("level", r.substep_level)
        .number("smallest", r.smallest_step);
    if (r.held_steps > 0) step.integer("held", r.held_steps);
    if (!r.retry_cause.empty()) step.text("cause", r.retry_cause);
    line.object("time_step", step);
  }
  if (r.solves > 0) {
    JsonLine solver;
    double max_residual = 0;
    for (double x : r.residuals) max_residual = std::max(max_residual, x);
    solver.integer("solves", r.solves)
        .integer("factorizations", r.factorizations)
        .integer("iterations", r.solver_iterations)
        .number("max_residual", max_residual)
        .numbers("residuals", r.residuals);
    line.object("solver", solver);
  }
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
  if (r.has_fracture) line.integer("cracks", r.fracture.cracks);
  return line.str();
}

}  // namespace arcsim
