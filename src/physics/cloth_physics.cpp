#include "physics/cloth_physics.hpp"

#include <algorithm>
#include <chrono>
#include <iterator>
#include <cmath>
#include <cstring>
#include <string>

#include "io/errors.hpp"
#include "physics/bending.hpp"
#include "physics/plate_bending.hpp"
#include "physics/system_premises.hpp"
#include "physics/membrane.hpp"
#include "physics/wind.hpp"

namespace arcsim {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// (row >= col) pairs without diagonal entries, sorted and unique.
std::vector<std::pair<int, int>> sorted_node_pairs(std::vector<std::pair<int, int>> pairs, int node_count) {
  for (auto& p : pairs)
    if (p.first < p.second) std::swap(p.first, p.second);
  pairs.erase(std::remove_if(pairs.begin(), pairs.end(), [](const auto& p) { return p.first == p.second; }),
              pairs.end());
  sort_unique_pairs(pairs, node_count);
  return pairs;
}

// Looks up every element's block ids in the pattern. Each element writes only its own ids, so threads change
// nothing but the time (the lookups were 2% of flag.json's wall, all on one core).
void refresh_block_ids(ElementCache& cache) {
  const int faces = static_cast<int>(cache.faces.size());
  const int count = faces + static_cast<int>(cache.bending.size());
#pragma omp parallel for schedule(static) if (count > 4096)
  for (int k = 0; k < count; ++k) {
    if (k < faces) {
      cache.faces[k].blocks = element_block_ids<3>(cache.pattern, cache.faces[k].dofs);
    } else {
      BendingElement& b = cache.bending[k - faces];
      b.blocks = element_block_ids<6>(cache.pattern, b.dofs);
    }
  }
}

// Builds the block pattern from the element and contact pairs and refreshes the elements' block ids.
void rebuild_pattern(ElementCache& cache) {
  cache.pattern_stale = false;
  std::vector<std::pair<int, int>> pairs = cache.element_pairs;
  pairs.insert(pairs.end(), cache.contact_pairs.begin(), cache.contact_pairs.end());
  cache.pattern.build(static_cast<int>(cache.node_mass.size()), std::move(pairs));
  refresh_block_ids(cache);
}

}  // namespace

const Vec3* BendingAngleMemo::find(size_t k, const std::array<Vec3, 6>& corners,
                                   const std::array<bool, 3>& has_wing) const {
  if (k >= entries_.size()) return nullptr;
  const Entry& e = entries_[k];
  if (!e.set || e.has_wing != has_wing) return nullptr;
  // Bits, not values: corners equal as numbers (+0 and -0) may still give different angles.
  return std::memcmp(e.corners.data(), corners.data(), sizeof(corners)) == 0 ? &e.theta : nullptr;
}

void BendingAngleMemo::reserve(size_t count) {
  if (entries_.size() < count) entries_.resize(count);
}

void BendingAngleMemo::store(size_t k, const std::array<Vec3, 6>& corners, const std::array<bool, 3>& has_wing,
                             const Vec3& theta) {
  Entry& e = entries_[k];
  e.corners = corners;
  e.has_wing = has_wing;
  e.theta = theta;
  e.set = true;
}

void update_node_masses(Mesh& mesh, const std::vector<Material>& materials) {
  for (Node& n : mesh.nodes) n.mass = 0;
  for (const Face& f : mesh.faces) {
    if (f.dead) continue;
    const double m = face_corner_mass(f, materials[f.material]);
    for (int i = 0; i < 3; ++i) mesh.nodes[mesh.verts[f.v[i]].node].mass += m;
  }
}

void update_node_masses(Mesh& mesh, const std::vector<Material>& materials, const std::vector<int>& nodes) {
  for (int n : nodes) {
    if (n < 0 || n >= static_cast<int>(mesh.nodes.size())) continue;
    double mass = 0;
    if (!mesh.nodes[n].dead)
      for (int f : mesh.node_faces(n))  // ascending, as the whole-mesh loop adds them
        if (!mesh.faces[f].dead) mass += face_corner_mass(mesh.faces[f], materials[mesh.faces[f].material]);
    mesh.nodes[n].mass = mass;
  }
}

