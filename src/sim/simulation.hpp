// The simulation: one object that owns every cloth, obstacle, handle and motion of a scene, and advances them
// in time. advance_step() is the one place where the modules hook into the time step, in the paper's order
// (§3.1): physics (implicit Euler with forces and handles), then (as they are added) collisions, plasticity,
// fracture substepping, and remeshing at frame ends.
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "collision/collision_step.hpp"
#include "fracture/fracture_step.hpp"
#include "mesh/mesh.hpp"
#include "physics/cloth_physics.hpp"
#include "remesh/remesh.hpp"
#include "restshape/reference_surface.hpp"
#include "scene/scene.hpp"

namespace arcsim {

// ARCSim's passive_time switch: from then on no fracture, a longer step and softer collisions.
constexpr double kPassiveStepFactor = 5;
constexpr double kPassiveStiffnessFactor = 0.4;

struct Cloth {
  Mesh mesh;
  std::vector<Material> materials;
  RemeshingParams remeshing;
  std::string source;           // mesh file, for messages
  ElementCache elements;        // physics data of the current topology
  CholeskySolver solver;
  CholeskySolver zone_solver;   // fracture's zone solves (its own pattern, changed every solve)
  bool elements_dirty = true;   // topology or rest state changed since the cache was built
  std::shared_ptr<const ReferenceSurface> reference;  // where remeshing puts new rest positions (restshape/)
};

struct Obstacle {
  Mesh mesh;                    // world positions at the current time
  std::vector<Vec3> base;       // positions after the scene transform, before the motion (m)
  int motion = -1;
  double start_time = 0, end_time = kInfinity;
  bool floor = false;           // `proxy: "floor"`
  bool active = true;
  std::string source;
};

struct Handle {
  int cloth = 0;
  std::vector<int> nodes;       // node indices (kept valid through topology edits)
  std::vector<Vec3> anchors;    // positions the nodes are held at before the motion is applied (m)
  int motion = -1;
  double start_time = 0, end_time = kInfinity, fade_time = 0;
  // Whether the handle holds a line rather than a list of points: a node remeshing adds between two of its
  // nodes joins it (sim/remesh_cloth.hpp, HandleLineKeeper). True for handles chosen by label ("every node with
  // that label": a split keeps a label both its ends share); false for node lists, which hold exactly the
  // listed nodes, as in ARCSim.
  bool holds_line = false;
  // Strength in [0, 1] at time t: 0 before start, 1 until end, then (1 - (t - end)/fade)^4 over fade_time.
  double strength(double t) const;
};

// A cloth's mechanical energy (J, physics/cloth_physics.hpp's mechanical_energy) at the phase boundaries of the
// last step, when Simulation::audit_energy is on. The differences are the work of each phase:
// after_physics - start is what the implicit solve added (contact penalties, air; minus damping),
// after_collision - after_physics what the collision response did, after_collision - after_plasticity the
// elastic energy the flow rules released (at least the reported plastic work: weakening releases some too),
// after_fracture - after_plasticity and after_remeshing - after_fracture what the topology edits and their moves
// added (ideally nothing: an opening conserves mass and momentum and should release, not add, elastic energy).
struct StepEnergies {
  double start = 0, after_physics = 0, after_collision = 0, after_plasticity = 0, after_fracture = 0,
         after_remeshing = 0;  // after_remeshing: equal to after_fracture in steps that do not remesh
};

// Wall-clock seconds spent per module since the counters were last cleared.
struct ModuleTimes {
  double physics = 0, collision = 0, remeshing = 0, plasticity = 0, fracture = 0;
  StepTiming solver;  // part of physics
  void clear() { *this = ModuleTimes(); }
};

class Simulation {
 public:
  // Loads the scene's meshes and sets up the initial state (time 0, frame 0). Throws InputError naming the
  // file and element for bad meshes or references.
  explicit Simulation(const Scene& scene);

  // One time step. Throws NumericalError (the state is then left as it was before the step's positions were
  // committed only where stated; callers stop the run) if the step goes unstable.
  void advance_step();
  // Steps until the next frame boundary.
  void advance_frame();
  bool finished() const;
  // "" if every number of the evolving state is finite (time, each cloth's mesh state, obstacle positions and
  // velocities, handle anchors), else "<where>: <problem>" naming the first element that is not. The output
  // guard: no frame or state file is written from a state that fails it.
  std::string nonfinite_state() const;

