#pragma once
// Why an implicit system failed to factorise. The matrix M + dt (dt + beta) H - dt D_v + contact terms is
// positive definite by construction when its premises hold: every free node has a positive finite mass, every
// element Hessian (membrane, bending) is projected to positive semi-definite with a finite non-negative
// damping, every contact has a non-negative stiffness and friction damping, and the drag Jacobian is negative
// semi-definite; and every term enters the matrix as computed. When CHOLMOD still reports "not positive
// definite", this checks each premise and names the first element, node or contact that breaks one. Then it
// looks where CHOLMOD stopped (`failed_row`, CholeskySolver::failed_row; -1 if unknown): if the assembled
// blocks around that node are indefinite although every term is not, a term was assembled wrongly (a block
// dropped or doubled: the node is named); if all hold, it says the matrix is too ill-conditioned, gives the
// spread of its diagonal and the element stiffest against its masses, overall and at that node. Costly (an
// eigen-decomposition per element): call it only on failure.
#include <string>
#include <vector>

#include "physics/block_system.hpp"
#include "physics/cloth_physics.hpp"
#include "physics/system_dofs.hpp"

namespace arcsim {

std::string explain_indefinite_system(const Mesh& mesh, const std::vector<FaceElement>& faces,
                                      const std::vector<BendingElement>& bending, const SystemDofs& dofs,
                                      const ExternalLoads& loads, double dt, const BlockSystem& system,
                                      int failed_row = -1);

}  // namespace arcsim