void build_element_cache(const Mesh& mesh, const std::vector<Material>& materials, ElementCache& cache,
                         PatternBuild pattern_build) {
  cache.faces.clear();
  cache.bending.clear();
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(18 * mesh.faces.size());

  for (size_t fi = 0; fi < mesh.faces.size(); ++fi) {
    const FaceElement el = make_face_element(mesh, materials, static_cast<int>(fi));
    cache.faces.push_back(el);
    pairs.emplace_back(el.nodes[0], el.nodes[1]);
    pairs.emplace_back(el.nodes[1], el.nodes[2]);
    pairs.emplace_back(el.nodes[2], el.nodes[0]);
  }

  for (size_t fi = 0; fi < mesh.faces.size(); ++fi) {
    const BendingElement b = make_bending_element(mesh, materials, static_cast<int>(fi));
    cache.bending.push_back(b);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < i; ++j)
        if (b.nodes[i] != b.nodes[j]) pairs.emplace_back(b.nodes[i], b.nodes[j]);
  }

  std::vector<std::pair<int, int>> element_pairs = sorted_node_pairs(std::move(pairs), static_cast<int>(mesh.nodes.size()));
  cache.node_mass.resize(mesh.nodes.size());
  for (size_t n = 0; n < mesh.nodes.size(); ++n) cache.node_mass[n] = mesh.nodes[n].mass;
  // Same connectivity (only rest state, thickness or plasticity changed): keep the pattern and its contact
  // pairs, so CHOLMOD's symbolic analysis is reused (plastic flow changes faces every step while it lasts).
  if (!cache.pattern_stale && element_pairs == cache.element_pairs &&
      cache.pattern.node_count() == static_cast<int>(mesh.nodes.size()) && cache.pattern.block_count() > 0) {
    refresh_block_ids(cache);
    return;
  }
  cache.element_pairs = std::move(element_pairs);
  cache.contact_pairs.clear();
  if (pattern_build == PatternBuild::kDeferred)
    cache.pattern_stale = true;
  else
    rebuild_pattern(cache);
}

void ensure_pattern(ElementCache& cache) {
  if (cache.pattern_stale) rebuild_pattern(cache);
}

bool update_contact_pattern(ElementCache& cache, const std::vector<ContactTerm>& contacts) {
  std::vector<std::pair<int, int>> needed;
  for (const ContactTerm& c : contacts)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < a; ++b)
        if (c.nodes[a] != kNone && c.nodes[b] != kNone && c.nodes[a] != c.nodes[b])
          needed.emplace_back(c.nodes[a], c.nodes[b]);
  needed = sorted_node_pairs(std::move(needed), static_cast<int>(cache.node_mass.size()));
  std::vector<std::pair<int, int>> extra;
  std::set_difference(needed.begin(), needed.end(), cache.element_pairs.begin(), cache.element_pairs.end(),
                      std::back_inserter(extra));
  const bool missing = !std::includes(cache.contact_pairs.begin(), cache.contact_pairs.end(), extra.begin(),
                                      extra.end());
  // Keeping stale pairs costs little (zero blocks) and avoids re-analysing the matrix every time a contact
  // ends; shrink once they clearly dominate.
  const bool bloated = cache.contact_pairs.size() > 2 * extra.size() + 256;
  if (!missing && !bloated && !cache.pattern_stale) return false;
  cache.contact_pairs = std::move(extra);
  rebuild_pattern(cache);
  return true;
}