  const Scene& scene() const { return scene_; }
  double time() const { return time_; }
  double step_time() const { return step_time_; }  // the scene's time step (s)
  // The step the next advance_step() takes (s): step_time(), or kPassiveStepFactor times it from passive_time on.
  double current_step_time() const;
  int step() const { return step_; }
  int frame() const { return frame_; }
  int frame_steps() const { return frame_steps_; }
  // Sets the clock from a saved state (io/state.hpp's load_state); nothing else changes.
  void restore_clock(double time, int step, int frame) {
    time_ = time;
    step_ = step;
    frame_ = frame;
  }

  std::vector<Cloth> cloths;
  std::vector<Obstacle> obstacles;
  std::vector<Handle> handles;
  ModuleTimes times;
  // Impact-zone statistics summed over the steps since clear_collision_totals() (the command line clears them
  // at each frame's start, so they describe one frame).
  const ImpactZoneTotals& collision_totals() const { return collisions_.totals(); }
  void clear_collision_totals() { collisions_.clear_totals(); }
  // Per cloth, the plastic work (J, plasticity/plastic_step.hpp) of the steps of the current frame so far; reset
  // at each frame's first step, so after advance_frame() it is the work of that frame.
  std::vector<double> plastic_work;
  // Per cloth, the operation counts of the last frame-end remeshing pass (active_faces left empty). Mesh sizes
  // for the log: sim/remesh_cloth.hpp's mesh_size_stats(cloths[c].mesh).
  std::vector<RemeshStats> remesh_stats;
  // Per cloth, what fracture substepping did in the steps of the current frame so far (reset at each frame's
  // first step, like plastic_work).
  std::vector<FractureStats> fracture_stats;
  // What the time stepping did in the steps of the current frame so far (reset at each frame's first step):
  // dynamics substeps run, failed attempts redone with a smaller step (adaptive_time_step), the smallest substep
  // (s), the finest level (substeps = 2^level), and the last failure's cause.
  struct TimeStepStats {
    // held_steps: steps taken with a persistent fallback held (Simulation::adaptive_dynamics_step).
    int substeps = 0, retries = 0, level = 0, held_steps = 0;
    double smallest = 0;
    std::string cause;
    // A step taken as `count` substeps of h (s) at `level`.
    void record(int count, double h, int at_level) {
      substeps += count;
      smallest = smallest > 0 ? std::min(smallest, h) : h;
      level = std::max(level, at_level);
    }
  };
  TimeStepStats time_step_stats;
  // Adaptive time stepping's state (saved in state files so that a resumed run continues identically): the
  // current level (each step as 2^level substeps) and the steps that succeeded at it.
  int substep_level() const { return substep_level_; }
  int steps_at_substep_level() const { return steps_at_level_; }
  void restore_substep_level(int level, int steps) {
    substep_level_ = level;
    steps_at_level_ = steps;
  }
  static constexpr int kMaxSubstepLevel = 20;
  // Attempts in a row whose first substep needs a fallback on shared nodes before the next attempt of the step
  // is taken as the finest (sim/persistent_fallback.hpp).
  static constexpr int kPersistentFallbackLevels = 3;
  // A persistent fallback is held (the step accepted with it, if the response ended collision free) when every
  // node it moved lies within this many edges of the nodes the streak fell back on.
  static constexpr int kHeldFallbackRings = 2;
  // Fracture parameters (from the scene; tests and the ablations of tools/ change them).
  FractureParams fracture;
  // Whether the fracture module runs at the current time: enabled in the scene, and before passive_time
  // (ARCSim: from passive_time on, fracture is off, the time step 5x longer, the collision stiffness x0.4).
  bool fracture_active() const;
  bool passive() const { return time_ >= scene_.passive_time; }

  // Energy audit, off by default (tests, diagnostics): fills step_energies (per cloth) in every step, at the
  // cost of one extra element build per cloth and plastic step. The step itself is unchanged by it.
  bool audit_energy = false;
  std::vector<StepEnergies> step_energies;

  // The one follow-up after edits of cloth c (remeshing, fracture: every client of edit/edit_session.hpp calls
  // it after a batch of edits): node masses from the current faces; if `edited` (some topology edit succeeded),
  // the element cache and the solver's pattern are rebuilt before the next solve; dead elements are dropped and
  // the handles' node indices remapped.
  void topology_changed(int c, bool edited);

