#include "sim/simulation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <sstream>

#include "fracture/fracture_sizing.hpp"
#include "io/obj.hpp"
#include "math/errors.hpp"
#include "mesh/validate.hpp"
#include "plasticity/plastic_step.hpp"
#include "sim/persistent_fallback.hpp"
#include "sim/remesh_cloth.hpp"

namespace arcsim {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A speed no sheet reaches in a stable run (m/s); beyond it the step has diverged.
constexpr double kUnstableSpeed = 1e4;

}  // namespace

double Handle::strength(double t) const {
  if (t < start_time) return 0;
  if (t <= end_time) return 1;
  if (fade_time <= 0) return 0;
  const double s = 1 - (t - end_time) / fade_time;
  return s > 0 ? s * s * s * s : 0;
}

Simulation::Simulation(const Scene& scene) : scene_(scene), motions_(scene.motions) {
  step_time_ = scene.step_time;
  frame_steps_ = scene.frame_steps;
  end_time_ = scene.end_time;
  end_frame_ = scene.end_frame;
  fracture.zone_rings = scene.fracture.zone_rings;
  fracture.max_zone_rings = scene.fracture.max_zone_rings;
  fracture.support_stress = scene.fracture.support_stress;
  fracture.substepping = scene.fracture.substepping;
  fracture.local_remesh = scene.fracture.local_remesh;
  fracture.reproject = scene.fracture.reproject;
  fracture.independent_openings = scene.fracture.independent_openings;
  fracture.virtual_iterations = scene.fracture.virtual_iterations;
  fracture.max_cracks = scene.magic.max_cracks;
  // New lips start apart by twice the projection thickness: closer, they would count as touching (an in-plane
  // contact with no room to resolve it) from their first step on.
  {
    const double projection = scene.magic.projection_thickness >= 0 ? scene.magic.projection_thickness
                                                                     : 0.1 * scene.magic.repulsion_thickness;
    fracture.opening.lip_gap = std::max(fracture.opening.lip_gap, 2 * projection);
  }
  for (Motion& m : motions_) m.finalize();
  for (size_t i = 0; i < scene.cloths.size(); ++i) load_cloth(scene.cloths[i], static_cast<int>(i));
  for (size_t i = 0; i < scene.obstacles.size(); ++i) load_obstacle(scene.obstacles[i], static_cast<int>(i));
  for (size_t i = 0; i < scene.handles.size(); ++i) load_handle(scene.handles[i], static_cast<int>(i));
  // ARCSim's fixed_high_res_mesh: one uniform refinement to size_min (after the handles marked their nodes
  // preserved), then no remeshing.
  if (scene_.enabled("remeshing") && scene_.magic.fixed_high_res_mesh) {
    const RemeshOptions options = remesh_options(scene_);
    for (size_t c = 0; c < cloths.size(); ++c) {
      HandleLineKeeper keeper(handles, static_cast<int>(c), cloths[c].mesh);
      RemeshOptions with_keeper = options;
      with_keeper.observers.push_back(&keeper);
      const RemeshStats stats = refine_to_size_min(cloths[c], with_keeper);
      topology_changed(static_cast<int>(c), edited(stats));
    }
  }
  move_obstacles(0);
  for (Obstacle& o : obstacles)
    for (Node& n : o.mesh.nodes) n.v.setZero();
  // ARCSim's start-up remeshes every cloth once before the first step (relax_initial_state's remeshing step,
  // without a pop filter), so frame 0 is already sized for the sheet at rest. WHY: stepping first on the input
  // mesh (square.json: 4 faces) folds it along its few edges, and the first remesh then refines those folds to
  // size_min (1024 faces) only to coarsen them again a frame later.
  if (scene_.magic.remesh_at_start) remeshing_step();
}

