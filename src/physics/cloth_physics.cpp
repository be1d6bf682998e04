#include "physics/cloth_physics.hpp"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <string>

#include "io/errors.hpp"
#include "physics/bending.hpp"
#include "physics/plate_bending.hpp"
#include "physics/membrane.hpp"
#include "physics/wind.hpp"

namespace arcsim {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double weakening_factor(const Material& m, double damage) { return 1.0 / (1.0 + m.weakening * damage); }

// Bending stiffness (N m) of face f for bending about an axis along rest direction d.
double face_bending_stiffness(const Mesh& mesh, const std::vector<Material>& materials, int f, const Vec3& d) {
  const Face& face = mesh.faces[f];
  const Material& m = materials[face.material];
  const double angle = std::atan2(face.rest_frame.col(1).dot(d), face.rest_frame.col(0).dot(d));
  return m.bending_stiffness(face.thickness, angle);
}

// Plastic stretch expressed in the face's 2D material frame.
Mat2 plastic_stretch_2d(const Face& f) {
  if (f.Fp.isIdentity(0)) return Mat2::Identity();
  return f.rest_frame.transpose() * f.Fp * f.rest_frame;
}

}  // namespace

void update_node_masses(Mesh& mesh, const std::vector<Material>& materials) {
  for (Node& n : mesh.nodes) n.mass = 0;
  for (const Face& f : mesh.faces) {
    if (f.dead) continue;
    const double m = materials[f.material].area_density(f.thickness) * f.rest_area / 3;
    for (int i = 0; i < 3; ++i) mesh.nodes[mesh.verts[f.v[i]].node].mass += m;
  }
}

void build_element_cache(const Mesh& mesh, const std::vector<Material>& materials, ElementCache& cache) {
  cache.faces.clear();
  cache.bending.clear();
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(18 * mesh.faces.size());

  for (size_t fi = 0; fi < mesh.faces.size(); ++fi) {
    const Face& f = mesh.faces[fi];
    ElementCache::FaceElement el;
    for (int i = 0; i < 3; ++i) el.nodes[i] = mesh.face_node(static_cast<int>(fi), i);
    const Material& m = materials[f.material];
    el.Dm_inv = f.Dm_inv * plastic_stretch_2d(f);
    el.area = f.rest_area;
    el.k = m.membrane_stiffness(f.thickness);
    const double w = weakening_factor(m, f.damage);
    el.k.k11 *= w, el.k.k12 *= w, el.k.k22 *= w, el.k.k33 *= w;
    el.damping = m.damping;
    cache.faces.push_back(el);
    pairs.emplace_back(el.nodes[0], el.nodes[1]);
    pairs.emplace_back(el.nodes[1], el.nodes[2]);
    pairs.emplace_back(el.nodes[2], el.nodes[0]);
  }

  for (size_t fi = 0; fi < mesh.faces.size(); ++fi) {
    const Face& f = mesh.faces[fi];
    const Material& m = materials[f.material];
    ElementCache::BendingElement b;
    std::array<double, 3> lengths;
    std::array<Vec3, 3> normals;
    std::array<double, 3> kb;
    for (int i = 0; i < 3; ++i) {
      const int e = f.e[i];
      const Edge& ed = mesh.edges[e];
      b.nodes[i] = mesh.face_node(static_cast<int>(fi), i);
      const int other = mesh.other_face(e, static_cast<int>(fi));
      b.has_wing[i] = other != kNone;
      b.nodes[3 + i] = other != kNone ? mesh.opposite_node(e, other) : kNone;
      b.rest_theta[i] = ed.rest_theta;
      const Vec3 d = mesh.verts[f.v[(i + 1) % 3]].u - mesh.verts[f.v[i]].u;
      lengths[i] = d.norm();
      normals[i] = lengths[i] > 0 ? Vec3(d.cross(f.rest_normal) / lengths[i]) : Vec3::Zero();
      // Bending about an axis along the edge; weakened by the edge's plastic damage.
      kb[i] = face_bending_stiffness(mesh, materials, static_cast<int>(fi), d) / (1.0 + m.weakening * ed.damage);
    }
    for (int i = 0; i < 3; ++i)
      if (!b.has_wing[i]) b.nodes[3 + i] = b.nodes[0];
    // Direction-dependent stiffness (data-driven materials) enters as sqrt(kb_i kb_j) in Q.
    const double nu = m.data_driven ? 0.0 : m.poisson_ratio;
    b.Q = plate_bending_matrix(lengths, normals, f.rest_area, 1.0, nu, b.has_wing);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) b.Q(i, j) *= std::sqrt(kb[i] * kb[j]);
    b.damping = m.damping;
    cache.bending.push_back(b);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < i; ++j)
        if (b.nodes[i] != b.nodes[j]) pairs.emplace_back(b.nodes[i], b.nodes[j]);
  }

  cache.pattern.build(static_cast<int>(mesh.nodes.size()), std::move(pairs));
  for (auto& f : cache.faces) f.blocks = element_block_ids<3>(cache.pattern, f.nodes);
  for (auto& b : cache.bending) b.blocks = element_block_ids<6>(cache.pattern, b.nodes);
  cache.node_mass.resize(mesh.nodes.size());
  for (size_t n = 0; n < mesh.nodes.size(); ++n) cache.node_mass[n] = mesh.nodes[n].mass;
}

