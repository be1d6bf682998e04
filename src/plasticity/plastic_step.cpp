#include "plasticity/plastic_step.hpp"

#include <algorithm>

#include "plasticity/bend_flow.hpp"
#include "plasticity/plastic_tensors.hpp"
#include "plasticity/stretch_flow.hpp"

namespace arcsim {

bool has_plasticity(const std::vector<Material>& materials) {
  return std::any_of(materials.begin(), materials.end(),
                     [](const Material& m) { return has_stretch_plasticity(m) || has_bending_plasticity(m); });
}

PlasticStepResult plastic_step(Mesh& mesh, const std::vector<Material>& materials, double dt) {
  PlasticStepResult out;
  if (!has_plasticity(materials)) return out;
  const int face_count = static_cast<int>(mesh.faces.size());
  // Per-face results, summed in face order afterwards so that the reported work does not depend on the thread
  // count. Faces are independent: each reads node positions and edge rest angles (unchanged here) and writes
  // only its own fields; the edges are rebuilt afterwards.
  std::vector<double> stretch_work(mesh.faces.size(), 0.0), bend_work(mesh.faces.size(), 0.0);
  std::vector<char> stretched(mesh.faces.size(), 0), bent(mesh.faces.size(), 0);
#pragma omp parallel for schedule(static) if (face_count > 2000)
  for (int f = 0; f < face_count; ++f) {
    if (mesh.faces[f].dead) continue;
    const Material& m = materials[mesh.faces[f].material];
    const StretchFlowResult s = apply_stretch_flow(mesh, f, m, dt);
    stretch_work[f] = s.work;
    stretched[f] = s.changed;
    const BendFlowResult b = apply_bend_flow(mesh, f, m);
    bend_work[f] = b.work;
    bent[f] = b.changed;
  }
  int bent_count = 0;
  for (int f = 0; f < face_count; ++f) {
    out.stretch_work += stretch_work[f];
    out.bend_work += bend_work[f];
    out.stretched_faces += stretched[f];
    bent_count += bent[f];
  }
  out.bent_faces = bent_count;
  if (bent_count == 0) return out;

  std::vector<int> edges;
  for (int f = 0; f < face_count; ++f)
    if (bent[f])
      for (int e : mesh.faces[f].e) edges.push_back(e);
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  update_edge_rest_angles_from_Sp(mesh, edges);
  update_edge_damage_from_faces(mesh, edges);
  return out;
}

}  // namespace arcsim