namespace {

std::array<Vec3, 6> gather_positions(const Mesh& mesh, const std::array<int, 6>& nodes) {
  std::array<Vec3, 6> x;
  for (int i = 0; i < 6; ++i) x[i] = mesh.nodes[nodes[i]].x;
  return x;
}

// The elastic energy (J) of the cache's elements with node n at x[n]. Elements are evaluated in parallel and
// summed in element order, so the sum is the same with or without threads. `angles`, if given, keeps the
// bending elements' angles at these positions.
double internal_energy_at(const std::vector<Vec3>& x, const ElementCache& cache, BendingAngleMemo* angles = nullptr) {
  const int faces = static_cast<int>(cache.faces.size());
  const int count = faces + static_cast<int>(cache.bending.size());
  std::vector<double> energy(count);
  if (angles) angles->reserve(cache.bending.size());
#pragma omp parallel for schedule(static) if (count > 4096)
  for (int k = 0; k < count; ++k) {
    if (k < faces) {
      const FaceElement& f = cache.faces[k];
      energy[k] = membrane_energy(x[f.nodes[0]], x[f.nodes[1]], x[f.nodes[2]], f.Dm_inv, f.area, f.k);
    } else {
      const BendingElement& b = cache.bending[k - faces];
      std::array<Vec3, 6> corners;
      for (int i = 0; i < 6; ++i) corners[i] = x[b.nodes[i]];
      Vec3 theta;
      energy[k] = plate_bending_energy(corners, b.has_wing, b.rest_theta, b.Q, angles ? &theta : nullptr);
      if (angles) angles->store(k - faces, corners, b.has_wing, theta);
    }
  }
  double sum = 0;
  for (double e : energy) sum += e;
  return sum;
}

}  // namespace

double internal_energy(const Mesh& mesh, const ElementCache& cache) {
  std::vector<Vec3> x;
  x.reserve(mesh.nodes.size());
  for (const Node& n : mesh.nodes) x.push_back(n.x);
  return internal_energy_at(x, cache);
}

double mechanical_energy(const Mesh& mesh, const ElementCache& cache, const ExternalLoads& loads) {
  double energy = internal_energy(mesh, cache);
  for (const Node& n : mesh.nodes) {
    if (n.dead) continue;
    energy += 0.5 * n.mass * n.v.squaredNorm() - n.mass * loads.gravity.dot(n.x);
  }
  for (const HandleSpring& s : loads.springs)
    energy += 0.5 * s.stiffness * (mesh.nodes[s.node].x - s.target).squaredNorm();
  return energy;
}

VecX internal_forces(const Mesh& mesh, const ElementCache& cache) {
  VecX f = VecX::Zero(3 * mesh.nodes.size());
  for (const auto& el : cache.faces) {
    const Vec9 g = membrane_gradient(mesh.nodes[el.nodes[0]].x, mesh.nodes[el.nodes[1]].x,
                                     mesh.nodes[el.nodes[2]].x, el.Dm_inv, el.area, el.k);
    for (int i = 0; i < 3; ++i) f.segment<3>(3 * el.nodes[i]) -= g.segment<3>(3 * i);
  }
  for (const auto& b : cache.bending) {
    const Vec18 g = plate_bending_terms(gather_positions(mesh, b.nodes), b.has_wing, b.rest_theta, b.Q,
                                        HessianKind::kNone).gradient;
    for (int i = 0; i < 6; ++i)
      if (i < 3 || b.has_wing[i - 3]) f.segment<3>(3 * b.nodes[i]) -= g.segment<3>(3 * i);
  }
  return f;
}