void Simulation::load_cloth(const ClothSpec& spec, int index) {
  Cloth cloth;
  cloth.source = spec.mesh;
  cloth.materials = spec.materials;
  cloth.remeshing = spec.remeshing;
  cloth.mesh = load_obj_mesh(spec.mesh);
  Mesh& mesh = cloth.mesh;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    Face& face = mesh.faces[f];
    if (face.material < 0 || face.material >= static_cast<int>(cloth.materials.size())) {
      std::ostringstream msg;
      msg << spec.mesh << ": face " << f + 1 << " uses material " << face.material << " but cloths[" << index
          << "].materials has " << cloth.materials.size() << " entries";
      throw InputError(msg.str());
    }
    if (face.thickness <= 0) face.thickness = cloth.materials[face.material].thickness;
  }
  // World placement; rest coordinates are scaled with the sheet (ARCSim). A curved reference shape takes the
  // placed world shape as its rest shape.
  for (Vert& v : mesh.verts) v.u *= spec.transform.scale;
  for (Node& n : mesh.nodes) n.x = n.x0 = spec.transform.apply(n.x);
  if (spec.reference != "linear") {
    // The placed world shape becomes the rest shape; edge rest angles follow it, keeping any plastic offset the
    // file gave (rest angle minus the rest dihedral).
    std::vector<double> plastic_offset(mesh.edges.size());
    for (size_t e = 0; e < mesh.edges.size(); ++e)
      plastic_offset[e] = mesh.edges[e].rest_theta - mesh.rest_dihedral(static_cast<int>(e));
    for (Vert& v : mesh.verts) v.u = mesh.nodes[v.node].x;
    for (size_t e = 0; e < mesh.edges.size(); ++e)
      mesh.edges[e].rest_theta = mesh.rest_dihedral(static_cast<int>(e)) + plastic_offset[e];
  }
  // The reference surface keeps a curved rest shape through remeshing; "sphere" also moves rest and world
  // positions onto the fitted sphere (ARCSim).
  cloth.reference = choose_reference(spec.reference, mesh, spec.transform,
                                     scene_.path + ": cloths[" + std::to_string(index) + "].reference");
  reproject_rest_positions(mesh, *cloth.reference);
  mesh.update_rest_data();
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!(mesh.faces[f].rest_area > 0)) {
      std::ostringstream msg;
      msg << spec.mesh << ": face " << f + 1 << " has zero rest area after the cloth transform";
      throw InputError(msg.str());
    }
  }
  const InitialVelocity& iv = spec.velocity;
  for (Node& n : mesh.nodes) n.v = iv.linear + iv.angular.cross(n.x - iv.origin);
  update_node_masses(mesh, cloth.materials);
  cloths.push_back(std::move(cloth));
}

void Simulation::load_obstacle(const ObstacleSpec& spec, int index) {
  Obstacle o;
  o.source = spec.mesh;
  o.mesh = load_obj_mesh(spec.mesh);
  o.motion = spec.motion;
  o.start_time = spec.start_time;
  o.end_time = spec.end_time;
  o.floor = spec.proxy == "floor";
  for (Node& n : o.mesh.nodes) {
    n.x = n.x0 = spec.transform.apply(n.x);
    o.base.push_back(n.x);
  }
  obstacles.push_back(std::move(o));
}

void Simulation::load_handle(const HandleSpec& spec, int index) {
  std::ostringstream where;
  where << scene_.path << ": handles[" << index << "]";
  if (spec.type != "node")
    throw InputError(where.str() + ".type: handle type '" + spec.type +
                     "' is not supported yet (node handles are)");
  Handle h;
  h.cloth = spec.cloth;
  h.motion = spec.motion;
  h.start_time = spec.start_time;
  h.end_time = spec.end_time;
  h.fade_time = spec.fade_time;
  h.holds_line = spec.label >= 0;
  Mesh& mesh = cloths[spec.cloth].mesh;
  if (spec.label >= 0) {
    for (size_t n = 0; n < mesh.nodes.size(); ++n)
      if (mesh.nodes[n].label == spec.label) h.nodes.push_back(static_cast<int>(n));
    if (h.nodes.empty())
      throw InputError(where.str() + ".label: no node of cloth " + std::to_string(spec.cloth) + " (" +
                       cloths[spec.cloth].source + ") has label " + std::to_string(spec.label));
  } else {
    for (int n : spec.nodes) {
      if (n < 0 || n >= static_cast<int>(mesh.nodes.size()))
        throw InputError(where.str() + ".nodes: node " + std::to_string(n) + " is out of range (the mesh has " +
                         std::to_string(mesh.nodes.size()) + " nodes)");
      h.nodes.push_back(n);
    }
  }
  for (int n : h.nodes) {
    mesh.nodes[n].preserve = true;
    h.anchors.push_back(mesh.nodes[n].x);
  }
  handles.push_back(std::move(h));
}

