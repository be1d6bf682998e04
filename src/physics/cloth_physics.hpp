// Internal forces of a cloth (membrane + plate bending) and the implicit Euler step (ARCSim's linearised
// backward Euler with stiffness-proportional damping), assembled on a fixed sparsity pattern and solved with
// CHOLMOD.
#pragma once

#include <array>
#include <vector>

#include "mesh/mesh.hpp"
#include "physics/block_system.hpp"
#include "physics/material.hpp"
#include "scene/scene.hpp"

namespace arcsim {

// Per-topology data of the physics: element node lists, hinge weights and block ids. Rebuilt whenever the
// mesh topology or rest state changes (after remeshing, fracture or plastic updates).
struct ElementCache {
  struct FaceElement {
    std::array<int, 3> nodes;
    std::array<int, 9> blocks;
    Mat2 Dm_inv;            // includes plastic stretch: F_el = F Fp
    double area;            // rest area (m^2)
    MembraneStiffness k;    // N/m, already weakened
    double damping;         // beta (s)
  };
  // Plate bending of one face (physics/plate_bending.hpp): corners then the wings across its three edges.
  struct BendingElement {
    std::array<int, 6> nodes;  // c0, c1, c2, w0, w1, w2 (a missing wing repeats c0; has_wing says which)
    std::array<bool, 3> has_wing;
    std::array<int, 36> blocks;
    Vec3 rest_theta;        // rad, per edge
    Mat3 Q;                 // J/rad^2, see plate_bending_matrix
    double damping;         // beta (s)
  };
  std::vector<FaceElement> faces;
  std::vector<BendingElement> bending;
  BlockPattern pattern;
  std::vector<double> node_mass;  // kg
};

// Recomputes node masses (kg) from face area densities.
void update_node_masses(Mesh& mesh, const std::vector<Material>& materials);

// Builds the element cache (and the block pattern) for the mesh's current topology and rest state.
void build_element_cache(const Mesh& mesh, const std::vector<Material>& materials, ElementCache& cache);

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
};

struct StepTiming {
  double assembly = 0, factorization = 0, solve = 0;  // wall seconds
};

// One implicit Euler step of size dt (s): solves for the velocity change, then v += dv, a = dv/dt, x0 = x,
// x += v dt. Throws NumericalError if the system cannot be factorised or the result is not finite.
void implicit_euler_step(Mesh& mesh, ElementCache& cache, CholeskySolver& solver, const ExternalLoads& loads,
                         double dt, StepTiming* timing = nullptr);

}  // namespace arcsim