namespace {

// Element results computed in parallel, then scattered serially in element order (deterministic). Terms is the
// element's evaluation (energy, gradient, hessian), written in place.
template <int N, typename Terms>
struct ElementResult {
  Terms terms;
  double scale;  // the system takes scale * hessian (scaled block by block as it is scattered: only the lower
                 // blocks are needed, and scaling them there gives the same products)
  Eigen::Matrix<double, 3 * N, 1> rhs;
};

template <int N, typename Terms>
void scatter(const std::array<int, N>& dofs, const std::array<int, N * N>& blocks, const ElementResult<N, Terms>& r,
             BlockSystem& system) {
  system.add_element<N>(dofs, blocks, r.terms.hessian, r.scale);
  for (int i = 0; i < N; ++i)
    if (dofs[i] >= 0) system.rhs.segment<3>(3 * dofs[i]) += r.rhs.template segment<3>(3 * i);
}

template <int N>
Eigen::Matrix<double, 3 * N, 1> gather_velocity(const Mesh& mesh, const std::array<int, N>& nodes) {
  Eigen::Matrix<double, 3 * N, 1> v;
  for (int i = 0; i < N; ++i) v.template segment<3>(3 * i) = mesh.nodes[nodes[i]].v;
  return v;
}

// Backward Euler terms of one contact: the penalty implicit in position (blocks dt^2 h w_a w_b n n^T, force
// evaluated at x + dt v) and friction implicit in velocity (blocks dt c w_a w_b P). `dofs` are the rows of the
// contact's nodes (-1: not in this cloth, or held fixed; their velocity still counts).
void assemble_contact(const Mesh& mesh, const ContactTerm& c, const std::array<int, 4>& dofs, double dt,
                      BlockSystem& system) {
  const BlockPattern& pattern = *system.pattern;
  Vec3 u = c.outside_velocity;
  for (int i = 0; i < 4; ++i)
    if (c.nodes[i] != kNone) u += c.weights[i] * mesh.nodes[c.nodes[i]].v;
  const Mat3 nn = c.normal * c.normal.transpose();
  const Mat3 tangent = Mat3::Identity() - nn;
  const Mat3 K = dt * dt * c.stiffness * nn + dt * c.friction_damping * tangent;
  const Vec3 force = c.force * c.normal - dt * c.stiffness * c.normal.dot(u) * c.normal -
                     c.friction_damping * (tangent * u);
  for (int a = 0; a < 4; ++a) {
    const int da = dofs[a];
    if (da < 0) continue;
    system.rhs.segment<3>(3 * da) += dt * c.weights[a] * force;
    for (int b = 0; b < 4; ++b) {
      const int db = dofs[b];
      if (db < 0 || db > da) continue;  // lower blocks only; a node listed twice also gets the cross terms
      const int block = pattern.block_index(da, db);
      system.blocks[block] += c.weights[a] * c.weights[b] * K;
    }
  }
}

}  // namespace

namespace {

// Elements are evaluated in parallel a chunk at a time into a reused buffer, then scattered serially in element
// order: the sums are the same whatever the thread count (bit-identical results), and memory stays bounded
// (a whole-mesh buffer of 18x18 matrices would be ~170 MB at 64k faces, touched afresh every step). Chunks are
// large because every parallel region ends in a barrier, which is costly when the cores are shared.
constexpr int kAssemblyChunk = 8192;
// Below this many elements a chunk runs on one thread: a parallel region costs a barrier, and when the cores
// are shared (another process running) a barrier can wait a whole scheduler time slice (milliseconds). Measured
// on ARCSim's square.json (172 faces) on a loaded 2-core machine: 24 ms per step with 2 threads, 1.7 with one.
constexpr int kParallelMinElements = 2048;

template <int N, typename Terms, typename Element, typename Evaluate>
double assemble_elements(const Mesh& mesh, const std::vector<Element>& elements, const InternalAssembly& how,
                         Evaluate evaluate, BlockSystem& system) {
  const int count = static_cast<int>(elements.size());
  const bool need_velocity = how.velocity_scale != 0 || how.damping_velocity_scale != 0;
  std::vector<ElementResult<N, Terms>> results(std::min(count, kAssemblyChunk));
  double energy = 0;
  for (int begin = 0; begin < count; begin += kAssemblyChunk) {
    const int end = std::min(count, begin + kAssemblyChunk);
#pragma omp parallel for schedule(static) if (end - begin >= kParallelMinElements)
    for (int i = begin; i < end; ++i) {
      const Element& el = elements[i];
      ElementResult<N, Terms>& r = results[i - begin];
      evaluate(el, r.terms);
      r.scale = how.stiffness_scale + how.damping_scale * el.damping;
      r.rhs = -how.force_scale * r.terms.gradient;
      // lazyProduct: a fixed-size product Eigen unrolls (its general matrix-vector kernel costs twice as much
      // at 18x18).
      if (need_velocity)
        r.rhs -= (how.velocity_scale + how.damping_velocity_scale * el.damping) *
                 r.terms.hessian.lazyProduct(gather_velocity<N>(mesh, el.nodes));
    }
    for (int i = begin; i < end; ++i) {
      energy += results[i - begin].terms.energy;
      scatter<N>(elements[i].dofs, elements[i].blocks, results[i - begin], system);
    }
  }
  return energy;
}

}  // namespace

