// The plasticity phase of a time step (paper §4.2): after the physics and collision response, every face of a
// plastic material lets its elastic strain flow into its plastic tensors (stretch_flow.hpp, bend_flow.hpp),
// then the rest angles and damage of the edges around changed faces are rebuilt (plastic_tensors.hpp).
//
// Plastic work (J), reported per step: the elastic energy the plastic update releases with the world
// positions and the stiffness frozen at their values before the update,
//   stretching  sum_f A_f (S_old + S_new)/2 : (G_old - G_new)      S: membrane stress (N/m), G: Green strain
//   bending     sum_f A_f (M_old + M_new)/2 : (Sp_new - Sp_old)    M: plate moment (N), Sp: 1/m
// with A_f the rest area (m^2). For the quadratic energies this is exactly the face energy before minus after
// the update, which the flow rules never increase, so each term is >= 0. (A h sigma : d(eps_p) in the usual
// notation, since S = h sigma.)
#pragma once

#include <vector>

#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

struct PlasticStepResult {
  double stretch_work = 0;  // J
  double bend_work = 0;     // J
  int stretched_faces = 0;  // faces whose Fp changed
  int bent_faces = 0;       // faces whose Sp changed
  double work() const { return stretch_work + bend_work; }
  bool changed() const { return stretched_faces + bent_faces > 0; }
};

// True if any material has stretching or bending plasticity.
bool has_plasticity(const std::vector<Material>& materials);

// Applies both flow rules to every live face of `mesh` (materials indexed by Face::material) for a step of
// dt seconds. Faces of non-plastic materials keep Fp = I and Sp = 0 exactly. The caller must rebuild the
// physics element cache when the result says something changed.
PlasticStepResult plastic_step(Mesh& mesh, const std::vector<Material>& materials, double dt);

}  // namespace arcsim