namespace {

std::array<Vec3, 6> gather_positions(const Mesh& mesh, const std::array<int, 6>& nodes) {
  std::array<Vec3, 6> x;
  for (int i = 0; i < 6; ++i) x[i] = mesh.nodes[nodes[i]].x;
  return x;
}

}  // namespace

double internal_energy(const Mesh& mesh, const ElementCache& cache) {
  double energy = 0;
  for (const auto& f : cache.faces)
    energy += membrane_energy(mesh.nodes[f.nodes[0]].x, mesh.nodes[f.nodes[1]].x, mesh.nodes[f.nodes[2]].x,
                              f.Dm_inv, f.area, f.k);
  for (const auto& b : cache.bending)
    energy += plate_bending_terms(gather_positions(mesh, b.nodes), b.has_wing, b.rest_theta, b.Q,
                                  HessianKind::kNone).energy;
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

// Element results computed in parallel, then scattered serially in element order (deterministic).
template <int N>
struct ElementResult {
  double energy;
  Eigen::Matrix<double, 3 * N, 1> rhs;
  Eigen::Matrix<double, 3 * N, 3 * N> K;
};

template <int N>
void scatter(const std::array<int, N>& nodes, const std::array<int, N * N>& blocks, const ElementResult<N>& r,
             BlockSystem& system) {
  system.add_element<N>(nodes, blocks, r.K, 1.0);
  for (int i = 0; i < N; ++i) system.rhs.segment<3>(3 * nodes[i]) += r.rhs.template segment<3>(3 * i);
}

template <int N>
Eigen::Matrix<double, 3 * N, 1> gather_velocity(const Mesh& mesh, const std::array<int, N>& nodes) {
  Eigen::Matrix<double, 3 * N, 1> v;
  for (int i = 0; i < N; ++i) v.template segment<3>(3 * i) = mesh.nodes[nodes[i]].v;
  return v;
}

}  // namespace

double assemble_internal(const Mesh& mesh, const ElementCache& cache, const InternalAssembly& how,
                         BlockSystem& system) {
  const int nf = static_cast<int>(cache.faces.size());
  const int nb = static_cast<int>(cache.bending.size());
  std::vector<ElementResult<3>> face_results(nf);
  std::vector<ElementResult<6>> bending_results(nb);
  const bool need_velocity = how.velocity_scale != 0 || how.damping_velocity_scale != 0;

#pragma omp parallel
  {
#pragma omp for schedule(static) nowait
    for (int i = 0; i < nf; ++i) {
      const auto& el = cache.faces[i];
      const MembraneTerms t =
          membrane_terms(mesh.nodes[el.nodes[0]].x, mesh.nodes[el.nodes[1]].x, mesh.nodes[el.nodes[2]].x,
                         el.Dm_inv, el.area, el.k, 1.0, HessianKind::kProjected);
      auto& r = face_results[i];
      r.energy = t.energy;
      r.K = (how.stiffness_scale + how.damping_scale * el.damping) * t.hessian;
      r.rhs = -how.force_scale * t.gradient;
      if (need_velocity)
        r.rhs -= (how.velocity_scale + how.damping_velocity_scale * el.damping) *
                 (t.hessian * gather_velocity<3>(mesh, el.nodes));
    }
#pragma omp for schedule(static)
    for (int i = 0; i < nb; ++i) {
      const auto& el = cache.bending[i];
      const PlateBendingTerms t = plate_bending_terms(gather_positions(mesh, el.nodes), el.has_wing,
                                                      el.rest_theta, el.Q, HessianKind::kProjected);
      auto& r = bending_results[i];
      r.energy = t.energy;
      r.K = (how.stiffness_scale + how.damping_scale * el.damping) * t.hessian;
      r.rhs = -how.force_scale * t.gradient;
      if (need_velocity)
        r.rhs -= (how.velocity_scale + how.damping_velocity_scale * el.damping) *
                 (t.hessian * gather_velocity<6>(mesh, el.nodes));
    }
  }

  double energy = 0;
  for (int i = 0; i < nf; ++i) {
    energy += face_results[i].energy;
    scatter<3>(cache.faces[i].nodes, cache.faces[i].blocks, face_results[i], system);
  }
  for (int i = 0; i < nb; ++i) {
    energy += bending_results[i].energy;
    scatter<6>(cache.bending[i].nodes, cache.bending[i].blocks, bending_results[i], system);
  }
  return energy;
}