double assemble_element_terms(const Mesh& mesh, const std::vector<FaceElement>& faces,
                              const std::vector<BendingElement>& bending, const InternalAssembly& how,
                              BlockSystem& system, const BendingAngleMemo* angles) {
  double energy = assemble_elements<3, MembraneTerms>(
      mesh, faces, how,
      [&](const FaceElement& el, MembraneTerms& t) {
        t = membrane_terms(mesh.nodes[el.nodes[0]].x, mesh.nodes[el.nodes[1]].x, mesh.nodes[el.nodes[2]].x,
                           el.Dm_inv, el.area, el.k, 1.0, HessianKind::kProjected);
      },
      system);
  energy += assemble_elements<6, PlateBendingTerms>(
      mesh, bending, how,
      [&](const BendingElement& el, PlateBendingTerms& t) {
        const std::array<Vec3, 6> x = gather_positions(mesh, el.nodes);
        const Vec3* theta = angles ? angles->find(static_cast<size_t>(&el - bending.data()), x, el.has_wing) : nullptr;
        plate_bending_terms(x, el.has_wing, el.rest_theta, el.Q, HessianKind::kProjected, t, theta);
      },
      system);
  return energy;
}

double assemble_internal(const Mesh& mesh, const ElementCache& cache, const InternalAssembly& how,
                         BlockSystem& system) {
  return assemble_element_terms(mesh, cache.faces, cache.bending, how, system);
}

void assemble_implicit_euler(const Mesh& mesh, const std::vector<FaceElement>& faces,
                             const std::vector<BendingElement>& bending, const SystemDofs& dofs,
                             const ExternalLoads& loads, double dt, BlockSystem& system,
                             Linearisation linearisation, std::vector<CompactWindForce>* wind,
                             const BendingAngleMemo* angles) {
  // Backward Euler linearised once (ARCSim): with H the PSD stiffness, beta the damping coefficient,
  //   (M + dt (dt + beta) H - dt D_v) dv = dt [ f - (dt + beta) H v + f_ext ]
  // where D_v is the velocity Jacobian of air drag. Units: blocks in kg, rhs in N s.
  InternalAssembly how;
  how.stiffness_scale = dt * dt;
  how.damping_scale = dt;
  how.force_scale = dt;
  const bool newton = linearisation == Linearisation::kNewtonFromRest;
  how.velocity_scale = newton ? 0 : dt * dt;
  how.damping_velocity_scale = dt;
  assemble_element_terms(mesh, faces, bending, how, system, angles);

  for (int d = 0; d < dofs.count(); ++d) {
    const Node& node = mesh.nodes[dofs.node(d)];
    system.add_diagonal(d, node.mass * Mat3::Identity());
    system.rhs.segment<3>(3 * d) += dt * node.mass * loads.gravity;
    if (newton) system.rhs.segment<3>(3 * d) -= node.mass * node.v;
  }
  for (const HandleSpring& s : loads.springs) {
    // Spring energy k/2 |x - target|^2, implicit in position.
    const int d = dofs.dof(s.node);
    if (d < 0) continue;
    const Node& node = mesh.nodes[s.node];
    system.add_diagonal(d, dt * dt * s.stiffness * Mat3::Identity());
    const double prediction = newton ? 0 : dt;
    system.rhs.segment<3>(3 * d) += dt * (-s.stiffness * (node.x - s.target) - prediction * s.stiffness * node.v);
  }
  if (wind) wind->clear();
  if (loads.wind.density != 0 || loads.wind.drag != 0) {
    if (wind) wind->reserve(faces.size());
    for (const auto& el : faces) {
      const WindForce w = wind_force(mesh.nodes[el.nodes[0]].x, mesh.nodes[el.nodes[1]].x,
                                     mesh.nodes[el.nodes[2]].x, mesh.nodes[el.nodes[0]].v,
                                     mesh.nodes[el.nodes[1]].v, mesh.nodes[el.nodes[2]].v, loads.wind.velocity,
                                     loads.wind.density, loads.wind.drag);
      if (wind) wind->push_back(CompactWindForce::of(w));
      system.add_element<3>(el.dofs, el.blocks, w.jacobian, -dt);
      for (int i = 0; i < 3; ++i)
        if (el.dofs[i] >= 0) system.rhs.segment<3>(3 * el.dofs[i]) += dt * w.force.segment<3>(3 * i);
    }
  }
  for (const ContactTerm& c : loads.contacts) {
    std::array<int, 4> contact_dofs;
    bool touches = false;
    for (int i = 0; i < 4; ++i) {
      contact_dofs[i] = c.nodes[i] == kNone ? -1 : dofs.dof(c.nodes[i]);
      touches = touches || contact_dofs[i] >= 0;
    }
    if (touches) assemble_contact(mesh, c, contact_dofs, dt, system);
  }
}

