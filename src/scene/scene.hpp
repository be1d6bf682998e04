// A parsed scene: everything a scene file says, with ARCSim 0.3's defaults, before any mesh is loaded.
// Produced by load_scene() (io/scene_parser.hpp); turned into a running Simulation by sim/simulation.hpp.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "math/types.hpp"
#include "physics/material.hpp"
#include "physics/solver_settings.hpp"
#include "scene/transform.hpp"

namespace arcsim {

struct RemeshingParams {
  double refine_angle = kInfinity;        // rad, target bending angle per element
  double refine_compression = kInfinity;  // compression/buckling term (m)
  double refine_velocity = kInfinity;     // velocity-gradient term
  double refine_fracture = kInfinity;     // fracture sizing factor; 0 disables
  double size_min = -kInfinity;           // m
  double size_max = kInfinity;            // m
  double size_uniform = kInfinity;        // m, for soft-handle regions
  double aspect_min = -kInfinity;
  bool plastic_embedding = true;  // "plastic_transfer": "embedding" (paper §5.2) or "interpolate" (false)
  bool has_size = false, has_aspect_min = false, has_refine_compression = false, has_refine_fracture = false;
};

struct InitialVelocity {
  Vec3 linear = Vec3::Zero();   // m/s
  Vec3 angular = Vec3::Zero();  // rad/s
  Vec3 origin = Vec3::Zero();   // m; v = linear + angular x (x - origin)
};

struct ClothSpec {
  std::string mesh;             // resolved path of the OBJ file
  Transform transform;
  InitialVelocity velocity;
  std::vector<Material> materials;
  RemeshingParams remeshing;
  std::string reference = "linear";  // "linear", "sphere", or a resolved mesh path
  bool reference_is_mesh = false;
};

struct HandleSpec {
  std::string type = "node";    // node, circle, glue, soft
  int cloth = 0;
  int label = -1;               // -1: use `nodes`
  std::vector<int> nodes;       // 0-based node indices
  int motion = -1;              // -1: static
  double start_time = 0, end_time = kInfinity, fade_time = 0;
  // circle
  double circumference = 0;
  Vec2 u = Vec2::Zero();
  Vec3 center = Vec3::Zero(), axis0 = Vec3::UnitX(), axis1 = Vec3::UnitY();
  // soft
  double radius = 0;
};

struct ObstacleSpec {
  std::string mesh;             // resolved path
  Transform transform;
  int motion = -1;
  double start_time = 0, end_time = kInfinity;
  std::string proxy;            // "" or "floor"
};

struct WindSpec {
  double density = 1;           // kg/m^3 (ARCSim's default 1 turns quadratic normal drag on)
  Vec3 velocity = Vec3::Zero(); // m/s
  double drag = 0;              // tangential drag coefficient (kg/(m^2 s))
};

struct MagicParams {
  bool fixed_high_res_mesh = false;
  // Ours: remesh every cloth once at start-up, before the first step, as ARCSim's initial relaxation does
  // (false: the first remesh comes at the end of frame 1, on the mesh the input file gave).
  bool remesh_at_start = true;
  double handle_stiffness = 1e3;       // N/m
  double collision_stiffness = 1e9;    // N/m^3 (times element area)
  double repulsion_thickness = 1e-3;   // m
  double projection_thickness = -1;    // m; < 0 means 0.1 * repulsion_thickness
  double edge_flip_threshold = 1e-2;
  double rib_stiffening = 1;
  bool combine_tensors = true;
  bool preserve_creases = false;
  bool add_jitter = false;
  double separation_step_size = 1e-2;
  int relax_method = 0;
  int max_cracks = 100;
  bool enable_localopt = false;
};

// Fracture substepping settings (top-level "fracture" object; ours, not ARCSim's). max_cracks stays in "magic"
// as in ARCSim.
struct FractureSpec {
  int zone_rings = 3;         // n-ring of Algorithm 1's zone
  int max_zone_rings = 3;     // rings the zone may grow to while its support is stressed past support_stress tau
  double support_stress = 1.0;
  bool substepping = true;    // false: the paper's ablation (one evaluation, no virtual update)
  bool local_remesh = true;   // refine the zone to size_min before predicting
  bool reproject = true;      // Eq. 13 after each opening
  // Openings per substep: false ("substep_openings": "one") is the strict Algorithm 1, one opening per
  // prediction; true ("independent", the default) also opens the further breaking nodes of the same prediction
  // that lie more than 2 (zone_rings + 1) rings from every node opened in that substep (fracture_step.hpp).
  bool independent_openings = true;
  int virtual_iterations = 4;  // Newton iterations of the virtual update (1: one linearised step)
};

// Adaptive time stepping (scene key `adaptive_time_step`; off unless given, so ARCSim's scenes keep their
// meaning). A step whose dynamics (proximity, implicit solve, collision response) fails is redone from its start
// as 2, 4, 8, ... substeps, down to min_step; after grow_after steps that succeed at a level, the next step tries
// one level coarser. Plasticity, fracture and remeshing still run once per scene step.
struct AdaptiveStepSpec {
  bool enabled = false;
  double min_step = 0;             // s; 0: the scene's step / 1024
  double max_motion = kInfinity;   // m: a substep in which a cloth node moves farther fails
  double max_correction = kInfinity;  // m: a substep in which the collision response moves a cloth node farther
                                      // fails (its projection strains a stiff sheet by about that / edge length)
  bool reject_fallbacks = true;    // a substep whose collision response needed a fallback (rigid, carried or
                                   // held impact zones) fails
  int grow_after = 8;              // steps at a level before a coarser one is tried
};

// The default collision_budget (work units per cloth node and step). See docs/scene-format.md for the figures it
// was chosen from.
constexpr double kDefaultCollisionBudget = 1e6;

struct Scene {
  std::string path;             // the scene file
  std::string base_dir;         // folder paths are resolved against first
  // Timing (style A: frame_time/frame_steps/end_time/end_frame; style B: timestep/save_frames/save_every/duration)
  double frame_time = 0;        // s per frame
  int frame_steps = 1;          // steps per frame
  double step_time = 0;         // s
  double end_time = kInfinity;  // s
  double end_frame = kInfinity;
  int save_every = 1;
  double passive_time = kInfinity;
  AdaptiveStepSpec adaptive_step;
  // Work units (collision/impact_zones.hpp) a step's collision response may spend per cloth node (scene key
  // `collision_budget`, ours); past it the step fails as a numerical failure. WHY a count: a time limit would
  // make results depend on the machine and its load.
  double collision_budget = kDefaultCollisionBudget;
  SolverSettings solver;        // scene key `solver` (ours)
  std::vector<ClothSpec> cloths;
  std::vector<Motion> motions;
  std::vector<HandleSpec> handles;
  std::vector<ObstacleSpec> obstacles;
  Vec3 gravity = Vec3::Zero();  // m/s^2
  WindSpec wind;
  double friction = 0.6;
  double obs_friction = 0.3;
  std::set<std::string> disabled;  // module names
  MagicParams magic;
  FractureSpec fracture;
  std::vector<std::string> referenced_files;  // every file the scene names (meshes, materials, motions)
  std::vector<std::string> warnings;          // e.g. unknown keys

  bool enabled(const std::string& module) const { return disabled.count(module) == 0; }
};

}  // namespace arcsim