void Simulation::move_obstacles(double t) {
  for (Obstacle& o : obstacles) {
    o.active = t >= o.start_time && t <= o.end_time;
    const Transform pose = o.motion >= 0 ? motions_[o.motion].pose(t) : Transform();
    for (size_t i = 0; i < o.mesh.nodes.size(); ++i) {
      Node& n = o.mesh.nodes[i];
      n.x0 = n.x;
      n.x = pose.apply(o.base[i]);
      n.v = o.motion >= 0 ? motions_[o.motion].velocity(t, o.base[i]) : Vec3::Zero();
    }
  }
}

ExternalLoads Simulation::loads_for(int cloth, double t) const {
  ExternalLoads loads;
  loads.gravity = scene_.gravity;
  loads.wind = scene_.wind;
  for (const Handle& h : handles) {
    if (h.cloth != cloth) continue;
    const double strength = h.strength(t);
    if (strength <= 0) continue;
    const Transform pose = h.motion >= 0 ? motions_[h.motion].pose(t) : Transform();
    for (size_t i = 0; i < h.nodes.size(); ++i)
      loads.springs.push_back({h.nodes[i], pose.apply(h.anchors[i]), scene_.magic.handle_stiffness * strength});
  }
  return loads;
}

void Simulation::refresh_elements() {
  for (Cloth& cloth : cloths) {
    if (!cloth.elements_dirty) continue;
    update_node_masses(cloth.mesh, cloth.materials);
    // The pattern waits for the step's contact pairs (physics_step), so that it is built once.
    build_element_cache(cloth.mesh, cloth.materials, cloth.elements, PatternBuild::kDeferred);
    cloth.elements_dirty = false;
  }
}

void Simulation::physics_step(double dt) {
  refresh_elements();
  for (size_t c = 0; c < cloths.size(); ++c) {
    Cloth& cloth = cloths[c];
    ExternalLoads loads = loads_for(static_cast<int>(c), time_);
    if (c < step_contacts_.size()) loads.contacts = step_contacts_[c];
    update_contact_pattern(cloth.elements, loads.contacts);
    cloth.solver.set_settings(scene_.solver);
    implicit_euler_step(cloth.mesh, cloth.elements, cloth.solver, loads, dt, &times.solver);
  }
}

namespace {

size_t cloth_node_count(const std::vector<Cloth>& cloths) {
  size_t nodes = 0;
  for (const Cloth& c : cloths) nodes += c.mesh.nodes.size();
  return nodes;
}

}  // namespace

CollisionSettings Simulation::collision_settings() const {
  CollisionSettings s;
  const MagicParams& magic = scene_.magic;
  s.repulsion_thickness = magic.repulsion_thickness;
  s.projection_thickness =
      magic.projection_thickness >= 0 ? magic.projection_thickness : 0.1 * magic.repulsion_thickness;
  s.stiffness = magic.collision_stiffness * (passive() ? kPassiveStiffnessFactor : 1.0);
  s.friction = scene_.friction;
  s.obstacle_friction = scene_.obs_friction;
  // Material neighbours (collision/proximity.hpp) exist to let a crack's lips close; a scene that cannot crack
  // keeps the full thickness between all parts of a sheet, as ARCSim has it (its frames stay as they were).
  s.neighbour_thickness = scene_.enabled("fracture") ? fracture.opening.lip_gap : s.repulsion_thickness;
  s.step = step_;
  s.work_budget = scene_.collision_budget * static_cast<double>(cloth_node_count(cloths));
  // Floor proxy: the plane y = lowest point of the (active) floor obstacles.
  for (const Obstacle& o : obstacles) {
    if (!o.floor || !o.active) continue;
    for (const Node& n : o.mesh.nodes) {
      s.floor_height = s.floor ? std::min(s.floor_height, n.x.y()) : n.x.y();
      s.floor = true;
    }
  }
  return s;
}

namespace {

std::vector<const Mesh*> active_obstacle_meshes(const std::vector<Obstacle>& obstacles) {
  std::vector<const Mesh*> meshes;
  for (const Obstacle& o : obstacles)
    if (o.active) meshes.push_back(&o.mesh);
  return meshes;
}

}  // namespace

std::vector<std::vector<ContactTerm>> Simulation::proximity_step(double dt) {
  std::vector<const Mesh*> cloth_meshes;
  for (const Cloth& c : cloths) cloth_meshes.push_back(&c.mesh);
  return collisions_.proximity_terms(cloth_meshes, active_obstacle_meshes(obstacles), collision_settings(), dt);
}

