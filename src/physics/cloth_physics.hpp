// Internal forces of a cloth (membrane + plate bending) and the implicit Euler step (ARCSim's linearised
// backward Euler with stiffness-proportional damping), assembled on a fixed sparsity pattern and solved with
// CHOLMOD.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"
#include "physics/block_system.hpp"
#include "physics/face_element.hpp"
#include "physics/material.hpp"
#include "physics/system_dofs.hpp"
#include "physics/wind.hpp"
#include "scene/scene.hpp"

namespace arcsim {

// Per-topology data of the physics: element node lists, element data (physics/face_element.hpp) and block ids.
// Rebuilt whenever the mesh topology or rest state changes (after remeshing, fracture or plastic updates).
// The world dihedral angles of bending elements, each with the corners it was computed at: the step's energy
// check evaluates every element at the positions the step then takes, and the next assembly finds the angles
// there again (bit for bit the same corners: the same angles) instead of recomputing them.
class BendingAngleMemo {
 public:
  // Element k's angles if they were last computed at exactly these corners (bits) and wings; nullptr otherwise.
  const Vec3* find(size_t k, const std::array<Vec3, 6>& corners, const std::array<bool, 3>& has_wing) const;
  // Room for `count` elements (before store is called from parallel loops).
  void reserve(size_t count);
  void store(size_t k, const std::array<Vec3, 6>& corners, const std::array<bool, 3>& has_wing, const Vec3& theta);

