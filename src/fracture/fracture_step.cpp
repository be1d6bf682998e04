#include "fracture/fracture_step.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <memory>

#include "collision/proximity.hpp"
#include "fracture/fracture_stress.hpp"
#include "math/errors.hpp"
#include "mesh/mesh_stats.hpp"
#include "physics/zone_solve.hpp"

namespace arcsim {

FractureStats& FractureStats::operator+=(const FractureStats& o) {
  cracks += o.cracks;
  refused += o.refused;
  substeps += o.substeps;
  candidates += o.candidates;
  largest_zone = std::max(largest_zone, o.largest_zone);
  remesh_edits += o.remesh_edits;
  max_ratio = std::max(max_ratio, o.max_ratio);
  edited = edited || o.edited;
  seconds += o.seconds;
  return *this;
}

bool has_fracture(const std::vector<Material>& materials) {
  return std::any_of(materials.begin(), materials.end(), [](const Material& m) { return m.toughness > 0; });
}

namespace {

struct Candidate {
  NodeSeparation separation;
  bool operator<(const Candidate& o) const {  // strongest first; ties by node index (determinism)
    const double a = separation.ratio(), b = o.separation.ratio();
    return a != b ? a > b : separation.node < o.separation.node;
  }
};

// Collects the nodes whose fans the edits changed (corners of the faces an edit added or removed, and the nodes
// it added or removed): the nodes whose lumped masses need recomputing.
class TouchedNodes : public EditObserver {
 public:
  explicit TouchedNodes(const Mesh& mesh) : mesh_(mesh) {}
  void stage_done(EditKind, EditStage stage, const EditResult& r) override {
    if (stage != EditStage::kDone || !r.ok) return;
    for (const std::vector<int>* faces : {&r.added_faces, &r.removed_faces})
      for (int f : *faces)
        for (int i = 0; i < 3; ++i) {
          const int v = mesh_.faces[f].v[i];
          if (v >= 0 && v < static_cast<int>(mesh_.verts.size())) nodes_.push_back(mesh_.verts[v].node);
        }
    nodes_.insert(nodes_.end(), r.added_nodes.begin(), r.added_nodes.end());
    nodes_.insert(nodes_.end(), r.removed_nodes.begin(), r.removed_nodes.end());
  }
  // The nodes collected since the last call (sorted, unique), and forgets them.
  std::vector<int> take() {
    std::vector<int> out;
    out.swap(nodes_);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

 private:
  const Mesh& mesh_;
  std::vector<int> nodes_;
};

// What the substeps of one fracture pass share: one world guard for all their edit sessions (building one
// indexes the whole mesh and its obstacles, far more than a substep's zone costs), and the record of touched
// nodes whose masses are brought up to date after each edit batch.
struct PassState {
  std::unique_ptr<WorldGuard> guard;
  TouchedNodes touched;
  double crack_scale = 0;  // m: the length the opening's snap and sliver limits scale with
  ExternalLoads loads;     // the virtual update's loads: the context's, contacts at the step's end positions
  explicit PassState(const Mesh& mesh) : touched(mesh) {}
};

// The step's contacts at the positions the step ended at: each gap grows by the weighted displacement of its
// nodes over the step (x - x0, which the collision response and the edits' reprojection keep) and by the other
// side's motion (dt times its velocity); contacts that came apart are dropped.
std::vector<ContactTerm> contacts_at_step_end(const Mesh& mesh, const std::vector<ContactTerm>& contacts,
                                              double dt) {
  std::vector<ContactTerm> out;
  out.reserve(contacts.size());
  const int node_count = static_cast<int>(mesh.nodes.size());
  for (ContactTerm c : contacts) {
    Vec3 displacement = dt * c.outside_velocity;
    bool valid = true;
    for (int i = 0; i < 4; ++i) {
      const int n = c.nodes[i];
      if (n == kNone) continue;
      if (n < 0 || n >= node_count || mesh.nodes[n].dead) valid = false;
      if (!valid) break;
      displacement += c.weights[i] * (mesh.nodes[n].x - mesh.nodes[n].x0);
    }
    if (valid && contact_term_at_gap_change(c, c.normal.dot(displacement))) out.push_back(c);
  }
  return out;
}

// Contacts with a node that an edit of the pass removed no longer apply.
void drop_dead_contacts(const Mesh& mesh, std::vector<ContactTerm>& contacts) {
  contacts.erase(std::remove_if(contacts.begin(), contacts.end(),
                                [&](const ContactTerm& c) {
                                  for (int n : c.nodes)
                                    if (n != kNone && mesh.nodes[n].dead) return true;
                                  return false;
                                }),
                 contacts.end());
}

void refresh_masses(Mesh& mesh, const std::vector<Material>& materials, PassState& pass) {
  update_node_masses(mesh, materials, pass.touched.take());
}

// The breaking nodes among `nodes` (live ones, not refused in this step), strongest first.
std::vector<Candidate> breaking_nodes(const Mesh& mesh, const std::vector<Material>& materials,
                                      const std::vector<int>& nodes, const std::vector<FaceFractureStress>& stress,
                                      const std::vector<char>& refused, const SeparationOptions& options) {
  std::vector<Candidate> out;
  SeparationOptions only_breaking = options;
  only_breaking.breaking_only = true;  // the others are dropped here
  for (int n : nodes) {
    if (n < 0 || n >= static_cast<int>(mesh.nodes.size()) || mesh.nodes[n].dead) continue;
    if (n < static_cast<int>(refused.size()) && refused[n]) continue;
    NodeSeparation s = node_separation(mesh, materials, n, stress, only_breaking);
    if (s.breaks()) out.push_back({std::move(s)});
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<int> live_nodes(const Mesh& mesh) {
  std::vector<int> out;
  for (size_t n = 0; n < mesh.nodes.size(); ++n)
    if (!mesh.nodes[n].dead) out.push_back(static_cast<int>(n));
  return out;
}

// The faces of `nodes` (each once, sorted).
std::vector<int> faces_of_nodes(const Mesh& mesh, const std::vector<int>& nodes) {
  std::vector<int> faces;
  for (int n : nodes)
    for (int f : mesh.node_faces(n)) faces.push_back(f);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

// The live faces with all three corners among `nodes` (sorted): the zone's interior, which the local remesh
// refines (its border edges may be split too).
std::vector<int> interior_faces(const Mesh& mesh, const std::vector<int>& nodes) {
  std::vector<char> in(mesh.nodes.size(), 0);
  for (int n : nodes) in[n] = 1;
  std::vector<int> out;
  for (int f : faces_of_nodes(mesh, nodes)) {
    bool all = true;
    for (int i = 0; i < 3; ++i) all = all && in[mesh.face_node(f, i)];
    if (all) out.push_back(f);
  }
  return out;
}

std::vector<int> nodes_of_faces(const Mesh& mesh, const std::vector<int>& faces) {
  std::vector<int> nodes;
  for (int f : faces) {
    if (f < 0 || f >= static_cast<int>(mesh.faces.size()) || mesh.faces[f].dead) continue;
    for (int i = 0; i < 3; ++i) nodes.push_back(mesh.face_node(f, i));
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

double size_min_of(const FractureContext& context) {
  const double s = context.remesh.sizing.remeshing.size_min;
  return std::isfinite(s) && s > 0 ? s : 0;
}

// The length the snap and sliver limits of an opening scale with: size_min when the cloth remeshes; without
// one (remeshing off), the median rest edge length of the mesh at the start of the pass. With no scale at all
// the limits vanish, and a crack running near a grid line cut 17 um x 1 um faces whose bending stiffness the
// implicit step could not factorise (measured: a glass strip of 2.5 mm cells).
double crack_length_scale(const Mesh& mesh, const FractureContext& context) {
  const double size_min = size_min_of(context);
  return size_min > 0 ? size_min : mesh_size_stats(mesh).rest_edge_median;
}

CrackOpeningOptions opening_options(const FractureParams& params, const PassState& pass) {
  CrackOpeningOptions o = params.opening;
  o.size_min = pass.crack_scale;
  return o;
}

EditSessionOptions session_options(const FractureParams& params, const FractureContext& context,
                                   PassState& pass) {
  EditSessionOptions o = edit_session_options(context.remesh);
  o.reproject = params.reproject && o.reproject;
  o.shared_guard = pass.guard.get();
  return o;
}

// Opens a crack at the candidate through a fresh edit session (sharing the pass's world guard, which every
// edit of the pass keeps current) and brings the masses of the nodes it touched up to date.
CrackOpening open_at(Mesh& mesh, const std::vector<Material>& materials, const Candidate& c,
                     const FractureParams& params, const FractureContext& context, PassState& pass,
                     FractureStats& stats) {
  EditSession session(mesh, materials, session_options(params, context, pass));
  session.add_observer(&pass.touched);
  CrackOpening opening = open_crack(session, c.separation.node, c.separation.rays, opening_options(params, pass));
  stats.edited = stats.edited || session.edited();
  if (opening.ok)
    ++stats.cracks;
  else
    ++stats.refused;
  refresh_masses(mesh, materials, pass);
  return opening;
}

// Step 2b: refines the zone's interior to size_min. Returns the zone's nodes after the edits.
std::vector<int> remesh_zone(Mesh& mesh, const std::vector<Material>& materials, const std::vector<int>& zone,
                             const FractureContext& context, PassState& pass, FractureStats& stats) {
  RemeshOptions o = context.remesh;
  o.extras = SizingExtras();
  o.extras.uniform_size = size_min_of(context);
  o.shared_guard = pass.guard.get();
  o.observers.push_back(&pass.touched);
  const std::vector<int> faces = interior_faces(mesh, zone);
  if (faces.empty()) return zone;
  const RemeshStats r = remesh_mesh(mesh, materials, o, &faces);
  const int edits = r.splits + r.flips + r.collapses;
  if (edits == 0) return zone;
  stats.remesh_edits += edits;
  stats.edited = true;
  refresh_masses(mesh, materials, pass);
  std::vector<int> nodes = nodes_of_faces(mesh, r.active_faces);
  for (int n : zone)
    if (!mesh.nodes[n].dead) nodes.push_back(n);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

// Grows the zone (sorted nodes) by rings while a face of its support ring is stressed past
// params.support_stress times its toughness, at the current positions (FractureParams::max_zone_rings).
std::vector<int> grow_to_calm_support(const Mesh& mesh, const std::vector<Material>& materials,
                                      std::vector<int> zone, const FractureParams& params,
                                      std::vector<FaceFractureStress>& stress) {
  for (int rings = std::max(params.zone_rings, 0); rings < params.max_zone_rings; ++rings) {
    const std::vector<int> grown = node_rings(mesh, zone, 1);
    std::vector<int> support;
    std::set_difference(grown.begin(), grown.end(), zone.begin(), zone.end(), std::back_inserter(support));
    if (support.empty()) break;
    const std::vector<int> faces = faces_of_nodes(mesh, support);
    update_fracture_stresses(mesh, materials, faces, stress);
    bool stressed = false;
    for (int f : faces) {
      const Face& face = mesh.faces[f];
      const double tau = face_toughness(face, materials[face.material]);
      if (tau > 0 && stress[f].lambda_max > params.support_stress * tau) {
        stressed = true;
        break;
      }
    }
    if (!stressed) break;
    zone = grown;
  }
  return zone;
}

// Steps 2c-d: the breaking nodes of the zone at the positions a zone step predicts, positions rewound. When the
// zone's system cannot be solved the prediction is skipped (the stress at the current positions decides).
std::vector<Candidate> predict(Mesh& mesh, const std::vector<Material>& materials, const std::vector<int>& zone,
                               const FractureParams& params, const FractureContext& context, PassState& pass,
                               CholeskySolver& solver, std::vector<FaceFractureStress>& stress,
                               const std::vector<char>& refused) {
  drop_dead_contacts(mesh, pass.loads.contacts);
  std::vector<Vec3> saved;
  std::vector<int> moved;
  // The prediction starts from rest: with the nodes' velocities in it, x + dt dv would also carry -dt v (the
  // stiff limit of dv is -v plus the relaxation), an error of the order of the step's own motion. The zone and
  // everything its elements read (support and bending wings, two rings) are held at v = 0 for the solve.
  const std::vector<int> still = node_rings(mesh, zone, 3);
  std::vector<Vec3> velocities(still.size());
  for (size_t i = 0; i < still.size(); ++i) {
    velocities[i] = mesh.nodes[still[i]].v;
    mesh.nodes[still[i]].v = Vec3::Zero();
  }
  // Newton iterations of the from-rest backward Euler step (see the header): one linearised step of a bent,
  // stiff sheet moves its nodes along tangents, and the spurious stretch of order theta^2 / 2 alone exceeds a
  // brittle sheet's critical strain.
  // The zone's nodes carry the iterate: x_0 + dt v_k and v_k (Linearisation::kNewtonFromRest).
  // The iterations change positions and velocities only: one zone system (elements, pattern and the solver's
  // symbolic analysis) serves them all.
  const int iterations = std::max(params.virtual_iterations, 1);
  double previous = kInfinity;
  ZoneSolveOptions zone_options;
  zone_options.linearisation = Linearisation::kNewtonFromRest;
  const ZoneSystem system(mesh, materials, zone, pass.loads, zone_options);
  for (int it = 0; it < iterations; ++it) {
    ZoneSolution sol;
    try {
      sol = system.solve(mesh, pass.loads, context.dt, solver);
    } catch (const NumericalError&) {
      if (it == 0) moved.clear(), saved.clear();
      break;  // later iterations keep the last iterate
    }
    if (it == 0) {
      moved = sol.nodes;
      saved.reserve(moved.size());
      for (int n : moved) saved.push_back(mesh.nodes[n].x);
    }
    double correction = 0, total = 0;
    for (size_t i = 0; i < moved.size(); ++i) correction = std::max(correction, context.dt * sol.dv[i].norm());
    // A correction larger than the one before means the iteration is not converging (the projected Hessian is
    // not the exact one): keep the last iterate.
    if (it > 0 && correction > previous) break;
    previous = correction;
    for (size_t i = 0; i < moved.size(); ++i) {
      Node& n = mesh.nodes[moved[i]];
      n.v += sol.dv[i];
      n.x = saved[i] + context.dt * n.v;
      total = std::max(total, context.dt * n.v.norm());
    }
    if (it > 0 && correction <= params.virtual_tolerance * total) break;
  }
  for (size_t i = 0; i < still.size(); ++i) mesh.nodes[still[i]].v = velocities[i];
  update_fracture_stresses(mesh, materials, faces_of_nodes(mesh, zone), stress);
  std::vector<Candidate> out = breaking_nodes(mesh, materials, zone, stress, refused, params.separation);
  for (size_t i = 0; i < moved.size(); ++i) mesh.nodes[moved[i]].x = saved[i];
  return out;
}

void mark(std::vector<char>& flags, int n) {
  if (n >= static_cast<int>(flags.size())) flags.resize(n + 1, 0);
  flags[n] = 1;
}

// The ablation: one evaluation, every breaking node opened strongest first, no prediction. A node whose fan an
// earlier opening changed is skipped (its evaluation is stale).
void open_without_substepping(Mesh& mesh, const std::vector<Material>& materials,
                              const std::vector<Candidate>& candidates, const FractureParams& params,
                              const FractureContext& context, PassState& pass, FractureStats& stats) {
  std::vector<char> touched(mesh.nodes.size(), 0);
  for (const Candidate& c : candidates) {
    if (stats.cracks >= params.max_cracks) break;
    const int n = c.separation.node;
    if (mesh.nodes[n].dead || (n < static_cast<int>(touched.size()) && touched[n])) continue;
    std::vector<int> fan_nodes = node_rings(mesh, {n}, 1);
    const CrackOpening opening = open_at(mesh, materials, c, params, context, pass, stats);
    if (!opening.ok) continue;
    for (int m : fan_nodes) mark(touched, m);
    for (int m : opening.split_nodes()) mark(touched, m);
  }
}

// The nodes within `rings` rings of the opening (every node it split and the new tips; for a refused opening,
// the node), on the mesh as it is after it, merged into the sorted `region`.
void add_opening_region(const Mesh& mesh, int node, const CrackOpening& opening, int rings,
                        std::vector<int>& region) {
  std::vector<int> seeds = opening.split_nodes();
  seeds.push_back(node);
  seeds.insert(seeds.end(), opening.tips.begin(), opening.tips.end());
  seeds.erase(std::remove_if(seeds.begin(), seeds.end(),
                             [&](int n) { return n < 0 || n >= static_cast<int>(mesh.nodes.size()) || mesh.nodes[n].dead; }),
              seeds.end());
  const std::vector<int> near = node_rings(mesh, seeds, rings);
  std::vector<int> merged;
  merged.reserve(region.size() + near.size());
  std::set_union(region.begin(), region.end(), near.begin(), near.end(), std::back_inserter(merged));
  region = std::move(merged);
}

// Step 2e: opens the strongest candidate of the prediction and, with independent openings, every further one
// (strongest first) that lies more than 2 (zone_rings + 1) rings from each node opened so far in this substep.
// Returns the next substep's Z: the candidates not opened (nor refused) and the new crack tips.
std::vector<int> open_candidates(Mesh& mesh, const std::vector<Material>& materials,
                                 const std::vector<Candidate>& candidates, const FractureParams& params,
                                 const FractureContext& context, PassState& pass, std::vector<char>& refused,
                                 FractureStats& stats) {
  const int separation = 2 * (std::max(params.zone_rings, 0) + 1);
  std::vector<int> region;  // nodes within `separation` rings of this substep's openings (sorted)
  std::vector<int> zone;
  for (size_t k = 0; k < candidates.size(); ++k) {
    const int n = candidates[k].separation.node;
    const bool may_open = stats.cracks < params.max_cracks && !mesh.nodes[n].dead &&
                          (k == 0 || (params.independent_openings && !std::binary_search(region.begin(), region.end(), n)));
    if (!may_open) {
      zone.push_back(n);
      continue;
    }
    const CrackOpening opening = open_at(mesh, materials, candidates[k], params, context, pass, stats);
    if (!opening.ok) mark(refused, n);
    if (opening.ok) zone.insert(zone.end(), opening.tips.begin(), opening.tips.end());
    if (params.independent_openings) add_opening_region(mesh, n, opening, separation, region);
  }
  zone.erase(std::remove_if(zone.begin(), zone.end(),
                            [&](int n) {
                              return n < 0 || n >= static_cast<int>(mesh.nodes.size()) || mesh.nodes[n].dead ||
                                     (n < static_cast<int>(refused.size()) && refused[n]);
                            }),
             zone.end());
  std::sort(zone.begin(), zone.end());
  zone.erase(std::unique(zone.begin(), zone.end()), zone.end());
  return zone;
}

}  // namespace

FractureStats fracture_step(Mesh& mesh, const std::vector<Material>& materials, const FractureParams& params,
                            const FractureContext& context, CholeskySolver& zone_solver) {
  const auto start = std::chrono::steady_clock::now();
  FractureStats stats;
  if (!has_fracture(materials) || params.max_cracks <= 0) return stats;

  std::vector<FaceFractureStress> stress = fracture_stresses(mesh, materials);
  std::vector<char> refused(mesh.nodes.size(), 0);
  if (!context.untrusted_nodes.empty()) {
    std::vector<int> untrusted;
    for (int n : context.untrusted_nodes)
      if (n >= 0 && n < static_cast<int>(mesh.nodes.size()) && !mesh.nodes[n].dead) untrusted.push_back(n);
    for (int n : node_rings(mesh, untrusted, 1)) refused[n] = 1;
  }
  std::vector<Candidate> candidates =
      breaking_nodes(mesh, materials, live_nodes(mesh), stress, refused, params.separation);
  stats.candidates = static_cast<int>(candidates.size());
  if (!candidates.empty()) stats.max_ratio = candidates.front().separation.ratio();
  if (candidates.empty()) {
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
  }

  PassState pass(mesh);
  pass.crack_scale = crack_length_scale(mesh, context);
  pass.loads = context.loads;
  pass.loads.contacts = contacts_at_step_end(mesh, context.loads.contacts, context.dt);
  if (context.remesh.world_clearance > 0)
    pass.guard = std::make_unique<WorldGuard>(mesh, context.remesh.obstacles, context.remesh.world_clearance);
  if (!params.substepping) {
    open_without_substepping(mesh, materials, candidates, params, context, pass, stats);
  } else {
    std::vector<int> zone;
    for (const Candidate& c : candidates) zone.push_back(c.separation.node);
    std::vector<FaceFractureStress> support_stress;  // scratch of grow_to_calm_support
    const bool remesh_locally = params.local_remesh && size_min_of(context) > 0;
    // Every iteration opens a crack or refuses a node for the rest of the step: bounded.
    const int max_iterations = 2 * params.max_cracks + 16;
    while (!zone.empty() && stats.cracks < params.max_cracks && stats.substeps < max_iterations) {
      ++stats.substeps;
      std::vector<int> zone_nodes = node_rings(mesh, zone, std::max(params.zone_rings, 0));
      zone_nodes = grow_to_calm_support(mesh, materials, std::move(zone_nodes), params, support_stress);
      if (remesh_locally) zone_nodes = remesh_zone(mesh, materials, zone_nodes, context, pass, stats);
      stats.largest_zone = std::max(stats.largest_zone, static_cast<int>(zone_nodes.size()));
      candidates = predict(mesh, materials, zone_nodes, params, context, pass, zone_solver, stress, refused);
      if (candidates.empty()) break;
      zone = open_candidates(mesh, materials, candidates, params, context, pass, refused, stats);
    }
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace arcsim