void Simulation::collision_step(double dt, bool finest_substep) {
  std::vector<Mesh*> cloth_meshes;
  for (Cloth& c : cloths) cloth_meshes.push_back(&c.mesh);
  CollisionSettings settings = collision_settings();
  // At the finest substep a fallback can no longer be substepped away, and stacked crack lips keep the side
  // they start on (at coarser levels their fallback made the step substep, which bounds the collision
  // correction: docs/stability.md, 2026-12-06 (h2)).
  settings.stacked_lips_keep_start_side = finest_substep;
  const ImpactZoneStats stats =
      collisions_.resolve_collisions(cloth_meshes, active_obstacle_meshes(obstacles), settings, dt);
  step_fallback_nodes_ = collisions_.fallback_nodes();
  step_collisions_resolved_ = stats.resolved;
  if (!stats.out_of_budget) return;
  // The cause; the step names itself (Simulation::step, or the adaptive step if even its smallest substep fails).
  std::ostringstream msg;
  msg << "collision handling did not converge within its budget (" << stats.work << " work units; collision_budget "
      << scene_.collision_budget << " per node x " << cloth_node_count(cloths) << " nodes): " << stats.zones
      << " impact zones, the largest " << stats.largest_zone << " nodes";
  if (!scene_.adaptive_step.enabled)
    msg << "; try adaptive_time_step, a smaller time step, or a larger collision_budget";
  throw NumericalError(msg.str());
}

std::string Simulation::nonfinite_state() const {
  if (!std::isfinite(time_)) return "the simulation time is not finite";
  for (size_t c = 0; c < cloths.size(); ++c) {
    const std::string problem = arcsim::nonfinite_state(cloths[c].mesh);
    if (!problem.empty()) return "cloth " + std::to_string(c) + " " + problem;
  }
  for (size_t i = 0; i < obstacles.size(); ++i)
    for (size_t n = 0; n < obstacles[i].mesh.nodes.size(); ++n) {
      const Node& node = obstacles[i].mesh.nodes[n];
      if (!node.x.allFinite() || !node.x0.allFinite() || !node.v.allFinite())
        return "obstacle " + std::to_string(i) + " node " + std::to_string(n) + ": has non-finite x, x0 or v";
    }
  for (size_t h = 0; h < handles.size(); ++h)
    for (size_t k = 0; k < handles[h].anchors.size(); ++k)
      if (!handles[h].anchors[k].allFinite())
        return "handle " + std::to_string(h) + " anchor " + std::to_string(k) + ": is not finite";
  return "";
}

void Simulation::check_state() const {
  for (size_t c = 0; c < cloths.size(); ++c) {
    const Mesh& mesh = cloths[c].mesh;
    for (size_t n = 0; n < mesh.nodes.size(); ++n) {
      const Node& node = mesh.nodes[n];
      const bool finite = node.x.allFinite() && node.v.allFinite();
      if (finite && node.v.norm() < kUnstableSpeed) continue;
      std::ostringstream msg;
      msg << "unstable at step " << step_ << " (t = " << time_ << " s): cloth " << c << " node " << n + 1
          << (finite ? " moves faster than 1e4 m/s" : " has a non-finite position or velocity")
          << "; try a smaller time step";
      throw NumericalError(msg.str());
    }
  }
}

double Simulation::current_step_time() const { return passive() ? kPassiveStepFactor * step_time_ : step_time_; }

void Simulation::advance_step() {
  const double dt = current_step_time();
  const double start = time_;
  time_ += dt;
  ++step_;
  if ((step_ - 1) % frame_steps_ == 0) {
    time_step_stats = TimeStepStats();
    // A frame's first step factorises afresh: a run resumed from a frame's state (which holds no factorisation)
    // then takes the same solves as one that ran through.
    for (Cloth& cloth : cloths) cloth.solver.refresh();
  }
  jitter_step();

  // Proximity forces enter the implicit solve; the impact-zone response follows the position update.
  refresh_elements();
  audit(&StepEnergies::start);
  double dynamics_dt = dt;
  if (scene_.adaptive_step.enabled) {
    dynamics_dt = adaptive_dynamics_step(start, dt);
  } else {
    move_obstacles(time_);
    try {
      dynamics_step(dt);
    } catch (const NumericalError& e) {
      // Named here, once, for every cause (the adaptive step names it when its smallest substep fails).
      std::ostringstream what;
      what << "step " << step_ << " (t = " << start << " to " << time_ << " s): " << e.what();
      throw NumericalError(what.str());
    }
    time_step_stats.record(1, dt, 0);
  }

  auto t0 = std::chrono::steady_clock::now();
  plasticity_step(dt);
  times.plasticity += seconds_since(t0);
  audit(&StepEnergies::after_plasticity, true);

  // Fracture's virtual update relaxes the last (sub)step: its contacts and displacements are that step's.
  t0 = std::chrono::steady_clock::now();
  fracture_step(dynamics_dt);
  times.fracture += seconds_since(t0);
  audit(&StepEnergies::after_fracture, true);

  if (step_ % frame_steps_ == 0) {
    t0 = std::chrono::steady_clock::now();
    remeshing_step();
    times.remeshing += seconds_since(t0);
    ++frame_;
  }
  audit(&StepEnergies::after_remeshing, true);
}