  // Overrides of the scene's end (command-line options); infinity keeps the scene's value.
  void set_end_time(double t) { end_time_ = t; }
  void set_end_frame(double f) { end_frame_ = f; }
  double end_time() const { return end_time_; }
  double end_frame() const { return end_frame_; }
  // Total number of frames the run will produce (infinity if unbounded).
  double total_frames() const;
  // The collision module's settings for the current step (thicknesses, stiffness, friction, floor, the
  // thickness between material neighbours).
  CollisionSettings collision_settings() const;

 private:
  void load_cloth(const ClothSpec& spec, int index);
  void load_obstacle(const ObstacleSpec& spec, int index);
  void load_handle(const HandleSpec& spec, int index);
  void move_obstacles(double t);
  ExternalLoads loads_for(int cloth, double t) const;
  void refresh_elements();
  // Proximity terms per cloth (empty lists when the module is disabled).
  std::vector<std::vector<ContactTerm>> proximity_step(double dt);
  // The implicit step of every cloth with its loads and step_contacts_.
  void physics_step(double dt);
  // The collision response over dt; finest_substep: the adaptive step's finest substep (no finer one left to
  // retry with).
  void collision_step(double dt, bool finest_substep);
  // Proximity, the implicit step and the collision response over dt, ending at time_ (obstacles already moved).
  void dynamics_step(double dt, bool finest_substep = false);
  // The dynamics of the step [start, start + dt] with adaptive time stepping: as 2^level substeps, redone from
  // the step's start one level finer whenever a substep fails (NumericalError, substep_problem). Returns the
  // last substep's size. Throws NumericalError when the step fails at min_step.
  double adaptive_dynamics_step(double start, double dt);
  // Why the substep just taken fails adaptive_time_step's checks ("" if it does not). With `tolerated` (per
  // cloth, a flag per node), a fallback on flagged nodes only does not fail it if the response ended collision
  // free; *tolerated_used then says whether there was one.
  std::string substep_problem(double dt, const std::vector<std::vector<char>>* tolerated = nullptr,
                              bool* tolerated_used = nullptr) const;
  // Plastic flow of every plastic cloth (module "plasticity"); marks changed cloths' elements dirty.
  void jitter_step();
  void plasticity_step(double dt);
  // Fracture substepping of every breakable cloth (module "fracture", fracture/fracture_step.hpp), then the
  // follow-up of topology_changed.
  void fracture_step(double dt);
  // Frame-end remeshing of every cloth (module "remeshing", unless the mesh is fixed), then compaction.
  void remeshing_step();
  void check_state() const;
  // Drops cloth c's dead elements and remaps the handles' node indices (part of topology_changed).
  void compact_cloth(int c);
  // With audit_energy: records every cloth's mechanical energy into the field `phase` of step_energies; the
  // energy after plasticity is measured with a fresh element cache (the flow rules changed the rest state).
  void audit(double StepEnergies::*phase, bool fresh_elements = false);

  Scene scene_;
  std::vector<Motion> motions_;
  double time_ = 0;
  double step_time_ = 0;
  int frame_steps_ = 1;
  int step_ = 0;
  int frame_ = 0;
  double end_time_ = kInfinity;
  double end_frame_ = kInfinity;
  CollisionHandler collisions_;
  // This step's proximity terms per cloth: the implicit step's contacts, and the loads of fracture's virtual
  // update (rebuilt every step; not part of the saved state).
  std::vector<std::vector<ContactTerm>> step_contacts_;
  // This step's nodes per cloth that the collision response moved by a fallback (fracture does not trust
  // their strain; FractureContext::untrusted_nodes).
  std::vector<std::vector<int>> step_fallback_nodes_;
  // Whether the last collision response ended collision free (with or without a fallback).
  bool step_collisions_resolved_ = true;
  int substep_level_ = 0;
  int steps_at_level_ = 0;
  // With adaptive_time_step: how far the last dynamics step's collision response moved a cloth node (m), and
  // which (cloth, node).
  double step_correction_ = 0;
  std::array<int, 2> step_correction_at_{-1, -1};
};

}  // namespace arcsim