void StepTiming::add(const StepTiming& other) {
  assembly += other.assembly;
  factorization += other.factorization;
  solve += other.solve;
  solves += other.solves;
  factorizations += other.factorizations;
  iterations += other.iterations;
  residuals.insert(residuals.end(), other.residuals.begin(), other.residuals.end());
}

VecX factor_and_solve(CholeskySolver& solver, const BlockSystem& system, const std::string& step,
                      StepTiming& timing, const std::function<std::string()>& explain) {
  VecX dv;
  SolveReport report;
  if (!solver.solve_system(system, dv, report))
    throw NumericalError(step + ": the system matrix is not positive definite (CHOLMOD factorisation failed" +
                         (explain ? ": " + explain() : std::string()) + "); the simulation is unstable");
  if (!dv.allFinite()) throw NumericalError(step + ": velocity update is not finite");
  timing.factorization += report.factor_seconds;
  timing.solve += report.solve_seconds;
  ++timing.solves;
  timing.factorizations += report.factorized ? 1 : 0;
  timing.iterations += report.iterations;
  timing.residuals.push_back(report.residual);
  return dv;
}

namespace {

// The incremental potential (J) the step's linear system is one Newton step of, at the velocities
// v = v_n + alpha dv (x = x_n + dt v): inertia 1/2 |v - v_n|^2_M, the elastic energy at x, gravity, the handle
// springs, each contact's penalty energy k d^3 / (6T) at its gap change dt n.u (repulsion_penalty; released
// past the thickness) and friction dissipation dt c |(I - n n^T) u|^2 / 2, and the wind as linearised in the
// system. Rayleigh damping, a quadratic in v, is added by step_fraction when it is needed.
// `magnitude` (J) gets the sum of the terms' absolute values, the scale of the sum's rounding.
// The wind's part is face e's -dt (alpha wind.linear[e] + alpha^2 wind.quadratic[e] / 2) (StepWind).
struct StepWind {
  std::vector<double> linear;     // f_e . dv_e (N m/s)
  std::vector<double> quadratic;  // dv_e . J_e dv_e (kg m^2/s^3)
};

// The wind terms of the faces' air forces as assembled, f_e and J_e (their velocity Jacobian), along dv_e, the
// faces' nodes' rows of dv. alpha dv_e's terms are alpha and alpha^2 times these, exactly for alpha a power of
// two (step_fraction's), so step_potential gets the same sums as from the forces themselves.
StepWind step_wind(const ElementCache& cache, const std::vector<CompactWindForce>& wind, const VecX& dv) {
  StepWind out;
  out.linear.resize(wind.size());
  out.quadratic.resize(wind.size());
  for (size_t e = 0; e < wind.size(); ++e) {
    const FaceElement& el = cache.faces[e];
    Vec9 change, force;
    for (int i = 0; i < 3; ++i) {
      change.segment<3>(3 * i) = dv.segment<3>(3 * el.nodes[i]);
      force.segment<3>(3 * i) = wind[e].node_force;
    }
    out.linear[e] = force.dot(change);
    out.quadratic[e] = change.dot(wind[e].jacobian_times(change));
  }
  return out;
}

double step_potential(const Mesh& mesh, const ElementCache& cache, const ExternalLoads& loads, double dt,
                      const StepWind& wind, const VecX& dv, double alpha, BendingAngleMemo* angles,
                      double* magnitude = nullptr) {
  const int n = static_cast<int>(mesh.nodes.size());
  std::vector<Vec3> v(n), x(n);
  double potential = 0, signed_terms = 0;  // signed_terms: gravity and wind
  for (int i = 0; i < n; ++i) {
    const Node& node = mesh.nodes[i];
    const Vec3 change = alpha * dv.segment<3>(3 * i);
    v[i] = node.v + change;
    x[i] = node.x + dt * v[i];
    potential += 0.5 * node.mass * change.squaredNorm();
    signed_terms -= dt * node.mass * loads.gravity.dot(v[i]);
  }
  potential += internal_energy_at(x, cache, angles);
  for (const HandleSpring& s : loads.springs) potential += 0.5 * s.stiffness * (x[s.node] - s.target).squaredNorm();
  for (const ContactTerm& c : loads.contacts) {
    Vec3 u = c.outside_velocity;
    for (int i = 0; i < 4; ++i)
      if (c.nodes[i] != kNone) u += c.weights[i] * v[c.nodes[i]];
    const double gap_change = dt * c.normal.dot(u);
    if (c.stiffness > 0) {
      // force = k d^2 / (2T), stiffness = k d / T (contact_terms).
      const double depth = 2 * c.force / c.stiffness;
      const double left = std::max(depth - gap_change, 0.0);
      potential += c.stiffness / depth * left * left * left / 6;
    } else {
      potential -= c.force * gap_change;
    }
    potential += 0.5 * dt * c.friction_damping * (u - c.normal * c.normal.dot(u)).squaredNorm();
  }
  const double alpha2 = alpha * alpha;
  for (size_t e = 0; e < wind.linear.size(); ++e)
    signed_terms -= dt * (alpha * wind.linear[e] + 0.5 * (alpha2 * wind.quadratic[e]));
  // Every other term is >= 0 except a released contact's linear one; gravity and wind carry a sign.
  if (magnitude) *magnitude = std::abs(potential) + std::abs(signed_terms);
  return potential + signed_terms;
}

// The fraction of the solved velocity change the step takes: 1, unless that raises the incremental potential
// (step_potential) by more than the linear model said it would lower it (`predicted`, J: the model is wrong by
// more than twice its own prediction); then the first of 1/2, 1/4, ..., 1/1024 that does not (none: 1). The
// lenient test keeps steps whole whose nonlinearity only eats into the predicted decrease, as ordinary steps'
// does. WHY: the step linearises once, and a direction the linear model finds almost free can be far from
// free. A border node of two faces folded by a few degrees has no membrane stiffness out of their plane but
// couples to their in-plane stretch by the sine of the fold, so the solve relieved a neighbour's stretch by
// swinging it out of the plane by 1/sin(fold) as far (1 cm on 1 cm edges in tests/stress/foil_crumple_test.cpp's
// case at 50 steps a frame: 55 J of elastic energy from one step, released as plastic work).
// `angles` keeps the bending angles of the last potential evaluated: at the positions the step takes.
double step_fraction(const Mesh& mesh, const ElementCache& cache, const ExternalLoads& loads, double dt,
                     const std::vector<CompactWindForce>& air, const VecX& dv, double predicted,
                     BendingAngleMemo* angles) {
  const StepWind wind = step_wind(cache, air, dv);
  double magnitude = 0;
  // alpha = 0 is never the step taken: its angles are not kept.
  const double start = step_potential(mesh, cache, loads, dt, wind, dv, 0, nullptr, &magnitude);
  // Rounding of the sums (~1e-16 of each term) must not shorten a step.
  const double allowed = std::max(predicted, 0.0) + 1e-9 * magnitude;
  auto lowers = [&](double from, double value) { return value <= from + allowed; };
  if (lowers(start, step_potential(mesh, cache, loads, dt, wind, dv, 1, angles))) return 1;  // the usual case
  // Only now the damping potential dt/2 v^T B v, B = sum of beta_e H_e at x_n as the system has it: a
  // damped step may raise the rest of the potential by less than it lowers this part.
  BlockSystem damping;
  damping.reset(cache.pattern);
  InternalAssembly how;
  how.stiffness_scale = 0;
  how.damping_scale = 1;
  how.force_scale = 0;
  assemble_element_terms(mesh, cache.faces, cache.bending, how, damping);
  VecX v(dv.size());
  for (size_t i = 0; i < mesh.nodes.size(); ++i) v.segment<3>(3 * i) = mesh.nodes[i].v;
  const VecX Bv = damping.multiply(v), Bdv = damping.multiply(dv);
  auto damping_potential = [&](double alpha) {
    return 0.5 * dt * (v.dot(Bv) + 2 * alpha * dv.dot(Bv) + alpha * alpha * dv.dot(Bdv));
  };
  constexpr int kMaxHalvings = 10;
  const double full_start = start + damping_potential(0);
  double alpha = 1;
  for (int k = 0; k <= kMaxHalvings; ++k) {
    if (lowers(full_start, step_potential(mesh, cache, loads, dt, wind, dv, alpha, angles) + damping_potential(alpha)))
      return alpha;
    alpha *= 0.5;
  }
  // No fraction lowers it: dv is no descent direction of this potential (the system's force prediction
  // f(x_n) + dt H v_n is far from f(x_n + dt v_n), as for paper-ornament's glass shell at its first step), so
  // the potential cannot judge the step; it is taken whole, as before.
  return 1;
}

}  // namespace