void Simulation::dynamics_step(double dt, bool finest_substep) {
  auto t0 = std::chrono::steady_clock::now();
  step_contacts_.clear();
  step_fallback_nodes_.clear();
  if (scene_.enabled("proximity") && scene_.enabled("physics")) step_contacts_ = proximity_step(dt);
  times.collision += seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  if (scene_.enabled("physics")) {
    physics_step(dt);
  } else {
    for (Cloth& cloth : cloths)
      for (Node& n : cloth.mesh.nodes) n.x0 = n.x;
  }
  times.physics += seconds_since(t0);
  check_state();
  audit(&StepEnergies::after_physics);

  // The collision response's largest correction, for adaptive_time_step.max_correction.
  const bool measure = scene_.adaptive_step.enabled && scene_.adaptive_step.max_correction < kInfinity;
  std::vector<std::vector<Vec3>> after_physics;
  if (measure)
    for (const Cloth& cloth : cloths) {
      after_physics.emplace_back();
      for (const Node& n : cloth.mesh.nodes) after_physics.back().push_back(n.x);
    }
  t0 = std::chrono::steady_clock::now();
  if (scene_.enabled("collision")) collision_step(dt, finest_substep);
  times.collision += seconds_since(t0);
  step_correction_ = 0;
  step_correction_at_ = {-1, -1};
  if (measure)
    for (size_t c = 0; c < cloths.size(); ++c)
      for (size_t i = 0; i < after_physics[c].size(); ++i) {
        const double moved = (cloths[c].mesh.nodes[i].x - after_physics[c][i]).norm();
        if (moved > step_correction_) {
          step_correction_ = moved;
          step_correction_at_ = {static_cast<int>(c), static_cast<int>(i)};
        }
      }
  check_state();
  audit(&StepEnergies::after_collision);
}

namespace {

// The node state the dynamics change (positions, start positions, velocities, accelerations), per cloth.
struct DynamicsSnapshot {
  std::vector<std::vector<std::array<Vec3, 4>>> nodes;
};

DynamicsSnapshot take_snapshot(const std::vector<Cloth>& cloths) {
  DynamicsSnapshot s;
  s.nodes.resize(cloths.size());
  for (size_t c = 0; c < cloths.size(); ++c)
    for (const Node& n : cloths[c].mesh.nodes) s.nodes[c].push_back({n.x, n.x0, n.v, n.a});
  return s;
}

void restore_snapshot(const DynamicsSnapshot& s, std::vector<Cloth>& cloths) {
  for (size_t c = 0; c < cloths.size(); ++c)
    for (size_t i = 0; i < s.nodes[c].size(); ++i) {
      Node& n = cloths[c].mesh.nodes[i];
      n.x = s.nodes[c][i][0];
      n.x0 = s.nodes[c][i][1];
      n.v = s.nodes[c][i][2];
      n.a = s.nodes[c][i][3];
    }
}

}  // namespace

