#include "fracture/fracture_sizing.hpp"

#include <cmath>

#include "fracture/fracture_step.hpp"
#include "fracture/fracture_stress.hpp"
#include "remesh/sizing.hpp"

namespace arcsim {

std::vector<Mat3> fracture_sizing_terms(const Mesh& mesh, const std::vector<Material>& materials,
                                        double refine_fracture, double size_min) {
  if (!(refine_fracture > 0) || !std::isfinite(refine_fracture) || !(size_min > 0) || !std::isfinite(size_min) ||
      !has_fracture(materials))
    return {};
  const std::vector<FaceFractureStress> stress = fracture_stresses(mesh, materials);
  std::vector<Mat3> terms(mesh.faces.size(), Mat3::Zero());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Face& face = mesh.faces[f];
    if (face.dead) continue;
    const double tau = face_toughness(face, materials[face.material]);
    if (!(tau > 0) || !(stress[f].lambda_max > 0)) continue;
    // fracture_sizing_term is the paper's (2 lambda / (tau' x_min))^2 I; tau' = 2 refine_fracture tau.
    terms[f] = face_metric_to_rest(face, fracture_sizing_term(stress[f].lambda_max, 2 * refine_fracture * tau, size_min));
  }
  return terms;
}

}  // namespace arcsim
