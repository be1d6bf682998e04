#include "physics/zone_solve.hpp"

#include <algorithm>
#include <chrono>
#include <iterator>
#include <utility>

#include "physics/face_element.hpp"
#include "physics/system_dofs.hpp"
#include "physics/system_premises.hpp"

namespace arcsim {

namespace {

void sort_unique(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// Pairs of distinct rows coupled by an element (rows of fixed nodes left out).
template <size_t N>
void add_dof_pairs(const std::array<int, N>& dofs, std::vector<std::pair<int, int>>& pairs) {
  for (size_t a = 0; a < N; ++a)
    for (size_t b = 0; b < a; ++b)
      if (dofs[a] >= 0 && dofs[b] >= 0 && dofs[a] != dofs[b]) pairs.emplace_back(dofs[a], dofs[b]);
}

template <size_t N>
std::array<int, N> dofs_of(const std::array<int, N>& nodes, const SystemDofs& dofs) {
  std::array<int, N> out;
  for (size_t i = 0; i < N; ++i) out[i] = nodes[i] == kNone ? -1 : dofs.dof(nodes[i]);
  return out;
}

// An element with its rows set to the zone's (-1 for fixed nodes); its row pairs go to `pairs`.
template <typename Element>
Element with_zone_rows(Element el, const SystemDofs& dofs, std::vector<std::pair<int, int>>& pairs) {
  el.dofs = dofs_of(el.nodes, dofs);
  add_dof_pairs(el.dofs, pairs);
  return el;
}

}  // namespace

std::vector<int> node_rings(const Mesh& mesh, const std::vector<int>& nodes, int rings) {
  std::vector<int> reached = nodes;
  sort_unique(reached);
  std::vector<int> front = reached;
  for (int ring = 0; ring < rings && !front.empty(); ++ring) {
    std::vector<int> next;
    for (int n : front)
      for (int e : mesh.nodes[n].edges) {
        const Edge& edge = mesh.edges[e];
        if (edge.dead) continue;
        const int other = edge.n[0] == n ? edge.n[1] : edge.n[0];
        if (!std::binary_search(reached.begin(), reached.end(), other)) next.push_back(other);
      }
    sort_unique(next);
    std::vector<int> merged;
    merged.reserve(reached.size() + next.size());
    std::merge(reached.begin(), reached.end(), next.begin(), next.end(), std::back_inserter(merged));
    reached = std::move(merged);
    front = std::move(next);
  }
  return reached;
}

ZoneSystem::ZoneSystem(const Mesh& mesh, const std::vector<Material>& materials,
                       const std::vector<int>& zone_nodes, const ExternalLoads& loads,
                       const ZoneSolveOptions& options)
    : options_(options) {
  const int node_count = static_cast<int>(mesh.nodes.size());
  // The zone's live nodes; its free nodes (the system's rows) are those the loads do not pin (a pinned node
  // keeps its velocity, as in the full step).
  for (int n : zone_nodes)
    if (n >= 0 && n < node_count && !mesh.nodes[n].dead) nodes_.push_back(n);
  sort_unique(nodes_);
  std::vector<int> free_nodes;
  // Nodes past the end of `pinned` were added by edits after the loads were made (fracture's openings): free.
  for (int n : nodes_)
    if (n >= static_cast<int>(loads.pinned.size()) || !loads.pinned[n]) free_nodes.push_back(n);
  dofs_ = SystemDofs::only(free_nodes);
  if (free_nodes.empty()) return;

  // The zone's elements: faces around a free node (membrane) and, for bending, also the faces that have a free
  // node as a wing (across the edge opposite it). In face order, as the full step assembles them.
  std::vector<int> membrane_faces, bending_faces;
  for (int n : free_nodes) {
    const std::vector<int> own = mesh.node_faces(n), reaching = bending_faces_of_node(mesh, n);
    membrane_faces.insert(membrane_faces.end(), own.begin(), own.end());
    bending_faces.insert(bending_faces.end(), reaching.begin(), reaching.end());
  }
  sort_unique(membrane_faces);
  sort_unique(bending_faces);

  faces_.reserve(membrane_faces.size());
  bending_.reserve(bending_faces.size());
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> support;
  for (int f : membrane_faces) faces_.push_back(with_zone_rows(make_face_element(mesh, materials, f), dofs_, pairs));
  for (int f : bending_faces) {
    bending_.push_back(with_zone_rows(make_bending_element(mesh, materials, f), dofs_, pairs));
    for (int i = 0; i < 6; ++i)
      if (bending_.back().dofs[i] < 0) support.push_back(bending_.back().nodes[i]);
  }
  for (const ContactTerm& c : loads.contacts) add_dof_pairs(dofs_of(c.nodes, dofs_), pairs);

  pattern_.build(dofs_.count(), std::move(pairs));
  for (FaceElement& el : faces_) el.blocks = element_block_ids<3>(pattern_, el.dofs);
  for (BendingElement& el : bending_) el.blocks = element_block_ids<6>(pattern_, el.dofs);

  // Support: the n-ring around the zone and every fixed node the zone's elements read.
  for (int n : node_rings(mesh, nodes_, std::max(options.support_rings, 1))) support.push_back(n);
  for (const FaceElement& el : faces_)
    for (int i = 0; i < 3; ++i) support.push_back(el.nodes[i]);
  sort_unique(support);
  std::set_difference(support.begin(), support.end(), nodes_.begin(), nodes_.end(),
                      std::back_inserter(support_nodes_));
}

ZoneSolution ZoneSystem::solve(const Mesh& mesh, const ExternalLoads& loads, double dt,
                               CholeskySolver& solver) const {
  const auto t0 = std::chrono::steady_clock::now();
  ZoneSolution out;
  out.nodes = nodes_;
  const size_t count = out.nodes.size();
  out.dv.assign(count, Vec3::Zero());
  out.v.resize(count);
  out.x.resize(count);
  auto finish = [&] {
    for (size_t i = 0; i < count; ++i) {
      const Node& node = mesh.nodes[out.nodes[i]];
      out.v[i] = node.v + out.dv[i];
      out.x[i] = node.x + dt * out.v[i];
    }
  };
  if (dofs_.count() == 0) {
    finish();
    return out;
  }

  BlockSystem system;
  system.reset(pattern_);
  assemble_implicit_euler(mesh, faces_, bending_, dofs_, loads, dt, system, options_.linearisation);
  out.timing.assembly = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const VecX dv = factor_and_solve(solver, system, "zone step", out.timing, [&] {
    return explain_indefinite_system(mesh, faces_, bending_, dofs_, loads, dt, system, solver.failed_row());
  });

  for (size_t i = 0; i < count; ++i) {
    const int d = dofs_.dof(out.nodes[i]);
    if (d >= 0) out.dv[i] = dv.segment<3>(3 * d);
  }
  finish();
  out.support_nodes = support_nodes_;
  out.face_elements = static_cast<int>(faces_.size());
  out.bending_elements = static_cast<int>(bending_.size());
  return out;
}

ZoneSolution solve_zone(const Mesh& mesh, const std::vector<Material>& materials,
                        const std::vector<int>& zone_nodes, const ExternalLoads& loads, double dt,
                        CholeskySolver& solver, const ZoneSolveOptions& options) {
  return ZoneSystem(mesh, materials, zone_nodes, loads, options).solve(mesh, loads, dt, solver);
}

void apply_zone_solution(Mesh& mesh, const ZoneSolution& solution, double dt) {
  for (size_t i = 0; i < solution.nodes.size(); ++i) {
    Node& node = mesh.nodes[solution.nodes[i]];
    node.v = solution.v[i];
    node.a = solution.dv[i] / dt;
    node.x0 = node.x;
    node.x = solution.x[i];
  }
}

ZoneSolution zone_implicit_step(Mesh& mesh, const std::vector<Material>& materials,
                                const std::vector<int>& zone_nodes, const ExternalLoads& loads, double dt,
                                CholeskySolver& solver, const ZoneSolveOptions& options) {
  ZoneSolution solution = solve_zone(mesh, materials, zone_nodes, loads, dt, solver, options);
  apply_zone_solution(mesh, solution, dt);
  return solution;
}

}  // namespace arcsim