std::string Simulation::substep_problem(double dt, const std::vector<std::vector<char>>* tolerated,
                                        bool* tolerated_used) const {
  const AdaptiveStepSpec& a = scene_.adaptive_step;
  if (a.reject_fallbacks)
    for (size_t c = 0; c < step_fallback_nodes_.size(); ++c) {
      const std::vector<int>& nodes = step_fallback_nodes_[c];
      if (nodes.empty()) continue;
      const bool held = tolerated && step_collisions_resolved_ && c < tolerated->size() &&
                        std::all_of(nodes.begin(), nodes.end(), [&](int n) {
                          return n < static_cast<int>((*tolerated)[c].size()) && (*tolerated)[c][n];
                        });
      if (held) {
        if (tolerated_used) *tolerated_used = true;
        continue;
      }
      return "the collision response of cloth " + std::to_string(c) + " needed a fallback (" +
             std::to_string(nodes.size()) + " nodes moved rigidly or held)";
    }
  if (step_correction_ > a.max_correction) {
    std::ostringstream what;
    what << "the collision response moved cloth " << step_correction_at_[0] << " node " << step_correction_at_[1] + 1
         << " by " << step_correction_ << " m in a substep of " << dt << " s (max_correction " << a.max_correction
         << " m)";
    return what.str();
  }
  if (a.max_motion < kInfinity)
    for (size_t c = 0; c < cloths.size(); ++c)
      for (size_t i = 0; i < cloths[c].mesh.nodes.size(); ++i) {
        const Node& n = cloths[c].mesh.nodes[i];
        const double moved = (n.x - n.x0).norm();
        if (moved > a.max_motion) {
          std::ostringstream what;
          what << "cloth " << c << " node " << i + 1 << " moved " << moved << " m in a substep of " << dt
               << " s (max_motion " << a.max_motion << " m)";
          return what.str();
        }
      }
  return "";
}

namespace {

// Per cloth, a flag per node: the nodes within `rings` edges of `seeds` (per cloth, node indices).
std::vector<std::vector<char>> nodes_within_rings(const std::vector<Cloth>& cloths,
                                                  const std::vector<std::vector<int>>& seeds, int rings) {
  std::vector<std::vector<char>> flags(cloths.size());
  for (size_t c = 0; c < cloths.size(); ++c) {
    const Mesh& mesh = cloths[c].mesh;
    flags[c].assign(mesh.nodes.size(), 0);
    std::vector<int> front;
    for (int n : c < seeds.size() ? seeds[c] : std::vector<int>())
      if (n >= 0 && n < static_cast<int>(mesh.nodes.size()) && !flags[c][n]) {
        flags[c][n] = 1;
        front.push_back(n);
      }
    for (int ring = 0; ring < rings; ++ring) {
      std::vector<int> next;
      for (int n : front)
        for (int e : mesh.nodes[n].edges)
          for (int m : mesh.edges[e].n)
            if (m != kNone && !flags[c][m]) {
              flags[c][m] = 1;
              next.push_back(m);
            }
      front = std::move(next);
    }
  }
  return flags;
}

}  // namespace

double Simulation::adaptive_dynamics_step(double start, double dt) {
  const AdaptiveStepSpec& a = scene_.adaptive_step;
  const DynamicsSnapshot snapshot = take_snapshot(cloths);
  PersistentFallback persistent(kPersistentFallbackLevels);
  bool retaken = false;  // the step was retaken at its streak's level once already
  int resume_level = 0;  // where refinement goes on if that attempt fails
  for (;;) {
    // A fallback that comes at one moment of the step whatever the substep's length (sim/persistent_fallback.hpp)
    // is retaken as at the finest substep, at the level where the streak began (finer substeps did not help),
    // and held if it persists there on the streak's nodes.
    const bool retake = persistent.persistent() && !retaken;
    if (retake) {
      retaken = true;
      resume_level = substep_level_;
      substep_level_ = persistent.streak_level();
      steps_at_level_ = 0;
    }
    const int substeps = 1 << substep_level_;
    const double h = dt / substeps;
    const bool smallest = !(0.5 * h >= a.min_step) || substep_level_ >= kMaxSubstepLevel;
    const bool finest = smallest || persistent.persistent();
    std::vector<std::vector<char>> tolerated;
    if (persistent.persistent()) tolerated = nodes_within_rings(cloths, persistent.streak_nodes(), kHeldFallbackRings);
    bool held = false;
    std::string problem;
    int failed_substep = -1;
    std::vector<std::vector<int>> fallback_nodes(cloths.size());
    try {
      // Obstacles start the step where they were at its start (a retried step finds them moved on).
      move_obstacles(start);
      for (int k = 0; k < substeps && problem.empty(); ++k) {
        time_ = k + 1 == substeps ? start + dt : start + (k + 1) * h;
        move_obstacles(time_);
        failed_substep = k;
        dynamics_step(h, finest);
        problem = substep_problem(h, persistent.persistent() ? &tolerated : nullptr, &held);
        for (size_t c = 0; c < step_fallback_nodes_.size() && c < cloths.size(); ++c)
          fallback_nodes[c].insert(fallback_nodes[c].end(), step_fallback_nodes_[c].begin(),
                                   step_fallback_nodes_[c].end());
      }
      // substep_problem names a fallback first whenever there was one (and fallbacks are rejected).
      if (!problem.empty())
        persistent.record_failure(failed_substep,
                                  a.reject_fallbacks ? step_fallback_nodes_ : std::vector<std::vector<int>>(),
                                  substep_level_);
    } catch (const NumericalError& e) {
      problem = e.what();
      persistent.record_failure(failed_substep, {}, substep_level_);
    }
    if (problem.empty()) {
      for (auto& nodes : fallback_nodes) {
        std::sort(nodes.begin(), nodes.end());
        nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
      }
      step_fallback_nodes_ = std::move(fallback_nodes);
      time_step_stats.record(substeps, h, substep_level_);
      if (held) ++time_step_stats.held_steps;
      if (substep_level_ > 0 && ++steps_at_level_ >= a.grow_after) {
        --substep_level_;
        steps_at_level_ = 0;
      }
      return h;
    }
    restore_snapshot(snapshot, cloths);
    time_ = start + dt;
    ++time_step_stats.retries;
    time_step_stats.cause = problem;
    // A step taken as the finest for a persistent fallback that fails anyway (for another cause) refines on.
    if (smallest) {
      std::ostringstream what;
      what << "step " << step_ << " (t = " << start << " to " << start + dt << " s) failed at the smallest substep "
           << h << " s (adaptive_time_step.min_step " << a.min_step << " s): " << problem
           << "; try a smaller min_step or time step";
      throw NumericalError(what.str());
    }
    // A retaken attempt that fails goes on refining from where the streak had got to.
    substep_level_ = retake ? resume_level : substep_level_ + 1;
    steps_at_level_ = 0;
  }
}