void implicit_euler_step(Mesh& mesh, ElementCache& cache, CholeskySolver& solver, const ExternalLoads& loads,
                         double dt, StepTiming* timing) {
  const auto t0 = std::chrono::steady_clock::now();
  const int n = static_cast<int>(mesh.nodes.size());
  BlockSystem system;
  system.reset(cache.pattern);

  // Backward Euler linearised once (ARCSim): with H the PSD stiffness, beta the damping coefficient,
  //   (M + dt (dt + beta) H - dt D_v) dv = dt [ f - (dt + beta) H v + f_ext ]
  // where D_v is the velocity Jacobian of air drag. Units: blocks in kg, rhs in N s.
  InternalAssembly how;
  how.stiffness_scale = dt * dt;
  how.damping_scale = dt;
  how.force_scale = dt;
  how.velocity_scale = dt * dt;
  how.damping_velocity_scale = dt;
  assemble_internal(mesh, cache, how, system);

  for (int i = 0; i < n; ++i) {
    const double m = mesh.nodes[i].mass;
    system.add_diagonal(i, m * Mat3::Identity());
    system.rhs.segment<3>(3 * i) += dt * m * loads.gravity;
  }
  for (const HandleSpring& s : loads.springs) {
    // Spring energy k/2 |x - target|^2, implicit in position.
    const Node& node = mesh.nodes[s.node];
    system.add_diagonal(s.node, dt * dt * s.stiffness * Mat3::Identity());
    system.rhs.segment<3>(3 * s.node) += dt * (-s.stiffness * (node.x - s.target) - dt * s.stiffness * node.v);
  }
  if (loads.wind.density != 0 || loads.wind.drag != 0) {
    for (const auto& el : cache.faces) {
      const WindForce w = wind_force(mesh.nodes[el.nodes[0]].x, mesh.nodes[el.nodes[1]].x,
                                     mesh.nodes[el.nodes[2]].x, mesh.nodes[el.nodes[0]].v,
                                     mesh.nodes[el.nodes[1]].v, mesh.nodes[el.nodes[2]].v, loads.wind.velocity,
                                     loads.wind.density, loads.wind.drag);
      system.add_element<3>(el.nodes, el.blocks, w.jacobian, -dt);
      for (int i = 0; i < 3; ++i) system.rhs.segment<3>(3 * el.nodes[i]) += dt * w.force.segment<3>(3 * i);
    }
  }
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
  const auto t1 = std::chrono::steady_clock::now();
  if (!solver.factorize(system))
    throw NumericalError("implicit step: the system matrix is not positive definite (CHOLMOD factorisation "
                         "failed); the simulation is unstable");
  const auto t2 = std::chrono::steady_clock::now();
  const VecX dv = solver.solve(system.rhs);
  if (!dv.allFinite()) throw NumericalError("implicit step: velocity update is not finite");
  for (int i = 0; i < n; ++i) {
    Node& node = mesh.nodes[i];
    node.v += dv.segment<3>(3 * i);
    node.a = dv.segment<3>(3 * i) / dt;
    node.x0 = node.x;
    node.x += dt * node.v;
  }
  if (timing) {
    timing->assembly += std::chrono::duration<double>(t1 - t0).count();
    timing->factorization += std::chrono::duration<double>(t2 - t1).count();
    timing->solve += seconds_since(t2);
  }
}

}  // namespace arcsim