 private:
  struct Entry {
    std::array<Vec3, 6> corners;
    std::array<bool, 3> has_wing{false, false, false};
    Vec3 theta = Vec3::Zero();
    bool set = false;
  };
  std::vector<Entry> entries_;
};

struct ElementCache {
  using FaceElement = arcsim::FaceElement;
  using BendingElement = arcsim::BendingElement;
  std::vector<FaceElement> faces;
  std::vector<BendingElement> bending;
  BlockPattern pattern;
  std::vector<double> node_mass;  // kg
  // Node pairs of the pattern: those of the elements, and extra ones for contacts (update_contact_pattern).
  std::vector<std::pair<int, int>> element_pairs;  // (row >= col), sorted, unique
  std::vector<std::pair<int, int>> contact_pairs;  // extra pairs not among element_pairs, sorted, unique
  bool pattern_stale = false;  // element pairs changed since the pattern was built (PatternBuild::kDeferred)
  BendingAngleMemo angles;     // of `bending`, from the last energy check (implicit_euler_step)
};

// A contact (proximity) term over up to four nodes, linearised for the implicit step. The gap
// g = n . sum_i w_i x_i feels a penalty force `force` (N, along +n) of stiffness `stiffness` (N/m), and the
// relative velocity u = sum_i w_i v_i a tangential friction damper -friction_damping (I - n n^T) u (N).
// Nodes of other meshes (kNone here) only contribute their velocity, through outside_velocity = sum of w_i v_i
// over them (m/s); they are held fixed in this cloth's solve.
struct ContactTerm {
  std::array<int, 4> nodes{kNone, kNone, kNone, kNone};  // node indices of this cloth
  std::array<double, 4> weights{0, 0, 0, 0};
  Vec3 normal = Vec3::UnitY();
  double force = 0;             // N
  double stiffness = 0;         // N/m
  double friction_damping = 0;  // kg/s
  Vec3 outside_velocity = Vec3::Zero();
};

// Recomputes node masses (kg) from face area densities.
void update_node_masses(Mesh& mesh, const std::vector<Material>& materials);
// The same for the listed nodes only (the nodes an edit's faces touch): bit-identical values, cost of their fans.
void update_node_masses(Mesh& mesh, const std::vector<Material>& materials, const std::vector<int>& nodes);

// When build_element_cache builds the block pattern: at once, or (kDeferred) at the next update_contact_pattern
// or ensure_pattern, so that a step that adds contact pairs builds it (and its block ids) once, not twice.
enum class PatternBuild { kNow, kDeferred };

// Builds the element cache (and the block pattern) for the mesh's current topology and rest state.
void build_element_cache(const Mesh& mesh, const std::vector<Material>& materials, ElementCache& cache,
                         PatternBuild pattern_build = PatternBuild::kNow);

// Builds the block pattern if build_element_cache deferred it.
void ensure_pattern(ElementCache& cache);

// Makes the pattern contain every node pair coupled by `contacts`. The pattern (and with it the CHOLMOD
// symbolic analysis) is rebuilt only when a needed pair is missing, when far more contact pairs are kept
// than needed, or when it was deferred. Returns true if it was rebuilt.
bool update_contact_pattern(ElementCache& cache, const std::vector<ContactTerm>& contacts);

// Total elastic energy (J) of the cloth at its current world positions.
double internal_energy(const Mesh& mesh, const ElementCache& cache);

// Internal force f = -dE/dx (N), stacked per node.
VecX internal_forces(const Mesh& mesh, const ElementCache& cache);

// Assembles sum_e scale_e * H_e (PSD-projected element Hessians) into `system` and adds to system.rhs the
// internal force plus rhs_velocity_factor_e * (-H_e v_e), with scale_e = hess_scale * (hess_time + beta_e) style
// factors given by the callbacks below. Used by the implicit step and the static solver.
struct InternalAssembly {
  double stiffness_scale = 1;     // multiplies every H_e
  double damping_scale = 0;       // adds damping_scale * beta_e * H_e
  double force_scale = 1;         // rhs += force_scale * f_e
  double velocity_scale = 0;      // rhs -= (velocity_scale + damping_velocity_scale * beta_e) * H_e v_e
  double damping_velocity_scale = 0;
};
// Returns the elastic energy.
double assemble_internal(const Mesh& mesh, const ElementCache& cache, const InternalAssembly& how,
                         BlockSystem& system);
// The same over any element lists (a zone's): rows and blocks from the elements' dofs and block ids.
// `angles`, if given, holds angles of `bending` already computed (BendingAngleMemo).
double assemble_element_terms(const Mesh& mesh, const std::vector<FaceElement>& faces,
                              const std::vector<BendingElement>& bending, const InternalAssembly& how,
                              BlockSystem& system, const BendingAngleMemo* angles = nullptr);

// External loads of one step.
struct HandleSpring {
  int node;
  Vec3 target;        // m
  double stiffness;   // N/m
};
struct ExternalLoads {
  Vec3 gravity = Vec3::Zero();
  WindSpec wind;
  std::vector<HandleSpring> springs;
  std::vector<char> pinned;  // optional, per node: velocity held fixed (Dirichlet)
  std::vector<ContactTerm> contacts;  // their pairs must be in the pattern (update_contact_pattern)
};

// Mechanical energy (J) of the cloth: kinetic, elastic (internal_energy), the handle springs' and the gravity
// potential (zero at the origin). Air drag and contact terms are not potentials and are left out. For energy
// audits (Simulation::audit_energy); implicit Euler never raises it without external work.
double mechanical_energy(const Mesh& mesh, const ElementCache& cache, const ExternalLoads& loads);

// Wall times and what the linear solves did (CholeskySolver::solve_system), summed over the solves.
struct StepTiming {
  double assembly = 0, factorization = 0, solve = 0;  // wall seconds
  int solves = 0, factorizations = 0, iterations = 0;  // iterations: conjugate-gradient ones
  std::vector<double> residuals;  // per solve, in order: |A dv - b| / |b|
  void add(const StepTiming& other);
};

// Assembles the linearised backward Euler system of one step of size dt (s) over the rows of `dofs`:
//   (M + dt (dt + beta) H - dt D_v) dv = dt [ f - (dt + beta) H v + f_ext ]
// from `faces` and `bending` (their dofs and block ids must refer to `dofs` and system's pattern), the node
// masses, gravity, the handle springs and contacts of rows of `dofs`, and air drag on `faces`. Fixed nodes
// (dof -1) enter with their positions and velocities only. Pinned nodes are not treated here: the full step
// makes them Dirichlet rows afterwards; a zone solve leaves them out of `dofs`. Shared by implicit_euler_step and
// solve_zone (physics/zone_solve.hpp). Blocks in kg, rhs in N s.
// kStep: the step's single linearisation about (x, v), predicting x + dt v'. kNewtonFromRest: a Newton
// iteration of backward Euler started from rest, with the mesh at the iterate (x_k = x_0 + dt v_k, v = v_k):
// the same matrix, right-hand side dt [f(x_k) - beta H v_k + f_ext] - M v_k (no prediction terms), so the
// solution is the correction of v_k. Contacts are linearised as in the step either way.
// `wind`, if given, gets each face's air force as assembled (empty when there is no wind or drag).
enum class Linearisation { kStep, kNewtonFromRest };

void assemble_implicit_euler(const Mesh& mesh, const std::vector<FaceElement>& faces,
                             const std::vector<BendingElement>& bending, const SystemDofs& dofs,
                             const ExternalLoads& loads, double dt, BlockSystem& system,
                             Linearisation linearisation = Linearisation::kStep,
                             std::vector<CompactWindForce>* wind = nullptr,
                             const BendingAngleMemo* angles = nullptr);

// Solves the assembled system for dv (CholeskySolver::solve_system: factorised, or by conjugate gradients with a
// kept factorisation for large systems), adding the wall times and the solve's report to `timing`. Throws NumericalError, its message starting with `step` ("implicit step", "zone step"), if the
// matrix is not positive definite or dv is not finite; `explain`, if given, says why the matrix failed
// (physics/system_premises.hpp) and is called only then.
VecX factor_and_solve(CholeskySolver& solver, const BlockSystem& system, const std::string& step,
                      StepTiming& timing, const std::function<std::string()>& explain = {});

// One implicit Euler step of size dt (s): solves for the velocity change, then v += dv, a = dv/dt, x0 = x,
// x += v dt. If the whole dv raises the step's incremental potential (the linearisation failed: see
// step_fraction in cloth_physics.cpp), it takes the first of dv/2, dv/4, ... that does not.
// Throws NumericalError if the system cannot be factorised or the result is not finite.
void implicit_euler_step(Mesh& mesh, ElementCache& cache, CholeskySolver& solver, const ExternalLoads& loads,
                         double dt, StepTiming* timing = nullptr);

}  // namespace arcsim