void Simulation::audit(double StepEnergies::*phase, bool fresh_elements) {
  if (!audit_energy) return;
  step_energies.resize(cloths.size());
  for (size_t c = 0; c < cloths.size(); ++c) {
    const Cloth& cloth = cloths[c];
    const ExternalLoads loads = loads_for(static_cast<int>(c), time_);
    if (fresh_elements && cloth.elements_dirty) {
      ElementCache rebuilt;
      build_element_cache(cloth.mesh, cloth.materials, rebuilt);
      step_energies[c].*phase = mechanical_energy(cloth.mesh, rebuilt, loads);
    } else {
      step_energies[c].*phase = mechanical_energy(cloth.mesh, cloth.elements, loads);
    }
  }
}

namespace {

// splitmix64: a counter-based generator, so a node's jitter depends only on (step, node) and resume replays it.
uint64_t mix_bits(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

// ARCSim's add_jitter: during frames 0, 10, ..., 90 every node moves along its normal by a random amount in
// [0, 1e-4) m. A perfectly flat sheet under compression has no reason to buckle one way or the other; the
// jitter gives it one, as real paper's waviness does.
void Simulation::jitter_step() {
  constexpr double kJitterAmplitude = 1e-4;  // m
  if (!scene_.magic.add_jitter || frame_ % 10 != 0 || frame_ >= 100) return;
  for (size_t c = 0; c < cloths.size(); ++c) {
    Mesh& mesh = cloths[c].mesh;
    const std::vector<Vec3> normals = world_node_normals(mesh);
    for (size_t n = 0; n < mesh.nodes.size(); ++n) {
      const uint64_t bits = mix_bits(mix_bits(mix_bits(static_cast<uint64_t>(step_)) ^ c) ^ n);
      const double unit = static_cast<double>(bits >> 11) * 0x1.0p-53;  // uniform in [0, 1)
      mesh.nodes[n].x += kJitterAmplitude * unit * normals[n];
    }
  }
}

void Simulation::plasticity_step(double dt) {
  plastic_work.resize(cloths.size(), 0.0);
  if ((step_ - 1) % frame_steps_ == 0) std::fill(plastic_work.begin(), plastic_work.end(), 0.0);
  if (!scene_.enabled("plasticity")) return;
  for (size_t c = 0; c < cloths.size(); ++c) {
    Cloth& cloth = cloths[c];
    if (!has_plasticity(cloth.materials)) continue;
    const PlasticStepResult r = plastic_step(cloth.mesh, cloth.materials, dt);
    plastic_work[c] += r.work();
    if (r.changed()) cloth.elements_dirty = true;
  }
}

bool Simulation::fracture_active() const { return scene_.enabled("fracture") && !passive(); }

void Simulation::fracture_step(double dt) {
  fracture_stats.resize(cloths.size());
  if ((step_ - 1) % frame_steps_ == 0) std::fill(fracture_stats.begin(), fracture_stats.end(), FractureStats());
  if (!fracture_active()) return;
  FractureContext context;
  context.remesh = remesh_options(scene_);
  context.dt = dt;
  FractureParams params = fracture;
  params.local_remesh = params.local_remesh && scene_.enabled("remeshing") && !scene_.magic.fixed_high_res_mesh;
  for (size_t c = 0; c < cloths.size(); ++c) {
    Cloth& cloth = cloths[c];
    if (!has_fracture(cloth.materials)) continue;
    context.remesh.sizing.remeshing = cloth.remeshing;
    context.remesh.reference = cloth.reference.get();
    context.remesh.obstacles = active_obstacle_meshes(obstacles);
    for (size_t other = 0; other < cloths.size(); ++other)
      if (other != c) context.remesh.obstacles.push_back(&cloths[other].mesh);
    context.loads = loads_for(static_cast<int>(c), time_);
    if (c < step_contacts_.size()) context.loads.contacts = step_contacts_[c];
    context.untrusted_nodes = c < step_fallback_nodes_.size() ? step_fallback_nodes_[c] : std::vector<int>();
    HandleLineKeeper keeper(handles, static_cast<int>(c), cloth.mesh);
    context.remesh.observers = {&keeper};
    const FractureStats s = arcsim::fracture_step(cloth.mesh, cloth.materials, params, context, cloth.zone_solver);
    context.remesh.observers.clear();
    fracture_stats[c] += s;
    topology_changed(static_cast<int>(c), s.edited);
  }
  check_state();
}

void Simulation::remeshing_step() {
  if (!scene_.enabled("remeshing") || scene_.magic.fixed_high_res_mesh) return;
  RemeshOptions options = remesh_options(scene_);
  remesh_stats.assign(cloths.size(), RemeshStats());
  for (size_t c = 0; c < cloths.size(); ++c) {
    // The edits may not push this cloth into an obstacle or another cloth.
    options.obstacles = active_obstacle_meshes(obstacles);
    for (size_t other = 0; other < cloths.size(); ++other)
      if (other != c) options.obstacles.push_back(&cloths[other].mesh);
    // Fracture sizing (paper §5.1) while fracture runs.
    std::vector<Mat3> fracture_terms;
    if (fracture_active())
      fracture_terms = fracture_sizing_terms(cloths[c].mesh, cloths[c].materials, cloths[c].remeshing.refine_fracture,
                                             cloths[c].remeshing.size_min);
    options.extras.face_terms = fracture_terms.empty() ? nullptr : &fracture_terms;
    HandleLineKeeper keeper(handles, static_cast<int>(c), cloths[c].mesh);
    options.observers = {&keeper};
    remesh_stats[c] = remesh(cloths[c], nullptr, options);
    options.observers.clear();
    options.extras.face_terms = nullptr;
    remesh_stats[c].active_faces.clear();
    topology_changed(static_cast<int>(c), edited(remesh_stats[c]));
  }
  check_state();
}

void Simulation::topology_changed(int c, bool edited) {
  Cloth& cloth = cloths[c];
  // Reprojection alone only moves world positions, which the element cache does not hold.
  if (edited) cloth.elements_dirty = true;
  update_node_masses(cloth.mesh, cloth.materials);
  compact_cloth(c);
}

void Simulation::compact_cloth(int c) {
  Cloth& cloth = cloths[c];
  if (cloth.mesh.is_compact()) return;
  remap_handles(handles, c, cloth.mesh.compact());
  cloth.elements_dirty = true;
}

void Simulation::advance_frame() {
  do {
    advance_step();
  } while (step_ % frame_steps_ != 0);
}

bool Simulation::finished() const {
  // Half a step of slack so that accumulated rounding in `time_` does not add a step.
  return time_ >= end_time_ - 0.5 * current_step_time() || frame_ >= end_frame_;
}

double Simulation::total_frames() const {
  const double frame_time = step_time_ * frame_steps_;
  if (!(end_time_ > scene_.passive_time)) return std::min(end_frame_, std::ceil(end_time_ / frame_time - 1e-9));
  // Frames before passive_time, then frames of the longer passive step.
  const double active = std::ceil(scene_.passive_time / frame_time - 1e-9);
  const double rest = std::ceil((end_time_ - active * frame_time) / (kPassiveStepFactor * frame_time) - 1e-9);
  return std::min(end_frame_, active + std::max(rest, 0.0));
}

}  // namespace arcsim
