// Fracture sizing (paper §5.1): faces under tensile stress near their toughness are refined towards size_min
// before they break, so a crack opens and runs at the finest resolution.
//
//   M_frac = (lambda / (refine_fracture tau x_min))^2 I   (1/m^2, each face with its own lambda and tau)
//
// lambda = the largest eigenvalue of the face's sigma+ (fracture/fracture_stress.hpp), tau its area toughness,
// x_min = size_min. At lambda = refine_fracture * tau the face asks for size_min; refine_fracture = 1/2 is the
// paper's (2 lambda / (tau x_min))^2. refine_fracture = 0 or infinite: no term (ARCSim's "0 disables").
// ARCSim evaluates the term with the face's own sigma for all of its neighbours (a bug we do not copy).
#pragma once

#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

// Rest-space 3x3 metric terms per face (indexed like mesh.faces; remesh/sizing.hpp's SizingExtras::face_terms).
// Empty when the term is off or no material breaks.
std::vector<Mat3> fracture_sizing_terms(const Mesh& mesh, const std::vector<Material>& materials,
                                        double refine_fracture, double size_min);

}  // namespace arcsim