void implicit_euler_step(Mesh& mesh, ElementCache& cache, CholeskySolver& solver, const ExternalLoads& loads,
                         double dt, StepTiming* timing) {
  const auto t0 = std::chrono::steady_clock::now();
  const int n = static_cast<int>(mesh.nodes.size());
  ensure_pattern(cache);
  BlockSystem system;
  system.reset(cache.pattern);
  std::vector<CompactWindForce> wind;
  assemble_implicit_euler(mesh, cache.faces, cache.bending, SystemDofs::all_nodes(n), loads, dt, system,
                          Linearisation::kStep, &wind, &cache.angles);
  if (!loads.pinned.empty()) {
    // Dirichlet: zero the pinned rows and columns, unit diagonal, zero right-hand side (dv = 0).
    for (int k = 0; k < cache.pattern.block_count(); ++k) {
      const int r = cache.pattern.block_row(k), c = cache.pattern.block_col(k);
      if (!loads.pinned[r] && !loads.pinned[c]) continue;
      // The node's own mass on the diagonal keeps the matrix well scaled.
      system.blocks[k] = (r == c) ? Mat3(std::max(mesh.nodes[r].mass, 1e-12) * Mat3::Identity()) : Mat3::Zero();
    }
    for (int i = 0; i < n; ++i)
      if (loads.pinned[i]) system.rhs.segment<3>(3 * i).setZero();
  }
  StepTiming times;
  times.assembly = seconds_since(t0);
  const VecX dv = factor_and_solve(solver, system, "implicit step", times, [&] {
    return explain_indefinite_system(mesh, cache.faces, cache.bending, SystemDofs::all_nodes(n), loads, dt, system,
                                     solver.failed_row());
  });
  // The linear model's decrease of the potential: b.dv - dv.A dv / 2 = b.dv / 2 (A dv = b).
  const double alpha = step_fraction(mesh, cache, loads, dt, wind, dv, 0.5 * system.rhs.dot(dv), &cache.angles);
  for (int i = 0; i < n; ++i) {
    Node& node = mesh.nodes[i];
    const Vec3 change = alpha * dv.segment<3>(3 * i);
    node.v += change;
    node.a = change / dt;
    node.x0 = node.x;
    node.x += dt * node.v;
  }
  if (timing) timing->add(times);
}

}  // namespace arcsim
